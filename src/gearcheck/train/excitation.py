"""What drives the train: torques, mesh stiffness variation and transmission error.

All functions of time here follow the nominal kinematics (the "nominal clock"), so the lumped
solver and the MuJoCo runner evaluate exactly the same excitation.  Signs: a static transmission
error e > 0 compresses the mesh, so the mesh force is k(t) f(delta - e) + c (d delta/dt - de/dt); a mesh
with tip relief sums its tooth pairs instead of k(t) (:meth:`Excitation.tooth_pairs`).
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.shared.errors import GearcheckError, one_line, shown
from gearcheck.shared.stepping import LIMIT_CYCLES
from gearcheck.shared.trust import named_code
from gearcheck.train.expression import Expression
from gearcheck.train.history import Clock, speed_clock, torque_clock
from gearcheck.train.kinematics import Kinematics
from gearcheck.train.line_of_action import line_of_action
from gearcheck.train.mesh_stiffness import ConstantStiffness, stiffness_model
from gearcheck.train.tooth_pairs import ToothPairs, relieved


def smooth_ramp(t, duration: float):
    """0 -> 1 over ``duration`` with zero slope at both ends (1 when duration is 0); array-valued."""
    t = np.asarray(t, dtype=float)
    if duration <= 0.0:
        return np.ones_like(t)
    s = np.clip(t / duration, 0.0, 1.0)
    return s * s * (3.0 - 2.0 * s)


class Excitation:
    """Time functions of one train at its operating point."""

    def __init__(self, spec, kin: Kinematics):
        self.spec = spec
        self.kin = kin
        meshes = spec.meshes
        self.mesh_ids = [m.id for m in meshes]
        self.frequency = np.array([kin.mesh_frequency[m.id] for m in meshes])
        self.phase = np.array([kin.mesh_phase[m.id] for m in meshes])
        self.models = [stiffness_model(m) for m in meshes]
        self.mean_stiffness = np.array([model.mean for model in self.models])
        self.max_stiffness = np.array([model.maximum for model in self.models])
        self.backlash = np.array([m.backlash for m in meshes])
        # meshes whose gears carry a tip relief: their force is the sum over their tooth pairs
        self.relieved = np.array([j for j, m in enumerate(meshes) if relieved(m)], dtype=int)
        self._pairs = [ToothPairs(meshes[j], self.mean_stiffness[j]) for j in self.relieved]
        self._ste = [(i, h, a, p) for i, m in enumerate(meshes) for (h, a, p) in m.ste]
        self._eccentric = list(self._eccentric_terms(spec, kin))
        self._terms = (np.array(self._ste, dtype=float).reshape(-1, 4),  # the compiled sums' rows
                       np.array(self._eccentric, dtype=float).reshape(-1, 6))
        op = spec.operating
        # torque ripple harmonics: (member "input" | "output", amplitude, angular frequency rad/s, phase rad)
        self.ripple = [(r.member, r.amplitude, self._ripple_omega(r), r.phase) for r in op.ripple]
        self._of_order = [r.frequency is None for r in op.ripple]  # turning with a member: on the nominal clock
        self._function = None  # the torque function, imported on first use (:meth:`torque_function`)
        self._profile = None if op.torque_profile is None else tuple(np.asarray(x) for x in op.torque_profile)
        self._expression = None if op.torque_expression is None else \
            Expression(op.torque_expression, f"{spec.path}: operating.torque_expression")
        self.history = op.history
        self.clock = None if op.history is None else self._clock()

    # ------------------------------------------------------------------ the nominal clock
    def nominal_time(self, t) -> np.ndarray:
        """Lambda(t): every nominal angle is its member's reference speed times it (t at constant speed)."""
        return np.asarray(t, dtype=float) if self.clock is None else self.clock.time(t)

    def speed_scale(self, t) -> np.ndarray:
        """lambda(t): the nominal speeds over their reference values (1 at constant speed)."""
        return np.ones(np.shape(t)) if self.clock is None else self.clock.scale(t)

    def _clock(self) -> Clock:
        """The nominal clock of the history (:mod:`gearcheck.train.history`): a prescribed speed's, or the rigid
        train's motion under the prescribed torques (the order ripple, whose phase needs the clock, left out: it
        has no mean)."""
        history, kin, spec = self.history, self.kin, self.spec
        if history.driven_by == "speed":
            return speed_clock(history, spec.operating.input_speed)
        inertia = drag = 0.0
        for mid, member in spec.members.items():
            w = kin.speeds[mid]
            inertia += member.inertia * w**2
            if member.orbits:
                inertia += member.mass * (member.radius * kin.speeds[f"{member.stage}.carrier"]) ** 2
            elif member.support:
                drag -= member.support.torsional_damping * w**2
        w_in, w_out = kin.speeds[spec.input], kin.speeds[spec.output]

        def power(t):
            t_in, t_out = self._torques(t, None)
            return w_in * t_in + w_out * t_out

        return torque_clock(power, history.corners, inertia, drag, 0.0 if history.start == "rest" else 1.0,
                            history.end)

    # ------------------------------------------------------------------ meshes
    def mesh_position(self, t, side=0) -> np.ndarray:
        """Mesh cycles elapsed (xi = f t - phase); shape (..., n_mesh) for t of shape (...).  ``side`` (+1, -1 or 0,
        broadcast with t): read the right-hand or left-hand limit of a drive that jumps at t,
        :data:`~gearcheck.shared.stepping.LIMIT_CYCLES` along the cycle."""
        t = np.asarray(t, dtype=float)
        shift = np.multiply(side, LIMIT_CYCLES)
        angle = np.broadcast_to(self.nominal_time(t), np.broadcast_shapes(t.shape, np.shape(shift)))
        xi = np.empty(angle.shape + (len(self.models),))
        for j in range(len(self.models)):
            self._cycles(j, angle, shift, xi[..., j])
        return xi

    def _cycles(self, j: int, angle, shift, out) -> np.ndarray:
        """Mesh j's cycles elapsed at the nominal times ``angle``, shifted by ``shift`` cycles, into ``out``:
        f_j angle - phase_j + shift, in that order (the bits :meth:`mesh_position` gives)."""
        np.multiply(self.frequency[j], angle, out=out)
        out -= self.phase[j]
        out += shift
        return out

    def stiffness(self, t, side=0) -> np.ndarray:
        """k(t) per mesh in N/m; shape (..., n_mesh) for t of shape (...); ``side`` as in :meth:`mesh_position`."""
        t = np.asarray(t, dtype=float)
        angle = self.nominal_time(t)
        shift = np.broadcast_to(np.multiply(side, LIMIT_CYCLES), t.shape)
        k = np.empty(t.shape + (len(self.models),))
        xi = np.empty(t.shape)
        for j, model in enumerate(self.models):  # one mesh at a time: no (..., n_mesh) temporary
            k[..., j] = model(self._cycles(j, angle, shift, xi))
        return k

    def tooth_pairs(self, t, side=0):
        """(k_j, e_j) of the relieved meshes' tooth pairs (:class:`~gearcheck.train.tooth_pairs.ToothPairs`):
        shape (..., n_relieved, pairs) for t of shape (...), each mesh's pairs padded to the largest count
        with k = 0, e = inf; (None, None) when no mesh is relieved; ``side`` as in :meth:`mesh_position`.  The
        mesh force is sum_j k_j max(0, delta - e(t) - e_j) + c (d delta/dt - de/dt)."""
        if not self._pairs:
            return None, None
        xi = self.mesh_position(t, side=side)[..., self.relieved]
        size = max(p.size for p in self._pairs)
        k = np.zeros(xi.shape + (size,))
        e = np.full(xi.shape + (size,), np.inf)
        for r, pairs in enumerate(self._pairs):
            k[..., r, :pairs.size], e[..., r, :pairs.size] = pairs(xi[..., r])
        return k, e

    def switch_times(self, t0: float, t1: float, meshes=None, corners: bool = True) -> np.ndarray:
        """Sorted times in (t0, t1) at which some mesh's stiffness (or that of the meshes of indices ``meshes`` alone)
        jumps (its model's ``breaks``) or, under a history and with ``corners``, the speed's or a torque's slope
        does (their points)."""
        times = []
        a0, a1 = (float(x) for x in self.nominal_time(np.array([t0, t1])))
        chosen = list(range(len(self.models)) if meshes is None else meshes)
        for f, phase, model in (zip(self.frequency[chosen], self.phase[chosen], [self.models[j] for j in chosen])):
            for b in model.breaks:
                if f > 0:  # xi = f Lambda(t) - phase = n + b
                    n = np.arange(math.floor(f * a0 - phase - b), math.ceil(f * a1 - phase - b) + 1)
                    at = (n + b + phase) / f
                    at = at[(at > a0) & (at < a1)]
                    times.append(at if self.clock is None else self.clock.times_at(at, t0, t1))
        if self.clock is not None and corners:
            times += [self.clock.corners, self.history.corners]
        t = np.concatenate(times) if times else np.empty(0)
        return np.unique(t[(t > t0) & (t < t1)])

    def periodic_terms(self) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """(the frequencies in Hz of the drive's periodic terms: time-varying mesh stiffness, transmission error
        harmonics, eccentricities, torque ripple, a torque profile repeated; those of the time-varying meshes
        alone; the terms without a period, named)."""
        varying = np.array([not isinstance(m, ConstantStiffness) for m in self.models], dtype=bool)
        meshes = np.abs(self.frequency[varying])
        freqs = [meshes]
        freqs += [np.array([h * abs(self.frequency[i])]) for i, h, _, _ in self._ste]
        freqs += [np.array([abs(omega) / (2 * math.pi)]) for _, _, omega, *_ in self._eccentric]
        freqs += [np.array([abs(omega) / (2 * math.pi)]) for _, _, omega, _ in self.ripple]
        if self._profile is not None:
            times = self._profile[0]
            freqs.append(np.array([1.0 / (times[-1] - times[0])]))
        op = self.spec.operating
        aperiodic = [op.aperiodic_torque] if op.aperiodic_torque else []
        if op.history is not None:
            aperiodic.append(f"the operating history ({op.history.words()})")
        if op.ramp > 0:
            aperiodic.append(f"the load ramp over the first {op.ramp:g} s")
        return np.concatenate(freqs), meshes, aperiodic

    def torque_function(self, t) -> np.ndarray:
        """The train file's ``operating.torque_function`` at times t, in N·m: code, so imported only when the user
        trusts its module (:func:`~gearcheck.shared.trust.named_code`), and each value checked to be a finite
        torque."""
        ref = self.spec.operating.torque_function
        label = f"{self.spec.path}: operating.torque_function"
        if self._function is None:
            self._function = named_code(ref, label, from_file=True)
        values = []
        for time in np.ravel(t):
            try:
                value = self._function(float(time))
            except (Exception, SystemExit) as exc:  # a wrong signature, or an error inside the user's function
                raise GearcheckError(f"{label}: {ref}({float(time)!r}) raised {type(exc).__name__}: {one_line(exc)} "
                                     "(it must map a time in s to a torque in N·m)") from None
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) \
                    or not math.isfinite(value):
                raise GearcheckError(f"{label}: {ref}({float(time)!r}) returned {shown(value)}; it must return a "
                                     "finite torque in N·m")
            values.append(float(value))
        return np.reshape(values, np.shape(t))

    @property
    def has_transmission_error(self) -> bool:
        return bool(self._ste or self._eccentric)

    def transmission_error(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Static transmission error e(t) and its rate per mesh, in m and m/s; shape (..., n_mesh)."""
        t = np.asarray(t, dtype=float)
        shape = t.shape + (len(self.mesh_ids),)
        if not self.has_transmission_error:  # zeros map zero pages until they are written (zeros_like writes them)
            return np.zeros(shape), np.zeros(shape)
        from gearcheck.train.compiled_excitation import add_terms  # numba on first use, not when a file is read

        flat = np.ravel(t)
        new = np.ones(flat.size, dtype=bool)  # a time equal to the one before it (a step's end and the next step's
        new[1:] = flat[1:] != flat[:-1]       # start, most often) takes its terms: the same bits, less work
        times = flat[new]
        angle = self.nominal_time(times)  # the angles turn at lambda times their speeds
        scale = np.ones(times.size) if self.clock is None else np.broadcast_to(self.clock.scale(times), times.shape)
        e, de = np.zeros((2, times.size, shape[-1]))
        add_terms(angle, np.ascontiguousarray(scale), self.frequency, self.phase, *self._terms, e, de)
        if times.size < flat.size:
            at = np.cumsum(new) - 1
            e, de = e[at], de[at]
        return e.reshape(shape), de.reshape(shape)

    @staticmethod
    def _eccentric_terms(spec, kin):
        """Eccentricity and installation error of a gear: its pitch-circle centre offset, turning with the
        gear (eccentricity) or with its mount (installation error: the housing for a central gear, the
        carrier for a planet) relative to the carrier frame, projected on the line of action (+ for the
        central gear, - for the planet)."""
        for i, mesh in enumerate(spec.meshes):
            stage = spec.stage_of(mesh.planet)
            planet = spec.members[mesh.planet]
            loa = line_of_action(mesh, planet.angle, stage.carrier_radius, kin.flanks[mesh.id])
            w_c = kin.speeds[stage.carrier]
            for gear, member, sign, base in ((mesh.central_gear, mesh.central, 1.0, 0.0),
                                             (mesh.planet_gear, mesh.planet, -1.0, planet.angle)):
                mount = w_c if member == mesh.planet else 0.0
                dx, dy = sign * loa.direction
                for amplitude, omega, phase in ((gear.eccentricity, kin.speeds[member] - w_c, gear.eccentricity_phase),
                                                (gear.installation_error, mount - w_c, gear.installation_error_phase)):
                    if amplitude > 0.0:
                        yield i, amplitude, omega, base + phase, dx, dy

    # ------------------------------------------------------------------ torques
    def _ripple_omega(self, ripple) -> float:
        if ripple.frequency is not None:
            return 2 * math.pi * ripple.frequency
        member = self.spec.input if ripple.member == "input" else self.spec.output
        return ripple.order * abs(self.kin.speeds[member])

    def torques(self, t) -> tuple[np.ndarray, np.ndarray]:
        """(torque on the input member, torque on the output member) in N·m, signed; array-valued.

        A shaft-driven input gets its mean torque from the shaft spring; only ripple and
        a user function act on it directly.  The load is ramped in over ``ramp_s``.  A history's input torque
        replaces the mean input torque, its load the mean load (opposing the output's rotation).
        """
        return self._torques(t, self.nominal_time(t))

    def _torques(self, t, angle) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`torques`, the order ripple at the nominal time ``angle`` (None: left out)."""
        t = np.asarray(t, dtype=float)
        op = self.spec.operating
        ramp = smooth_ramp(t, op.ramp)
        t_in_mean = self.kin.input_torque
        t_out_mean = self.kin.output_torque
        t_in = np.zeros_like(t) if op.input_shaft_stiffness is not None else t_in_mean * ramp
        t_out = t_out_mean * ramp
        history = self.history
        if history is not None and history.torque is not None:
            t_in = history.torque(t)
        if history is not None and history.load is not None:
            t_out = -math.copysign(1.0, self.kin.speeds[self.spec.output]) * history.load(t)
        for (member, amp, omega, phase), order in zip(self.ripple, self._of_order):
            if (order and angle is None) or (history is not None and
                                             (history.torque if member == "input" else history.load) is not None):
                continue  # a history's torques replace the mean torques and their ripple
            wave = amp * np.cos(omega * (angle if order else t) + phase) * ramp
            if member == "input":
                t_in = t_in + t_in_mean * wave
            else:
                t_out = t_out + t_out_mean * wave
        if op.torque_function:
            t_in = t_in + self.torque_function(t)
        if op.torque_expression:
            t_in = t_in + self._expression(t)
        if self._profile is not None:
            times, values = self._profile
            phase = times[0] + np.mod(t - times[0], times[-1] - times[0])
            t_in = t_in + np.interp(phase, times, values)
        return t_in, t_out
