"""The ``gearcheck`` command line: parses arguments, calls the front door, prints.

Exit status: 0 done (a cross-check passed), 1 a cross-check failed (a tolerance exceeded or a
baseline metric moved), 3 a cross-check inconclusive (no steady state reached, or an integration
error estimate as large as a tolerance), 2 bad input (one line on stderr naming the file, field or option, and the
value; nothing written; also a full disk and memory run out), 70 an internal error (one line; ``GEARCHECK_DEBUG=1``
shows its traceback), 130 interrupted (SIGINT), 143 terminated (SIGTERM); a closed pipe ends the
program quietly, as other command-line tools do.  Outputs are written whole or not at all
(:class:`~gearcheck.shared.outputs.OutputDirectory`).  ``-v`` logs what a run does and what each step costs,
``-vv`` every debug line, ``-q`` leaves errors only.
"""

from __future__ import annotations

import argparse
import errno
import io
import json
import logging
import math
import os
import re
import signal
import sys
import warnings
from collections import Counter
from collections.abc import Callable
from contextlib import contextmanager
from pathlib import Path

import gearcheck
from gearcheck.shared.progress import ProgressBar
from gearcheck.compare.presentation.summary import overall, overall_line, summary_row, write_summary
from gearcheck.shared.citations import REFERENCES
from gearcheck.shared.errors import GearcheckError, did_you_mean, one_line
from gearcheck.shared.outputs import OutputDirectory, check_place, write_file
from gearcheck.shared.trust import granted
from gearcheck.shared.units import checked_rpm, rad_s_to_rpm
from gearcheck.train.schema import HISTORY_START

# the names the arguments offer, written here so that building the parser imports no solver (``gearcheck --help``
# answers at once); tests/test_cli.py checks them against the library's own
SOLVERS = ("lumped", "mujoco")  # gearcheck.SOLVERS
PUBLISHED_MODELS = ("as-published", "energy-derived", "energy-derived-axis", "consistent")  # --model's 4-DOF models


FULL = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS}  # a disk full, a quota, a read-only file system


