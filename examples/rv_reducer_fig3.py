"""Yang, Chen & Wang (2018) Fig. 3: the output wheel's time response at 1000 rpm and 3136 N·m, from
``gearcheck run``, with its harmonic content against harmonic balance.

First the run (the preset's operating point is the paper's; about 10 s)::

    gearcheck run rv-reducer --solver lumped --duration 0.34 --output-dt 2.8935e-5 --out out/rv-fig3-run

then ``python examples/rv_reducer_fig3.py [RUN_DIR [OUT_DIR [MESH ECCENTRIC]]]`` (default ``out/rv-fig3-run``,
``docs/rv-reducer/fig3-time-response``, a harmonic-balance box of 9 mesh and 4 eccentric harmonics).

The output sampling is 9 of the run's steps, and a mesh period is 1251 steps, so the last 69 x 139 samples are one
whole turn of the eccentrics in the carrier (69 mesh periods, 39 pin passes, 0.2775 s).  The free vibration has
decayed to 1e-3 by 0.053 s (``examples/rv_reducer_harmonic_vs_time.py``): the window starts at 0.0625 s.  On that
window the discrete Fourier transform's bins are the multiples n of the eccentrics' frequency f_e exactly, a mesh
harmonic at n = 69 k.  Harmonic balance, sampled at the same times, goes through the same transform.
Writes ``fig3_time_response.png`` and ``fig3_lines.csv`` (the largest lines of the output's rotation, both ways).
"""

import sys
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

import gearcheck
from gearcheck.lumped import harmonic_balance_response, parametric_problem

run_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("out/rv-fig3-run")
out = Path(sys.argv[2]) if len(sys.argv) > 2 else Path("docs/rv-reducer/fig3-time-response")
orders = tuple(int(o) for o in sys.argv[3:5]) if len(sys.argv) > 4 else (9, 4)
out.mkdir(parents=True, exist_ok=True)

raw = pd.read_parquet(run_dir / "raw.parquet")
t = raw["t"].to_numpy()
train = gearcheck.Train("rv-reducer")
model = train.lumped.model
f_mesh = float(model.excitation.frequency.min())  # Hz
f_e = f_mesh / 69  # the eccentrics' turn in the carrier: the sun mesh is its 69th harmonic
per_turn = round(1.0 / (f_e * (t[1] - t[0])))
assert abs(per_turn * (t[1] - t[0]) * f_e - 1) < 1e-9, "the output sampling must hold a whole eccentric turn"
window = slice(len(t) - per_turn, len(t))
tw = t[window]

problem = parametric_problem(model)
hb = harmonic_balance_response(problem, orders).at(tw)
labels = model.dofs.labels()


def lines(x):
    """One-sided amplitudes of the bins n f_e, n = 0 .. N/2 (n = 0: the mean)."""
    spectrum = np.fft.rfft(x) / len(x)
    spectrum[1:] *= 2
    return np.abs(spectrum)


theta = raw["rv.carrier.theta"].to_numpy()
time_lines = lines(theta[window])
hb_lines = lines(hb[:, labels.index("rv.carrier.theta")])
n = np.arange(time_lines.size)
mesh = (n % 69 == 0) & (n > 0)
ac = (time_lines[1:] ** 2).sum()
share_mesh = (time_lines[mesh] ** 2).sum() / ac
order = np.argsort(time_lines[1:])[::-1] + 1
largest = np.concatenate([order[mesh[order]][:10], order[~mesh[order]][:6]])  # the mesh's and the rest's largest


def name(k):
    if k % 69 == 0:
        return f"mesh x {k // 69}"
    if k % 39 == 0:
        return f"pin pass x {k // 39}"
    k1 = round(k / 69)
    return f"eccentric x {k}" if k1 == 0 else f"mesh x {k1} {'+' if k - 69 * k1 > 0 else '-'} {abs(k - 69 * k1)} f_e"


table = pd.DataFrame({"n": largest, "frequency_hz": largest * f_e, "line": [name(k) for k in largest],
                      "time_rad": time_lines[largest], "harmonic_balance_rad": hb_lines[largest]})
