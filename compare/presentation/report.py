"""Cross-check reports: ``report.json`` (versioned schema), ``report.md``, ``report.html`` and PNGs.

Everything that changes from run to run for the same inputs (the timestamp and the wall
times) lives in one place: the ``volatile`` field of the JSON and the single ``Run:``
line of the Markdown and HTML.  Everything else is identical byte for byte.

JSON schema ``gearcheck.crosscheck`` version 1: every number that has a unit is an object
``{"value": x, "unit": "..."}``; dimensionless ratios carry unit ``"1"``.  :func:`report_schema` is that
schema in JSON Schema (draft 2020-12); :func:`gearcheck.compare.presentation.junit.write_schemas` writes it with the
train file's (the repository ships them in ``schemas/``).

A report is read at a glance: a verdict banner with the count of every status, failing rows first in
every table, every spectral line flagged against its quantity's tolerance (advisory), and the measured
values explained in plain sentences (is the train calibrated; is it the model or the solvers that miss).
"""

from __future__ import annotations

import base64
import datetime as _dt
import hashlib
import html
import json
import math
import platform
import re
import subprocess
from importlib import metadata
from pathlib import Path

import mujoco
import numpy as np

from gearcheck.compare.engine.align import STEADY_THRESHOLD
from gearcheck.compare.engine.diagnosis import KINDS
from gearcheck.compare.presentation.html_page import page
from gearcheck.train.files import read_text
from gearcheck.train.json_schema import DRAFT
from gearcheck.train.loader import preset_text
from gearcheck.train.schema import MEASUREMENT
from gearcheck.shared.citations import cite
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.side import display_name

SCHEMA = "gearcheck.crosscheck"
SCHEMA_VERSION = 2  # 2: the sides keyed 'reference' and 'test' (1: 'lumped' and 'mujoco'), 'sides' added
RATIO = "1"
STATUSES = ("fail", "unresolved", "pass", "negligible")  # the order of every table's rows
STATUS_WORDS = {"fail": "fail", "unresolved": "inconclusive (unresolved)", "pass": "pass",
                "negligible": "not gated (negligible)"}
# A measured value is missed by a model when its error is beyond twice the relative standard uncertainty a
# train file's [[measurements]] entry has by default (a 95 % band).
MISS = 2 * MEASUREMENT.fields["uncertainty"].default
# The header `gearcheck calibrate` writes on a calibrated train file (gearcheck.compare.studies.calibrate)
CALIBRATED = re.compile(r"# Calibrated by `gearcheck calibrate` from (.+?): (.+)\.\n")
# Where a preset's calibrated comparison with its measurements lives (gearcheck's repository)
CALIBRATED_COMPARISONS = {
    "hub-drive": "docs/hub-drive-calibration/ in gearcheck's repository (the stage I transmission error and the "
                 "drag fitted at 606 rpm, 1823 rpm predicted, both solvers reading the calibrated train file)",
}


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
        "reference_solver": result.settings["reference"], "test_solver": result.settings["test"],
        "train_file": result.spec.path, "train_sha256": result.spec.text_hash,
    }


def calibration(spec) -> dict | None:
    """``{"from", "fitted"}`` when the train file is one ``gearcheck calibrate`` wrote (its header), else None
    (the file's own parameters; also when the file can no longer be read as the run read it)."""
    name = spec.path.removeprefix("preset:")
    try:
        text = preset_text(name) if spec.path.startswith("preset:") else read_text(spec.path, "train file")
    except (OSError, GearcheckError):
        return None
    if hashlib.sha256(text.encode("utf-8")).hexdigest() != spec.text_hash:
        return None
    match = CALIBRATED.match(text)
    return None if match is None else {"from": match[1], "fitted": match[2].split(", ")}


LINE_NEGLIGIBLE = 1e-5  # a line below this part of its quantity's RMS amplitude in both solvers is not flagged
LINE_SHARE = 0.1  # a line is flagged only when it carries at least this share of its quantity's NRMSE tolerance


def nrmse_part(line: dict, rms: float) -> float | None:
    """What a line's amplitude difference alone adds to its quantity's NRMSE: |A_b - A_a| / (sqrt(2) RMS_a), a
    tone's RMS over the reference's (None without a reference RMS)."""
    return abs(line["test"] - line["reference"]) / (math.sqrt(2) * rms) if rms else None


