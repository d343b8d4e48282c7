"""Mode shapes compared, not only frequencies: two models' modes paired by the modal assurance criterion.

Both sides give their modes in the train's physical coordinates (each member's centre along x, y or its
radial and tangential axes, its rotation, and its axial motion in a helical stage; the MuJoCo side maps
its joints there through its own Jacobians).  The mass-weighted MAC (Allemang & Brown 1982) of every
reference mode against every test mode follows.  A multiple frequency's shapes are any basis of their
space, so a mode is matched by its share in the span of the test modes of its frequency group (the sum
of its MAC over them).  Findings:

* swapped: a reference mode lies, not in its own group's test modes, but in another group's;
* missing: a reference mode lies in no test mode;
* spurious: a test mode lies in no reference mode.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gearcheck.compare.engine.reduction import reduced_reference
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.modal import frequency_groups, modal_assurance

MATCH = 0.9  # a share of a shape above it counts as a match
NO_MATCH = 0.5  # a shape whose best share is below it has no partner


@dataclass
class ModePairing:
    """MAC matrix (reference modes x test modes) and what it says."""

    train: str
    reference: str
    test: str
    frequencies_reference: np.ndarray
    frequencies_test: np.ndarray
    mac: np.ndarray
    paired: np.ndarray  # per reference mode: its share in its own frequency group's test modes
    findings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # what was done to the test model and the reference, in words

    def plot(self):
        """The MAC matrix as a :class:`matplotlib.figure.Figure` (no pyplot)."""
        from gearcheck.compare.presentation.plots import mac_figure

        return mac_figure(self)

    def to_dict(self) -> dict:
        return {"train": self.train, "reference": self.reference, "test": self.test,
                "frequencies_reference_hz": self.frequencies_reference.tolist(),
                "frequencies_test_hz": self.frequencies_test.tolist(), "mac": self.mac.tolist(),
                "paired": self.paired.tolist(), "worst_paired": float(self.paired.min()), "findings": self.findings,
                "notes": self.notes}


def pair_modes(train: str, reference, test, modes: tuple | None = None) -> ModePairing:
    """Pair the modes of two sides (objects with ``solver``, ``modes()`` and ``physical_modes(modal)``).

    A test model with fewer coordinates (a ring eliminated, a torsional model) is compared with the reference
    reduced to them (:func:`~gearcheck.compare.engine.reduction.reduced_reference`: held or condensed, as the
    model declares), on the coordinates it has, with the reference's mass over them; each reference mode's own
    partners are the test modes of the frequency group nearest to it.  ``modes``: the two sides' modes when
    already computed."""
    modes_a, modes_b = modes if modes is not None else (reference.modes(), test.modes())
    reference, modes_a, reduction = reduced_reference(reference, test, (modes_a, modes_b))
    labels_a, M, shapes_a = reference.physical_modes(modes_a)
    labels_b, _, shapes_b = test.physical_modes(modes_b)
    missing = [label for label in labels_b if label not in labels_a]
    if missing:
        raise GearcheckError(f"{train}: {test.solver} has coordinates {reference.solver} does not ({missing[0]}, ...)")
    keep = [labels_a.index(label) for label in labels_b]
    M, shapes_a = M[np.ix_(keep, keep)], shapes_a[keep]
    fa, fb = np.asarray(modes_a.frequencies), np.asarray(modes_b.frequencies)
    mac = modal_assurance(M, shapes_a, shapes_b)
    groups = frequency_groups(fb)
    centres = np.array([fb[g[0]] for g in groups])
    own = [int(np.argmin(np.abs(centres - f) / max(f, centres.max() * 1e-12))) for f in fa]
    shares = np.array([[mac[i, g].sum() for g in groups] for i in range(len(fa))])  # reference mode x test group
    paired = shares[np.arange(len(fa)), own]
    findings = []
    for i in range(len(fa)):
        if paired[i] >= MATCH:
            continue
        best = int(np.argmax(shares[i]))
        if shares[i, best] >= MATCH and best != own[i]:
            j = groups[best][0]
            findings.append(f"swapped: {reference.solver} mode {i + 1} ({fa[i]:.6g} Hz) is {test.solver} mode "
                            f"{j + 1} ({fb[j]:.6g} Hz), MAC {shares[i, best]:.3f}")
        elif shares[i].max() < NO_MATCH:
            findings.append(f"missing: {reference.solver} mode {i + 1} ({fa[i]:.6g} Hz) has no {test.solver} "
                            f"partner (best MAC {shares[i].max():.3f})")
        else:
            findings.append(f"mixed: {reference.solver} mode {i + 1} ({fa[i]:.6g} Hz) is shared among "
                            f"{test.solver} modes (its own {paired[i]:.3f})")
    for j in np.where(mac.max(axis=0) < NO_MATCH)[0]:
        findings.append(f"spurious: {test.solver} mode {j + 1} ({fb[j]:.6g} Hz) has no {reference.solver} "
                        f"partner (best MAC {mac[:, j].max():.3f})")
    notes = [*getattr(test, "notes", ())] + ([reduction] if reduction else [])
    return ModePairing(train, reference.solver, test.solver, fa, fb, mac, paired, findings, notes)
