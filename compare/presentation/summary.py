"""The summary of a cross-check of every preset: ``summary.json``, ``summary.md`` and ``summary.html``."""

from __future__ import annotations

import html
import json
import math
from pathlib import Path

from gearcheck.compare.presentation.html_page import page


def summary_row(data: dict) -> dict:
    """One preset's row of the summary, from its report data (:func:`gearcheck.compare.presentation.report.to_dict`)."""
    modes = data["modes"]
    gated = [q for q in data["quantities"] if q["status"] != "negligible"]

    def worst(*kinds):
        values = [q["errors"]["nrmse"]["value"] for q in gated if q["kind"] in kinds and q["errors"]["nrmse"]]
        return max(values) if values else None

    moved = data["verdict"]["moved_from_baseline"] or []
    return {
        "train": data["train"]["name"], "status": data["verdict"]["verdict"],
        "modes": len(modes), "max_mode_rel_error": max((m["rel_error"]["value"] for m in modes), default=None),
        "quantities": len(data["quantities"]), "failed": len(data["verdict"]["failures"]), "moved": len(moved),
        "worst_nrmse_mesh_force": worst("mesh_force"),
        "worst_nrmse_acceleration": worst("acceleration", "angular_acceleration"),
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
    body = ["<h1>gearcheck cross-check of every preset</h1><table><tr>"
            + "".join(f"<th>{esc(h)}</th>" for h in header) + "</tr>"]
    for r in rows:
        cells = [f"<a href=\"{esc(r['train'])}/report.html\">{esc(r['train'])}</a>"]
        cells += [esc(_cell(r[k])) for k, _ in SUMMARY_COLUMNS[1:]]
        body.append(f"<tr class=\"{r['status']}\">" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    body.append("</table>")
    (out / "summary.html").write_text(page("gearcheck summary", "\n".join(body)), encoding="utf-8")
