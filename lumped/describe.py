"""Derived quantities of a train, as ``gearcheck show`` prints them: ratio, speeds, gear geometry
(helix angles), contact ratios (transverse and face), operating pressure angles, mesh frequencies and phases, loaded
flanks, mesh stiffness and damping; what the other parts show of themselves (an RV reducer's cycloid-pin stage:
:meth:`gearcheck.train.parts.Part.describe`)."""

from __future__ import annotations

import math

from gearcheck.lumped.assembly import build_model
from gearcheck.shared.units import rad_s_to_rpm


def describe(spec) -> dict:
    """Derived quantities of a train, JSON-ready (SI, speeds in rpm, angles in degrees)."""
    model = build_model(spec)
    kin = model.kin
    out = {
        "train": spec.name, "description": spec.description, "source": spec.source, "file": spec.path,
        "input": spec.input, "output": spec.output, "held": list(spec.held),
        "references": list(spec.references), "ratio": kin.ratio,
        "input_speed_rpm": rad_s_to_rpm(spec.operating.input_speed),
        "input_torque_nm": kin.input_torque, "output_torque_nm": kin.output_torque,
        "speeds_rpm": {m: rad_s_to_rpm(w) for m, w in kin.speeds.items()},
        "stages": [], "meshes": [],
    }
    for stage in spec.stages:
        out["stages"].append({
            "name": stage.name, "planets": len(stage.planets), "carrier_radius_m": stage.carrier_radius,
            "planet_angles_deg": [math.degrees(a) for a in stage.planet_angles],
            "gears": {_gear_label(spec.members[mid], g): {
                "teeth": g.teeth, "pitch_radius_m": g.pitch_radius, "base_radius_m": g.base_radius,
                "tip_radius_m": g.tip_radius, "profile_shift": g.profile_shift,
                "helix_angle_deg": math.degrees(g.helix_angle), "normal_module_m": g.normal_module}
                for mid in stage.centrals + stage.planets[:1] for g in spec.members[mid].gears.values()},
        })
    stages = {entry["name"]: entry for entry in out["stages"]}
    touching = {r.name for r in model.rows if r.kind == "contact"}
    for part in spec.parts:
        shown = part.describe(spec, kin, touching)
        if shown:
            stages[part.stage][part.element] = shown
    for j, mesh in enumerate(spec.meshes):
        g = mesh.geometry
        out["meshes"].append({
            "mesh": mesh.id, "contact_ratio": g.contact_ratio, "face_contact_ratio": g.face_contact_ratio,
            "base_helix_angle_deg": math.degrees(g.base_helix_angle), "operating_pressure_angle_deg":
                math.degrees(g.pressure_angle), "mesh_frequency_hz": kin.mesh_frequency[mesh.id],
            "phase_cycles": kin.mesh_phase[mesh.id], "loaded_flank": kin.flanks[mesh.id],
            "mean_stiffness_n_per_m": float(model.excitation.mean_stiffness[j]),
            "damping_n_s_per_m": float(model.mesh_damping[j]), "backlash_m": mesh.backlash,
            "stiffness_model": mesh.stiffness["model"],
        })
    return out


def _gear_label(member, gear) -> str:
    if member.is_planet:
        return "planet" if gear.name == "planet" else f"planet.{gear.name}"
    return gear.name
