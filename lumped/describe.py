"""Derived quantities of a train, as ``gearcheck show`` prints them: ratio, speeds, gear geometry
(helix angles), contact ratios (transverse and face), operating pressure angles, mesh frequencies and phases, loaded
flanks, mesh stiffness and damping; what the other parts show of themselves (an RV reducer's cycloid-pin stage:
:meth:`gearcheck.train.parts.Part.describe`); how long the free vibration of a start takes to die away, and which
supports have no damping (gearcheck adds none that the train file does not state)."""

from __future__ import annotations

import math

from gearcheck.lumped.assembly import build_model
from gearcheck.shared.modal import slowest_decaying_mode
from gearcheck.shared.units import rad_s_to_rpm

SETTLED = 2e-3  # the fraction of a start's free vibration that counts as died away (the cross-check's steady rule)


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
            "torsional": [mid for mid, m in spec.members.items() if m.stage == stage.name and m.torsional],
            "tilting_inertia_kg_m2": {mid: m.tilting_inertia for mid, m in spec.members.items()
                                      if m.stage == stage.name and m.tilting},
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
    rows = {r.name: r for r in model.rows}
    for j, mesh in enumerate(spec.meshes):
        g = mesh.geometry
        out["meshes"].append({
            "mesh": mesh.id, "contact_ratio": None if mesh.central_gear.idealised else g.contact_ratio,
            "face_contact_ratio": g.face_contact_ratio,
            "base_helix_angle_deg": math.degrees(g.base_helix_angle), "operating_pressure_angle_deg":
                math.degrees(g.pressure_angle), "mesh_frequency_hz": kin.mesh_frequency[mesh.id],
            "phase_cycles": kin.mesh_phase[mesh.id], "loaded_flank": kin.flanks[mesh.id],
            "mean_stiffness_n_per_m": float(model.excitation.mean_stiffness[j]),
            "damping_n_s_per_m": float(model.mesh_damping[j]), "backlash_m": mesh.backlash,
            "stiffness_model": mesh.stiffness["model"],
        })
        tilt = rows.get(f"{mesh.id}.tilt")
        if tilt is not None:  # a tilting stage's mesh: its face and tilting stiffness
            out["meshes"][-1].update(face_centre_m=mesh.axial_centre, face_width_m=mesh.contact_width,
                                     tilting_stiffness_n_m_per_rad=tilt.stiffness)
    out["settling"] = settling(spec, model)
    return out


def settling(spec, model) -> dict:
    """The slowest-decaying mode of the model at mean mesh stiffness (frequency, damping ratio, time constant), the
    time its free vibration takes to fall to ``SETTLED`` of its start, and each support or bearing direction that
    is stiff but has no damping ("stage1.sun radial")."""
    frequency, zeta = slowest_decaying_mode(model.M, model.C + model.G, model.K_mean + model.K_frame)
    tau = None if zeta <= 0.0 else 1.0 / (2 * math.pi * frequency * zeta)  # None: it never decays
    undamped = [f"{mid} {direction}" for mid, member in spec.members.items() for s in (member.support, member.bearing)
                if s is not None for direction in _undamped(s)]
    return {"slowest_mode_hz": frequency, "damping_ratio": zeta, "time_constant_s": tau,
            "settle_s": None if tau is None else tau * math.log(1.0 / SETTLED), "undamped_supports": undamped}


def _undamped(support) -> list[str]:
    """The directions in which ``support`` is stiff but has no damping."""
    return [direction for direction, k, c in (("radial", support.radial_stiffness, support.radial_damping),
                                              ("torsional", support.torsional_stiffness, support.torsional_damping),
                                              ("axial", support.axial_stiffness, support.axial_damping),
                                              ("tilting", support.tilting_stiffness, support.tilting_damping))
            if k > 0.0 and c <= 0.0]


def _gear_label(member, gear) -> str:
    if member.is_planet:
        return "planet" if gear.name == "planet" else f"planet.{gear.name}"
    return gear.name
