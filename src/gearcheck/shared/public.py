"""The public names of a package beneath :mod:`gearcheck`: the advanced layer under the front door.

A package lists what it offers beyond ``import gearcheck`` (a model's matrices, the harmonic solvers, the
diagnosis, a study's statistics) as ``{name: module}``; :func:`public` gives it ``__all__`` and the module
``__getattr__`` and ``__dir__`` of PEP 562, which import each name's module on first use, so importing the
package costs nothing and no package is imported before it is asked for.  Everything not listed is internal:
examples and notebooks use the front door and these names only (``tests/test_front_door.py``).
"""

from __future__ import annotations

import importlib


def public(package: str, names: dict[str, str]):
    """(``__all__``, ``__getattr__``, ``__dir__``) of ``package`` whose public ``names`` live in the given
    modules (relative to it)."""

    def __getattr__(name: str):
        if name not in names:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(f"{package}.{names[name]}"), name)

    def __dir__() -> list[str]:
        return sorted(names)

    return sorted(names), __getattr__, __dir__
