"""Table 3 of Yang, Chen & Wang (2018), "Response sensitivity to design parameters of RV reducer", against
gearcheck's model of the reducer built from the paper's Tables 1-2 (the ``rv-reducer`` preset).

Prints (a) the natural frequencies of the published parameters, (b) what unprinted inertias it would take to
reach the paper's model column, (c) the honest protocol: the test's inertia plate J_plate calibrated on the
measured first mode, the other modes predicted.  The test rig's inertias enter as added inertia on the output's
and the sun's rotation (the same as raising the train file's carrier or sun inertia).

Run it as a script; it takes about 2 s.
"""

from __future__ import annotations

from dataclasses import replace

from scipy.optimize import brentq, fsolve

import gearcheck
from gearcheck.lumped import modes  # the modes of a model whose mass matrix the script edits

TEST = (148.95, 387.88, 681.47)  # Table 3, experiment (Hz)
PAPER = (154.56, 396.09, 697.16)  # Table 3, the paper's model


def frequencies(model, j_plate: float = 0.0, j_input: float = 0.0):
    """Natural frequencies (Hz) with ``j_plate`` added to the output's inertia and ``j_input`` to the sun's."""
    M = model.M.copy()
    for member, extra in (("rv.carrier", j_plate), ("rv.sun", j_input)):
        i = model.dofs(member, "theta")
        M[i, i] += extra
    return modes(replace(model, M=M)).frequencies


def plate_for(model, target: float, j_input: float = 0.0) -> float:
    """The output inertia that puts the lowest mode at ``target`` Hz."""
    return brentq(lambda j: frequencies(model, j, j_input)[0] - target, 1e-3, 1e3, xtol=1e-12)


def plate_and_input_for(model, f1: float, f2: float) -> tuple[float, float]:
    """Output and input inertias that put the two lowest modes at ``f1`` and ``f2`` Hz."""
    start = plate_for(model, f1)
    x = fsolve(lambda x: [frequencies(model, x[0], x[1] * 1e-3)[0] - f1,
                          frequencies(model, x[0], x[1] * 1e-3)[1] - f2], [start, 1.0])
    return float(x[0]), float(x[1] * 1e-3)


def pct(model_value: float, reference: float) -> str:
    return f"{100 * (model_value / reference - 1):+.2f} %"


def main() -> None:
    text = gearcheck.preset_text("rv-reducer")
    try:  # the paper's example layout: 4 planets, 3 discs
        gearcheck.load_text(text.replace("planets = 3", "planets = 4").replace("discs = 2", "discs = 3"),
                            "paper layout")
        print("the paper's 4-planet layout loaded")
    except gearcheck.TrainFileError as exc:
        print(f"paper's layout (4 planets, 3 discs) refused: {exc}\n")
    model = gearcheck.Train(gearcheck.load_text(text, "preset:rv-reducer")).lumped.model
    f = frequencies(model)
    print("(a) published parameters, 3 cranks and 2 discs (no inertia plate, no motor)")
    print(f"{'mode':>4} {'test':>8} {'paper':>8} {'gearcheck':>10}   note")
    notes = ("whole train against the sun's shaft k_st", "sun translation pair", "sun translation pair")
    for k in range(3):
        print(f"{k + 1:>4} {TEST[k]:8.2f} {PAPER[k]:8.2f} {f[k]:10.2f}   {notes[k]}")
    print(f"     lowest mode {f[0]:.2f} Hz vs the paper's mode 3 {PAPER[2]} Hz: {pct(f[0], PAPER[2])}; "
          f"next torsional mode {f[3]:.1f} Hz (output against the pins)\n")

    print("(b) what it would take to reach the paper's model column")
    j = plate_for(model, PAPER[0])
    print(f"    output inertia {j:.3f} kg m^2 puts mode 1 at {PAPER[0]} Hz; mode 2 is then "
          f"{frequencies(model, j)[1]:.1f} Hz")
    jp, ji = plate_and_input_for(model, PAPER[0], PAPER[1])
    f3 = frequencies(model, jp, ji)[2]
    print(f"    with {ji:.3e} kg m^2 more on the input as well (output {jp:.3f}): modes 1-2 at {PAPER[0]}, "
          f"{PAPER[1]} Hz and mode 3 at {f3:.2f} Hz, {pct(f3, PAPER[2])} from the paper's {PAPER[2]}\n")

    print("(c) calibrated on the test's mode 1 (one unknown: the inertia plate), the others predicted")
    j = plate_for(model, TEST[0])
    g = frequencies(model, j)
    print(f"    J_plate = {j:.3f} kg m^2 -> model modes {g[0]:.2f}, {g[1]:.2f}, {g[2]:.2f}, {g[3]:.2f} Hz")
    print(f"    test mode 2 {TEST[1]} Hz: no model mode between {g[0]:.0f} and {g[1]:.0f} Hz "
          f"(nearest {pct(g[1], TEST[1])})")
    print(f"    test mode 3 {TEST[2]} Hz <- model {g[1]:.2f} Hz (input side against k_st): {pct(g[1], TEST[2])}")
    alternatives = [
        ("input inertia on mode 1", 0.0, brentq(lambda x: frequencies(model, 0.0, x)[0] - TEST[0], 0, 1)),
        ("J_plate on mode 2 (mode 1 unexplained)", plate_for(model, TEST[1]), 0.0),
        ("J_plate + input inertia on modes 1-2", *plate_and_input_for(model, TEST[0], TEST[1])),
    ]
    for name, jp, ji in alternatives:
        h = frequencies(model, jp, ji)
        third = h[2] if ji and jp else h[1]
        print(f"    alt. {name}: J_plate {jp:.3f}, J_input {ji:.3e} -> next mode {third:.2f} Hz vs "
              f"{TEST[2]} Hz: {pct(third, TEST[2])}")
    print(f"    any added inertia on two coordinates leaves the third mode >= {f[0]:.2f} Hz (interlacing), "
          f"above the test's {TEST[2]} Hz")


if __name__ == "__main__":
    main()
