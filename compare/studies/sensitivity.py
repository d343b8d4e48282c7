"""Response sensitivity to design parameters: derivatives of the steady harmonic amplitudes with respect to any
number of a train file (Yang, Chen & Wang 2018, Eqs. 13-16), and maps of them over the mesh frequency.

The derivative of the response is in closed form (:mod:`gearcheck.lumped.response_sensitivity`: the harmonic
equations differentiated); the derivative of the model's data -- M, C, K(theta), F -- is the central difference
of two models built from the train file with the number moved by +-``step`` of itself, the pins' contact pattern
held (exact to round-off for a stiffness, a mass or a damping, which enter linearly; O(step^2) for a geometric
number such as the eccentricity).  :func:`field_sensitivity` also differentiates the whole response by central
differences (Richardson-extrapolated over h and h/2), so every closed-form derivative comes with its check.  The
check is on the complex amplitudes Q_h, which are rational in the number; the modulus |Q_h| is not smooth where
Q_h passes near zero (an entry of the RV reducer moves by 39 times the relative change of the pins' stiffness),
and its derivative follows from dQ_h by Eq. (13) without further approximation.
"""

from __future__ import annotations

import math

import tomllib
from dataclasses import dataclass, replace

import numpy as np
import tomli_w

from gearcheck.compare.studies.calibrate import FitParameter
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.forced_response import parametric_problem
from gearcheck.lumped.fourier_response import (
    HarmonicResponse,
    ParametricProblem,
    fourier_series_response,
    harmonic_balance_response,
)
from gearcheck.train.kinematics import require_mesh_cycle
from gearcheck.train.loader import load_text, load_train
from gearcheck.train.spec import ROTATION
from gearcheck.lumped.response_sensitivity import (
    fourier_series_sensitivity,
    harmonic_balance_sensitivity,
    parameter_derivative,
)
from gearcheck.shared.errors import GearcheckError, did_you_mean

METHODS = ("harmonic balance", "Fourier series")
ORDERS = (3, 2)  # harmonics kept per clock by default: the mesh's, then an RV reducer's eccentrics'
MAX_UNKNOWNS = 20_000  # a dense complex system of 20 000 unknowns is 6.4 GB
STEP = 1e-4  # relative: the matrices are linear in most numbers, so round-off (1e-12) rules, not the step
CHECK_STEP = 3e-3  # relative, of the whole response's differences: its round-off is 1e-10 of |dQ_h| x step
MAP_GRIDS = {"mesh_grid": 1024, "eccentric_grid": 512, "alias": 1e-2}  # a map's samples per clock: 1e-2 aliasing


@dataclass(frozen=True)
class FieldSensitivity:
    """d|Q_h|/d p of every harmonic and coordinate for the number ``parameter`` (value ``value`` in the file's
    unit): ``closed_form`` from the differentiated harmonic equations, ``truncated`` the same with the paper's
    Eq. (15) (dA dropped; Fourier-series method only, else None), ``finite_difference`` of the whole response's
    moduli; ``derivative`` and ``difference`` are the complex dQ_h/dp (and d mean/dp) of the closed form and of
    the central differences."""

    parameter: str
    value: float
    method: str
    response: HarmonicResponse
    closed_form: np.ndarray  # (harmonics, n), per unit of the file's number
    truncated: np.ndarray | None
    finite_difference: np.ndarray
    derivative: HarmonicResponse
    difference: HarmonicResponse

    def _parts(self):
        """(closed form, finite difference, response) of the harmonics' amplitudes and of the mean."""
        return ((self.derivative.amplitudes, self.difference.amplitudes, self.response.amplitudes),
                (self.derivative.mean[None], self.difference.mean[None], self.response.mean[None]))

    def _null(self, cf, fd, response) -> bool:
        """Whether both derivatives of one part are round-off: a relative change of the response below ``NULL``
        per relative change of the parameter (a sun's mass moves no mean deflection: no centripetal load at the
        centre)."""
        level = NULL * float(np.abs(response).max()) / abs(self.value) if self.value else 0.0
        return float(np.abs(fd).max()) <= level and float(np.abs(cf).max()) <= level

    @property
    def independent(self) -> bool:
        """The response does not depend on the parameter: every derivative is round-off (:meth:`_null`)."""
        return all(self._null(*part) for part in self._parts())

    def relative_error(self, floor: float = 1e-3) -> float:
        """The largest |closed form - finite difference| of dQ_h/dp and d mean/dp, relative to the largest
        |dQ_h/dp| or |d mean/dp| of the same coordinate, over the coordinates where that is above ``floor`` times
        the largest of all (the others are round-off: a sun's translation the in-phase planets never load).  A part
        whose derivatives are both round-off (:meth:`_null`) agrees (0); where the differences are all zero (the
        Fourier-series mean does not see an inertia) the closed form must be too: the error is then 0 or
        infinite."""
        errors = []
        for cf, fd, response in self._parts():
            if self._null(cf, fd, response):
                errors.append(0.0)
                continue
            scale = np.abs(fd).max(axis=0)
            if not scale.any():
                errors.append(np.inf if np.abs(cf).any() else 0.0)
                continue
            big = scale > floor * scale.max()
            errors.append((np.abs(cf - fd)[:, big] / scale[big]).max())
        return float(max(errors))


