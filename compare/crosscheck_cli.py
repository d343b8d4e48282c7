"""The ``crosscheck`` command: one train, or every preset with a summary page."""

from __future__ import annotations

import html
import json
import math
from pathlib import Path

from lumped import load_train, preset_names
from lumped.errors import GearcheckError

from .baseline import BASELINE_DIR, check_settings, compare_to_baseline, read_baseline, write_baseline
from .crosscheck import crosscheck
from .measurements import attach, load_measurements
from .progress import ProgressBar
from .report import write_report
from .tolerances import Tolerances


def _baseline_path(args, spec) -> Path | None:
    if args.baseline is None:
        return None
    if str(args.baseline) == "shipped":
        return BASELINE_DIR / f"{spec.name}.json"
    return Path(args.baseline)


def run_one(args, spec, out: Path) -> tuple[dict, list[str]]:
    """Cross-check ``spec``, write its report into ``out``; return (report data, moved baseline metrics)."""
    tolerances = Tolerances.for_train(spec, args.tolerances)
    baseline = _baseline_path(args, spec)
    stored = None
    if baseline is not None and not args.update_baseline:
        stored = read_baseline(baseline)  # before the run: a mismatch is refused at once
        check_settings(stored, args.duration, spec.operating.input_speed * 60 / (2 * math.pi))
    bar = ProgressBar(f"crosscheck {spec.name}")
    if args.model == "general":
        result = crosscheck(spec, duration=args.duration, tolerances=tolerances, dt_lumped=args.dt_lumped,
                            dt_mujoco=args.dt_mujoco, sensor_band=args.sensor_band, progress=bar)
    else:
        from .published import crosscheck_published

        result = crosscheck_published(spec, model=args.model, duration=args.duration, tolerances=tolerances)
    bar.close()
    entries = list(spec.measurements)
    if args.measurements:
        entries += load_measurements(args.measurements)
    attach(result, entries)
    moved = []
    if baseline is not None and args.update_baseline:
        write_baseline(result, baseline)
    elif stored is not None:
        moved = compare_to_baseline(result, stored)
    data = write_report(result, out)
    return data, moved


def _verdict_line(spec, data, moved, out) -> str:
    v = data["verdict"]
    state = "PASS" if v["passed"] and not moved else "FAIL"
    detail = ""
    if v["failures"]:
        detail += f"; beyond tolerance: {', '.join(v['failures'])}"
    if moved:
        detail += f"; moved from baseline: {'; '.join(moved)}"
    return f"{spec.name}: {state}{detail} (report: {out / 'report.md'})"


def crosscheck_one(args, spec, out: Path) -> int:
    data, moved = run_one(args, spec, out)
    print(_verdict_line(spec, data, moved, out))
    return 0 if data["verdict"]["passed"] and not moved else 1


def crosscheck_all(args) -> int:
    if args.speed is not None:
        raise GearcheckError("--speed applies to one train; --all runs each preset at its own speed")
    rows = []
    worst = 0
    for name in preset_names():
        spec = load_train(name)
        out = args.out / name
        data, moved = run_one(args, spec, out)
        print(_verdict_line(spec, data, moved, out))
        ok = data["verdict"]["passed"] and not moved
        worst = max(worst, 0 if ok else 1)
        rows.append(_summary_row(name, data, moved, ok))
    write_summary(args.out, rows)
    print(f"summary: {args.out / 'summary.md'}")
    return worst


def _summary_row(name, data, moved, ok) -> dict:
    modes = data["modes"]
    gated = [q for q in data["quantities"] if q["status"] != "negligible"]

    def worst(*kinds):
        values = [q["errors"]["nrmse"]["value"] for q in gated if q["kind"] in kinds and q["errors"]["nrmse"]]
        return max(values) if values else None

    return {
        "train": name, "status": "PASS" if ok else "FAIL",
        "modes": len(modes), "max_mode_rel_error": max(m["rel_error"]["value"] for m in modes),
        "quantities": len(data["quantities"]), "failed": len(data["verdict"]["failures"]), "moved": len(moved),
        "worst_nrmse_mesh_force": worst("mesh_force"), "worst_nrmse_acceleration": worst("acceleration", "angular_acceleration"),
        "speed_rpm": data["settings"]["input_speed"]["value"],
    }


SUMMARY_COLUMNS = [("train", "train"), ("status", "status"), ("speed_rpm", "speed [rpm]"), ("modes", "modes"),
                   ("max_mode_rel_error", "max mode rel. diff."), ("quantities", "quantities"),
                   ("worst_nrmse_mesh_force", "worst NRMSE mesh force"),
                   ("worst_nrmse_acceleration", "worst NRMSE acceleration (linear, angular)"), ("failed", "failed"),
                   ("moved", "moved vs baseline")]


def _cell(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}" if math.isfinite(value) else str(value)
    return "—" if value is None else str(value)


def write_summary(out: Path, rows: list[dict]) -> None:
    out.mkdir(parents=True, exist_ok=True)
    (out / "summary.json").write_text(json.dumps({"presets": rows}, indent=2) + "\n", encoding="utf-8")
    header = [label for _, label in SUMMARY_COLUMNS]
    lines = ["# gearcheck cross-check of every preset", "", "| " + " | ".join(header) + " |",
             "|" + "---|" * len(header)]
    for r in rows:
        cells = [f"[{r['train']}]({r['train']}/report.md)"] + [_cell(r[k]) for k, _ in SUMMARY_COLUMNS[1:]]
        lines.append("| " + " | ".join(cells) + " |")
    (out / "summary.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    esc = html.escape
    body = ["<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>gearcheck summary</title>",
            "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}td,th{border:1px solid "
            "#ccc;padding:3px 8px}.FAIL{background:#fdd}.PASS{background:#dfd}</style></head><body>",
            "<h1>gearcheck cross-check of every preset</h1><table><tr>"
            + "".join(f"<th>{esc(h)}</th>" for h in header) + "</tr>"]
    for r in rows:
        cells = [f"<a href=\"{esc(r['train'])}/report.html\">{esc(r['train'])}</a>"]
        cells += [esc(_cell(r[k])) for k, _ in SUMMARY_COLUMNS[1:]]
        body.append(f"<tr class=\"{r['status']}\">" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    body.append("</table></body></html>\n")
    (out / "summary.html").write_text("\n".join(body), encoding="utf-8")