def line_status(line: dict, quantity_status: str, tolerance: float | None, rms: float) -> str:
    """A spectral line's flag: ``negligible`` with its quantity, without a reference amplitude, or below
    ``LINE_NEGLIGIBLE`` of its quantity's RMS amplitude sqrt(2) rms in both solvers (the level of round-off and of a
    periodic start's residual: double-planet's mesh lines of ring b's acceleration are 1e-7 to 1e-6 of it, and
    read 55 times apart); ``fail`` when |relative error| exceeds the quantity's NRMSE tolerance and the line
    carries at least ``LINE_SHARE`` of that tolerance (:func:`nrmse_part`), else ``pass``.  Advisory: the verdict
    gates the waveform (NRMSE), to which a line contributes only its share; a line that the train's phasing all
    but cancels (a sun's 3x mesh line with three planets, 4e-4 m/s^2 against an RMS near 900) can differ many
    times over between two good models and carry a ten-thousandth of the tolerance, and is no finding."""
    rel_error = line["rel_error"]
    small = max(abs(line["reference"]), abs(line["test"])) < LINE_NEGLIGIBLE * math.sqrt(2) * rms
    if quantity_status == "negligible" or rel_error is None or small:
        return "negligible"
    if tolerance is None or abs(rel_error) <= tolerance:
        return "pass"
    part = nrmse_part(line, rms)
    return "fail" if part is None or part >= LINE_SHARE * tolerance else "pass"


def _count(statuses, keys) -> dict[str, int]:
    statuses = list(statuses)
    return {k: statuses.count(k) for k in keys}


def to_dict(result) -> dict:
    spec = result.spec
    stats_units = lambda q, s: {k: _u(v, q.unit) for k, v in s.items()}  # noqa: E731
    quantities = []
    for q in result.quantities:
        m = q.metrics
        rms = m["reference"]["rms"]
        quantities.append({
            "name": q.name, "kind": q.kind, "unit": q.unit, "description": q.description, "status": q.status,
            "tolerance_nrmse": _u(q.tolerance, RATIO),
            "reference": stats_units(q, m["reference"]), "test": stats_units(q, m["test"]),
            "errors": {"rel_rms": _u(m["rel_rms"], RATIO), "rel_peak_to_peak": _u(m["rel_peak_to_peak"], RATIO),
                       "rel_peak": _u(m["rel_peak"], RATIO), "nrmse": _u(m["nrmse"], RATIO),
                       "nrmse_ac": _u(m["nrmse_ac"], RATIO), "correlation": _u(m["correlation"], RATIO),
                       "lag": _u(m["lag_s"], "s")},
            "integration_error": {"reference": _u(m["integration_error"]["reference"], RATIO),
                                  "test": _u(m["integration_error"]["test"], RATIO)},
            "spectrum": [{"line": s["line"], "frequency": _u(s["frequency_hz"], "Hz"),
                          "reference": _u(s["reference"], q.unit), "test": _u(s["test"], q.unit),
                          "rel_error": _u(s["rel_error"], RATIO),
                          "nrmse_part": _u(nrmse_part(s, rms), RATIO),
                          "status": line_status(s, q.status, q.tolerance, rms)} for s in q.spectrum],
            "measured": q.measured,
        })
    modes = [{"mode": r["mode"], "type": r["type"], "multiplicity": r["multiplicity"],
              "reference": _u(r["reference_hz"], "Hz"), "test": _u(r["test_hz"], "Hz"),
              "test_type": r["test_type"], "rel_error": _u(r["rel_error"], RATIO),
              "status": "pass" if r["rel_error"] <= result.modal_tolerance else "fail"} for r in result.modal]
    counts = {"quantities": _count((q["status"] for q in quantities), STATUSES),
              "modes": _count((m["status"] for m in modes), ("fail", "pass")),
              "spectral_lines": _count((s["status"] for q in quantities for s in q["spectrum"]),
                                       ("fail", "pass", "negligible"))}
    return {
        "schema": SCHEMA, "schema_version": SCHEMA_VERSION,
        "train": {"name": spec.name, "description": spec.description, "source": spec.source},
        "calibration": calibration(spec),
        "provenance": provenance(result),
        "settings": _settings_with_units(result.settings),
        "verdict": {"verdict": result.verdict, "passed": result.passed, "failures": result.failures,
                    "unresolved": result.unresolved, "moved_from_baseline": result.moved, "counts": counts},
        "steady_state": {"start": _u(result.steady_start_s, "s"), "detected": result.steady_found,
                         "how": result.steady_how, "settling_time": _u(result.settle_s, "s")},
        "modes": modes,
        "modes_tolerance": _u(result.modal_tolerance, RATIO),
        "solvers": {"reference": result.solvers[0], "test": result.solvers[1]},
        "sides": {"reference": result.kinds[0], "test": result.kinds[1]},
        "diagnosis": result.diagnosis.to_dict() if result.diagnosis is not None else None,
        "quantities": quantities,
        "measurements": result.measurements,
        "notes": result.notes,
        "references": cite(result.references),
        "volatile": {"timestamp": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
                     "wall_time": {k: _u(v, "s") for k, v in result.wall_times.items()},
                     "cpu_time": {k: _u(v, "s") for k, v in result.cpu_times.items()}},
    }


