"""The lumped model's elements: one file per kind of part, each registered by the kind it builds.

``ELEMENTS[part.element](part, build)`` returns the part's :class:`~gearcheck.lumped.elements.base.Contribution`
(:mod:`gearcheck.lumped.assembly` does nothing else with a part).  Kinds: ``support``, ``bearing``,
``spline``, ``coupling`` (with :class:`~gearcheck.lumped.elements.coupling.TurningCoupling`), ``drive``,
``mesh`` and ``cycloid`` (:class:`~gearcheck.lumped.elements.cycloid.CycloidRows`).
"""

from gearcheck.shared.elements import Registry

ELEMENTS = Registry("lumped")

from gearcheck.lumped.elements import bearing, coupling, cycloid, drive, mesh, spline, support  # noqa: E402, F401
