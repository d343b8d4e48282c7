"""Train variants the benchmarks scale over (stages, planets), built from the demo preset's text."""

from __future__ import annotations

import re

from lumped.loader import load_text, preset_text


def chained_train(n_stages: int):
    """n copies of demo-3p's stage in series, carrier k -> sun k+1 by a spline coupling."""
    text = preset_text("demo-3p")
    head, stage = text.split("[[stages]]", 1)
    head = head.replace('output = "stage1.carrier"', f'output = "stage{n_stages}.carrier"')
    head = head.replace('held = ["stage1.ring"]',
                        "held = [" + ", ".join(f'"stage{i}.ring"' for i in range(1, n_stages + 1)) + "]")
    parts = [head]
    for i in range(1, n_stages + 1):
        parts.append("[[stages]]" + stage.replace('name = "stage1"', f'name = "stage{i}"'))
    for i in range(1, n_stages):
        parts.append(f'\n[[couplings]]\nname = "spline{i}"\nfrom = "stage{i}.carrier"\nto = "stage{i + 1}.sun"\n'
                     "torsional_stiffness = 2.0e6\ntorsional_damping = 5.0\n")
    return load_text("\n".join(parts), f"chain-{n_stages}")


def planets_train(n_planets: int):
    """demo-3p's stage with z = 30/24/78 (z_s + z_r = 108 admits 3, 4 and 6 planets)."""
    text = preset_text("demo-3p")
    for old, new in ((r"^planets = 3", f"planets = {n_planets}"), (r"^teeth = 22", "teeth = 30"),
                     (r"^teeth = 20", "teeth = 24"), (r"^teeth = 62", "teeth = 78")):
        text = re.sub(old, new, text, flags=re.M)
    return load_text(text, f"planets-{n_planets}")