SETTING_UNITS = {"duration_s": ("duration", "s"), "simulated_s": ("simulated", "s"),
                 "input_speed_rpm": ("input_speed", "rpm"), "output_torque_nm": ("output_torque", "N·m"),
                 "common_sample_rate_hz": ("common_sample_rate", "Hz"), "sensor_band_hz": ("sensor_band", "Hz"),
                 "steady_cycle_s": ("steady_cycle", "s"), "integration_check_steps_s": ("integration_check_steps", "s")}


def _settings_with_units(settings: dict) -> dict:
    out = {}
    for key, value in settings.items():
        if key in SETTING_UNITS:
            name, unit = SETTING_UNITS[key]
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


def failing_first(rows: list[list[str]]) -> list[list[str]]:
    """Rows whose last cell is a status: fail, then unresolved, pass, negligible; stable otherwise."""
    return sorted(rows, key=lambda r: STATUSES.index(r[-1]) if r[-1] in STATUSES else len(STATUSES))


def _counts_text(counts: dict[str, int]) -> str:
    return ", ".join(f"{n} {STATUS_WORDS[k]}" for k, n in counts.items())


def banner(data) -> tuple[str, str, list[str]]:
    """(verdict, the counts in one line, the reasons: what failed, moved or cannot be decided)."""
    v, counts = data["verdict"], data["verdict"]["counts"]
    lines = counts["spectral_lines"]
    parts = [f"quantities: {_counts_text(counts['quantities'])}"]
    if data["modes"]:
        parts.append(f"modes: {_counts_text(counts['modes'])}")
    parts.append(f"spectral lines beyond tolerance (advisory): {lines['fail']} of {lines['fail'] + lines['pass']}")
    reasons = []
    if v["failures"]:
        reasons.append("Beyond tolerance: " + ", ".join(v["failures"]))
    if v["moved_from_baseline"]:
        reasons.append("Moved from the baseline: " + "; ".join(v["moved_from_baseline"]))
    if v["unresolved"]:
        reasons.append("Cannot decide: " + ", ".join(v["unresolved"]))
    return v["verdict"], "; ".join(parts), reasons


LINE_RULE = ("A line is flagged fail when its relative amplitude error exceeds its quantity's NRMSE tolerance and "
             f"the line carries at least {LINE_SHARE:.0%} of that tolerance: its part of the NRMSE, "
             "|A_b − A_a|/(√2 RMS_a) (column 'NRMSE part'), the least it adds to the waveform's error; negligible "
             f"when it is below {LINE_NEGLIGIBLE:g} of its quantity's RMS amplitude in both solvers. A line the "
             "train's phasing all but cancels may differ many times over and still carry nothing. The flags are "
             "advisory and leave the verdict alone: the verdict gates the whole waveform (NRMSE). The table "
             "lists the world-y accelerations and the forces; report.json holds every quantity's lines.")


