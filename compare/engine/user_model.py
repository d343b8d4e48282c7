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

import importlib
import importlib.util
from pathlib import Path

from gearcheck.lumped.linear_model import LinearModel
from gearcheck.lumped.matrix_file import SUFFIXES, read_matrix_file
from gearcheck.lumped.side import LinearSide
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.side import Side

SIDE_METHODS = tuple(sorted(Side.__abstractmethods__))  # what an object needs to be a side
CAPABILITIES = tuple(n for n in vars(Side) if not n.startswith("_") and n not in Side.__abstractmethods__)


def user_side(model, spec) -> Side:
    """The side of ``model`` (see the module docstring) for the train ``spec``."""
    if isinstance(model, LinearModel):
        return LinearSide(model, spec)
    if _is_side(model):
        return _as_side(model, spec, model)
    text = str(model)
    if Path(text).suffix in SUFFIXES:
        return LinearSide(read_matrix_file(text), spec)
    try:
        built = load_factory(text)(spec)
    except GearcheckError:
        raise
    except Exception as exc:  # the user's code, failing in its own way
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
    if not getattr(obj, "solver", None):
        raise GearcheckError(f"model={given}: the side it gives needs a 'solver' name")
    return obj if isinstance(obj, Side) else AdoptedSide(obj, spec)


class AdoptedSide(Side):
    """A side object of the user's own that does not derive from :class:`~gearcheck.shared.side.Side`: its
    methods and, of the optional capabilities (:data:`CAPABILITIES`), those it has; the Side's defaults for the
    others.  The one place a foreign object's members are looked up."""

    def __init__(self, side, spec):
        self.side, self.spec, self.solver = side, spec, side.solver
        for name in CAPABILITIES:
            if hasattr(side, name):
                setattr(self, name, getattr(side, name))
        self.references = tuple(self.references)

    def modes(self):
        return self.side.modes()

    def run(self, settings, progress=None):
        return self.side.run(settings, progress)

    def stable_step(self) -> float:
        return self.side.stable_step()


def load_factory(text: str):
    """``module:name`` or ``file.py:name`` -> the named callable."""
    where, _, name = text.rpartition(":")
    if not where or not name:
        raise GearcheckError(f"model={text!r}: give a model file ({' or '.join(SUFFIXES)}), module:factory or "
                             "file.py:factory")
    try:
        if where.endswith(".py"):
            path = Path(where)
            if not path.is_file():
                raise GearcheckError(f"model={text}: no such file {where}")
            spec = importlib.util.spec_from_file_location(path.stem, path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
        else:
            module = importlib.import_module(where)
    except GearcheckError:
        raise
    except Exception as exc:  # the user's code may fail in any way while it loads
        raise GearcheckError(f"model={text}: importing {where} failed: {type(exc).__name__}: "
                             f"{str(exc).splitlines()[0] if str(exc) else ''}") from None
    factory = getattr(module, name, None)
    if not callable(factory):
        raise GearcheckError(f"model={text}: {where} has no callable {name!r}")
    return factory
