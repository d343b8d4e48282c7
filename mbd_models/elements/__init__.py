"""The twin's elements: one file per kind of part, each registered by the kind it builds.

``ELEMENTS[part.element]`` is an :class:`~gearcheck.mbd_models.elements.base.Element`: what the part adds to the
MJCF (springs on its members' joints, tendons, actuators, sensors, and for a cycloid-pin stage its own bodies,
sites, assets and visuals).  :mod:`gearcheck.mbd_models.mjcf_builder` does nothing else with a part.
"""

from gearcheck.shared.elements import Registry

ELEMENTS = Registry("mujoco")

from gearcheck.mbd_models.elements import (  # noqa: E402, F401
    bearing,
    coupling,
    cycloid,
    drive,
    mesh,
    spline,
    support,
)
