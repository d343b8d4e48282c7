"""Writing a calibration: the calibrated train file (with the files it names), calibration.json and
calibration.md."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from gearcheck.compare.studies.multistart import AS_GOOD

from gearcheck.train.files import read_bytes


def write_calibration(result, name: str, out: Path, final: Path | None = None) -> list[str]:
    """Write the files into the folder ``out``, which will be ``final`` (named in the lines; default ``out``): the
    calibrated train file with copies of the files it names, the calibration; return the lines printed on the
    console."""
    final = out if final is None else final
    train = out / f"{name}-calibrated.toml"
    train.write_text(result.text(), encoding="utf-8")
    for copy_name, original in result.files().items():
        (out / copy_name).write_bytes(read_bytes(original, "file the train file names"))
    rows = result.rows()
    minima = [{"chi2": m.chi2, "starts": m.starts, "values": [float(v) for v in np.exp(m.x)]}
              for m in result.search.minima]
    data = {
        "schema": "gearcheck.calibration", "schema_version": 2, "train": name, "runs": result.evaluations,
        "parameters": [{"path": p, "start": float(s), "fitted": float(f), "relative_uncertainty": float(u)}
                       for p, s, f, u in zip(result.names, result.start, result.fitted, result.relative_uncertainty)],
        "measurements": rows,
        "starts": len(result.search.starts), "starts_at_best": result.starts_at_best, "minima": minima,
        "minima_as_good": len(result.search.as_good),
    }
    (out / "calibration.json").write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    lines = [f"# Calibration of {name}", "", "| parameter | start | fitted | std. uncertainty |", "|---|---|---|---|"]
    lines += [f"| `{p}` | {s:.6g} | {f:.6g} | ±{100 * u:.1f} % |"
              for p, s, f, u in zip(result.names, result.start, result.fitted, result.relative_uncertainty)]
    lines += ["", "| quantity | speed [rpm] | role | measured | published model | before | after (lumped) | "
                  "error published | error before | error after |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        pub = "—" if r["published_model"] is None else f"{r['published_model']:.6g}"
        epub = "—" if r["error_published_model"] is None else f"{100 * r['error_published_model']:+.2f} %"
        speed = "—" if r["speed_rpm"] is None else f"{r['speed_rpm']:.6g}"
        mac = "" if r.get("mac") is None else f", MAC {r['mac']:.3f}"
        what = f"{r['quantity']} ({r['metric']})" if "model_mode" not in r else \
            f"{r['quantity']} (model mode {r['model_mode']}{mac})"
        lines.append(f"| {what} | {speed} | {r['role']} | {r['measured']:.6g} | {pub} | {r['before']:.6g} "
                     f"| {r['after']:.6g} | {epub} | {100 * r['error_before']:+.2f} % "
                     f"| {100 * r['error_after']:+.2f} % |")
    starts = len(result.search.starts)
    design = "the file's values" if starts == 1 else "the file's values and a Latin hypercube in ln p within the bounds"
    lines += ["", f"{starts} start{'' if starts == 1 else 's'} ({design}); {result.starts_at_best} reached the best "
                  f"minimum; {len(minima)} distinct minim{'um' if len(minima) == 1 else 'a'}:", "",
              "| chi^2 | starts | " + " | ".join(f"`{p}`" for p in result.names) + " |",
              "|---|---|" + "---|" * len(result.names)]
    lines += [f"| {m['chi2']:.6g} | {m['starts']} | " + " | ".join(f"{v:.6g}" for v in m["values"]) + " |"
              for m in minima]
    if len(result.search.as_good) > 1:
        lines += ["", f"{len(result.search.as_good)} minima fit the measurements as well as the best (chi^2 within "
                      f"{AS_GOOD:g}): the measurements do not decide between them (narrower bounds, more "
                      "frequencies or a measured shape can)."]
    lines += ["", f"Calibrated train file: {final / train.name}"]
    (out / "calibration.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    return lines