def field_sensitivity(text: str, source: str, parameter: str, orders=None, method: str = METHODS[0],
                      speed: float | None = None, step: float = STEP, check_step: float = CHECK_STEP,
                      **grids) -> FieldSensitivity:
    """The sensitivity of the steady response of the train file ``text`` to the number at ``parameter``
    (a path such as ``stages[0].crank.eccentricity_mm``), at ``speed`` rpm (default the file's), on the
    harmonic lattice ``orders`` (default :data:`ORDERS`, one per clock); the model's data differentiated with
    ``step``, the whole response with ``check_step``; ``grids`` go to
    :func:`~gearcheck.lumped.forced_response.parametric_problem`."""
    _check(method)
    spec = load_text(text, source)
    require_mesh_cycle(spec if speed is None else spec.with_operating(input_speed=1.0), "a response sensitivity")
    field = FitParameter.parse(parameter, "parameter")
    value = field.get(tomllib.loads(text))
    contacts: dict = {}
    base = _problem(text, source, field, value, speed, contacts, grids)
    orders = lattice(base, orders)
    h = step * value
    plus, minus = (_problem(text, source, field, value + s, speed, contacts, grids) for s in (h, -h))
    closed, truncated = _closed_form(base, _derivative(base, plus, minus, h), orders, method)
    solve = harmonic_balance_response if method == METHODS[0] else fourier_series_response
    h = check_step * value
    responses = {s: solve(_problem(text, source, field, value + s, speed, contacts, grids), orders)
                 for s in (h, -h, h / 2, -h / 2)}

    def richardson(of):  # central differences over h and h/2, extrapolated: O(h^4)
        one, half = ((of(responses[d]) - of(responses[-d])) / (2 * d) for d in (h, h / 2))
        return (4 * half - one) / 3

    difference = replace(closed.derivative, method=f"{closed.derivative.method}, central differences",
                         mean=richardson(lambda r: r.mean), amplitudes=richardson(lambda r: r.amplitudes))
    return FieldSensitivity(parameter, value, method, closed.response, closed.d_modulus, truncated,
                            richardson(lambda r: np.abs(r.amplitudes)), closed.derivative, difference)


def _check(method: str) -> None:
    if method not in METHODS:
        raise GearcheckError(f"method={method!r}: one of {', '.join(METHODS)}")


def _closed_form(base: ParametricProblem, derivative: ParametricProblem, orders, method: str):
    """(the closed-form sensitivity, the paper's Eq. (15) form of its modulus or None) by ``method``."""
    if method == METHODS[0]:
        return harmonic_balance_sensitivity(base, derivative, orders), None
    return (fourier_series_sensitivity(base, derivative, orders),
            fourier_series_sensitivity(base, derivative, orders, truncated=True).d_modulus)


def lattice(problem: ParametricProblem, orders) -> tuple[int, ...]:
    """``orders`` checked against the problem's clocks, or :data:`ORDERS` cut to them."""
    if orders is None:
        return ORDERS[:problem.dim]
    orders = tuple(orders)
    if len(orders) != problem.dim or not all(isinstance(o, (int, np.integer)) and not isinstance(o, bool)
                                             and o >= 0 for o in orders) or not any(orders):
        raise GearcheckError(f"orders={orders}: give {problem.dim} whole non-negative number"
                             f"{'s' if problem.dim > 1 else ''}, one per clock of this train (mesh"
                             f"{', eccentrics' if problem.dim > 1 else ''}), not all 0")
    unknowns = problem.M.shape[0] * math.prod(2 * o + 1 for o in orders)
    if unknowns > MAX_UNKNOWNS:
        raise GearcheckError(f"orders={orders}: {unknowns} complex unknowns (coordinates times harmonics), more than "
                             f"the {MAX_UNKNOWNS} whose dense system fits in memory: keep fewer orders")
    return orders


def _derivative(base: ParametricProblem, plus: ParametricProblem, minus: ParametricProblem, h: float):
    """The central difference of two problems' data (sampled like ``base``, whose aliasing was checked)."""
    difference = lambda a, b: (a - b) / (2 * h)  # noqa: E731
    periodic = {name: None if getattr(base, name) is None else
                (lambda theta, name=name: difference(getattr(plus, name)(theta), getattr(minus, name)(theta)))
                for name in ("C_of", "F_of")}
    return replace(parameter_derivative(
        base, dM=difference(plus.M, minus.M), dC=difference(plus.C, minus.C),
        dK_of=lambda theta: difference(plus.K_of(theta), minus.K_of(theta)), dF=difference(plus.F, minus.F),
        dC_of=periodic["C_of"], dF_of=periodic["F_of"]), alias=1.0)


def _problem(text, source, field: FitParameter | None, value, speed, contacts: dict, grids) -> ParametricProblem:
    """The train file's problem at ``speed`` with ``field`` (if any) set to ``value``."""
    return parametric_problem(_model(text, source, field, value, speed), contacts=contacts, **grids)


