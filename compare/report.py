"""Cross-check reports: ``report.json`` (versioned schema), ``report.md``, ``report.html`` and PNGs.

Everything that changes from run to run for the same inputs (the timestamp and the wall
times) lives in one place: the ``volatile`` field of the JSON and the single ``Run:``
line of the Markdown and HTML.  Everything else is identical byte for byte.

JSON schema ``gearcheck.crosscheck`` version 1: every number that has a unit is an object
``{"value": x, "unit": "..."}``; dimensionless ratios carry unit ``"1"``.
"""

from __future__ import annotations

import base64
import datetime as _dt
import html
import json
import platform
import subprocess
from importlib import metadata
from pathlib import Path

import mujoco
import numpy as np

from gearcheck.compare.align import STEADY_THRESHOLD
from gearcheck.shared.citations import cite
from gearcheck.shared.side import display_name

SCHEMA = "gearcheck.crosscheck"
SCHEMA_VERSION = 1
RATIO = "1"


def _u(value, unit):
    return None if value is None else {"value": value, "unit": unit}


def git_revision() -> str | None:
    try:
        run = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                             cwd=Path(__file__).parent, timeout=5)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return run.stdout.strip() or None if run.returncode == 0 else None


def provenance(result) -> dict:
    try:
        version = metadata.version("gearcheck")
    except metadata.PackageNotFoundError:  # pragma: no cover - running from a bare checkout
        version = "unknown"
    return {
        "gearcheck_version": version, "git_revision": git_revision(), "mujoco_version": mujoco.__version__,
        "numpy_version": np.__version__, "python": platform.python_version(),
        "machine": f"{platform.system()} {platform.machine()}",
        "lumped_solver": result.settings["lumped"], "mujoco_solver": result.settings["mujoco"],
        "train_file": result.spec.path, "train_sha256": result.spec.text_hash,
    }


def to_dict(result) -> dict:
    spec = result.spec
    stats_units = lambda q, s: {k: _u(v, q.unit) for k, v in s.items()}  # noqa: E731
    quantities = []
    for q in result.quantities:
        m = q.metrics
        quantities.append({
            "name": q.name, "kind": q.kind, "unit": q.unit, "description": q.description, "status": q.status,
            "tolerance_nrmse": _u(q.tolerance, RATIO),
            "lumped": stats_units(q, m["reference"]), "mujoco": stats_units(q, m["test"]),
            "errors": {"rel_rms": _u(m["rel_rms"], RATIO), "rel_peak_to_peak": _u(m["rel_peak_to_peak"], RATIO),
                       "rel_peak": _u(m["rel_peak"], RATIO), "nrmse": _u(m["nrmse"], RATIO),
                       "nrmse_ac": _u(m["nrmse_ac"], RATIO), "correlation": _u(m["correlation"], RATIO),
                       "lag": _u(m["lag_s"], "s")},
            "integration_error": {"lumped": _u(m["integration_error"]["reference"], RATIO),
                                  "mujoco": _u(m["integration_error"]["test"], RATIO)},
            "spectrum": [{"line": s["line"], "frequency": _u(s["frequency_hz"], "Hz"),
                          "lumped": _u(s["reference"], q.unit), "mujoco": _u(s["test"], q.unit),
                          "rel_error": _u(s["rel_error"], RATIO)} for s in q.spectrum],
            "measured": q.measured,
        })
    return {
        "schema": SCHEMA, "schema_version": SCHEMA_VERSION,
        "train": {"name": spec.name, "description": spec.description, "source": spec.source},
        "provenance": provenance(result),
        "settings": _settings_with_units(result.settings),
        "verdict": {"verdict": result.verdict, "passed": result.passed, "failures": result.failures,
                    "unresolved": result.unresolved, "moved_from_baseline": result.moved},
        "steady_state": {"start": _u(result.steady_start_s, "s"), "detected": result.steady_found,
                         "how": result.steady_how, "settling_time": _u(result.settle_s, "s")},
        "modes": [{"mode": r["mode"], "type": r["type"], "multiplicity": r["multiplicity"],
                   "lumped": _u(r["reference_hz"], "Hz"), "mujoco": _u(r["test_hz"], "Hz"),
                   "mujoco_type": r["test_type"], "rel_error": _u(r["rel_error"], RATIO),
                   "status": "pass" if r["rel_error"] <= result.modal_tolerance else "fail"} for r in result.modal],
        "modes_tolerance": _u(result.modal_tolerance, RATIO),
        "solvers": {"reference": result.solvers[0], "test": result.solvers[1]},
        "diagnosis": result.diagnosis.to_dict() if result.diagnosis is not None else None,
        "quantities": quantities,
        "measurements": result.measurements,
        "notes": result.notes,
        "references": cite(result.references),
        "volatile": {"timestamp": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
                     "wall_time": {k: _u(v, "s") for k, v in result.wall_times.items()}},
    }