table["hb_over_time"] = table["harmonic_balance_rad"] / table["time_rad"]
table.to_csv(out / "fig3_lines.csv", index=False, float_format="%.6g")
translation = max(np.abs(raw[c].to_numpy()[window]).max() for c in ("rv.carrier.x", "rv.carrier.y"))
summary = {"mean_time_rad": time_lines[0], "mean_hb_rad": hb_lines[0],
           "ac_rms_time_rad": float(np.std(theta[window])),
           "ac_rms_hb_rad": float(np.std(hb[:, labels.index("rv.carrier.theta")])),
           "mesh_share_of_ac_power": float(share_mesh),
           "pin_pass_over_first_mesh_line": float(time_lines[39] / time_lines[69]),
           "max_translation_m": float(translation),
           "f_mesh_hz": f_mesh, "f_eccentric_hz": f_e, "hb_orders": orders}
for key, value in summary.items():
    print(f"{key}: {value}")
print(table.to_string(index=False))

fig = Figure(figsize=(10, 10), layout="constrained")
ax = fig.subplots(4, 1)
ax[0].plot(t * 1e3, theta * 1e6, color="C0", lw=0.6)
ax[0].axvspan(tw[0] * 1e3, tw[-1] * 1e3, color="0.9", zorder=0, label="one eccentric turn, analysed")
ax[0].set_ylabel("output θ (µrad)")
ax[0].set_xlabel("time (ms)")
ax[0].legend(fontsize=8, loc="lower right")
ax[0].set_title("(a) output wheel rotation from the static start, 1000 rpm at the sun, 3136 N·m on the output",
                fontsize=9)
zoom = tw < tw[0] + 8 / 140.54  # eight pin passes
ax[1].plot(tw[zoom] * 1e3, theta[window][zoom] * 1e6, color="C0", lw=1.0, label="time marching (gearcheck run)")
ax[1].plot(tw[zoom] * 1e3, hb[zoom, labels.index("rv.carrier.theta")] * 1e6, color="C3", lw=0.9, ls="--",
           label=f"harmonic balance {orders}")
ax[1].set_ylabel("output θ (µrad)")
ax[1].set_xlabel("time (ms)")
ax[1].legend(fontsize=8, loc="lower right")
ax[1].set_title(f"(b) 57 ms of the window: mesh period {1e3 / f_mesh:.2f} ms, pin pass {1e3 / (39 * f_e):.2f} ms",
                fontsize=9)
shown = n * f_e <= 2600
ax[2].semilogy(n[shown][1:] * f_e, time_lines[shown][1:], color="C0", lw=0.8, label="time marching")
ax[2].semilogy(n[shown][1:] * f_e, np.maximum(hb_lines[shown][1:], 1e-16), color="C3", lw=0, marker=".", ms=3,
               label=f"harmonic balance {orders}")
for k in range(1, 11):
    ax[2].axvline(k * f_mesh, color="0.6", lw=0.5, ls=":")
ax[2].axvline(39 * f_e, color="C2", lw=0.8, ls="--", label="pin pass 39 f_e (140.5 Hz)")
ax[2].set_ylim(1e-13, 1e-6)
ax[2].set_xlabel("frequency (Hz); dotted: mesh harmonics k x 248.6 Hz")
ax[2].set_ylabel("line amplitude (rad)")
ax[2].legend(fontsize=8, loc="upper right")
ax[2].set_title(f"(c) lines of the output rotation over one eccentric turn (bins of f_e = {f_e:.3f} Hz); "
                f"mesh harmonics hold {100 * share_mesh:.1f} % of the AC power", fontsize=9)
for c, colour in (("rv.carrier.x", "C1"), ("rv.carrier.y", "C4")):
    ax[3].plot(t * 1e3, raw[c].to_numpy(), color=colour, lw=0.6, label=c)
ax[3].set_ylabel("output translation (m)")
ax[3].set_xlabel("time (ms)")
ax[3].legend(fontsize=8, loc="upper right")
ax[3].set_title(f"(d) output translation: round-off, at most {translation:.1e} m on the window "
                "(in-phase planets, discs 180° apart)", fontsize=9)
for a in ax:
    a.grid(alpha=0.3)
fig.suptitle("Yang, Chen & Wang (2018) Fig. 3 for the buildable RV reducer (3 cranks, 2 discs): gearcheck run "
             "rv-reducer --solver lumped", fontsize=10)
fig.savefig(out / "fig3_time_response.png", dpi=110, metadata={"Software": None})
print(f"wrote {out / 'fig3_time_response.png'}, {out / 'fig3_lines.csv'}")
