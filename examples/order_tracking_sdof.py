"""Order tracking of a run-up against the stepped sweep, on a single-degree-of-freedom oscillator.

An oscillator (f_n = 100 Hz, zeta = 0.02) is forced at order 6 of an input shaft that runs up linearly from 200 to
2000 rpm, x'' + 2 zeta w_n x' + w_n^2 x = w_n^2 cos(2 pi 6 theta(t)), at three run-up rates; scipy's solve_ivp
integrates it (DOP853, rtol 1e-10).  Computed order tracking (gearcheck.compare.studies.order_tracking) turns each
run into the order-6 curve, which is compared with the steady response |H(6 rpm / 60)| (the stepped sweep): the
table gives both at a few speeds, then each run's peak against the steady one (speed shift, amplitude ratio) with
the prediction of gearcheck.compare.studies.resonance_passage.  Writes order_plot.png (whole run),
order_plot_resonance.png (around the resonance) and waterfall.png (the fastest run) into the folder given.

Run:  python examples/order_tracking_sdof.py out/
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from gearcheck.compare.presentation import order_plot, waterfall_plot
from gearcheck.compare.studies import against_sweep, order_track, passage, resonance_speeds, sweep_effect, waterfall

F_N, ZETA, ORDER = 100.0, 0.02, 6.0
START, STOP, RATES = 200.0, 2000.0, (400.0, 200.0, 100.0)  # rpm, rpm, rpm/s
FS = 4000.0  # samples/s: 20 a cycle of order 6 at 2000 rpm
SHOWN = (300, 500, 700, 900, 950, 1000, 1025, 1050, 1100, 1300, 1600, 1900)


def steady(rpm):
    """The steady complex response per unit static deflection at the order's frequency."""
    r = ORDER * np.asarray(rpm) / 60.0 / F_N
    return 1.0 / (1.0 - r * r + 2j * ZETA * r)


def run_up(rate: float):
    """(t, x, reference angle in revolutions) of the run-up at ``rate`` rpm/s, from the steady state at START."""
    w_n = 2.0 * np.pi * F_N
    duration = (STOP - START) / rate
    def angle(t):
        return (START * t + 0.5 * rate * t * t) / 60.0

    def rhs(t, y):
        return [y[1], -2.0 * ZETA * w_n * y[1] - w_n * w_n * y[0] + w_n * w_n * np.cos(2 * np.pi * ORDER * angle(t))]

    h0 = steady(START)
    t = np.arange(0.0, duration, 1.0 / FS)
    y0 = [h0.real, (2j * np.pi * ORDER * START / 60.0 * h0).real]
    solution = solve_ivp(rhs, (0.0, duration), y0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t)
    return t, solution.y[0], angle(t)


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    resonance = float(resonance_speeds(ORDER, [F_N])[0])
    fine = np.arange(START, STOP + 0.25, 0.25)
    stepped = np.arange(START, STOP + 1, 50.0)
    tracks, effects, runs = {}, {}, {}
    for rate in RATES:
        t, x, angle = runs[rate] = run_up(rate)
        track = order_track(t, x, angle, [ORDER], revs_per_block=1.0, overlap=0.9)
        tracks[f"{rate:g} rpm/s"] = track
        effects[rate] = sweep_effect(track.curve(ORDER), (fine, np.abs(steady(fine))),
                                     within=(0.8 * resonance, 1.25 * resonance))
        worst = against_sweep(track, ORDER, stepped, np.abs(steady(stepped)), [resonance], 300.0).worst
        print(f"{rate:g} rpm/s: largest difference from the stepped sweep farther than 300 rpm from the resonance "
              f"({resonance:g} rpm): {worst:.2e}")
    print("\nspeed (rpm)  steady |H|  " + "  ".join(f"{label:>12}" for label in tracks))
    for n in SHOWN:
        row = [np.interp(n, track.speed_rpm, track.amplitude[:, 0]) for track in tracks.values()]
        print(f"{n:11.0f}  {abs(steady(n)):10.4f}  " + "  ".join(f"{a:12.4f}" for a in row))
    print("\nrate (rpm/s)  eps    peak (rpm)  shift (rpm) predicted  ratio   predicted")
    for rate, e in effects.items():
        p = passage(F_N, ZETA, ORDER * rate / 60.0)
        print(f"{rate:12g}  {p.eps:5.3f}  {e.peak.speed_rpm:10.2f}  {e.shift_rpm:11.2f} {p.delay_hz * 60 / ORDER:9.2f}"
              f"  {e.ratio:.4f}  {p.peak_ratio:.4f}")
    print(f"steady peak: {effects[RATES[0]].reference.speed_rpm:.2f} rpm, {effects[RATES[0]].reference.amplitude:.3f}")
    sweep = {ORDER: (stepped, np.abs(steady(stepped)))}
    title = f"SDOF f_n = {F_N:g} Hz, zeta = {ZETA:g}, forced at order {ORDER:g} of a {START:g}-{STOP:g} rpm run-up"
    (out / "order_plot.png").write_bytes(order_plot(tracks, sweep, "per static deflection", title))
    near = {ORDER: (fine[::20], np.abs(steady(fine[::20])))}
    zoom = title + "\naround the resonance; markers: the steady response every 5 rpm"
    (out / "order_plot_resonance.png").write_bytes(order_plot(
        tracks, near, "per static deflection", zoom, (0.85 * resonance, 1.2 * resonance)))
    t, x, angle = runs[RATES[0]]
    (out / "waterfall.png").write_bytes(waterfall_plot(
        waterfall(t, x, angle, 0.1, overlap=0.75, max_hz=250.0), [ORDER, 2 * ORDER], [F_N], "per static deflection",
        f"waterfall of the {RATES[0]:g} rpm/s run-up: order {ORDER:g} (dashed), its double, f_n (dotted)"))
    print(f"\nfigures in {out}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="folder for the figures")
    main(parser.parse_args().out)