def _settings_with_units(settings: dict) -> dict:
    units = {"duration_s": ("duration", "s"), "simulated_s": ("simulated", "s"), "input_speed_rpm": ("input_speed", "rpm"),
             "output_torque_nm": ("output_torque", "N·m"), "common_sample_rate_hz": ("common_sample_rate", "Hz"),
             "sensor_band_hz": ("sensor_band", "Hz"),
             "steady_cycle_s": ("steady_cycle", "s"), "integration_check_steps_s": ("integration_check_steps", "s")}
    out = {}
    for key, value in settings.items():
        if key in units:
            name, unit = units[key]
            out[name] = _u(value, unit)
        elif key == "tolerances":
            out[key] = {k: _u(v, RATIO) for k, v in value.items()}
        else:
            out[key] = value
    return out


# ------------------------------------------------------------------------------ Markdown
def _fmt(x, digits=4) -> str:
    if x is None:
        return "—"
    if isinstance(x, str):
        return x
    if x == 0:
        return "0"
    return f"{x:.{digits}g}"


def _run_line(data) -> str:
    wall = ", ".join(f"{k.replace('_s', '')} {v['value']:.3g} s" for k, v in data["volatile"]["wall_time"].items())
    return f"Run: {data['volatile']['timestamp']}; wall times: {wall}"


def solver_names(data) -> tuple[str, str]:
    """How the report names the reference (a) and the test (b): the built-in solvers as "lumped" and "MuJoCo",
    a user's model by its own name."""
    names = data.get("solvers", {"reference": "lumped", "test": "mujoco"})
    return tuple(display_name(names[k]) for k in ("reference", "test"))


def markdown_tables(data) -> list[tuple[str, list[str], list[list[str]]]]:
    """(title, header, rows) of every table, shared by the Markdown and HTML writers."""
    A, B = solver_names(data)
    tables = []
    if data["modes"]:  # a recording without a modes file has none
        tables.append(("Natural frequencies", ["mode", "type", "mult.", f"{A} [Hz]", f"{B} [Hz]", "rel. diff.",
                                               "status"],
                       [[str(m["mode"]), m["type"], str(m["multiplicity"]), f"{m['lumped']['value']:.6f}",
                         f"{m['mujoco']['value']:.6f}", f"{m['rel_error']['value']:.2e}", m["status"]]
                        for m in data["modes"]]))
    rows = []
    for q in data["quantities"]:
        e, ie = q["errors"], q["integration_error"]
        rows.append([q["name"], q["unit"], _fmt(q["lumped"]["rms"]["value"]), _fmt(q["mujoco"]["rms"]["value"]),
                     _fmt(q["lumped"]["peak_to_peak"]["value"]), _fmt(q["mujoco"]["peak_to_peak"]["value"]),
                     _fmt(e["rel_rms"] and e["rel_rms"]["value"], 3), _fmt(e["nrmse"] and e["nrmse"]["value"], 3),
                     _fmt(e["correlation"] and e["correlation"]["value"], 6), _fmt(e["lag"]["value"] * 1e6, 3),
                     _fmt(ie["lumped"] and ie["lumped"]["value"], 2), _fmt(ie["mujoco"] and ie["mujoco"]["value"], 2),
                     _fmt(q["tolerance_nrmse"] and q["tolerance_nrmse"]["value"], 3), q["status"]])
    tables.append(("Time-domain quantities (steady window)",
                   ["quantity", "unit", f"RMS {A}", f"RMS {B}", f"p-p {A}", f"p-p {B}", "rel. RMS err.",
                    "NRMSE", "correlation", "lag [µs]", f"integr. err. {A}", f"integr. err. {B}", "tol. NRMSE",
                    "status"], rows))
    rows = []
    for q in data["quantities"]:
        if q["name"].endswith(".ay.world") or q["name"].endswith(".force"):
            for s in q["spectrum"]:
                rows.append([q["name"], s["line"], f"{s['frequency']['value']:.6g}", _fmt(s["lumped"]["value"]),
                             _fmt(s["mujoco"]["value"]), _fmt(s["rel_error"] and s["rel_error"]["value"], 3)])
    tables.append(("Spectral lines (Hann-windowed amplitude)",
                   ["quantity", "line", "f [Hz]", A, B, "rel. err."], rows))
    if data["measurements"]:
        def value(x, digits=4):
            return _fmt(x and x["value"], digits)

        tables.append(("Measured reference values",
                       ["quantity", "metric", "chain band [Hz]", "measured", "published model", "lumped", "MuJoCo",
                        "err. published", "err. lumped", "err. MuJoCo", "source"],
                       [[m["quantity"], m["metric"], "—" if m["sensor_band"] is None else
                         "–".join(f"{f:g}" for f in m["sensor_band"]["value"]), value(m["measured"]),
                         value(m["published_model"]), value(m["lumped"]), value(m["mujoco"]),
                         value(m["error_published_model"], 3), value(m["error_lumped"], 3), value(m["error_mujoco"], 3),
                         m["source"]] for m in data["measurements"]]))
    return tables