def markdown_tables(data) -> list[tuple[str, list[str], list[list[str]], list[str]]]:
    """(title, header, rows, notes) of every table, failing rows first, shared by the Markdown and HTML writers."""
    A, B = solver_names(data)
    tables = []
    if data["modes"]:  # a recording without a modes file has none
        tables.append(("Natural frequencies", ["mode", "type", "mult.", f"{A} [Hz]", f"{B} [Hz]", "rel. diff.",
                                               "tol.", "status"],
                       [[str(m["mode"]), m["type"], str(m["multiplicity"]), f"{m['reference']['value']:.6f}",
                         f"{m['test']['value']:.6f}", f"{m['rel_error']['value']:.2e}",
                         f"{data['modes_tolerance']['value']:.0e}", m["status"]] for m in data["modes"]], []))
    rows = []
    for q in data["quantities"]:
        e, ie = q["errors"], q["integration_error"]
        rows.append([q["name"], q["unit"], _fmt(q["reference"]["rms"]["value"]), _fmt(q["test"]["rms"]["value"]),
                     _fmt(q["reference"]["peak_to_peak"]["value"]), _fmt(q["test"]["peak_to_peak"]["value"]),
                     _fmt(e["rel_rms"] and e["rel_rms"]["value"], 3), _fmt(e["nrmse"] and e["nrmse"]["value"], 3),
                     _fmt(e["correlation"] and e["correlation"]["value"], 6), _fmt(e["lag"]["value"] * 1e6, 3),
                     _fmt(ie["reference"] and ie["reference"]["value"], 2), _fmt(ie["test"] and ie["test"]["value"], 2),
                     _fmt(q["tolerance_nrmse"] and q["tolerance_nrmse"]["value"], 3), q["status"]])
    tables.append(("Time-domain quantities (steady window)",
                   ["quantity", "unit", f"RMS {A}", f"RMS {B}", f"p-p {A}", f"p-p {B}", "rel. RMS err.",
                    "NRMSE", "correlation", "lag [µs]", f"integr. err. {A}", f"integr. err. {B}", "tol. NRMSE",
                    "status"], rows, []))
    rows = []
    for q in data["quantities"]:
        if q["name"].endswith(".ay.world") or q["name"].endswith(".force"):
            tol = _fmt(q["tolerance_nrmse"] and q["tolerance_nrmse"]["value"], 3)
            for s in q["spectrum"]:
                rows.append([q["name"], s["line"], f"{s['frequency']['value']:.6g}", _fmt(s["reference"]["value"]),
                             _fmt(s["test"]["value"]), _fmt(s["rel_error"] and s["rel_error"]["value"], 3),
                             _fmt(s["nrmse_part"] and s["nrmse_part"]["value"], 2), tol, s["status"]])
    tables.append(("Spectral lines (Hann-windowed amplitude)",
                   ["quantity", "line", "f [Hz]", A, B, "rel. err.", "NRMSE part", "tol.", "status"], rows,
                   [LINE_RULE]))
    if data["measurements"]:
        def value(x, digits=4):
            return _fmt(x and x["value"], digits)

        tables.append(("Measured reference values",
                       ["quantity", "metric", "chain band [Hz]", "measured", "published model", A, B,
                        "err. published", f"err. {A}", f"err. {B}", "source"],
                       [[m["quantity"], m["metric"], "—" if m["sensor_band"] is None else
                         "–".join(f"{f:g}" for f in m["sensor_band"]["value"]), value(m["measured"]),
                         value(m["published_model"]), value(m["reference"]), value(m["test"]),
                         value(m["error_published_model"], 3), value(m["error_reference"], 3),
                         value(m["error_test"], 3),
                         m["source"]] for m in data["measurements"]],
                       measurement_notes(data)))
    return [(title, header, failing_first(rows), note) for title, header, rows, note in tables]


def _percent(x: float) -> str:
    return f"{100 * x:+.1f} %"


