"""Response sensitivity to design parameters: derivatives of the steady harmonic amplitudes with respect to any
number of a train file (Yang, Chen & Wang 2018, Eqs. 13-16), and maps of them over the mesh frequency.

The derivative of the response is in closed form (:mod:`gearcheck.lumped.response_sensitivity`: the harmonic
equations differentiated); the derivative of the model's data -- M, C, K(theta), F -- is the central difference
of two models built from the train file with the number moved by +-``step`` of itself, the pins' contact pattern
held (exact to round-off for a stiffness, a mass or a damping, which enter linearly; O(step^2) for a geometric
number such as the eccentricity).  :func:`field_sensitivity` also differentiates the whole response by central
differences (Richardson-extrapolated over h and h/2: near a resonance the plain difference's h^2 error is
amplified by the inverse detuning squared), so every closed-form derivative comes with its check.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, replace

import numpy as np
import tomli_w

from gearcheck.compare.calibrate import FitParameter
from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.forced_response import parametric_problem
from gearcheck.lumped.fourier_response import (
    HarmonicResponse,
    ParametricProblem,
    fourier_series_response,
    harmonic_balance_response,
)
from gearcheck.lumped.loader import load_text, load_train
from gearcheck.lumped.response_sensitivity import (
    fourier_series_sensitivity,
    harmonic_balance_sensitivity,
    parameter_derivative,
)
from gearcheck.shared.errors import GearcheckError

METHODS = ("harmonic balance", "Fourier series")
ORDERS = (3, 2)  # harmonics kept per clock by default: the mesh's, then an RV reducer's eccentrics'
STEP = 1e-4  # relative: the matrices are linear in most numbers, so round-off (1e-12) rules, not the step
MAP_GRIDS = {"mesh_grid": 1024, "eccentric_grid": 512, "alias": 1e-2}  # a map's samples per clock: 1e-2 aliasing


@dataclass(frozen=True)
class FieldSensitivity:
    """d|Q_h|/d p of every harmonic and coordinate for the number ``parameter`` (value ``value`` in the file's
    unit): ``closed_form`` from the differentiated harmonic equations, ``truncated`` the same with the paper's
    Eq. (15) (dA dropped; Fourier-series method only, else None), ``finite_difference`` of the whole response."""

    parameter: str
    value: float
    method: str
    response: HarmonicResponse
    closed_form: np.ndarray  # (harmonics, n), per unit of the file's number
    truncated: np.ndarray | None
    finite_difference: np.ndarray

    def relative_error(self, floor: float = 1e-3) -> float:
        """The largest |closed form - finite difference| over the entries whose finite difference is above
        ``floor`` times the largest, relative to that entry."""
        fd, cf = self.finite_difference, self.closed_form
        big = np.abs(fd) > floor * np.nanmax(np.abs(fd))
        return float(np.nanmax(np.abs(cf[big] - fd[big]) / np.abs(fd[big])))


def field_sensitivity(text: str, source: str, parameter: str, orders=None, method: str = METHODS[0],
                      speed: float | None = None, step: float = STEP, **grids) -> FieldSensitivity:
    """The sensitivity of the steady response of the train file ``text`` to the number at ``parameter``
    (a path such as ``stages[0].crank.eccentricity_mm``), at ``speed`` rpm (default the file's), on the
    harmonic lattice ``orders`` (default :data:`ORDERS`, one per clock); ``grids`` go to
    :func:`~gearcheck.lumped.forced_response.parametric_problem`."""
    _check(method)
    field = FitParameter.parse(parameter, option="--parameter")
    value = field.get(tomllib.loads(text))
    h = step * value
    contacts: dict = {}
    base = _problem(text, source, field, value, speed, contacts, grids)
    orders = lattice(base, orders)
    plus, minus = (_problem(text, source, field, value + s, speed, contacts, grids) for s in (h, -h))
    closed, truncated = _closed_form(base, _derivative(base, plus, minus, h), orders, method)
    solve = harmonic_balance_response if method == METHODS[0] else fourier_series_response
    half = [_problem(text, source, field, value + s, speed, contacts, grids) for s in (h / 2, -h / 2)]
    fd = [(np.abs(solve(a, orders).amplitudes) - np.abs(solve(b, orders).amplitudes)) / (2 * d)
          for a, b, d in ((plus, minus, h), (*half, h / 2))]
    return FieldSensitivity(parameter, value, method, closed.response, closed.d_modulus, truncated,
                            (4 * fd[1] - fd[0]) / 3)  # Richardson: O(h^4)


def _check(method: str) -> None:
    if method not in METHODS:
        raise GearcheckError(f"--method {method!r}: one of {', '.join(METHODS)}")


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
    if len(orders) != problem.dim or min(orders) < 0:
        raise GearcheckError(f"--orders {' '.join(map(str, orders))}: give {problem.dim} non-negative number"
                             f"{'s' if problem.dim > 1 else ''}, one per clock of this train (mesh"
                             f"{', eccentrics' if problem.dim > 1 else ''})")
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


def sensitivity_map(text: str, source: str, parameters: list[str], speeds_rpm, coordinate: str, orders=None,
                    method: str = METHODS[1], progress=None, **grids):
    """d|Q_h|/d ln p of ``coordinate`` (a model coordinate, ``rv.carrier.theta``) for each parameter at each input
    speed (the paper's Figs. 5-10 over the mesh frequency), with the paper's Eq. (15) beside it for the
    Fourier-series method.  The pins' contact pattern is that of the first speed at every speed (it moves only
    with the rotating-frame terms); ``grids`` default to :data:`MAP_GRIDS`.  A pandas DataFrame, one row per
    speed, parameter and harmonic."""
    import pandas as pd

    grids = grids or MAP_GRIDS
    _check(method)
    fields = [FitParameter.parse(p, option="--parameter") for p in parameters]
    document = tomllib.loads(text)
    values = [f.get(document) for f in fields]
    contacts: dict = {}
    rows = []
    for k, rpm in enumerate(speeds_rpm):
        model = _model(text, source, None, None, rpm)
        labels = model.dofs.labels()
        if coordinate not in labels:
            raise GearcheckError(f"--coordinate {coordinate!r}: not a coordinate of {model.spec.name} "
                                 f"(e.g. {', '.join(labels[:4])}, ...)")
        index = labels.index(coordinate)
        base = parametric_problem(model, contacts=contacts, **grids)
        orders = lattice(base, orders)
        f_mesh = float(model.excitation.frequency.min())
        for field, value in zip(fields, values):
            h = STEP * value
            plus, minus = (_problem(text, source, field, value + s, rpm, contacts, grids) for s in (h, -h))
            full, truncated = _closed_form(base, _derivative(base, plus, minus, h), orders, method)
            for j, hk in enumerate(full.response.harmonics):
                rows.append({"speed_rpm": float(rpm), "mesh_frequency_hz": f_mesh, "parameter": field.path,
                             "harmonic": str(tuple(int(x) for x in hk)),
                             "frequency_hz": float(full.response.frequencies[j]) / (2 * np.pi),
                             "amplitude": float(np.abs(full.response.amplitudes[j, index])),
                             "d_amplitude_d_ln_p": float(full.d_modulus[j, index]) * value,
                             "eq15_d_amplitude_d_ln_p": None if truncated is None
                             else float(truncated[j, index]) * value})
        if progress is not None:
            progress((k + 1) / len(speeds_rpm))
    return pd.DataFrame(rows)
