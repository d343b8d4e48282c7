"""Writing a calibration: the calibrated train file (with the files it names), calibration.json and
calibration.md."""

from __future__ import annotations

import json
from pathlib import Path

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
    data = {
        "schema": "gearcheck.calibration", "schema_version": 1, "train": name, "runs": result.evaluations,
        "parameters": [{"path": p, "start": float(s), "fitted": float(f), "relative_uncertainty": float(u)}
                       for p, s, f, u in zip(result.names, result.start, result.fitted, result.relative_uncertainty)],
        "measurements": rows,
    }
    (out / "calibration.json").write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    lines = [f"# Calibration of {name}", "", "| parameter | start | fitted | std. uncertainty |", "|---|---|---|---|"]
    lines += [f"| `{p}` | {s:.6g} | {f:.6g} | ±{100 * u:.1f} % |"
              for p, s, f, u in zip(result.names, result.start, result.fitted, result.relative_uncertainty)]
    lines += ["", "| quantity | speed [rpm] | role | measured | published model | before | after (lumped) | "
                  "error published | error before | error after |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        pub = "—" if r["published_model"] is None else f"{r['published_model']:.4g}"
        epub = "—" if r["error_published_model"] is None else f"{100 * r['error_published_model']:+.2f} %"
        lines.append(f"| {r['quantity']} ({r['metric']}) | {r['speed_rpm']:.6g} | {r['role']} | {r['measured']:.4g} | "
                     f"{pub} | {r['before']:.4g} | {r['after']:.4g} | {epub} | {100 * r['error_before']:+.2f} % | "
                     f"{100 * r['error_after']:+.2f} % |")
    lines += ["", f"Calibrated train file: {final / train.name}"]
    (out / "calibration.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    return lines