UNIT_SUFFIXES = (("_rad_s", "rad/s"), ("_s", "s"), ("_hz", "Hz"))


def _settings_line(settings: dict) -> str:
    parts = []
    for key, value in settings.items():
        unit = ""
        for suffix, name in UNIT_SUFFIXES:
            if key.endswith(suffix):
                key, unit = key[: -len(suffix)], f" {name}"
                break
        shown = _fmt(value, 6) if isinstance(value, float) else value
        parts.append(f"{key.replace('_', ' ')} {shown}{unit}")
    return ", ".join(parts)


def _summary_lines(data) -> list[str]:
    s = data["settings"]
    v = data["verdict"]
    verdict = {"PASS": "PASS", "FAIL": "FAIL: " + ", ".join(v["failures"] + (v["moved_from_baseline"] or [])),
               "INCONCLUSIVE": "INCONCLUSIVE: " + ", ".join(v["unresolved"])}[v["verdict"]]
    steady = data["steady_state"]
    how = {"detected": "detected: the mesh forces repeat cycle after cycle",
           "decayed": f"the free vibration of the start decayed to {STEADY_THRESHOLD:g}",
           "transient": "the whole transient",
           None: "NO steady state: second half shown, verdict inconclusive"}[steady["how"]]
    steps = [f"{x:.4g} s" if x is not None else "none: a recording" for x in s["integration_check_steps"]["value"]]
    p = data["provenance"]
    A, B = solver_names(data)
    return [
        f"Verdict: **{verdict}**",
        "",
        f"- Train: {data['train']['name']} — {data['train']['description']} ({data['train']['source']})",
        f"- Operating point: {s['input_speed']['value']:.6g} rpm, output torque {s['output_torque']['value']:.6g} N·m,"
        f" simulated {s['simulated']['value']:.6g} s; steady window from {steady['start']['value']:.6g} s ({how})",
        f"- Reference ({A}): {_settings_line(s['lumped'])}",
        f"- Test ({B}): {_settings_line(s['mujoco'])}",
        f"- gearcheck {p['gearcheck_version']} (git {p['git_revision']}), MuJoCo {p['mujoco_version']}, "
        f"NumPy {p['numpy_version']}, Python {p['python']}, {p['machine']}; train {p['train_file']} "
        f"sha256 {p['train_sha256'][:16]}…",
        f"- Metrics: NRMSE = rms(b − a)/rms(a) after removing the lag; {A} = a (reference), {B} = b; "
        "'negligible' = below 1e-6 of the largest quantity of its kind in both solvers (not gated).",
        "- Integration error: a bound per solver, rms(x_h − x_2h)/rms(a) against the same run at twice the step "
        f"(check steps {', '.join(steps)}; an order-p integrator's error is at most that, RK4's "
        "a fifteenth of it); 'unresolved' = the two bounds together reach the tolerance.",
    ]


