"""Train variants derived from a preset's text: for tests, benchmarks and parameter studies.

Edits are regular-expression substitutions on the TOML text (multiline mode), so a variant
goes through the same validation as any train file.
"""

from __future__ import annotations

import re

from gearcheck.train.loader import load_text, preset_text
from gearcheck.train.spec import TrainSpec


def edited_text(preset: str, pairs) -> str:
    """The text of ``preset`` with each (pattern, replacement) applied; a pattern must match."""
    text = preset_text(preset)
    for old, new in pairs:
        if not re.search(old, text, flags=re.M):
            raise ValueError(f"{old!r} does not occur in preset {preset}")
        text = re.sub(old, new, text, flags=re.M)
    return text


def edited(preset: str, pairs, label: str = "edited") -> TrainSpec:
    """The edited preset; errors name it ``preset:NAME (label)`` and its files resolve beside the preset."""
    return load_text(edited_text(preset, pairs), f"preset:{preset} ({label})")


def chained(n_stages: int, radial_stiffness: float = 0.0) -> TrainSpec:
    """n copies of demo-3p's stage in series, carrier k -> sun k+1 by a spline
    (torsional 2e6 N·m/rad, optionally radial)."""
    return load_text(chained_text(n_stages, radial_stiffness), f"chain-{n_stages}")


def chained_text(n_stages: int, radial_stiffness: float = 0.0) -> str:
    """The train file of :func:`chained`."""
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
                     "torsional_stiffness = 2.0e6\ntorsional_damping = 5.0\n"
                     + (f"radial_stiffness = {radial_stiffness!r}\n" if radial_stiffness else ""))
    return "\n".join(parts)


def wide_stage(n_planets: int, teeth: tuple[int, int, int] = (30, 24, 78), torque_driven: bool = False) -> TrainSpec:
    """demo-3p's stage with ``n_planets`` and the tooth counts (sun, planet, ring): the default
    z = 30/24/78 (z_s + z_r = 108) admits 3, 4 and 6 equally spaced planets, 21/24/69 admits 5.
    ``torque_driven``: without the input shaft, the sun driven by the torque that balances the load."""
    z_s, z_p, z_r = teeth
    pairs = [(r"^planets = 3", f"planets = {n_planets}"), (r"^teeth = 22", f"teeth = {z_s}"),
             (r"^teeth = 20", f"teeth = {z_p}"), (r"^teeth = 62 .*$", f"teeth = {z_r}")]
    if torque_driven:
        pairs.append((r"^input_shaft_.*\n", ""))
    return edited("demo-3p", pairs, f"{n_planets} planets, z = {z_s}/{z_p}/{z_r}"
                  + (", torque-driven" if torque_driven else ""))


def helical_stage(helix_deg: float = 15.0, axial_stiffness: float = 5.0e8, stiffness: str = "constant",
                  extra=()) -> TrainSpec:
    """demo-3p with helical gears (planets ``helix_deg``, positive = right hand; the sun the other hand), every
    member held axially by ``axial_stiffness`` (N/m, damping as its radial support's) and the mesh stiffness
    model ``stiffness`` at demo-3p's mean; ``extra`` (pattern, replacement) pairs applied after those."""
    axial = f"axial_stiffness = {axial_stiffness!r}, axial_damping = 500.0"
    pairs = [(r"^face_width_mm = 40.0$", f"face_width_mm = 40.0\nhelix_angle_deg = {helix_deg!r}"),
             (r'model = "rectangular"', f'model = "{stiffness}"'),
             (r"^(support|bearing) = \{ (.*) \}$", rf"\1 = {{ \2, {axial} }}"), *extra]
    return edited("demo-3p", pairs, f"helical {helix_deg:g} deg")
