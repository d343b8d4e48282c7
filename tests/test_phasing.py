"""Mesh-phasing selection rules (Parker 2000, J. Sound Vib. 236: 561-573) by forced response.

With the sun-mesh phases of N equally spaced planets, the l-th mesh harmonic excites only
rotational modes when l z_s / N is an integer, only translational modes when l z_s +/- 1 is a
multiple of N, and otherwise only planet modes.  The forced response of the undamped model is
projected on the modes; the modal amplitudes of the excluded types must vanish.
"""

import numpy as np
import pytest

from gearcheck.lumped.assembly import build_model
from gearcheck.lumped.harmonic import harmonic_response, transmission_error_force
from gearcheck.train.loader import load_train
from gearcheck.lumped.modal import modes


def modal_amplitudes(preset, harmonic, central):
    model = build_model(load_train(preset), rotating_frame_terms=False)
    undamped = type(model)(**{**model.__dict__, "rows": [type(r)(r.name, r.kind, r.a, r.stiffness, 0.0)
                                                         for r in model.rows],
                              "mesh_damping": np.zeros_like(model.mesh_damping)})
    result = modes(undamped)
    omega = 2 * np.pi * 0.37 * result.frequencies[0]  # below the first mode: no resonance
    x = harmonic_response(undamped, omega, transmission_error_force(undamped, harmonic, central))
    eta = np.abs(result.shapes.T @ undamped.M @ x)
    return eta / eta.max(), result.types


@pytest.mark.parametrize("preset, harmonic, central, excited", [
    ("demo-3p", 1, "stage1.sun", "translational"),  # 22 + (-1) = 21 = 7 * 3
    ("demo-3p", 2, "stage1.sun", "translational"),  # 44 + 1 = 45 = 15 * 3
    ("demo-3p", 3, "stage1.sun", "rotational"),  # 66 / 3 = 22
    ("demo-3p", 3, "stage1.ring", "rotational"),  # 186 / 3 = 62
    ("demo-3p", 1, "stage1.ring", "translational"),  # 62 + 1 = 63 = 21 * 3
    ("demo-4p", 2, "stage1.sun", "rotational"),  # 44 / 4 = 11
    ("demo-4p", 1, "stage1.sun", "planet"),  # 22 / 4, 21 / 4, 23 / 4: none
    ("demo-4p", 1, "stage1.ring", "planet"),  # 62 / 4, 61 / 4, 63 / 4: none
    ("demo-4p", 2, "stage1.ring", "rotational"),  # 124 / 4 = 31
])
def test_selection_rule(preset, harmonic, central, excited):
    eta, types = modal_amplitudes(preset, harmonic, central)
    for a, t in zip(eta, types):
        if t == excited:
            continue
        assert a < 1e-9, f"{t} mode excited ({a:.2e}) by harmonic {harmonic} of {central}"
    assert max(a for a, t in zip(eta, types) if t == excited) == pytest.approx(1.0)


@pytest.mark.parametrize("preset", ["demo-3p", "demo-4p", "hub-drive", "helical-planetary"])
def test_every_mesh_reads_a_switch_on_the_same_side_however_late_in_a_run(preset):
    """The stages' one-sided limits (``STAGE_SIDES``): at each of its stiffness switches (and tooth pairs' entries
    and exits) a mesh read on the right is as a hundred-thousandth of a cycle later, on the left as one earlier, at
    0, 8 and 60 s into a run, so every mesh, and every planet of a phased set, sees a switch that falls on a step
    boundary on one side.  The limit is read along the cycle, 1e-9 cycle on, far above the round-off of the cycle
    position (1.5e-11 cycle after 66,000 cycles).  Read in time, 1e-9 of a step on (the old rule), it sank into the
    round-off of t: at a sixteenth of the default step, 60 s in, demo-3p read 48 of its 96 limits on the wrong side,
    and a 0.5 s run past 2.4 million steps broke its planets' symmetry."""
    exc = build_model(load_train(preset)).excitation
    d = 1e-5 / exc.frequency.max()
    for t0 in (0.0, 8.0, 60.0):
        t = exc.switch_times(t0, t0 + 4.0 / exc.frequency.min())
        assert t.size >= 30
        for side, shifted in ((1, t + d), (-1, t - d)):
            np.testing.assert_allclose(exc.stiffness(t, side), exc.stiffness(shifted), rtol=1e-3)
            pairs, pairs_shifted = exc.tooth_pairs(t, side)[0], exc.tooth_pairs(shifted)[0]
            if pairs is not None:
                np.testing.assert_allclose(pairs, pairs_shifted, rtol=1e-3)
