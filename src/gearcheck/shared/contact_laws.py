"""Contact laws both solvers state the same way.

A mesh with backlash carries no force while its teeth are inside the clearance: with total
backlash 2b along the line of action, the elastic deflection is the dead zone

    f(delta) = delta - b  (delta > b),   0  (|delta| <= b),   delta + b  (delta < -b).

MuJoCo states the same law as a tendon's two-valued spring length ``springlength="-b b"``.
"""

from __future__ import annotations

import numpy as np


def deadzone(delta, half_backlash):
    """f(delta) = delta - b above b, 0 inside |delta| <= b, delta + b below -b."""
    return np.where(delta > half_backlash, delta - half_backlash,
                    np.where(delta < -half_backlash, delta + half_backlash, 0.0))
