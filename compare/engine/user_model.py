"""A user's model, however it is given, as a side of the cross-check (:class:`~gearcheck.shared.side.Side`).

* a :class:`~gearcheck.lumped.linear_model.LinearModel` (built in Python);
* a file of matrices, ``.mat`` or ``.npz`` (:mod:`gearcheck.lumped.matrix_file`);
* ``module:factory`` or ``path/to/file.py:factory``: ``factory(spec)`` returns a LinearModel, or an object
  that is a side itself (``solver``, ``modes()``, ``run(settings, progress)``, ``stable_step()``; with
  ``physical_modes(modal)`` its mode shapes are paired too).
"""

from __future__ import annotations

import importlib
import importlib.util
from pathlib import Path

from gearcheck.lumped.linear_model import LinearModel
from gearcheck.lumped.matrix_file import SUFFIXES, read_matrix_file
from gearcheck.lumped.side import LinearSide
from gearcheck.shared.errors import GearcheckError

SIDE_METHODS = ("modes", "run", "stable_step")


def user_side(model, spec):
    """The side of ``model`` (see the module docstring) for the train ``spec``."""
    if isinstance(model, LinearModel):
        return LinearSide(model, spec)
    if all(callable(getattr(model, m, None)) for m in SIDE_METHODS):
        return model
    text = str(model)
    if Path(text).suffix in SUFFIXES:
        return LinearSide(read_matrix_file(text), spec)
    try:
        built = load_factory(text)(spec)
    except GearcheckError:
        raise
    except Exception as exc:  # the user's code, failing in its own way
        raise GearcheckError(f"--model {text}: building the model failed: {type(exc).__name__}: {exc}") from None
    if isinstance(built, LinearModel):
        built.source = built.source or text
        return LinearSide(built, spec)
    if all(callable(getattr(built, m, None)) for m in SIDE_METHODS):
        if not getattr(built, "solver", None):
            raise GearcheckError(f"--model {text}: the side it returns needs a 'solver' name")
        built.references = tuple(getattr(built, "references", ()))
        return built
    raise GearcheckError(f"--model {text}: returned {type(built).__name__}, neither a LinearModel nor a side "
                         f"(an object with {', '.join(SIDE_METHODS)})")


def load_factory(text: str):
    """``module:name`` or ``file.py:name`` -> the named callable."""
    where, _, name = text.rpartition(":")
    if not where or not name:
        raise GearcheckError(f"--model {text!r}: give a model file ({' or '.join(SUFFIXES)}), module:factory or "
                             "file.py:factory")
    try:
        if where.endswith(".py"):
            path = Path(where)
            if not path.is_file():
                raise GearcheckError(f"--model {text}: no such file {where}")
            spec = importlib.util.spec_from_file_location(path.stem, path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
        else:
            module = importlib.import_module(where)
    except GearcheckError:
        raise
    except Exception as exc:  # the user's code may fail in any way while it loads
        raise GearcheckError(f"--model {text}: importing {where} failed: {type(exc).__name__}: "
                             f"{str(exc).splitlines()[0] if str(exc) else ''}") from None
    factory = getattr(module, name, None)
    if not callable(factory):
        raise GearcheckError(f"--model {text}: {where} has no callable {name!r}")
    return factory
