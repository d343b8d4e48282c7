"""What a kind of part adds to the twin's MJCF: every hook of :class:`Element` adds nothing by default."""

from __future__ import annotations

import math


class Element:
    """The MJCF of one kind of part (hooks get the part and the :class:`~gearcheck.train.spec.TrainSpec`)."""

    def joint_springs(self, part, spec) -> dict:
        """{(member id, joint suffix): (stiffness, damping)} the part puts on its members' joints."""
        return {}

    def tendons(self, part, spec) -> list[str]:
        """The part's tendons; a number known only once the twin is compiled is
        :data:`~gearcheck.mbd_models.mjcf_text.LATE` (see :func:`~gearcheck.mbd_models.mjcf_text.fixed`)."""
        return []

    def actuators(self, part, spec) -> list[str]:
        return []

    def sensors(self, part, spec) -> list[str]:
        return []

    def header(self, part) -> list[str]:
        """Lines for the file's comment."""
        return []

    def assets(self, part, spec) -> list[str]:
        return []

    def sites(self, part, spec, member) -> list[str]:
        """Sites the part needs on ``member``'s body."""
        return []

    def visuals(self, part, spec, member) -> list[str] | None:
        """``member``'s visual geoms when the part draws it (None: the builder's gears and plates)."""
        return None

    def bodies(self, part, spec, z_stage: float, visuals: bool, inner, springs: dict) -> list[str]:
        """Bodies of the world the part adds after its stage's carrier (``inner(member)``: a member's sites and
        visual geoms; ``springs``: every part's springs on the members' joints)."""
        return []

    def bore(self, part, stage) -> float:
        """The radius within which the stage's carrier plate must stay to clear the part."""
        return math.inf

    def reach(self, part) -> list[float]:
        """Radii the front camera must take in."""
        return []

    def contacts(self, spec, model):
        """The kind's moving contacts at run time in the compiled ``model``, once for all its parts: an object whose
        tendons follow the bodies, set before every step, or None (the kind has none).  It gives ``tendons``,
        ``contacts`` (the static contact set of t = 0), ``clearance``, ``refresh(d, touching=None, gaps=True)``
        (the coefficients at ``d``'s pose; returns the compressions), ``pin_forces(d)``, ``freeze(d, every)`` and
        ``undamp()`` (the linearisation), ``written()`` (what the file writes), ``per_disc(forces)`` and
        ``with_signals(result, forces, series, static_forces)`` (its result signals).  The cycloid element's
        ``CycloidTwin`` is the one there is."""
        return None