def measurement_notes(data) -> list[str]:
    """Plain sentences on the measured values: whose parameters the model has (the train file's own or a
    calibrated file), where the calibrated comparison lives, and, row by row, whether it is the model or the
    solvers that miss."""
    A, B = solver_names(data)
    name, cal, train_file = data["train"]["name"], data["calibration"], data["provenance"]["train_file"]
    reading = ("Each row reads both solvers through the measuring chain's band and takes the test's statistic over "
               "the steady window.")
    if cal is None:
        where = CALIBRATED_COMPARISONS.get(name)
        notes = [f"{reading} These rows compare the train file's own parameters ({train_file}), which are not "
                 "calibrated to these measurements, with the test."
                 + (f" The calibrated comparison: {where}." if where else
                    f" `gearcheck calibrate {train_file.removeprefix('preset:')} --fit FIELD=LOW:HIGH` fits "
                    "chosen fields of the train file to them.")]
    else:
        notes = [f"{reading} The train file was calibrated to measurements by `gearcheck calibrate` from "
                 f"{cal['from']} ({', '.join(cal['fitted'])})."]
    tolerance = {q["name"]: q["tolerance_nrmse"] and q["tolerance_nrmse"]["value"] for q in data["quantities"]}
    for m in data["measurements"]:
        what = f"{m['quantity']} {m['metric']}"
        a, b, measured = m["reference"]["value"], m["test"]["value"], m["measured"]["value"]
        ea, eb = m["error_reference"]["value"], m["error_test"]["value"]
        apart = abs(b - a) / abs(a) if a else math.inf
        tol = tolerance.get(m["quantity"]) or 0.0
        if apart > tol:
            notes.append(f"{what}: {A} and {B} differ from each other by {100 * apart:.3g} % (beyond the quantity's "
                         f"tolerance of {100 * tol:g} %): read the quantity's row before the measurement.")
        elif abs(ea) > MISS and abs(eb) > MISS and ea * eb > 0:
            published = m["error_published_model"]
            notes.append(f"{what}: both solvers miss the test by the same amount ({A} {_percent(ea)}, {B} "
                         f"{_percent(eb)}; they agree with each other to {100 * apart:.2g} %): it is the model, "
                         "its parameters, not the solvers, that disagrees with the test"
                         + (f" (the source's own model: {_percent(published['value'])})." if published else "."))
        else:
            notes.append(f"{what}: {A} {_percent(ea)}, {B} {_percent(eb)} from the measured {measured:.4g} "
                         f"{m['measured']['unit']}" + (f", within twice the default measurement uncertainty "
                                                       f"({100 * MISS:g} %)." if max(abs(ea), abs(eb)) <= MISS
                                                       else "."))
    return notes


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
    steady = data["steady_state"]
    how = {"detected": "detected: the mesh forces repeat cycle after cycle",
           "decayed": f"the free vibration of the start decayed to {STEADY_THRESHOLD:g}",
           "transient": "the whole transient",
           "periodic": "both runs start on their periodic steady states: the whole run",
           "modes only": "no run: nothing drives the test model, its modes alone are compared",
           None: "NO steady state: second half shown, verdict inconclusive"}[steady["how"]]
    steps = [f"{x:.4g} s" if x is not None else "none: a recording" for x in s["integration_check_steps"]["value"]]
    p = data["provenance"]
    A, B = solver_names(data)
    runs = [] if steady["how"] == "modes only" else [
        f"Reference ({A}): {_settings_line(s['reference'])}",
        f"Test ({B}): {_settings_line(s['test'])}"]
    integration = [] if steady["how"] == "modes only" else [
        "Integration error per solver, from the same run at twice the step or half it "
        f"(check steps {', '.join(steps)}): Richardson's estimate for gearcheck's fourth-order solvers, "
        "rms(x_h − x_2h)/rms(a)/15 or 16/15 rms(x_h − x_h/2)/rms(a); the change itself, a bound, for a model of "
        "unknown order or runs outside the asymptotic range (the findings say which); 'unresolved' = the two "
        "estimates together reach the tolerance."]
    return [
        f"Train: {data['train']['name']} — {data['train']['description']} ({data['train']['source']})",
        f"Operating point: {s['input_speed']['value']:.6g} rpm, output torque {s['output_torque']['value']:.6g} N·m,"
        f" simulated {s['simulated']['value']:.6g} s; steady window from {steady['start']['value']:.6g} s ({how})"
        + (f"; operating history: {s['operating_history']} (a transient by design: the two solvers' transients "
           "are compared as they are)" if "operating_history" in s else ""),
        f"Sides: {A}, the {data['sides']['reference']} (reference, a); {B}, the {data['sides']['test']} (test, b)",
        *runs,
        f"gearcheck {p['gearcheck_version']} (git {p['git_revision']}), MuJoCo {p['mujoco_version']}, "
        f"NumPy {p['numpy_version']}, Python {p['python']}, {p['machine']}; train {p['train_file']} "
        f"sha256 {p['train_sha256'][:16]}…",
        f"Metrics: NRMSE = rms(b − a)/rms(a) after removing the lag; {A} = a (reference), {B} = b; "
        "'negligible' = below 1e-6 of the largest quantity of its kind in both solvers, or held at zero by one and "
        "below 1e-3 of it in the other (a second-order motion, named in the findings) (not gated).",
        *integration,
    ]


NOT_DRAWN = "Not drawn: the report was asked for its numbers only (`--no-figures`, `figures=False`)."


def write_markdown(data, path: Path, figures: list[str] | None) -> None:
    """report.md; ``figures``: the names of the figures drawn beside it (None: none were asked for)."""
    verdict, counts, reasons = banner(data)
    lines = [f"# gearcheck cross-check: {data['train']['name']}", "", f"Verdict: **{verdict}** — {counts}", ""]
    failing = "failing.png" in (figures or ())
    if reasons or failing:
        lines += [f"{r}." for r in reasons]
        lines += ["Failing quantities plotted: [failing.png](failing.png)."] if failing else []
        lines.append("")
    lines += [f"- {line}" for line in _summary_lines(data)]
    lines += ["", _run_line(data), ""]
    if data["notes"]:
        lines += ["## Findings", ""] + [f"{note}\n" for note in data["notes"]]
    for title, header, rows, notes in markdown_tables(data):
        lines += [f"## {title}", ""] + [f"{note}\n" for note in notes]
        lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        lines += ["| " + " | ".join(r) + " |" for r in rows]
        lines.append("")
    lines += ["## Figures", ""] + ([f"![{f}]({f})" for f in figures] if figures is not None else [NOT_DRAWN]) + [""]
    lines += ["## References", ""] + [f"- [{r['key']}] {r['citation']}" for r in data["references"]] + [""]
    path.write_text("\n".join(lines), encoding="utf-8")


OPEN_ROWS = 12  # a table longer than this, with nothing failing or unresolved in it, starts folded in the HTML


