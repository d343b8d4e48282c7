"""What a kind of part adds to the twin's MJCF: every hook of :class:`Element` adds nothing by default.

A kind whose contacts move with the bodies (:meth:`Element.contacts`) also hands the compiled runner
(:mod:`gearcheck.mbd_models.compiled`) its *group*: a named tuple of arrays, with its functions on the hooks
:data:`REFRESH`, :data:`SWITCHING` and :data:`RECORD` (:mod:`gearcheck.shared.kernel_hooks`), registered by
:func:`compiled_group` in the kind's element file; the runner calls every kind's functions without naming one.
"""

from __future__ import annotations

import math

from gearcheck.shared.kernel_hooks import Hook


class Element:
    """The MJCF of one kind of part (hooks get the part and the :class:`~gearcheck.train.spec.TrainSpec`)."""

    def joint_springs(self, part, spec) -> dict:
        """{(member id, joint suffix): :class:`~gearcheck.mbd_models.mjcf_text.Spring`} the part puts on its members'
        joints."""
        return {}

    def driven_tendons(self, part, spec) -> list[str]:
        """The part's tendons whose stiffness the runner drives every step (a mesh's), as :meth:`tendons`: the
        file writes every part's before any other tendon, so that they come first in the model."""
        return []

    def tendons(self, part, spec) -> list[str]:
        """The part's tendons; a number known only once the twin is compiled is
        :data:`~gearcheck.mbd_models.mjcf_text.LATE` (see :func:`~gearcheck.mbd_models.mjcf_text.fixed`)."""
        return []

    def late_rows(self, part, spec, kin, model, data) -> list[tuple]:
        """(tendon name, row over all dofs) of each of the part's tendons whose coefficients are late: MuJoCo's own
        Jacobians (:mod:`gearcheck.mbd_models.jacobians`) in the compiled ``model`` at ``data``'s reference
        configuration (``kin``: the train's :class:`~gearcheck.train.kinematics.Kinematics`)."""
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
        ``with_signals(result, forces, series, static_forces)`` (its result signals), and ``compiled``, its
        group's class (:func:`compiled_group`).  The cycloid element's ``CycloidTwin`` is the one there is."""
        return None


# ------------------------------------------------------------------------- the compiled runner's groups
# function(group, (kinematics, com_pos, jac, m, d, model, data)): its tendons at the data's pose (MuJoCo's C
# functions and the mjModel and mjData addresses, then the views of their fields, as the runner has them)
REFRESH = Hook("refresh")
# function(group, (g, rate), n) -> the next n: its switching functions (as the last refresh found them) into g and
# their rates into ``rate`` from index n on
SWITCHING = Hook("switching", threads=True)
# function(group, (row, model, data), n) -> the next n: its contact forces at the data's state into ``row`` from
# column n on (the contacts' order, ``MbdModel.moving_slices``)
RECORD = Hook("record", threads=True)
GROUPS: list[type] = []  # the compiled groups, in the order their files register them


def compiled_group(group: type, refresh, switching, record) -> None:
    """Register the compiled form of a kind's moving contacts: ``group`` a named tuple class whose
    ``group.of(contacts, nv)`` packs that kind's contacts objects of a twin (none: empty arrays of the same types,
    on which its functions do nothing), and its :data:`REFRESH`, :data:`SWITCHING` and :data:`RECORD` functions."""
    GROUPS.append(group)
    REFRESH.register(group, refresh)
    SWITCHING.register(group, switching)
    RECORD.register(group, record)


def group_order(contacts) -> int:
    """Where a moving contact's group comes among :data:`GROUPS` (the compiled runner fills the contacts' forces and
    switching functions group after group, so a twin keeps its contacts in this order); TypeError for a contact
    with no compiled form."""
    if contacts.compiled not in GROUPS:
        raise TypeError(f"no compiled form of the moving contacts {type(contacts).__name__}")
    return GROUPS.index(contacts.compiled)
