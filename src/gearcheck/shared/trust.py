"""What a train file may make gearcheck do beyond reading numbers: nothing the user has not allowed.

A train file and the files it names are data that people exchange (DESIGN.md 10).  Two things in them reach
further, and each needs the user's word:

* **code** -- ``operating.torque_function = "module:function"`` and ``train.user_model = "module:factory"`` or
  ``"file.py:factory"`` name Python code.  Loading, validating and showing such a file never imports it; running
  it imports the module only when the user trusts it: ``--trust MODULE`` (or ``--trust path/to/file.py``) on the
  command line, :func:`trust` in Python, or ``GEARCHECK_TRUST`` in the environment.  Trusting a package trusts its
  modules.  Code the user names directly (``--model file.py:f``, ``model=`` in Python) is not from a file and
  needs no trust;
* **files** -- a file a train file names (measurements, a torque table, a user model) resolves relative to the
  train file and, symbolic links followed, must lie inside that file's folder or a folder the user allows:
  ``--data-root DIR``, :func:`allow_data`, or ``GEARCHECK_DATA_ROOTS``.

Grants live in the environment (``os.pathsep``-separated), so the processes of a sweep inherit them.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
from contextlib import contextmanager
from pathlib import Path

from gearcheck.shared.errors import GearcheckError, one_line

TRUST = "GEARCHECK_TRUST"
DATA_ROOTS = "GEARCHECK_DATA_ROOTS"
GRANTS = (TRUST, DATA_ROOTS)


def _granted(variable: str) -> list[str]:
    return [entry for entry in os.environ.get(variable, "").split(os.pathsep) if entry]


def _grant(variable: str, entries) -> None:
    merged = list(dict.fromkeys([*_granted(variable), *entries]))
    os.environ[variable] = os.pathsep.join(merged)


def trust(*modules: str) -> None:
    """Allow train files to run the code of ``modules``: module or package names (``mypkg.torques``), or paths
    of Python files (resolved here, against the current folder)."""
    entries = []
    for module in modules:
        if not isinstance(module, str) or not module.strip() or os.pathsep in module:
            raise GearcheckError(f"trust={module!r}: a module name or the path of a Python file")
        entries.append(str(Path(module).resolve()) if module.endswith(".py") else module.strip())
    _grant(TRUST, entries)


def allow_data(*folders: str | os.PathLike) -> None:
    """Allow train files to name files inside ``folders`` (and their subfolders)."""
    entries = []
    for folder in folders:
        path = Path(folder).resolve()
        if not str(folder).strip() or not path.is_dir():  # "" would allow the current folder by accident
            raise GearcheckError(f"data_root={str(folder)!r}: not a folder")
        entries.append(str(path))
    _grant(DATA_ROOTS, entries)


def grants() -> dict[str, str | None]:
    """The grants in force, as :func:`restore` takes them (a sweep hands them to its workers)."""
    return {variable: os.environ.get(variable) for variable in GRANTS}


def restore(given: dict[str, str | None]) -> None:
    """Put the grants of :func:`grants` in force, and only them."""
    for variable, value in given.items():
        if value is None:
            os.environ.pop(variable, None)
        else:
            os.environ[variable] = value


@contextmanager
def granted(modules=(), folders=()):
    """:func:`trust` ``modules`` and :func:`allow_data` ``folders`` while the block runs (the command line's
    ``--trust`` and ``--data-root``); the grants before it afterwards."""
    before = grants()
    try:
        trust(*modules)
        allow_data(*folders)
        yield
    finally:
        restore(before)


def trusted(module: str) -> bool:
    """Whether the user trusts ``module`` (a dotted name: itself or a package above it; a ``.py`` path: that
    file, resolved)."""
    given = _granted(TRUST)
    if module.endswith(".py"):
        return str(Path(module).resolve()) in given
    parts = module.split(".")
    return any(".".join(parts[:n]) in given for n in range(1, len(parts) + 1))


def named_code(reference: str, label: str, from_file: bool):
    """The callable that ``reference`` (``module:name`` or ``path/to/file.py:name``) names; ``label`` starts every
    error (``model=x``, ``operating.torque_function``).  Named by a train file (``from_file``), its module is
    imported only if the user trusts it (:func:`trusted`)."""
    where, _, name = reference.rpartition(":")
    if not where or not name:
        raise GearcheckError(f"{label}: {reference!r} is neither module:name nor file.py:name")
    if from_file and not trusted(where):
        raise GearcheckError(f"{label}: {reference!r} is Python code named by a train file, which is data and runs "
                             f"no code unless you allow it: --trust {where} (gearcheck.trust({where!r}) in Python)")
    try:
        if where.endswith(".py"):
            path = Path(where)
            if not path.is_file():
                raise GearcheckError(f"{label}: no such file {where}")
            spec = importlib.util.spec_from_file_location(path.stem, path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
        else:
            module = importlib.import_module(where)
    except GearcheckError:
        raise
    except (Exception, SystemExit) as exc:  # the user's code may fail in any way while it loads, sys.exit too
        raise GearcheckError(f"{label}: importing {where} failed: {type(exc).__name__}: {one_line(exc)}") from None
    obj = getattr(module, name, None)
    if not callable(obj):
        raise GearcheckError(f"{label}: {where} has no callable {name!r}")
    return obj


def inside_roots(path: Path, home: Path) -> bool:
    """Whether ``path`` (resolved) lies inside the folder ``home`` or a folder the user allows."""
    resolved = path.resolve()
    return any(resolved.is_relative_to(Path(root).resolve()) for root in (home, *_granted(DATA_ROOTS)))