def write_html(data, path: Path, figure_paths: list[Path] | None) -> None:
    """report.html, one page with ``figure_paths`` (the figures drawn) embedded (None: none were asked for)."""
    esc = html.escape
    title = f"gearcheck cross-check: {data['train']['name']}"
    parts = [f"<h1>{esc(title)}</h1>"]
    verdict, counts, reasons = banner(data)
    names = [fig.name for fig in figure_paths or ()]
    parts.append(f"<div class=\"banner {verdict}\"><span class=\"verdict\">{verdict}</span>{esc(counts)}"
                 + "".join(f"<p>{esc(r)}.</p>" for r in reasons)
                 + ("<p><a href=\"#failing.png\">Failing quantities plotted</a>.</p>" if "failing.png" in names
                    else "") + "</div>")
    parts.append("<ul>" + "".join(f"<li>{esc(line)}</li>" for line in _summary_lines(data)) + "</ul>")
    parts.append(f"<p>{esc(_run_line(data))}</p>")
    if data["notes"]:
        parts.append("<h2>Findings</h2>" + "".join(f"<p>{esc(note)}</p>" for note in data["notes"]))
    for heading, header, rows, notes in markdown_tables(data):
        statuses = [r[-1] for r in rows if r[-1] in STATUSES]
        folded = len(rows) > OPEN_ROWS and not {"fail", "unresolved"} & set(statuses)
        tally = _counts_text({k: statuses.count(k) for k in STATUSES if k in statuses})
        parts.append(f"<details class=\"section\"{'' if folded else ' open'}><summary>{esc(heading)}"
                     + (f" — {esc(tally)}" if tally else "") + "</summary>"
                     + "".join(f"<p>{esc(note)}</p>" for note in notes)
                     + "<table class=\"numbers\"><tr>" + "".join(f"<th>{esc(h)}</th>" for h in header) + "</tr>")
        for r in rows:
            cls = f" class=\"{r[-1]}\"" if r[-1] in STATUSES else ""
            parts.append(f"<tr{cls}>" + "".join(f"<td>{esc(c)}</td>" for c in r) + "</tr>")
        parts.append("</table></details>")
    parts.append("<h2>Figures</h2>")
    if figure_paths is None:
        parts.append(f"<p>{esc(NOT_DRAWN.replace('`', ''))}</p>")
    for fig in figure_paths or ():
        encoded = base64.b64encode(fig.read_bytes()).decode("ascii")
        parts.append(f"<figure id=\"{esc(fig.name)}\"><img alt=\"{esc(fig.name)}\" "
                     f"src=\"data:image/png;base64,{encoded}\"><figcaption>{esc(fig.name)}</figcaption></figure>")
    parts.append("<h2>References</h2><ul>" + "".join(f"<li>[{esc(r['key'])}] {esc(r['citation'])}</li>"
                                                     for r in data["references"]) + "</ul>")
    path.write_text(page(title, "\n".join(parts)), encoding="utf-8")