class Terminated(Exception):
    """SIGTERM, raised where the program is so that every ``finally`` runs."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``gearcheck: error: ...``, exit status 2, no usage block) that reads
    every negative number as a value, ``--dt -1e-6`` and ``--speed -inf`` too (argparse's own pattern
    knows only plain decimals and would take them for options)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|nan)$",
                                                   re.IGNORECASE)

    def error(self, message):
        raise GearcheckError(message)


def _terminate(signum, frame):
    raise Terminated()


FLAGS = {  # a library error's Python parameter -> this command line's flag
    "model": "--model", "results": "--results", "columns": "--columns", "speed": "--speed", "duration": "--duration",
    "measurements": "--measurements", "solver": "--solver", "method": "--method", "coordinate": "--coordinate",
    "samples": "--samples", "seed": "--seed", "harmonics": "--harmonics", "refine": "--refine", "workers": "--workers",
    "scheduler": "--scheduler", "speeds": "--speeds", "cache": "--cache", "fit": "--fit", "parameter": "--parameter",
    "orders": "--orders", "trust": "--trust", "data_root": "--data-root", "fps": "--fps",
    "slow_motion": "--slow-motion", "magnify": "--magnify", "output_dt": "--output-dt", "starts": "--starts",
    # a parameter that the command line names otherwise: a repeatable flag gives one entry of its list or dict
    "fields": "--set", "distributions": "--vary", "parameters": "--parameter", "quantities": "--quantity"}
_PARAMETER = re.compile(rf"(?<![.\]-])\b({'|'.join(FLAGS)})=(?=([^\s,.;:)]?))")


def as_flags(message: str) -> str:
    """A library error as the command line says it: ``model=x: ...`` as ``--model x: ...``, ``(duration=)`` as
    ``(--duration)``; a key of a train-file path (``stages[0].mesh.stiffness.model=``) is no parameter."""
    return _PARAMETER.sub(lambda m: FLAGS[m[1]] + (" " if m[2] else ""), message)


def _note(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as the command line says it: one line, ``gearcheck: note: ...`` (none with ``-q``)."""
    if logging.getLogger("gearcheck").isEnabledFor(logging.WARNING):
        print(f"gearcheck: note: {' '.join(str(message).split())}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `gearcheck show | head`: end quietly, like other tools
    previous = signal.signal(signal.SIGTERM, _terminate)
    shown_before, warnings.showwarning = warnings.showwarning, _note
    try:
        args = _parser().parse_args(argv)
        with granted(args.trust, args.data_root), told(args.verbose, args.quiet):
            return args.func(args)
    except GearcheckError as exc:
        print(f"gearcheck: error: {as_flags(' '.join(str(exc).splitlines()))}", file=sys.stderr)
        return 2
    except OSError as exc:
        if exc.errno not in FULL:
            raise
        print(f"gearcheck: error: {exc.filename or 'an output'}: cannot be written ({exc.strerror}); the previous "
              "output stays as it was", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("gearcheck: interrupted", file=sys.stderr)
        return 130
    except Terminated:
        print("gearcheck: terminated", file=sys.stderr)
        return 143
    except MemoryError:
        print("gearcheck: error: out of memory (the inputs ask for more than this machine has)", file=sys.stderr)
        return 2
    except Exception as exc:  # a fault of gearcheck's own that an input found: one line, and how to see the rest
        if os.environ.get("GEARCHECK_DEBUG"):
            raise
        print(f"gearcheck: error: internal error, {type(exc).__name__}: {one_line(exc, 300)} (a bug in gearcheck: "
              "please report it with the command; GEARCHECK_DEBUG=1 shows the traceback)", file=sys.stderr)
        return 70
    finally:
        signal.signal(signal.SIGTERM, previous)
        warnings.showwarning = shown_before


def _number(kind: str, positive: bool = True, minimum: float | None = None):
    """An argparse type: a finite number (positive unless told otherwise, at least ``minimum`` when given);
    ``kind`` says of what."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a number of {kind}, got {text!r}") from None
        if not math.isfinite(value) or (positive and value <= 0) or (minimum is not None and value < minimum):
            raise argparse.ArgumentTypeError(f"must be a {'positive ' if positive else ''}number of {kind}, "
                                             f"got {text}")
        return value
    return parse


SECONDS, RPM, HZ = _number("seconds"), _number("rpm"), _number("Hz")
RPM_OR_ZERO = _number("rpm >= 0", positive=False, minimum=0.0)


def PATH(text: str) -> Path:
    """An argparse type: a path, not an empty string (which names the current folder by accident)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("give a path, not an empty string")
    return Path(text)


def _range(unit: str):
    """An argparse type: A:B:N -> N values from A to B (``unit``), 0 <= A < B."""
    def parse(text: str) -> list[float]:
        parts = text.split(":")
        try:
            low, high, count = float(parts[0]), float(parts[1]), int(parts[2])
            if len(parts) != 3:
                raise ValueError
        except (ValueError, IndexError):
            raise argparse.ArgumentTypeError(f"must be A:B:N ({unit}, {unit}, count), got {text!r}") from None
        if not (math.isfinite(low) and math.isfinite(high) and 0 <= low < high and 2 <= count <= 10000):
            raise argparse.ArgumentTypeError(f"needs 0 <= A < B and 2 <= N <= 10000, got {text!r}")
        return [low + (high - low) * i / (count - 1) for i in range(count)]
    return parse


SPEED_RANGE, MICROMETRE_RANGE = _range("rpm"), _range("um")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="gearcheck", description="Cross-verify lumped-parameter planetary gear "
                                              "models against MuJoCo multibody twins.")
    p.add_argument("--version", action="version", version=f"gearcheck {gearcheck.__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    for name, command in COMMANDS.items():
        s = sub.add_parser(name, help=command.help)
        for flags, options in command.arguments:
            s.add_argument(*flags, **options)
        s.set_defaults(func=command.run)
    return p


def arg(*flags: str, **options) -> tuple:
    """An argument of a command: ``argparse``'s flags and options."""
    return flags, options


GRANTS = (  # every command's: what a train file may do beyond numbers (gearcheck.shared.trust)
    arg("--trust", action="append", default=[], metavar="MODULE",
        help="run the Python code a train file names from MODULE (a module, package or .py file); a train file is "
             "data and runs no code otherwise (repeatable)"),
    arg("--data-root", action="append", default=[], metavar="DIR",
        help="let train files name files inside DIR, besides their own folder (repeatable)"),
)

VERBOSITY = (  # every command's: how much it tells on stderr (gearcheck's loggers)
    arg("-v", "--verbose", action="count", default=0,
        help="say what the run does and what each step costs (wall and CPU time, steps, right-hand-side calls); "
             "-vv: every logger's debug lines"),
    arg("-q", "--quiet", action="store_true", help="no progress bars and no notes: errors only"),
)
LEVELS = {0: logging.WARNING, 1: logging.INFO}  # -v count -> level of the "gearcheck" logger (more: DEBUG)


@contextmanager
def told(verbose: int, quiet: bool):
    """Logging for one command: gearcheck's loggers to stderr as ``gearcheck: ...`` lines at the level ``-v`` and
    ``-q`` ask (notes are warnings, shown unless ``-q``); the logger as it was afterwards."""
    if verbose and quiet:
        raise GearcheckError("-v and -q: give one")
    logger = logging.getLogger("gearcheck")
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("gearcheck: %(name)s: %(message)s" if verbose > 1 else
                                           "gearcheck: %(message)s"))
    before = logger.level, logger.propagate
    logger.setLevel(logging.ERROR if quiet else LEVELS.get(verbose, logging.DEBUG))
    logger.addHandler(handler)
    logger.propagate = False
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(before[0])
        logger.propagate = before[1]


class Command:
    """A command of the command line: the function that runs it (each calls the front door), its help line and its
    arguments, as :func:`arg` writes them (and :data:`GRANTS`)."""

    def __init__(self, run: Callable[[argparse.Namespace], int], help: str, *arguments: tuple):
        self.run, self.help, self.arguments = run, help, (*arguments, *GRANTS, *VERBOSITY)


TRAIN = arg("train", metavar="TRAIN", help="preset name or path to a train TOML file")


# ----------------------------------------------------------------------------- commands
def cmd_presets(args) -> int:
    rows = []
    for name in gearcheck.presets():
        spec = gearcheck.load(name)
        cited = "; ".join(f"{REFERENCES[key].authors} {REFERENCES[key].year}" for key in spec.references)
        rows.append((name, spec.description, cited or spec.source))
    width = max(len(r[0]) for r in rows)
    for name, description, source in rows:
        print(f"{name:<{width}}  {description}  [{source}]")
    return 0


def cmd_show(args) -> int:
    info = gearcheck.describe(args.train)
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    print(f"{info['train']}: {info['description']}")
    print(f"  source: {info['source']}    file: {info['file']}" if info["source"] else f"  file: {info['file']}")
    if info["references"]:
        print("  references: " + ", ".join(info["references"]))
    print(f"  input {info['input']} at {info['input_speed_rpm']:.6g} rpm, {info['input_torque_nm']:.6g} N·m; "
          f"output {info['output']}, {info['output_torque_nm']:.6g} N·m; held {', '.join(info['held']) or '-'}")
    print(f"  ratio input/output = {info['ratio']:.10g}")
    print("  speeds (rpm): " + ", ".join(f"{m} {w:.6g}" for m, w in info["speeds_rpm"].items()))
    for st in info["stages"]:
        print(f"  stage {st['name']}: {st['planets']} planets at "
              f"{', '.join(f'{a:.6g}' for a in st['planet_angles_deg'])} deg, carrier radius "
              f"{st['carrier_radius_m'] * 1e3:.6g} mm")
        if st["torsional"]:
            print(f"    torsional (rotation only): {', '.join(st['torsional'])}")
        if st["tilting_inertia_kg_m2"]:
            print("    tilting, inertias about a diameter (kg·m²): "
                  + ", ".join(f"{mid.split('.')[-1]} {i:.4g}" for mid, i in st["tilting_inertia_kg_m2"].items()))
        for name, g in st["gears"].items():
            helix = f"  beta={g['helix_angle_deg']:+.6g} deg" if g["helix_angle_deg"] else ""
            teeth = "—" if g["teeth"] is None else g["teeth"]  # an idealised gear's
            print(f"    {name:<16} z={teeth:<4} r_pitch={g['pitch_radius_m'] * 1e3:.6g} mm  "
                  f"r_base={g['base_radius_m'] * 1e3:.6g} mm  r_tip={g['tip_radius_m'] * 1e3:.6g} mm{helix}")
        if "cycloid" in st:
            c = st["cycloid"]
            print(f"    cycloid: {c['cranks']} cranks, {c['discs']} discs at "
                  f"{', '.join(f'{a:.6g}' for a in c['eccentric_phases_deg'])} deg, Z_c={c['lobes']}, Z_p={c['pins']}, "
                  f"e={c['eccentricity_m'] * 1e3:.6g} mm, R_p={c['pin_circle_radius_m'] * 1e3:.6g} mm, "
                  f"r_rp={c['pin_radius_m'] * 1e3:.6g} mm, K1={c['K1']:.4f}, "
                  f"rho_min={c['min_curvature_radius_m'] * 1e3:.4g} mm")
            print(f"    pins: f_pin={c['pin_frequency_hz']:.6g} Hz  k={c['pin_stiffness_n_per_m']:.4g} N/m per "
                  "contact  "
                  f"{c['pins_touching_at_rest']} contacts loaded at t = 0  clearance "
                  f"{c['clearance_m'] * 1e6:.4g} µm")
    print("  meshes:")
    for m in info["meshes"]:
        face = f"+{m['face_contact_ratio']:.4f}" if m["face_contact_ratio"] else ""
        eps = "—" if m["contact_ratio"] is None else f"{m['contact_ratio']:.4f}"  # an idealised mesh has none
        print(f"    {m['mesh']:<24} eps={eps}{face}  "
              f"alpha'={m['operating_pressure_angle_deg']:.4f} deg  "
              f"f_mesh={m['mesh_frequency_hz']:.6g} Hz  phase={m['phase_cycles']:.4f}  "
              f"k={m['mean_stiffness_n_per_m']:.4g} N/m ({m['stiffness_model']})  c={m['damping_n_s_per_m']:.4g} N·s/m")
        if "face_width_m" in m:
            print(f"    {'':<24} face w={m['face_width_m'] * 1e3:.6g} mm at z={m['face_centre_m'] * 1e3:.6g} mm  "
                  f"k_tilt={m['tilting_stiffness_n_m_per_rad']:.4g} N·m/rad")
    print(settling_line(info["settling"]))
    return 0


PRACTICAL_SETTLE_S = 1.0  # a start that takes longer than this to die away gets a note


def settling_line(s: dict) -> str:
    """What ``gearcheck show`` says of how a start settles, with a note where it takes longer than a practical run."""
    tau = "never decays" if s["time_constant_s"] is None else f"time constant {s['time_constant_s']:.3g} s"
    line = (f"  settling: slowest-decaying mode {s['slowest_mode_hz']:.6g} Hz, damping ratio "
            f"{100 * s['damping_ratio']:.3g} %, {tau}")
    if s["settle_s"] is not None and s["settle_s"] <= PRACTICAL_SETTLE_S:
        return line + f"; a run from rest settles in {s['settle_s']:.3g} s"
    supports = (f" Supports and bearings without damping: {', '.join(s['undamped_supports'])} (gearcheck adds no "
                "damping a train file does not state; their radial/torsional/axial_damping fields add it)."
                if s["undamped_supports"] else "")
    settles = "never" if s["settle_s"] is None else f"only after {s['settle_s']:.3g} s"
    return (line + f"\n  note: a run from rest settles {settles}: a cross-check at its default duration starts both "
            f"solvers on their periodic steady states instead, and a shorter plain run (gearcheck run) stays in its "
            f"start-up transient.{supports}")


def cmd_modes(args) -> int:
    spec = gearcheck.load(args.train)
    solvers = list(SOLVERS) if args.solver == "both" else [args.solver]
    results = [gearcheck.modes(spec, solver, speed=args.speed) for solver in solvers]
    if args.json:
        out = {"train": spec.name, "unit": "Hz", "solvers": [r.to_dict() for r in results]}
        if args.speed is not None:
            out["speed_rpm"] = args.speed
        print(json.dumps(out, indent=2))
        return 0
    at_speed = args.speed is not None
    extra = "  growth [1/s]  stability " if at_speed else ""
    header = f"{'mode':>4}  " + "  ".join(f"{r.solver + ' (Hz)':>16}  {'type':<13} {'mult':>4}{extra}" for r in results)
    if len(results) == 2:
        header += f"  {'rel. diff':>10}"
    print(f"{spec.name}: natural frequencies at mean mesh stiffness, "
          + (f"turning at {args.speed:g} rpm (gyroscopic)" if at_speed else "at rest"))
    print(header)
    for i in range(len(results[0])):
        line = f"{i + 1:>4}  " + "  ".join(
            f"{r.frequencies[i]:>16.6f}  {r.types[i]:<13} {r.multiplicity[i]:>4}"
            + (f"  {r.growth[i]:>12.4g}  {r.stability[i]:<10}" if at_speed else "") for r in results)
        if len(results) == 2:
            a, b = results[0].frequencies[i], results[1].frequencies[i]
            line += f"  {abs(a - b) / max(abs(a), 1e-300):>10.2e}"
        print(line)
    if at_speed and not all(r.stable for r in results):
        print("UNSTABLE: " + "; ".join(f"{r.solver}: {r.stability.count('divergence')} divergent, "
                                      f"{r.stability.count('flutter')} flutter modes" for r in results))
    return 0


def cmd_campbell(args) -> int:
    from gearcheck.compare.presentation.plots import campbell_diagram

    with OutputDirectory(args.out) as place:
        result = gearcheck.campbell(args.train, args.speeds, solver=args.solver, harmonics=args.harmonics)
        write_file(place.path / "campbell.png", campbell_diagram(result))
        write_file(place.path / "campbell.json", json.dumps(result.to_dict(), indent=2) + "\n")
    kept = sum(c["excited"] is False for c in result.crossings)
    print(f"{result.train}: {len(result.speeds_rpm)} speeds from {result.speeds_rpm[0]:g} to "
          f"{result.speeds_rpm[-1]:g} rpm, {len(result.crossings)} crossings of mesh harmonics with modes"
          + (f", {kept} of them out of their line's reach (the planets' phasing, Parker 2000, or a mode the line's "
             f"meshes do not move): drawn hollow" if kept else ""))
    if result.agreement is not None:
        print(f"  lumped and MuJoCo frequencies agree to {result.agreement:.2e} (relative, worst over all speeds)")
    for zone in result.zones:
        print(f"  UNSTABLE ({zone['solver']}) from {zone['from_rpm']:g} to {zone['to_rpm']:g} rpm")
    print(f"  wrote {args.out / 'campbell.png'} and {args.out / 'campbell.json'}")
    return 0


def cmd_mac(args) -> int:
    from gearcheck.compare.presentation.plots import mac_heatmap

    with OutputDirectory(args.out) as place:
        pairing = gearcheck.mode_pairing(args.train, args.model, args.against)
        write_file(place.path / "mac.png", mac_heatmap(pairing))
        write_file(place.path / "mac.json", json.dumps(pairing.to_dict(), indent=2) + "\n")
    print(f"{pairing.train}: {len(pairing.paired)} modes; each {pairing.reference} mode lies in its frequency group's "
          f"{pairing.test} modes to {1.0 - pairing.paired.min():.1e} (worst)")
    for line in pairing.notes:
        print(f"  {line}")
    for line in pairing.findings:
        print(f"  {line}")
    print(f"  wrote {args.out / 'mac.png'} and {args.out / 'mac.json'}")
    return 0 if not pairing.findings else 1


def cmd_ste(args) -> int:
    import numpy as np

    from gearcheck.compare.presentation import plots

    if args.slices is not None and not 1 <= args.slices <= 1000:
        raise GearcheckError(f"--slices {args.slices}: must be between 1 and 1000")
    train = gearcheck.Train(args.train)
    spec = train.spec
    with OutputDirectory(args.out) as place:
        curves = train.ste(args.slices)
        report = {"train": spec.name, "meshes": [c.to_dict() for c in curves]}
        write_file(place.path / "ste.png", plots.static_transmission_error(curves, spec.name))
        if args.relief_sweep:
            report["relief_sweep"] = train.relief_sweep([a * 1e-6 for a in args.relief_sweep], args.slices)
            write_file(place.path / "relief_sweep.png", plots.relief_sweep(report["relief_sweep"], spec.name))
        write_file(place.path / "ste.json", json.dumps(report, indent=2) + "\n")
    for c in curves:
        if ".planet1." in c.mesh or len(curves) == 1:
            print(f"{c.mesh}: load {c.load:.6g} N, loaded STE peak-to-peak {np.ptp(c.loaded) * 1e6:.4g} µm "
                  f"(mean {np.mean(c.loaded) * 1e6:.4g} µm, F/k_mean {c.mean_deflection * 1e6:.4g} µm), unloaded "
                  f"peak-to-peak {np.ptp(c.unloaded) * 1e6:.4g} µm")
    for mesh, data in report.get("relief_sweep", {}).get("meshes", {}).items():
        if ".planet1." in mesh:
            print(f"  {mesh}: smallest loaded peak-to-peak at {data['best_amount_m'] * 1e6:.4g} µm of relief")
    print(f"  wrote {args.out}")
    return 0


def _profiled(args, train):
    """The train under the command line's operating history (--speed-profile, --torque-profile, --load-profile,
    --start), or as loaded."""
    return gearcheck.load(train, args.speed, speed_profile=args.speed_profile, torque_profile=args.torque_profile,
                          load_profile=args.load_profile, start=args.start)


def cmd_run(args) -> int:
    spec = _profiled(args, args.train)
    with OutputDirectory(args.out) as place:
        bar = ProgressBar(f"{args.solver} {spec.name}")
        result = gearcheck.simulate(spec, args.solver, args.duration, dt=args.dt, output_dt=args.output_dt,
                                    method=args.method, progress=bar)
        bar.close()
        written = [path.name for path in result.write_files(place.path, args.format)]
    print(f"{spec.name} ({args.solver}): {result.t.size} samples over {result.t[-1]:.6g} s, "
          f"dt = {result.info['dt_s']:.4g} s, wall {result.info.wall_s:.3g} s")
    for name in written:
        print(f"  wrote {args.out / name}")
    return 0


def cmd_runup(args) -> int:
    from gearcheck.compare.presentation.runup_report import write_runup
    from gearcheck.compare.studies.runup import PARTING

    spec = gearcheck.load(args.train)
    sweep = None
    if args.against is not None:
        import pandas as pd

        from gearcheck.train.files import read_bytes

        try:
            sweep = pd.read_parquet(io.BytesIO(read_bytes(args.against, "sweep table", 1 << 30)))
        except GearcheckError:
            raise
        except Exception as exc:  # pyarrow raises many kinds on a damaged file
            raise GearcheckError(f"--against {args.against}: not a sweep table ({one_line(exc)})") from None
        if not {"metric", "solver", "quantity", "mesh", "order", "speed_rpm", "amplitude"} <= set(sweep.columns):
            raise GearcheckError(f"--against {args.against}: not a sweep table (gearcheck sweep's sweep.parquet)")
    solvers = SOLVERS if args.solver == "both" else (args.solver,)
    natural = gearcheck.modes(spec).frequencies
    with OutputDirectory(args.out) as place:
        bar = ProgressBar(f"run-up {spec.name}")
        run = gearcheck.runup(spec, args.start, args.stop, args.duration, solver=args.solver,
                              quantities=args.quantity or None, harmonics=args.harmonics, output_dt=args.output_dt,
                              progress=bar)
        bar.close()
        written = write_runup(run, place.path, natural, sweep)
    costs = ", ".join(f"{s} {run.cpu_s[s]:.3g} s CPU" for s in solvers)
    print(f"{spec.name}: run-up {args.start:g} -> {args.stop:g} rpm in {args.duration:g} s "
          f"({run.rate_rpm_s:.4g} rpm/s), {len(run.orders)} orders of {len({q for _, q in run.tracks})} quantities; "
          f"{costs}")
    agreement = run.agreement()
    if agreement:
        print(f"  lumped and MuJoCo order curves differ by at most {max(agreement.values()):.2g} of each quantity's "
              "largest order amplitude")
        for quantity, speed in run.parting().items():
            if speed is not None:
                print(f"  {quantity}: the two solvers part (by over {PARTING:g} of its largest) from {speed:.5g} "
                      "rpm on")
    for name in written:
        print(f"  wrote {args.out / name}")
    return 0


def cmd_sensitivity(args) -> int:
    import numpy as np

    from gearcheck.compare.presentation import plots
    from gearcheck.compare.studies import sensitivity
    from gearcheck.train.loader import read_train_text

    text, source = read_train_text(args.train)
    spec = gearcheck.load(args.train)
    coordinate = args.coordinate or f"{spec.output}.theta"
    method = sensitivity.METHODS[0] if args.method == "hb" else sensitivity.METHODS[1]
    for rpm in args.speeds or ():
        checked_rpm(rpm, "--speeds: every speed")
    index = _coordinate(spec, coordinate)
    with OutputDirectory(args.out) as place:
        if args.values:
            speeds = args.speeds or [rad_s_to_rpm(spec.operating.input_speed)]
            bar = ProgressBar(f"sensitivity over {args.parameter[0]}")
            frame = sensitivity.sensitivity_map(text, source, args.parameter, speeds, coordinate, args.orders, method,
                                                progress=bar, values=args.values)
            bar.close()
            frame.to_csv(place.path / "sensitivity_values.csv", index=False, float_format="%.10g")
            written = ["sensitivity_values.csv"]
            title = f"{spec.name}: sensitivity of {coordinate} to {args.parameter[0]}"
            if len(speeds) <= VALUES_PLOT_SPEEDS:  # a line style per speed, against the value
                write_file(place.path / "sensitivity_values.png", plots.sensitivity_values(frame, coordinate, title))
                written.append("sensitivity_values.png")
            if len(speeds) >= FAMILY_PLOT_SPEEDS:  # over the mesh frequency, a curve per value
                write_file(place.path / "sensitivity_family.png", plots.sensitivity_family(
                    frame[frame["harmonic"].isin(_mesh_harmonics(frame, 3))], coordinate, f"{title}, mesh harmonics"))
                written.append("sensitivity_family.png")
            if frame["negligible"].all():
                print(f"{args.parameter[0]}: the response of {coordinate} does not depend on it at these values and "
                      "speeds (every derivative is round-off: negligible)")
        elif args.speeds:
            bar = ProgressBar(f"sensitivity map {spec.name}")
            frame = sensitivity.sensitivity_map(text, source, args.parameter, args.speeds, coordinate,
                                                args.orders, method, progress=bar)
            bar.close()
            frame.to_csv(place.path / "sensitivity_map.csv", index=False, float_format="%.10g")
            write_file(place.path / "sensitivity_map.png", plots.sensitivity_map(
                frame[frame["harmonic"].isin(_mesh_harmonics(frame, 3))], coordinate,
                f"{spec.name}: sensitivity of {coordinate}, mesh harmonics"))
            written = ["sensitivity_map.csv", "sensitivity_map.png"]
        else:
            rows = []
            for parameter in args.parameter:
                result = sensitivity.field_sensitivity(text, source, parameter, args.orders, method)
                for j, h in enumerate(result.response.harmonics):
                    rows.append({"parameter": parameter, "value": result.value,
                                 "harmonic": str(tuple(int(x) for x in h)),
                                 "frequency_hz": result.response.frequencies[j] / (2 * np.pi),
                                 "amplitude": abs(result.response.amplitudes[j, index]),
                                 "amplitude_unit": sensitivity.coordinate_unit(coordinate),
                                 "closed_form": result.closed_form[j, index],
                                 "finite_difference": result.finite_difference[j, index],
                                 "eq15": None if result.truncated is None else result.truncated[j, index]})
                if result.independent:
                    print(f"{parameter} = {result.value:.6g}: the response does not depend on it (every derivative "
                          f"is round-off: negligible)")
                else:
                    print(f"{parameter} = {result.value:.6g}: closed form against finite differences, largest "
                          f"relative difference {result.relative_error():.1e} ({method})")
            import pandas as pd

            frame = pd.DataFrame(rows)
            frame.to_csv(place.path / "sensitivity.csv", index=False, float_format="%.10g")
            top = frame.sort_values("amplitude", ascending=False).drop_duplicates("parameter")
            for _, r in top.iterrows():
                eq15 = "" if r["eq15"] is None else f", Eq. 15 {r['eq15']:.4g}"
                print(f"  {r['parameter']}: largest harmonic {r['harmonic']} of {coordinate} at "
                      f"{r['frequency_hz']:.6g} Hz, |Q| {r['amplitude']:.4g}, d|Q|/dp {r['closed_form']:.4g}{eq15}")
            written = ["sensitivity.csv"]
    print(f"  {sensitivity.HARMONIC_NOTATION}; amplitudes in {sensitivity.coordinate_unit(coordinate)}, their "
          "derivatives per unit of the field as the train file gives it (a map's d_amplitude_d_ln_p: per relative "
          "change of the field)")
    for name in written:
        print(f"  wrote {args.out / name}")
    return 0


VALUES_PLOT_SPEEDS = 4  # sensitivity --values: against the value with a line style per speed up to this many speeds
FAMILY_PLOT_SPEEDS = 3  # ... and over the mesh frequency with a curve per value from this many


def _mesh_harmonics(frame, count: int) -> list[str]:
    """The first ``count`` pure mesh harmonics of a sensitivity table: (k,) or (k, 0)."""
    return [h for h in dict.fromkeys(frame["harmonic"]) if h.endswith(", 0)") or "," not in h.strip("(,)")][:count]


def _coordinate(spec, name: str) -> int:
    from gearcheck.lumped.assembly import build_model

    labels = build_model(spec).dofs.labels()
    if name not in labels:
        raise GearcheckError(f"--coordinate {name!r}: not a coordinate of {spec.name}"
                             + did_you_mean(name, labels, n=3, cutoff=0))
    return labels.index(name)


def cmd_pins(args) -> int:
    from gearcheck.compare.presentation.plots import pin_loads as figure

    spec = gearcheck.load(args.train)
    path = args.output or Path("out") / f"{spec.name}-pins.png"
    check_place(path, "-o", folder=False)
    loads = gearcheck.pin_loads(spec, span=args.span, samples=args.samples)
    s = loads.summary()
    write_file(path, figure(loads, title=f"{spec.name}: static pin loads at {abs(loads.output_torque):.6g} N·m over "
                                         f"one {'pin pitch' if args.span == 'pitch' else 'eccentric turn'}"))
    print(f"{spec.name}: {s['loaded_pins_min']}-{s['loaded_pins_max']} pins loaded per disc, peak "
          f"{s['peak_force_n']:.6g} N = {s['peak_ratio_max']:.4f} x the rigid disc's 4 T/(Z_p r_c) = "
          f"{s['classical_peak_n']:.6g} N; pins hold {s['wheel_torque_nm']:.6g} N·m "
          f"(balance error {s['torque_balance_error_max']:.1e})")
    print(f"wrote {path}")
    return 0


def cmd_stiffness(args) -> int:
    from gearcheck.compare.presentation.plots import mesh_stiffness

    spec = gearcheck.load(args.train)
    path = args.output or Path("out") / f"{spec.name}-stiffness.png"
    check_place(path, "-o", folder=False)
    write_file(path, mesh_stiffness(spec))
    print(f"wrote {path}")
    return 0


def cmd_animate(args) -> int:
    from gearcheck.compare.presentation.animate import check_output

    for name in ("fps", "slow_motion", "magnify"):
        value = getattr(args, name)
        if not (math.isfinite(value) and value > 0):
            raise GearcheckError(f"--{name.replace('_', '-')} {value:g}: needs a positive number")
    if min(args.size) < 16 or max(args.size) > 4096:
        raise GearcheckError(f"--size {args.size[0]} {args.size[1]}: between 16 and 4096 pixels")
    check_output(args.output)
    check_place(args.output, "-o", folder=False)
    train = gearcheck.Train(args.train)
    bar = ProgressBar(f"animate {train.spec.name}")
    width, height = args.size
    options = {"duration": args.duration, "fps": args.fps, "width": width, "height": height, "progress": bar}
    if args.mode is None:
        train.animate(args.output, magnify=args.magnify, slow_motion=args.slow_motion, **options)
    else:
        train.animate(args.output, args.mode, args.solver, **options)
    bar.close()
    print(f"wrote {args.output}")
    return 0


def cmd_view(args) -> int:
    gearcheck.Train(args.train).view(slow_motion=args.slow_motion, magnify=args.magnify)
    return 0


def cmd_dashboard(args) -> int:
    site = gearcheck.dashboard(args.store, args.output)
    print(f"wrote {site / 'index.html'}")
    return 0


def head_commit() -> str:
    """The commit checked out here (`git rev-parse HEAD`); --commit where there is none."""
    import subprocess

    try:
        run = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        run = None
    if run is None or run.returncode != 0:
        raise GearcheckError("--history: no git commit here to record; give --commit SHA")
    return run.stdout.strip()


def commit_date(commit: str) -> str | None:
    """The committer date of ``commit`` (ISO 8601), or None where git does not know it."""
    import subprocess

    try:
        run = subprocess.run(["git", "show", "-s", "--format=%cI", commit], capture_output=True, text=True,
                             timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return run.stdout.strip() or None if run.returncode == 0 else None


def cmd_export(args) -> int:
    if args.output.suffix not in (".mat", ".npz"):
        raise GearcheckError(f"-o {args.output}: a model file is .mat or .npz")
    gearcheck.export_model(args.train, args.output)
    print(f"wrote {args.output}")
    return 0


def cmd_mjcf(args) -> int:
    if args.output is not None:
        check_place(args.output, "-o", folder=False)
    text = gearcheck.mjcf(args.train)
    if args.output is None:
        sys.stdout.write(text)
        return 0
    write_file(args.output, text)
    print(f"wrote {args.output}")
    return 0


def cmd_calibrate(args) -> int:
    from gearcheck.compare.presentation.calibrate_report import write_calibration

    spec = gearcheck.load(args.train)

    def progress(runs):
        if sys.stderr.isatty():
            print(f"\rcalibrate {spec.name}: {runs} evaluations", end="", file=sys.stderr, flush=True)

    with OutputDirectory(args.out) as place:
        result = gearcheck.calibrate(args.train, args.fit, measurements=args.measurements, duration=args.duration,
                                     fit_speed=args.fit_speed, starts=args.starts, progress=progress)
        if sys.stderr.isatty():
            print(file=sys.stderr)
        lines = write_calibration(result, spec.name, place.path, args.out)
    for line in lines:
        print(line)
    return 0


def _read_distributions(path) -> dict[str, str]:
    """The ``[distributions]`` table of the TOML file ``--distributions`` names: ``"FIELD" = "normal(mean, sd)"``, one
    per field."""
    from gearcheck.train.files import read_toml

    try:
        data = read_toml(path, "distributions file")
    except GearcheckError as exc:
        raise GearcheckError(f"--distributions {exc}") from None
    table = data.get("distributions")
    if not isinstance(table, dict) or not table:
        raise GearcheckError(f"--distributions {path}: needs a [distributions] table of \"FIELD\" = "
                             "\"normal(mean, sd)\" entries")
    bad = [k for k, v in table.items() if not isinstance(v, str)]
    if bad:
        raise GearcheckError(f"--distributions {path}: {bad[0]} must be a string such as \"normal(10, 1)\"")
    return dict(table)


def cmd_sweep(args) -> int:
    from gearcheck.compare.studies.sweep import check_quantities, parse_speeds, parse_values
    from gearcheck.compare.studies.sweep_lines import CONVERGED

    speeds = None if args.speeds is None else parse_speeds(args.speeds)
    fields: dict[str, list[float]] = {}
    for text in args.set:
        path, values = parse_values(text)
        if path in fields:
            raise GearcheckError(f"--set {path}: given twice")
        fields[path] = values
    distributions = _read_distributions(args.distributions) if args.distributions is not None else {}
    for text in args.vary:
        path, eq, law = text.partition("=")
        if not eq or not path.strip():
            raise GearcheckError(f"--vary {text!r}: give FIELD=DISTRIBUTION, e.g. stages[0].sun.mass=normal(1.0,0.05)")
        if path.strip() in distributions:
            raise GearcheckError(f"--vary {path.strip()}: given twice")
        distributions[path.strip()] = law
    if args.no_cache and args.cache is not None:
        raise GearcheckError("--cache and --no-cache: give one")
    cache = None if args.no_cache else (args.cache or args.out.with_name(args.out.name + ".cache"))
    inside = cache is not None and Path(os.path.abspath(args.out)) in (Path(os.path.abspath(cache)),
                                                                       *Path(os.path.abspath(cache)).parents)
    if inside:
        raise GearcheckError(f"--cache {cache}: inside --out {args.out}, which each run replaces whole: give a folder "
                             "beside it")
    if args.quantity:
        check_quantities(args.train, args.quantity)
    with OutputDirectory(args.out) as place:
        bar = ProgressBar(f"sweep {args.train}")
        result = gearcheck.sweep(args.train, speeds=speeds, fields=fields, distributions=distributions,
                                 samples=args.samples, seed=args.seed, solver=args.solver, duration=args.duration,
                                 harmonics=args.harmonics, integration_check=args.integration_check,
                                 refine=args.refine, continuation=args.continuation, workers=args.workers,
                                 scheduler=args.scheduler,
                                 cache=cache, progress=bar)
        bar.close()
        written = result.write_files(place.path, args.quantity)
        summary = result.summary()
    n = len(result.plan.points)
    per_point = f", {sum(result.point_wall_s) / result.computed:.3g} s per point run" if result.computed else ""
    where = "in this process" if result.backend == "in-process" else f"on {result.backend}"
    print(f"{result.train}: {n} points ({result.computed} run, {result.cached} from the cache"
          f"{'' if cache is None else f' {cache}'}) in {result.wall_s:.3g} s {where}{per_point}")
    by_quantity: dict[str, list[str]] = {}
    for peak in summary["peaks"]:
        by_quantity.setdefault(peak["quantity"], []).append(
            f"{peak['mesh']} x{peak['order']} = {peak['amplitude']:.4g} {peak['unit']} at {peak['speed_rpm']:.6g} rpm "
            f"({peak['frequency_hz']:.5g} Hz, {peak['solver']})")
    for quantity, peaks in by_quantity.items():
        print(f"  {quantity}: largest harmonic " + "; ".join(peaks))
    checked = result.checked_points()
    if checked:
        print(f"  integration check on {sum(checked.values())} of {n} points ("
              + ", ".join(f"{count} {reason}" for reason, count in checked.items()) + "; the checked column)")
    if summary["no_steady_state"]:
        print(f"  {summary['no_steady_state']} of {n * len(result.settings['solvers'])} runs reached no steady state "
              "(steady = none: their second half is reduced, left out of the peaks and plots); a longer --duration "
              "helps")
    if summary["unconverged_lines"]:
        print(f"  {summary['unconverged_lines']} of {summary['lines']} resolved lines have an integration error "
              f"estimate above {CONVERGED:.0%} of their amplitude (their own, or at an unchecked speed their checked "
              "neighbours'): left out of the peaks, faint in the plots")
    for failure in summary["failed"]:
        print(f"  point {failure['point']} ({failure['solver']}) failed: {failure['error']}")
    print(f"  wrote {args.out / 'sweep.parquet'} ({result.table.num_rows} rows), "
          + ", ".join(str(args.out / name) for name in written[1:]))
    return 0


def cmd_crosscheck(args) -> int:
    from gearcheck.compare.engine.crosscheck import MODELS
    from gearcheck.compare.presentation import history
    from gearcheck.compare.presentation.junit import write_junit
    from gearcheck.compare.presentation.report import write_report
    from gearcheck.train.files import report_folders, train_list

    if args.all == bool(args.train):
        raise GearcheckError("give TRAIN (one or more) or --all, not both")
    names = gearcheck.presets() if args.all else train_list(args.train)
    fleet = args.all or len(names) > 1
    if fleet and (args.model not in MODELS or args.results is not None):
        raise GearcheckError("--model FILE and --results check one train, not several")
    if fleet and args.speed is not None:
        raise GearcheckError("--speed applies to one train; several run each at its own speed")
    profiled = any((args.speed_profile, args.torque_profile, args.load_profile))
    if fleet and profiled:
        raise GearcheckError("--speed-profile, --torque-profile and --load-profile apply to one train")
    if profiled:
        names = [_profiled(args, names[0])]
    specs = [gearcheck.load(name) for name in names]  # every train checked before anything runs or is written
    named = Counter(spec.name for spec in specs)
    for spec, name in zip(specs, names):
        if args.history is not None and named[spec.name] > 1:
            raise GearcheckError(f"TRAIN {name}: another train of the fleet has its name {spec.name!r}, and "
                                 "--history keeps one record per commit and train name")
    folders = report_folders(names) if fleet else [""]
    rows, lines, reports = [], [], []
    if args.junit is not None:
        check_place(args.junit, "--junit", folder=False)
    commit = None
    if args.history is not None:
        history.check_store(args.history)
        commit = history.checked_commit(args.history, args.commit or os.environ.get("GITHUB_SHA") or head_commit())
    with OutputDirectory(args.out) as place:
        for name, folder in zip(names, folders):
            bar = ProgressBar(f"crosscheck {getattr(name, 'name', name)}")
            result = gearcheck.crosscheck(
                name, speed=None if profiled else args.speed, duration=args.duration, model=args.model,
                against=args.against,
                results=args.results, columns=args.columns, modes=args.modes, dt_lumped=args.dt_lumped,
                dt_mujoco=args.dt_mujoco, tolerances=args.tolerances, measurements=args.measurements,
                sensor_band=args.sensor_band, baseline=args.baseline, update_baseline=args.update_baseline,
                progress=bar)
            bar.close()
            data = write_report(result, place.path / folder, figures=args.figures)
            lines.append(_verdict_line(result, args.out / folder))
            rows.append(summary_row(data, folder))
            reports.append(data)
            if args.history is not None:
                history.append(args.history, data, commit, commit_date(commit))
        if fleet:
            write_summary(place.path, rows, "every preset" if args.all else f"{len(rows)} trains")
    if args.junit is not None:
        write_junit(reports, args.junit)
    for line in lines:
        print(line)
    if fleet:
        print(f"{overall_line(rows)} (summary: {args.out / 'summary.md'})")
    if args.junit is not None:
        print(f"junit: {args.junit}")
    return EXIT_STATUS[overall(rows)]


EXIT_STATUS = {"PASS": 0, "FAIL": 1, "INCONCLUSIVE": 3}  # of the worst verdict (summary.overall)
MOVED_SHOWN = 3  # baseline moves named on the verdict line (the report lists them all)


def _verdict_line(result, out: Path) -> str:
    detail = ""
    if result.failures:
        detail += f"; beyond tolerance: {', '.join(result.failures)}"
    if result.moved:
        shown = "; ".join(result.moved[:MOVED_SHOWN])
        more = f"; and {len(result.moved) - MOVED_SHOWN} more" if len(result.moved) > MOVED_SHOWN else ""
        detail += f"; moved from baseline ({len(result.moved)}): {shown}{more}"
    if result.verdict == "INCONCLUSIVE":
        detail += f"; cannot decide: {', '.join(result.unresolved)}"
    return f"{result.spec.name}: {result.verdict}{detail} (report: {out / 'report.md'})"


PROFILES = (  # an operating history from the command line (gearcheck.train.history)
    arg("--speed-profile", metavar="FILE|T:RPM,...",
        help="input speed over time: a CSV/Parquet table (time_s, speed_rpm) or points T:RPM,T:RPM,... joined by "
             "straight lines (the train is driven through its input shaft)"),
    arg("--torque-profile", metavar="FILE|T:NM,...",
        help="input torque over time instead (N·m; the speed follows from the rigid train, the input shaft unused)"),
    arg("--load-profile", metavar="FILE|T:NM,...", help="output load torque over time (N·m, opposing rotation)"),
    arg("--start", choices=HISTORY_START,
        help="start of a profile run: steady state at its initial speed, or at rest (default: rest from 0 rpm or a "
             "torque, else steady)"),
)


COMMANDS = {  # name: the function that runs it, its help line, its arguments (argparse's, by flags)
    "presets": Command(
        cmd_presets, "list the shipped train presets",
    ),
    "show": Command(
        cmd_show, "the validated train with derived quantities",
        TRAIN,
        arg("--json", action="store_true", help="machine-readable output"),
    ),
    "modes": Command(
        cmd_modes, "natural frequencies and mode types (at rest, or turning at --speed)",
        TRAIN,
        arg("--solver", choices=SOLVERS + ("both",), default="lumped"),
        arg("--speed", type=RPM_OR_ZERO, metavar="RPM",
            help="the gyroscopic modes of the train turning at this input speed (0 allowed)"),
        arg("--json", action="store_true", help="machine-readable output"),
    ),
    "campbell": Command(
        cmd_campbell, "Campbell diagram: gyroscopic modes over a speed range (PNG and JSON)",
        TRAIN,
        arg("--speeds", type=SPEED_RANGE, required=True, metavar="A:B:N",
            help="N input speeds from A to B rpm (0 <= A < B, N >= 2)"),
        arg("--solver", choices=SOLVERS + ("both",), default="both"),
        arg("--harmonics", type=int, default=3, metavar="H", help="mesh harmonics drawn (default 3)"),
        arg("--out", type=PATH, default=Path("out/campbell"), metavar="DIR",
            help="writes campbell.png and campbell.json (default out/campbell)"),
    ),
    "mac": Command(
        cmd_mac, "mode shapes of the lumped model and the MuJoCo twin (or your --model and --against) paired by the "
                 "modal assurance criterion (PNG heat map and JSON)",
        TRAIN,
        arg("--model", metavar="MODEL",
            help="your model: a .mat/.npz file of matrices, module:factory or file.py:factory"),
        arg("--against", default="lumped", choices=("lumped", "mujoco"), help="what --model is paired with"),
        arg("--out", type=PATH, default=Path("out/mac"), metavar="DIR",
            help="writes mac.png and mac.json (default out/mac)"),
    ),
    "ste": Command(
        cmd_ste, "static transmission error of every mesh, unloaded and loaded, with its tip reliefs (PNG and JSON)",
        TRAIN,
        arg("--relief-sweep", type=MICROMETRE_RANGE, metavar="A:B:N",
            help="also the loaded STE peak-to-peak for N tip relief amounts from A to B µm (every tip relief of the "
                 "train, lengths as given)"),
        arg("--slices", type=int, metavar="N", help="slices across a helical face (default 400)"),
        arg("--out", type=PATH, default=Path("out/ste"), metavar="DIR",
            help="writes ste.png, ste.json (and relief_sweep.png) (default out/ste)"),
    ),
    "run": Command(
        cmd_run, "time response at the operating point",
        TRAIN,
        arg("--solver", choices=SOLVERS, default="lumped"),
        arg("--speed", type=RPM, metavar="RPM", help="input speed (default: the train file's)"),
        arg("--duration", type=SECONDS, default=0.2, metavar="S", help="simulated time (default 0.2 s)"),
        arg("--dt", type=SECONDS, metavar="S", help="time step (default: from the highest natural frequency)"),
        arg("--output-dt", type=SECONDS, metavar="S", help="output sampling interval (default: every step)"),
        arg("--method", default="rk4", help="lumped integrator: rk4 (default) or RK45, DOP853, Radau, BDF, LSODA"),
        arg("--format", choices=("parquet", "csv"), default="parquet",
            help="time series file format: parquet (default: full precision, compressed, units in its metadata) or "
                 "csv"),
        *PROFILES,
        arg("--out", type=PATH, default=Path("out"), metavar="DIR", help="output directory (default out/)"),
    ),
    "crosscheck": Command(
        cmd_crosscheck, "run both solvers, compare them, write a report; exit 1 when a tolerance is exceeded or a "
                        "baseline metric moved, 3 when the comparison is inconclusive",
        arg("train", metavar="TRAIN", nargs="*",
            help="preset name or train TOML file; several, a folder (its *.toml) or a quoted pattern ('fleet/*.toml') "
                 "check a fleet: a report each, one summary, one --junit file, one --history append"),
        arg("--all", action="store_true", help="every shipped preset, with a summary table"),
        arg("--speed", type=RPM, metavar="RPM", help="input speed (default: the train file's)"),
        arg("--duration", type=SECONDS, metavar="S",
            help="simulated time (default: the baseline's with --baseline, else 0.1 s; 0.02 s for a --model other "
                 "than general)"),
        arg("--model", default="general", metavar="MODEL",
            help="the model checked: gearcheck's general model against MuJoCo (default), a published "
                        f"4-DOF model ({', '.join(PUBLISHED_MODELS)}: double-planet) against the twin of its "
                        "idealisation, or your own: a .mat/.npz file of matrices, module:factory, "
                        "file.py:factory, or 'user' (the train file's train.user_model), checked against --against"),
        arg("--against", default="lumped", choices=("lumped", "mujoco"),
            help="what your own model is checked against: the reference lumped model (default) or the MuJoCo twin"),
        arg("--results", type=PATH, metavar="FILE",
            help="another solver's time series as the model checked (.csv, .parquet, .mat)"),
        arg("--columns", type=PATH, metavar="FILE", help="TOML map of --results' columns to signals"),
        arg("--modes", type=PATH, metavar="FILE",
            help="with --results: its natural frequencies and mode shapes (.npz, .mat, .csv)"),
        arg("--dt-lumped", type=SECONDS, metavar="S", help="lumped RK4 step (default: derived)"),
        arg("--dt-mujoco", type=SECONDS, metavar="S", help="MuJoCo step (default: derived)"),
        arg("--tolerances", type=PATH, metavar="FILE", help="TOML file with a [tolerances] table"),
        arg("--sensor-band", type=HZ, nargs=2, metavar=("LOW", "HIGH"),
            help="accelerometer chain: band-pass both solvers' accelerations to LOW-HIGH Hz"),
        arg("--measurements", type=PATH, metavar="FILE", help="TOML file with [[measurements]]"),
        arg("--baseline", type=str, metavar="FILE", nargs="?", const="shipped",
            help="compare with a stored baseline (without FILE: the shipped one of the preset)"),
        arg("--update-baseline", action="store_true", help="rewrite the baseline instead of checking it"),
        arg("--junit", type=PATH, metavar="FILE",
            help="also write the verdicts as JUnit XML: a testcase per gated quantity and mode, for any CI"),
        arg("--no-figures", dest="figures", action="store_false",
            help="reports without figures (a third of a cross-check's time): the numbers, verdicts and JUnit "
                 "are the same"),
        arg("--history", type=PATH, metavar="STORE",
            help="append each run's metrics, versions and wall times to this history store (SQLite), one record per "
                 "commit and train (a rerun replaces it); draw it with `gearcheck dashboard`"),
        arg("--commit", metavar="SHA",
            help="the commit --history records (default: $GITHUB_SHA, else `git rev-parse HEAD` here)"),
        *PROFILES,
        arg("--out", type=PATH, default=Path("out"), metavar="DIR", help="output directory (default out/)"),
    ),
    "calibrate": Command(
        cmd_calibrate, "least-squares fit of train-file parameters to measured amplitudes and natural frequencies, "
                       "from several starts",
        TRAIN,
        arg("--fit", action="append", required=True, metavar="PATH[=LOW:HIGH]",
            help="a train-file field in its own units, e.g. stages[0].mesh.ste[0].amplitude_um=0.05:20"),
        arg("--measurements", type=PATH, metavar="FILE",
            help="TOML file with [[measurements]] (amplitudes) and [[natural_frequencies]] (default: the train "
                 "file's [[measurements]])"),
        arg("--fit-speed", type=RPM, action="append", metavar="RPM",
            help="use only the amplitudes at this speed for the fit; the others are predicted"),
        arg("--starts", type=int, metavar="N",
            help="starting points of the fit: the file's values and a Latin hypercube in ln p within the bounds "
                 "(default 16 when every measurement is a natural frequency, 1 when amplitudes need time runs)"),
        arg("--duration", type=SECONDS, default=0.6, metavar="S", help="simulated time per run (default 0.6 s)"),
        arg("--out", type=PATH, default=Path("out"), metavar="DIR", help="output directory (default out/)"),
    ),
    "sweep": Command(
        cmd_sweep, "speed sweeps, parameter studies and Monte Carlo: many runs reduced to one Parquet table of "
                   "mesh-harmonic amplitudes with order plots; cached points, local processes or a Dask cluster",
        TRAIN,
        arg("--speeds", metavar="A:B:N|V,V,...",
            help="input speeds in rpm: N from A to B, or a list (default: the train file's)"),
        arg("--set", action="append", default=[], metavar="FIELD=V,V,...",
            help="a parameter study: values of a train-file field in its own units, or FIELD=A:B:N (repeatable: the "
                 "grid over all), e.g. stages[0].mesh.ste[0].amplitude_um=5,10,20"),
        arg("--vary", action="append", default=[], metavar="FIELD=DIST",
            help="Monte Carlo: a field's distribution, normal(mean,sd), uniform(low,high) or "
                 "lognormal(median,factor) (repeatable)"),
        arg("--distributions", type=PATH, metavar="FILE",
            help="Monte Carlo: a TOML file with a [distributions] table, \"FIELD\" = \"normal(mean, sd)\""),
        arg("--samples", type=int, metavar="N", help="Monte Carlo draws (default 32)"),
        arg("--seed", type=int, default=0, metavar="S", help="Monte Carlo seed (default 0)"),
        arg("--solver", choices=SOLVERS + ("both",), default="both"),
        arg("--duration", type=SECONDS, default=0.5, metavar="S",
            help="simulated time of a run from the static state, the longest a continued point runs (default 0.5 s)"),
        arg("--harmonics", type=int, default=3, metavar="N", help="mesh harmonics per mesh frequency (default 3)"),
        arg("--integration-check", choices=("subset", "all", "none"), default="subset",
            help="which points run each solver a second time at twice the step, for each line's integration error: "
                 "every 8th speed, every point with a line in the half-power band of a mode it drives and every "
                 "point where a contact that can part unloads: a mesh with backlash or tip relief, a cycloid "
                 "disc's pins (subset, the default), all, or none"),
        arg("--no-integration-check", dest="integration_check", action="store_const", const="none",
            help="the same as --integration-check none (every line then counts)"),
        arg("--no-continuation", dest="continuation", action="store_false",
            help="start every point from the static state, not from the final state of the point at the "
                 "neighbouring speed"),
        arg("--refine", type=int, default=1, metavar="N",
            help="divide each solver's default step by N (default 1), for lines whose integration error estimate is "
                 "too large to read them; the work grows N times"),
        arg("--workers", type=int, metavar="N",
            help="local worker processes (default: the cores available; 1 runs in this process)"),
        arg("--scheduler", metavar="ADDRESS",
            help="run the points on a Dask distributed cluster, e.g. tcp://scheduler.example.org:8786"),
        arg("--cache", type=PATH, metavar="DIR",
            help="finished points, one Parquet file per input hash: a rerun skips them (default OUT.cache)"),
        arg("--no-cache", action="store_true", help="keep no cache"),
        arg("--quantity", action="append", metavar="NAME",
            help="a quantity to plot (repeatable; default: carrier and ring accelerations and the first sun and ring "
                 "mesh forces of each stage)"),
        arg("--out", type=PATH, default=Path("out/sweep"), metavar="DIR",
            help="writes sweep.parquet, sweep.json and the figures (default out/sweep)"),
    ),
    "runup": Command(
        cmd_runup, "run the train up through a speed range in both solvers and track the mesh orders (order curves, "
                   "waterfall; against a stepped sweep's table with --against)",
        TRAIN,
        arg("--from", dest="start", type=RPM, required=True, metavar="RPM", help="start speed (steady state there)"),
        arg("--to", dest="stop", type=RPM, required=True, metavar="RPM", help="end speed"),
        arg("--duration", type=SECONDS, required=True, metavar="S", help="time of the linear ramp"),
        arg("--solver", choices=("lumped", "mujoco", "both"), default="both"),
        arg("--quantity", action="append", metavar="NAME", help="a gated quantity to track (repeatable; default all)"),
        arg("--harmonics", type=int, default=3, metavar="N", help="mesh harmonics tracked per mesh frequency"),
        arg("--output-dt", type=SECONDS, metavar="S",
            help="sampling of the runs (default: twice what the orders need; near the step for a train whose mesh "
                 "stiffness switches, to read its orders to a stepped sweep's accuracy)"),
        arg("--against", type=PATH, metavar="SWEEP.parquet",
            help="a stepped sweep's table (gearcheck sweep) to compare the lumped order curves with"),
        arg("--out", type=PATH, default=Path("out/runup"), metavar="DIR", help="output directory (default out/runup)"),
    ),
    "sensitivity": Command(
        cmd_sensitivity, "derivatives of the steady harmonic response to train-file numbers (closed form, checked by "
                         "finite differences; maps over speed)",
        TRAIN,
        arg("--parameter", action="append", required=True, metavar="PATH",
            help="a number of the train file, e.g. stages[0].crank.eccentricity_mm (repeatable)"),
        arg("--coordinate", metavar="NAME",
            help="the coordinate whose harmonics are reported (default: the output's rotation, e.g. "
                 "rv.carrier.theta)"),
        arg("--method", choices=("hb", "fourier"), default="fourier",
            help="harmonic balance, or the paper's Fourier-series method (default; shows its Eq. 15 beside)"),
        arg("--orders", type=int, nargs="+", metavar="H",
            help="harmonics kept per clock (mesh, then an RV reducer's eccentrics), default 3 2"),
        arg("--speeds", type=SPEED_RANGE, metavar="A:B:N",
            help="a map over input speeds (rpm) instead of the train's speed"),
        arg("--values", type=float, nargs="+", metavar="V",
            help="the sensitivity against the one --parameter set to each value (the file's unit), at the train's "
                 "speed or each of --speeds (Yang, Chen & Wang 2018, Figs. 6, 8, 10: sensitivity_values.png up to "
                 "4 speeds); over 3 or more --speeds also the family of curves over the mesh frequency, one per value "
                 "(Figs. 5, 7, 9: sensitivity_family.png)"),
        arg("--out", type=PATH, default=Path("out"), metavar="DIR", help="output directory (default out/)"),
    ),
    "pins": Command(
        cmd_pins, "an RV reducer's static pin loads over a pin pitch or an eccentric turn (PNG)",
        TRAIN,
        arg("--span", choices=("pitch", "turn"), default="pitch",
            help="frozen configurations over one pin pitch (default) or a whole turn of the eccentrics"),
        arg("--samples", type=int, default=16, metavar="N", help="frozen times (default 16)"),
        arg("-o", "--output", type=PATH, metavar="FILE", help="PNG file (default out/TRAIN-pins.png)"),
    ),
    "stiffness": Command(
        cmd_stiffness, "plot the mesh stiffness over the mesh cycle (PNG)",
        TRAIN,
        arg("-o", "--output", type=PATH, metavar="FILE", help="PNG file (default out/TRAIN-stiffness.png)"),
    ),
    "animate": Command(
        cmd_animate, "render the MuJoCo twin running (or a mode shape) offscreen as a GIF or MP4, vibration "
                     "magnified, with time and mesh-force overlays",
        TRAIN,
        arg("-o", "--output", type=PATH, required=True, metavar="FILE", help="the .gif (or .mp4, with ffmpeg)"),
        arg("--duration", type=SECONDS, default=4.0, metavar="S", help="playback length (default 4 s)"),
        arg("--fps", type=float, default=15.0, metavar="N", help="frames per second (default 15)"),
        arg("--slow-motion", type=float, default=100.0, metavar="X",
            help="playback time per simulated time (default 100: 4 s show 40 ms)"),
        arg("--magnify", type=float, default=1000.0, metavar="X",
            help="vibration displacements (from the rigid-body motion) times X (default 1000)"),
        arg("--mode", type=int, metavar="K", help="animate mode shape K (1-based) instead of the running train"),
        arg("--solver", choices=("mujoco", "lumped"), default="mujoco", help="whose mode shape (--mode)"),
        arg("--size", type=int, nargs=2, default=(480, 360), metavar=("W", "H"), help="pixels (480 360)"),
    ),
    "view": Command(
        cmd_view, "the MuJoCo viewer with the twin running live (needs a display)",
        TRAIN,
        arg("--slow-motion", type=float, default=100.0, metavar="X", help="wall time per simulated time"),
        arg("--magnify", type=float, default=1000.0, metavar="X", help="vibration displacements times X"),
    ),
    "dashboard": Command(
        cmd_dashboard, "draw a history store as a static site: each metric over commits with its tolerance and "
                       "change points, wall times, what changed last",
        arg("store", type=PATH, metavar="STORE", help="the history store (crosscheck --history)"),
        arg("-o", "--output", type=PATH, default=Path("site"), metavar="DIR",
            help="the site's folder (default site/); open DIR/index.html"),
    ),
    "export": Command(
        cmd_export, "write the reference lumped model as a file of matrices (.mat or .npz): the layout --model "
                    "reads, with every convention of gearcheck's coordinates",
        TRAIN,
        arg("-o", "--output", type=PATH, required=True, metavar="FILE", help="output .mat or .npz file"),
    ),
    "mjcf": Command(
        cmd_mjcf, "write the MuJoCo model (MJCF) of a train",
        TRAIN,
        arg("-o", "--output", type=PATH, metavar="FILE", help="output file (default: standard output)"),
    ),
}


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