def _model(text, source, field: FitParameter | None, value, speed):
    """The train file's reference model at ``speed`` with ``field`` (if any) set to ``value``."""
    document = tomllib.loads(text)
    if field is not None:
        field.set(document, value)
    return build_model(load_train(load_text(tomli_w.dumps(document), source), speed))


NULL = 1e-9  # d ln|Q| / d ln p below this is round-off: the response does not depend on the parameter there
HARMONIC_NOTATION = ("harmonic (k1, k2): the orders of the train's clocks, at k1 times the mesh frequency plus k2 "
                     "times the second clock's (an RV reducer's eccentrics turning in the carrier); (k1,) with one "
                     "clock")


def coordinate_unit(coordinate: str) -> str:
    """The unit of a model coordinate's amplitude: rad for a rotation (``....theta``), m for a translation."""
    return "rad" if coordinate.endswith(f".{ROTATION}") else "m"


def sensitivity_map(text: str, source: str, parameters: list[str], speeds_rpm, coordinate: str, orders=None,
                    method: str = METHODS[1], progress=None, values=None, **grids):
    """d|Q_h|/d ln p of ``coordinate`` (a model coordinate, ``rv.carrier.theta``) for each parameter at each input
    speed (the paper's Figs. 5-10 over the mesh frequency), with the paper's Eq. (15) beside it for the
    Fourier-series method; with ``values``, of the one parameter set to each of those values (the file's unit) at
    each speed (the paper's Figs. 6, 8 and 10: the sensitivity against the parameter at a constant speed).  Over
    speeds the pins' contact pattern is that of the first speed at every speed (it moves only with the
    rotating-frame terms); over values each value has its own.  ``grids`` default to :data:`MAP_GRIDS`.  A pandas
    DataFrame, one row per speed, parameter, value and harmonic (:data:`HARMONIC_NOTATION`), amplitudes and their
    derivatives in ``amplitude_unit`` (:func:`coordinate_unit`), ``d_amplitude_d_p`` per unit of the number;
    ``negligible`` where d|Q_h|/d ln p or |Q_h| itself is round-off, below :data:`NULL` of the point's largest
    harmonic (a harmonic the planets' phasing cancels; a
    response that does not depend on the number: an RV reducer's in-phase planets never load the sun's
    translations, so nothing depends on its support or its mass)."""
    import pandas as pd

    grids = grids or MAP_GRIDS
    _check(method)
    fields = [FitParameter.parse(p, "parameters") for p in parameters]
    document = tomllib.loads(text)
    if values is None:
        points = [(rpm, None, [(f, f.get(document)) for f in fields]) for rpm in speeds_rpm]
    else:
        if len(fields) != 1:
            raise GearcheckError(f"parameters={parameters}: the sensitivity over values takes one parameter")
        for v in values:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v == 0:
                raise GearcheckError(f"values: {v!r} is no value of {fields[0].path} to differentiate at (a finite, "
                                     "non-zero number in the file's unit)")
        points = [(rpm, fields[0], [(fields[0], float(v))]) for rpm in speeds_rpm for v in values]
    contacts: dict = {}
    rows = []
    for k, (rpm, moved, at) in enumerate(points):
        if moved is not None:
            contacts = {}  # each value's own contact pattern
        model = _model(text, source, moved, at[0][1], rpm)
        labels = model.dofs.labels()
        if coordinate not in labels:
            raise GearcheckError(f"coordinate={coordinate!r}: not a coordinate of {model.spec.name}"
                                 + did_you_mean(coordinate, labels, n=3, cutoff=0))
        index = labels.index(coordinate)
        base = parametric_problem(model, contacts=contacts, **grids)
        orders = lattice(base, orders)
        f_mesh = float(model.excitation.frequency.min())
        for field, value in at:
            h = STEP * value
            plus, minus = (_problem(text, source, field, value + s, rpm, contacts, grids) for s in (h, -h))
            full, truncated = _closed_form(base, _derivative(base, plus, minus, h), orders, method)
            level = NULL * float(np.abs(full.response.amplitudes[:, index]).max())  # round-off of d|Q|/d ln p
            for j, hk in enumerate(full.response.harmonics):
                rows.append({"speed_rpm": float(rpm), "mesh_frequency_hz": f_mesh, "parameter": field.path,
                             "value": value, "harmonic": str(tuple(int(x) for x in hk)),
                             "frequency_hz": float(full.response.frequencies[j]) / (2 * np.pi),
                             "amplitude": float(np.abs(full.response.amplitudes[j, index])),
                             "amplitude_unit": coordinate_unit(coordinate),
                             "d_amplitude_d_p": float(full.d_modulus[j, index]),
                             "d_amplitude_d_ln_p": float(full.d_modulus[j, index]) * value,
                             "eq15_d_amplitude_d_ln_p": None if truncated is None
                             else float(truncated[j, index]) * value,
                             "negligible": float(np.abs(full.response.amplitudes[j, index])) <= level
                             or abs(float(full.d_modulus[j, index]) * value) <= level})
        if progress is not None:
            progress((k + 1) / len(points))
    return pd.DataFrame(rows)
