"""The element registry: one kind of part, one implementation per side.

A train is members joined by parts (:attr:`gearcheck.train.spec.TrainSpec.parts`), each naming its kind in
``element`` ("support", "bearing", "mesh", "cycloid", ...).  Each model keeps its own :class:`Registry` of
element implementations by kind, filled by its element files, and builds a train by looking every part up;
no engine file asks a part for its type.  A new kind of part is one description dataclass, one element file
per side and one test file.
"""

from __future__ import annotations

from gearcheck.shared.errors import GearcheckError


class Registry:
    """Element implementations of one side (``"lumped"``, ``"mujoco"``) by part kind."""

    def __init__(self, side: str):
        self.side = side
        self._kinds: dict[str, object] = {}

    def register(self, kind: str):
        """Decorator: ``@ELEMENTS.register("support")`` over the implementation of that kind of part (a function, or
        a class whose one instance is registered)."""
        def add(implementation):
            if kind in self._kinds:
                raise ValueError(f"{self.side}: element kind {kind!r} registered twice")
            self._kinds[kind] = implementation() if isinstance(implementation, type) else implementation
            return implementation
        return add

    def __getitem__(self, kind: str):
        try:
            return self._kinds[kind]
        except KeyError:
            raise GearcheckError(f"the {self.side} model has no element for parts of kind {kind!r} (it knows "
                                 f"{', '.join(sorted(self._kinds))})") from None

    def kinds(self) -> list[str]:
        return sorted(self._kinds)