def write_report(result, directory, figures: bool = True) -> dict:
    """Write report.json, report.md, report.html and the PNG figures into the folder ``directory`` (made if
    missing); return the JSON dict.  :meth:`CrosscheckResult.write` writes them whole or not at all.
    ``figures=False``: no figures (a CI job that reads the numbers; drawing them is a third of a cross-check's
    time), which report.md and report.html say; report.json is the same either way."""
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    data = to_dict(result)
    drawn = _draw(result, out) if figures else None
    (out / "report.json").write_text(json.dumps(data, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    write_markdown(data, out / "report.md", drawn)
    write_html(data, out / "report.html", None if drawn is None else [out / f for f in drawn])
    return data


def _draw(result, out: Path) -> list[str]:
    """The report's figures drawn into ``out``: the names of those drawn."""
    from gearcheck.compare.presentation.plots import FIGURES  # matplotlib only when a figure is drawn

    # False: nothing to draw (no modes, nothing failing)
    return [name for name, draw in FIGURES.items() if draw(result, out / name) is not False]


# ------------------------------------------------------------------------------ JSON Schema of report.json
def _value(unit: str | None = None, value: dict | None = None, nullable: bool = False) -> dict:
    """A ``{"value", "unit"}`` object (``unit`` fixed when given), or null when ``nullable``."""
    schema = {"type": "object", "properties": {"value": value or {"type": "number"},
                                               "unit": {"const": unit} if unit else {"type": "string"}},
              "required": ["value", "unit"], "additionalProperties": False}
    return {"anyOf": [schema, {"type": "null"}]} if nullable else schema


def _object(properties: dict, required=None, closed: bool = True, description: str | None = None) -> dict:
    out = {"type": "object"} | ({"description": description} if description else {})
    out |= {"properties": properties, "required": list(properties) if required is None else required}
    return out | ({"additionalProperties": False} if closed else {})


def _array(items: dict, description: str | None = None) -> dict:
    return {"type": "array"} | ({"description": description} if description else {}) | {"items": items}


STRING, NUMBER, BOOLEAN = {"type": "string"}, {"type": "number"}, {"type": "boolean"}
NULLABLE_STRING, NULLABLE_NUMBER = {"type": ["string", "null"]}, {"type": ["number", "null"]}


def report_schema() -> dict:
    """The JSON Schema (draft 2020-12) of ``report.json``, schema ``gearcheck.crosscheck`` version 2, as
    :func:`to_dict` writes it."""
    return {
        "$schema": DRAFT,
        "title": f"gearcheck cross-check report ({SCHEMA} version {SCHEMA_VERSION})",
        "description": "report.json of `gearcheck crosscheck`. Numbers with a unit are {value, unit} objects; "
                       "ratios have unit '1'. 'reference' and 'test' key the two sides' values; 'solvers' names them "
                       "and 'sides' says what each is (reference lumped model, MuJoCo twin, user model, recording). "
                       "Only 'volatile' changes between runs of the same inputs.",
        "type": "object",
        "properties": _report_properties(),
        "required": ["schema", "schema_version", "train", "calibration", "provenance", "settings", "verdict",
                     "steady_state", "modes", "modes_tolerance", "solvers", "sides", "diagnosis", "quantities",
                     "measurements", "notes", "references", "volatile"],
        "additionalProperties": False,
        "$defs": {"value": _value(), "measurement": _measurement_schema(), "candidate": _candidate_schema()},
    }


def _report_properties() -> dict:
    """The schema of each top-level field of ``report.json``, in the order :func:`to_dict` writes them."""
    seconds = _value("s")
    return {
        "schema": {"const": SCHEMA}, "schema_version": {"const": SCHEMA_VERSION},
        "train": _object({"name": STRING, "description": STRING, "source": STRING}),
        "calibration": {"anyOf": [_object({"from": STRING, "fitted": _array(STRING)}), {"type": "null"}],
                        "description": "the calibrated train file's origin and fitted fields (its header), "
                                       "null for a train file's own parameters"},
        "provenance": _object({
            "gearcheck_version": STRING, "git_revision": NULLABLE_STRING, "mujoco_version": STRING,
            "numpy_version": STRING, "python": STRING, "machine": STRING, "reference_solver": {"type": "object"},
            "test_solver": {"type": "object"}, "train_file": STRING, "train_sha256": STRING}),
        "settings": _settings_schema(),
        "verdict": _verdict_schema(),
        "steady_state": _object({"start": seconds, "detected": BOOLEAN,
                                 "how": {"enum": ["detected", "decayed", "transient", "periodic", "modes only",
                                                  None]},
                                 "settling_time": _value("s", nullable=True)}),
        "modes": _array(_object({
            "mode": {"type": "integer"}, "type": STRING, "multiplicity": {"type": "integer"},
            "reference": _value("Hz"), "test": _value("Hz"), "test_type": STRING, "rel_error": _value(RATIO),
            "status": {"enum": ["fail", "pass"]}})),
        "modes_tolerance": _value(RATIO),
        "solvers": _object({"reference": STRING, "test": STRING}),
        "sides": _object({"reference": STRING, "test": STRING}),
        "diagnosis": _diagnosis_schema(),
        "quantities": _array(_quantity_schema()),
        "measurements": _array({"$ref": "#/$defs/measurement"}),
        "notes": _array(STRING),
        "references": _array(_object({"key": STRING, "citation": STRING})),
        "volatile": _object({"timestamp": {"type": "string", "format": "date-time"},
                             "wall_time": {"type": "object", "additionalProperties": seconds},
                             "cpu_time": {"type": "object", "additionalProperties": seconds}},
                            required=["timestamp", "wall_time"]),  # cpu_time: in reports after gearcheck 0.2.0
    }


def _settings_schema() -> dict:
    """``settings``: the run's settings, open to those a published 4-DOF model's run adds."""
    seconds = _value("s")
    properties = {
        "duration": seconds, "simulated": seconds, "input_speed": _value("rpm"),
        "output_torque": _value("N·m"), "reference": {"type": "object"}, "test": {"type": "object"},
        "common_sample_rate": _value("Hz"), "steady_cycle": seconds,
        "integration_check_steps": _value("s", {"type": "array", "items": NULLABLE_NUMBER}),
        "sensor_band": _value("Hz", {"type": "array", "items": NUMBER, "minItems": 2, "maxItems": 2}, True),
        "tolerances": {"type": "object", "additionalProperties": _value(RATIO)},
    }
    return _object(properties | {"steady_cycle_of": {"type": "string", "description": "what steady_cycle is the "
                                                      "cycle of: 'the stage2 mesh', 'mode 1'"}},
                   required=list(properties),  # steady_cycle_of: in reports after gearcheck 0.2.0
                   closed=False, description="run settings; a published 4-DOF model's run adds its own")


def _verdict_schema() -> dict:
    """``verdict``: the verdict, what failed or stayed unresolved, what moved from a baseline, the counts."""
    counts = lambda keys: _object({k: {"type": "integer", "minimum": 0} for k in keys})  # noqa: E731
    return _object({
        "verdict": {"enum": ["PASS", "FAIL", "INCONCLUSIVE"]}, "passed": BOOLEAN,
        "failures": _array(STRING), "unresolved": _array(STRING),
        "moved_from_baseline": {"anyOf": [_array(STRING), {"type": "null"}],
                                "description": "null: no baseline checked"},
        "counts": _object({"quantities": counts(STATUSES), "modes": counts(("fail", "pass")),
                           "spectral_lines": counts(("fail", "pass", "negligible"))}),
    })


def _diagnosis_schema() -> dict:
    """``diagnosis``: a user's model's best-explaining term of the reference, or null."""
    return {"anyOf": [_object({
        "train": STRING, "agrees": BOOLEAN, "reduced_to": {"type": ["integer", "null"]},
        "reduction": {"enum": ["held", "condensed", None]},
        "reference_score": NULLABLE_NUMBER, "held": _array(STRING),
        "evidence": _object({k: {"type": "integer"} for k in ("rest", "shapes", "speed")}),
        "tried": {"type": "integer"}, "candidates": _array({"$ref": "#/$defs/candidate"}),
        "rigid_modes": _object({k: {"type": "integer"} for k in ("evidence", "reference")}),
        "pairs": {"type": "integer"}}),
        {"type": "null"}], "description": "a user's model: the term of the reference that best explains "
                                          "its modes; null otherwise"}


def _quantity_schema() -> dict:
    """An entry of ``quantities``: one compared signal, its statistics, errors, spectrum and measurements."""
    ratio_or_null = _value(RATIO, nullable=True)
    stats = _object({k: {"$ref": "#/$defs/value"} for k in ("mean", "rms", "peak_to_peak", "peak")})
    return _object({
        "name": STRING, "kind": STRING, "unit": STRING, "description": STRING,
        "status": {"enum": list(STATUSES)}, "tolerance_nrmse": ratio_or_null,
        "reference": stats, "test": stats,
        "errors": _object({"rel_rms": ratio_or_null, "rel_peak_to_peak": ratio_or_null, "rel_peak": ratio_or_null,
                           "nrmse": ratio_or_null, "nrmse_ac": ratio_or_null, "correlation": ratio_or_null,
                           "lag": _value("s")}),
        "integration_error": _object({"reference": ratio_or_null, "test": ratio_or_null}),
        "spectrum": _array(_object({
            "line": STRING, "frequency": _value("Hz"), "reference": {"$ref": "#/$defs/value"},
            "test": {"$ref": "#/$defs/value"}, "rel_error": ratio_or_null,
            "nrmse_part": ratio_or_null, "status": {"enum": ["fail", "pass", "negligible"]},
        }), "spectral lines; status advisory: fail when |rel_error| exceeds the quantity's NRMSE tolerance and "
            f"nrmse_part is at least {LINE_SHARE:g} of it"),
        "measured": _array({"$ref": "#/$defs/measurement"}),
    }, description="one compared signal: 'reference' is the reference side (a), 'test' the test side (b)")


def _measurement_schema() -> dict:
    """``$defs/measurement``: a measured value beside both solvers' statistic of it."""
    ratio = _value(RATIO)
    return _object({
        "quantity": STRING, "metric": {"enum": list(MEASUREMENT.fields["metric"].choices)}, "source": STRING,
        "sensor_band": _value("Hz", {"type": "array", "items": NUMBER, "minItems": 2, "maxItems": 2}, True),
        "measured": {"$ref": "#/$defs/value"}, "reference": {"$ref": "#/$defs/value"},
        "test": {"$ref": "#/$defs/value"}, "published_model": _value(nullable=True),
        "error_reference": ratio, "error_test": ratio, "error_published_model": _value(RATIO, nullable=True),
    }, description="a measured value beside both solvers' statistic of it; errors (model - measured)/|measured|")


def _candidate_schema() -> dict:
    """``$defs/candidate``: a one-term change of the reference that a diagnosis tried."""
    return _object({
        "term": STRING, "kind": {"enum": list(KINDS)}, "score": NUMBER,
        "parts": {"type": "object", "additionalProperties": NUMBER}, "row": STRING, "coordinate": STRING,
        "member": STRING, "factor": NUMBER, "stiffness": NUMBER, "coordinates": _array(STRING),
        "equivalents": _array({"$ref": "#/$defs/candidate"}), "pair": _array({"$ref": "#/$defs/candidate"}),
    }, required=["term", "kind", "score", "parts"], description="a one-term change of the reference (or a pair)")
