"""The summary of a cross-check of several trains (every preset, or a fleet of train files): ``summary.json``,
``summary.md`` and ``summary.html``, headed by the overall verdict."""

from __future__ import annotations

import html
import json
import math
from pathlib import Path

from gearcheck.compare.presentation.html_page import page

ORDER = ("FAIL", "INCONCLUSIVE", "PASS")  # the overall verdict is the worst of the trains'
NAMED = 3  # quantities named in a row's reason (the report lists them all)


def summary_row(data: dict, folder: str) -> dict:
    """One train's row of the summary, from its report data (:func:`gearcheck.compare.presentation.report.to_dict`)
    and the folder its report is in: the verdict and its reason, and the worst NRMSE of each kind of quantity
    with that quantity's tolerance."""
    modes = data["modes"]
    gated = [q for q in data["quantities"] if q["status"] != "negligible" and q["errors"]["nrmse"]]

    def worst(*kinds) -> tuple[float | None, float | None]:
        quantities = [q for q in gated if q["kind"] in kinds]
        if not quantities:
            return None, None
        q = max(quantities, key=lambda q: q["errors"]["nrmse"]["value"])
        return q["errors"]["nrmse"]["value"], (q.get("tolerance_nrmse") or {}).get("value")

    verdict = data["verdict"]
    moved = verdict["moved_from_baseline"] or []
    mesh, mesh_tolerance = worst("mesh_force")
    acceleration, acceleration_tolerance = worst("acceleration", "angular_acceleration")
    return {
        "train": data["train"]["name"], "folder": folder, "status": verdict["verdict"], "reason": _reason(verdict),
        "modes": len(modes), "max_mode_rel_error": max((m["rel_error"]["value"] for m in modes), default=None),
        "quantities": len(data["quantities"]), "failed": len(verdict["failures"]), "moved": len(moved),
        "worst_nrmse_mesh_force": mesh, "tolerance_mesh_force": mesh_tolerance,
        "worst_nrmse_acceleration": acceleration, "tolerance_acceleration": acceleration_tolerance,
        "speed_rpm": data["settings"]["input_speed"]["value"],
    }


def _reason(verdict: dict) -> str:
    """Why a train has its verdict, in a few words."""
    def named(what: str, items: list) -> str:
        more = f" and {len(items) - NAMED} more" if len(items) > NAMED else ""
        return f"{what}: {', '.join(items[:NAMED])}{more}"
    parts = []
    if verdict["failures"]:
        parts.append(named("beyond tolerance", verdict["failures"]))
    if verdict["moved_from_baseline"]:
        parts.append(named("moved from baseline", verdict["moved_from_baseline"]))
    if verdict["unresolved"]:
        parts.append(named("cannot decide", verdict["unresolved"]))
    return "; ".join(parts) or "every quantity and mode within tolerance"


def overall(rows: list[dict]) -> str:
    """The fleet's verdict: FAIL when any train failed, else INCONCLUSIVE when any was, else PASS."""
    return min((r["status"] for r in rows), key=ORDER.index, default="PASS")


def overall_line(rows: list[dict]) -> str:
    """``overall: FAIL (1 failed, 0 inconclusive, 5 passed of 6 trains)``."""
    count = {v: sum(r["status"] == v for r in rows) for v in ORDER}
    return (f"overall: {overall(rows)} ({count['FAIL']} failed, {count['INCONCLUSIVE']} inconclusive, "
            f"{count['PASS']} passed of {len(rows)} trains)")


SUMMARY_COLUMNS = [("train", "train"), ("status", "status"), ("reason", "reason"), ("speed_rpm", "speed [rpm]"),
                   ("modes", "modes"), ("max_mode_rel_error", "max mode rel. diff."), ("quantities", "quantities"),
                   ("worst_nrmse_mesh_force", "worst NRMSE mesh force (tolerance)"),
                   ("worst_nrmse_acceleration", "worst NRMSE acceleration, linear or angular (tolerance)"),
                   ("failed", "failed"), ("moved", "moved vs baseline")]
TOLERANCE_OF = {"worst_nrmse_mesh_force": "tolerance_mesh_force",
                "worst_nrmse_acceleration": "tolerance_acceleration"}


def _number(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}" if math.isfinite(value) else str(value)
    return "—" if value is None else str(value)


def _cell(row: dict, key: str) -> str:
    if key in TOLERANCE_OF and row[key] is not None and row[TOLERANCE_OF[key]] is not None:
        return f"{_number(row[key])} ({_number(row[TOLERANCE_OF[key]])})"
    return _number(row[key])


def _link(row: dict, page_name: str) -> str:
    return f"{row['folder']}/{page_name}"


def write_summary(out: Path, rows: list[dict], what: str) -> None:
    """``summary.json``, ``summary.md`` and ``summary.html`` in ``out``, of the cross-check of ``what`` ("every
    preset", "6 trains")."""
    out.mkdir(parents=True, exist_ok=True)
    verdict, line = overall(rows), overall_line(rows)
    (out / "summary.json").write_text(json.dumps({"verdict": verdict, "trains": rows}, indent=2) + "\n",
                                      encoding="utf-8")
    header = [label for _, label in SUMMARY_COLUMNS]
    lines = [f"# gearcheck cross-check of {what}", "", f"**{line}**", "", "| " + " | ".join(header) + " |",
             "|" + "---|" * len(header)]
    for r in rows:
        cells = [f"[{r['train']}]({_link(r, 'report.md')})"] + [_cell(r, k) for k, _ in SUMMARY_COLUMNS[1:]]
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    (out / "summary.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    esc = html.escape
    body = [f"<h1>gearcheck cross-check of {esc(what)}</h1><p class=\"{verdict}\"><strong>{esc(line)}</strong></p>"
            "<table><tr>" + "".join(f"<th>{esc(h)}</th>" for h in header) + "</tr>"]
    for r in rows:
        cells = [f"<a href=\"{esc(_link(r, 'report.html'))}\">{esc(r['train'])}</a>"]
        cells += [esc(_cell(r, k)) for k, _ in SUMMARY_COLUMNS[1:]]
        body.append(f"<tr class=\"{r['status']}\">" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    body.append("</table>")
    (out / "summary.html").write_text(page("gearcheck summary", "\n".join(body)), encoding="utf-8")