def write_markdown(data, path: Path, figures: list[str]) -> None:
    lines = [f"# gearcheck cross-check: {data['train']['name']}", ""]
    lines += _summary_lines(data)
    lines += ["", _run_line(data), ""]
    if data["notes"]:
        lines += ["## Findings", ""] + [f"{note}\n" for note in data["notes"]]
    for title, header, rows in markdown_tables(data):
        lines += [f"## {title}", "", "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        lines += ["| " + " | ".join(r) + " |" for r in rows]
        lines.append("")
    lines += ["## Figures", ""] + [f"![{f}]({f})" for f in figures] + [""]
    lines += ["## References", ""] + [f"- [{r['key']}] {r['citation']}" for r in data["references"]] + [""]
    path.write_text("\n".join(lines), encoding="utf-8")


def write_html(data, path: Path, figure_paths: list[Path]) -> None:
    esc = html.escape
    parts = ["<!DOCTYPE html>", "<html lang=\"en\"><head><meta charset=\"utf-8\">",
             f"<title>gearcheck cross-check: {esc(data['train']['name'])}</title>",
             "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}"
             "table{border-collapse:collapse;font-size:0.85em;margin-bottom:1.5em}"
             "td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}th{background:#eee}"
             "td:first-child{text-align:left}.fail{background:#fdd}.pass{background:#dfd}.unresolved{background:#ffd}"
             "img{max-width:100%}</style></head><body>",
             f"<h1>gearcheck cross-check: {esc(data['train']['name'])}</h1>"]
    summary = _summary_lines(data)
    parts.append(f"<p>{esc(summary[0]).replace('**', '')}</p><ul>")
    parts += [f"<li>{esc(line[2:])}</li>" for line in summary[2:]]
    parts.append(f"</ul><p>{esc(_run_line(data))}</p>")
    if data["notes"]:
        parts.append("<h2>Findings</h2>" + "".join(f"<p>{esc(note)}</p>" for note in data["notes"]))
    for title, header, rows in markdown_tables(data):
        parts.append(f"<h2>{esc(title)}</h2><table><tr>" + "".join(f"<th>{esc(h)}</th>" for h in header) + "</tr>")
        for r in rows:
            cls = f" class=\"{r[-1]}\"" if r[-1] in ("pass", "fail", "unresolved") else ""
            parts.append(f"<tr{cls}>" + "".join(f"<td>{esc(c)}</td>" for c in r) + "</tr>")
        parts.append("</table>")
    parts.append("<h2>Figures</h2>")
    for fig in figure_paths:
        encoded = base64.b64encode(fig.read_bytes()).decode("ascii")
        parts.append(f"<figure><img alt=\"{esc(fig.name)}\" src=\"data:image/png;base64,{encoded}\">"
                     f"<figcaption>{esc(fig.name)}</figcaption></figure>")
    parts.append("<h2>References</h2><ul>" + "".join(f"<li>[{esc(r['key'])}] {esc(r['citation'])}</li>"
                                                     for r in data["references"]) + "</ul>")
    parts.append("</body></html>\n")
    path.write_text("\n".join(parts), encoding="utf-8")


def write_report(result, directory) -> dict:
    """Write report.json, report.md, report.html and the PNG figures into the folder ``directory`` (made if
    missing); return the JSON dict.  :meth:`CrosscheckResult.write` writes them whole or not at all."""
    from gearcheck.compare.plots import FIGURES  # matplotlib only when a report is written

    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    data = to_dict(result)
    figures = []
    for name, draw in FIGURES.items():
        if draw(result, out / name) is not False:  # False: nothing to draw (a recording without modes)
            figures.append(name)
    (out / "report.json").write_text(json.dumps(data, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    write_markdown(data, out / "report.md", figures)
    write_html(data, out / "report.html", [out / f for f in figures])
    return data


