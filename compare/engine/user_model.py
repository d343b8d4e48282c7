"""A user's model, however it is given, as a side of the cross-check (:class:`~gearcheck.shared.side.Side`).

* a :class:`~gearcheck.lumped.linear_model.LinearModel` (built in Python);
* a file of matrices, ``.mat`` or ``.npz`` (:mod:`gearcheck.lumped.matrix_file`);
* ``module:factory`` or ``path/to/file.py:factory``: ``factory(spec)`` returns a LinearModel or a side;
* a side: a :class:`~gearcheck.shared.side.Side`, or any object with ``solver``, ``modes()``,
  ``run(settings, progress)`` and ``stable_step()`` (:class:`AdoptedSide`: with ``physical_modes(modal)`` its
  mode shapes are paired too).

Errors name the parameter, ``model=...``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from gearcheck.lumped.linear_model import LinearModel
from gearcheck.lumped.matrix_file import SUFFIXES, read_matrix_file
from gearcheck.lumped.side import LinearSide
from gearcheck.shared.errors import GearcheckError, one_line, shown
from gearcheck.shared.modal import ModalResult
from gearcheck.shared.results import TimeResult
from gearcheck.shared.side import Side
from gearcheck.shared.trust import named_code

SIDE_METHODS = tuple(sorted(Side.__abstractmethods__))  # what an object needs to be a side
CAPABILITIES = tuple(n for n in vars(Side) if not n.startswith("_") and n not in Side.__abstractmethods__)


def user_side(model, spec, from_file: bool = False) -> Side:
    """The side of ``model`` (see the module docstring) for the train ``spec``; ``from_file``: named by the train
    file (``train.user_model``), whose code runs only when trusted (:mod:`gearcheck.shared.trust`)."""
    if isinstance(model, LinearModel):
        return LinearSide(model, spec)
    if _is_side(model):
        return _as_side(model, spec, type(model).__name__)
    text = str(model)
    if Path(text).suffix in SUFFIXES:
        return LinearSide(read_matrix_file(text), spec)
    if not text.rpartition(":")[0]:
        raise GearcheckError(f"model={text!r}: give a model file ({' or '.join(SUFFIXES)}), module:factory or "
                             "file.py:factory")
    factory = named_code(text, f"model={text}", from_file)
    try:
        built = factory(spec)
    except GearcheckError:
        raise
    except (Exception, SystemExit) as exc:  # the user's code, failing in its own way (sys.exit too)
        raise GearcheckError(f"model={text}: building the model failed: {type(exc).__name__}: {exc}") from None
    if isinstance(built, LinearModel):
        built.source = built.source or text
        return LinearSide(built, spec)
    if _is_side(built):
        return _as_side(built, spec, text)
    raise GearcheckError(f"model={text}: returned {type(built).__name__}, neither a LinearModel nor a side "
                         f"(an object with {', '.join(SIDE_METHODS)})")


def _is_side(obj) -> bool:
    return isinstance(obj, Side) or all(callable(getattr(obj, m, None)) for m in SIDE_METHODS)


def _as_side(obj, spec, given) -> Side:
    if not isinstance(getattr(obj, "solver", None), str) or not obj.solver:
        raise GearcheckError(f"model={given}: the side it gives needs a 'solver' name")
    return obj if type(obj).__module__.startswith("gearcheck.") else AdoptedSide(obj, spec, given)


def _number(value, none: bool = False, positive: bool = True) -> bool:
    if value is None:
        return none
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) and \
        math.isfinite(value) and (value > 0 if positive else value >= 0)


RETURNS = {  # what each method of a side must return: (a check of the value, the words for it)
    "modes": (lambda v: isinstance(v, ModalResult), "a ModalResult"),
    "modes_at_speed": (lambda v: isinstance(v, ModalResult), "a ModalResult"),
    "run": (lambda v: isinstance(v, TimeResult), "a TimeResult"),
    "stable_step": (_number, "a positive step in s"),
    "default_step": (lambda v: _number(v, none=True), "None or a positive step in s"),
    "omega_max": (_number, "a positive angular frequency in rad/s"),
    "settling_time": (lambda v: _number(v, none=True, positive=False), "None or a time in s"),
    "slowest_mode": (lambda v: v is None or (isinstance(v, tuple) and len(v) == 2 and all(map(_number, v))),
                     "None or (frequency in Hz, damping ratio)"),
    "physical_modes": (lambda v: isinstance(v, tuple) and len(v) == 3, "(labels, mass matrix, shapes)"),
    "unmapped": (lambda v: isinstance(v, list) and all(isinstance(x, str) for x in v), "a list of signal names"),
    "run_periodic": (lambda v: isinstance(v, tuple) and len(v) == 3 and all(isinstance(r, TimeResult) for r in v[:2])
                     and isinstance(v[2], str), "(TimeResult, TimeResult, words)"),
    "operating": (lambda v: isinstance(v, dict), "a dict"),
}


class AdoptedSide(Side):
    """A side object of the user's own (a :class:`~gearcheck.shared.side.Side` or any object with its methods):
    its methods and, of the optional capabilities (:data:`CAPABILITIES`), those it has; the Side's defaults for
    the others.  The one place a foreign object's members are looked up, and the wall around its code: what it
    raises (``sys.exit`` too) and what it returns that is not what a side returns (:data:`RETURNS`) become one
    line naming the model and the method."""

    kind = "user model"

    def __init__(self, side, spec, given: str):
        self.side, self.spec, self.solver, self.given = side, spec, side.solver, given
        for name in CAPABILITIES:
            if hasattr(side, name):
                value = getattr(side, name)
                setattr(self, name, self._guarded(name, value) if callable(value) else value)
        self.references = tuple(self.references)
        if isinstance(self.notes, str) or not all(isinstance(x, str) for x in self.notes):
            raise GearcheckError(f"model={given}: its notes {shown(self.notes)} are not a list of sentences")
        self.notes = tuple(self.notes)
        if not isinstance(self.kind, str) or not self.kind.strip():
            raise GearcheckError(f"model={given}: its kind {shown(self.kind)} is no words for what it is (a string)")
        if isinstance(self.order, bool) or self.order not in (1, 2, 3, 4, 5, 6, 7, 8):
            raise GearcheckError(f"model={given}: its order {shown(self.order)} is no order of convergence (1-8)")

    def _guarded(self, name: str, method):
        check, words = RETURNS.get(name, (lambda v: True, ""))

        def call(*args):
            try:
                value = method(*args)
            except GearcheckError:
                raise
            except (Exception, SystemExit) as exc:  # the user's code, failing in its own way (sys.exit too)
                raise GearcheckError(f"model={self.given}: its {name}() raised {type(exc).__name__}: "
                                     f"{one_line(exc)}") from None
            if not check(value):
                raise GearcheckError(f"model={self.given}: its {name}() returned {shown(value)}, not {words}")
            return value
        return call

    def modes(self):
        return self._guarded("modes", self.side.modes)()

    def run(self, settings, progress=None):
        return self._guarded("run", self.side.run)(settings, progress)

    def stable_step(self) -> float:
        return self._guarded("stable_step", self.side.stable_step)()
