"""Natural frequencies of the reference lumped model at mean mesh stiffness.

* :func:`modes`: K_mean q = omega^2 M q without the rotating-frame terms (as in Lin & Parker 1999,
  section 3), classified by the central members' coordinates (:func:`gearcheck.shared.modal.mode_types`);
* :func:`modes_at_speed`: the gyroscopic eigenproblem (M s^2 + Omega G s + K_mean + K_Omega) x = 0 of the
  train turning at a speed (Cooley & Parker 2012): complex s, frequency splitting of the degenerate
  modes, divergence and flutter where the centripetal softening wins;
* :func:`settling_time`: how long the damped free vibration of a start lasts;
* :func:`line_drives`, :func:`line_resonances`: the modes each mesh-harmonic line can drive (mesh-phasing
  selection rules).
"""

from __future__ import annotations

import numpy as np

from gearcheck.lumped.harmonic import phased_force
from gearcheck.lumped.static import static_solution
from gearcheck.train.spec import AXIAL, ROTATION
from gearcheck.shared import modal as shared
from gearcheck.shared.modal import ModalResult, modal_result
from gearcheck.shared.units import rad_s_to_rpm


def central_coordinates(spec, labels) -> tuple[list[int], list[int]]:
    """Indices, among the coordinate ``labels`` (``member.dof``), of the central members' translations and of
    their rotations (a helical mesh's axial force goes with its torque, Eritenel & Parker 2009: the axial
    slides count with the rotations); labels of no member of ``spec`` are neither."""
    named = [(i, label.rsplit(".", 1)) for i, label in enumerate(labels) if "." in label]
    central = [(i, dof) for i, (member, dof) in named if member in spec.members and spec.members[member].central]
    turning = (ROTATION, AXIAL)
    return [i for i, d in central if d not in turning], [i for i, d in central if d in turning]


def _central(model) -> tuple[list[int], list[int]]:
    return central_coordinates(model.spec, model.dofs.labels())


def modes(model) -> ModalResult:
    """Natural frequencies of a :class:`~gearcheck.lumped.assembly.LumpedModel` at mean mesh stiffness."""
    return modal_result(model.spec.name, "lumped", model.K_mean, model.M, model.dofs.labels(), *_central(model))


def modes_at_speed(model, input_speed: float) -> ModalResult:
    """The undamped modes of the train turning with its input at ``input_speed`` (rad/s, 0 allowed: then
    the modes of :func:`modes`), every mesh at its mean stiffness."""
    at = model.at_speed(input_speed)
    return shared.speed_modal_result(model.spec.name, "lumped", at.M, at.G, at.K_mean + at.K_centripetal,
                                     model.dofs.labels(), *_central(model), rad_s_to_rpm(input_speed))


def settling_time(model, fraction: float) -> float:
    """The time the free vibration of the damped, rotating model at mean mesh stiffness takes to fall to
    ``fraction`` (its slowest-decaying mode): how long a run from the static state needs before its
    start has died away."""
    return shared.settling_time(model.M, model.C + model.G, model.K_mean + model.K_frame, fraction)


DRIVEN = 1e-6  # a line drives a mode if it drives it more than this, relative to the mode it drives most
CYCLE_SAMPLES = 4096  # a mesh cycle's stiffness samples for its Fourier coefficients


def line_resonances(model, lines) -> list[tuple[np.ndarray, np.ndarray]]:
    """For each line (mesh frequency in Hz, harmonic k) of ``lines``, (natural frequencies in Hz, damping
    ratios) of the modes of the damped, rotating model at mean mesh stiffness that the line drives
    (:func:`line_drives`)."""
    natural, damping, driven = line_drives(model, lines)
    return [(natural[line], damping[line]) for line in driven.T]


def drives_are_linear(model) -> bool:
    """Whether :func:`line_drives` finds the modes each line drives from its first-order forces: every mesh's force
    linear in its deflection (no tip relief) and no torque ripple that may fall on a line; else it counts every
    mode."""
    return not (model.excitation.relieved.size or model.excitation.ripple)


def line_drives(model, lines) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(natural frequencies in Hz, damping ratios) of the elastic modes of the damped, rotating model at mean mesh
    stiffness (:func:`gearcheck.shared.modal.damped_modes`), and whether each line (mesh frequency in Hz at the
    model's own speed, harmonic k) of ``lines`` drives each mode (modes, lines).

    A line is forced by the meshes of its frequency: to first order, mesh m's force k_m(t) (a_m.q - e_m(t))
    puts into it a_m (c_mk d_m - k_m E_mk) e^(-2 pi i k phi_m), c_mk the k-th Fourier coefficient of its
    stiffness over a mesh cycle, d_m its static elastic deflection (static force over mean stiffness k_m), E_mk
    that of its static transmission error's harmonic k, phi_m its mesh phase (Parker & Lin 2004).  The planets'
    phases cancel the sum on whole families of modes (rotational modes only where k z_s is a multiple of the
    number N of equally spaced planets, translational ones where k z_s = +-1 mod N, Parker 2000).  A mode counts
    where the line drives it (:func:`gearcheck.shared.modal.driven_modes`) more than :data:`DRIVEN` of the mode
    it drives most: over the speed ranges of the hub drive, the helical planetary, the RV reducer and demo-3p,
    the cancelled ones sit at round-off (1.3e-10 and below), the driven ones at 4e-4 and above.  A gear's
    eccentricity forces its rotation frequency, off the lines.  A line at no mesh's frequency is refused
    (ValueError): no mesh forces it, and "it drives no mode" would be a wrong answer.  Where a mesh's force is not
    linear in its deflection (tip relief) or a torque ripple may fall on a line, every mode counts for every
    line."""
    exc = model.excitation
    M, D, K = model.M, model.C + model.G, model.K_mean + model.K_frame
    if not drives_are_linear(model):
        natural, damping = shared.damped_modes(M, D, K)
        return natural, damping, np.ones((natural.size, len(lines)), dtype=bool)
    deflection = static_solution(model).mesh_force / exc.mean_stiffness
    xi = np.arange(CYCLE_SAMPLES) / CYCLE_SAMPLES
    shapes = [stiffness(xi) for stiffness in exc.models]
    forces = np.zeros((M.shape[0], len(lines)), dtype=complex)
    for i, (frequency, k) in enumerate(lines):
        amplitudes = np.zeros(len(exc.models), dtype=complex)
        meshes = np.flatnonzero(np.isclose(exc.frequency, frequency, rtol=1e-9, atol=0.0))
        if not meshes.size:  # no force to drive anything: not "drives nothing"
            raise ValueError(f"line at {frequency!r} Hz (harmonic {k}) is no mesh frequency of {model.spec.name} at "
                             f"its speed ({', '.join(f'{f:.6g}' for f in np.unique(exc.frequency))} Hz)")
        for m in meshes:
            c = np.mean(shapes[m] * np.exp(-2j * np.pi * k * xi))
            error = sum(0.5 * amplitude * np.exp(1j * phase)
                        for h, amplitude, phase in model.spec.meshes[m].ste if h == k)
            amplitudes[m] = c * deflection[m] - exc.mean_stiffness[m] * error
        forces[:, i] = phased_force(model, k, amplitudes)
    natural, damping, drive = shared.driven_modes(M, D, K, forces)
    return natural, damping, drive > DRIVEN
