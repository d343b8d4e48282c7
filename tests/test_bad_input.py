"""Bad input of every kind, as a new user and a hostile one would give it: train files with numbers
past every bound and geometry no gear has, broken files, command-line options out of range, output
places that cannot be written.  Every case must end in exit status 2 with one line on stderr that names
the file, field or option and the value, no traceback, and nothing written."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from gearcheck.cli import main
from gearcheck.train.loader import preset_text

DEMO = preset_text("demo-3p")
TABLE3 = Path(__file__).parents[1] / "src" / "gearcheck" / "train" / "presets" / "data" / "rv-reducer-table3.toml"


def demo(*pairs) -> str:
    """demo-3p's text with (regex, replacement) edits, each of which must match."""
    text = DEMO
    for old, new in pairs:
        assert re.search(old, text, flags=re.M), old
        text = re.sub(old, new, text, count=1, flags=re.M)
    return text


def gears(sun, planet, ring, *extra) -> str:
    """demo-3p with other tooth counts (the planet's line first: its count may equal the sun's new one)."""
    return demo((r"^teeth = 20", f"teeth = {planet}"), (r"^teeth = 22", f"teeth = {sun}"),
                (r"^teeth = 62 .*", f"teeth = {ring}"), *extra)


# (id, train file text, expected fragment of the one line): train files, numbers past their bounds
NUMBERS = [
    ("module-1e300", demo((r"^module_mm = 3.0", "module_mm = 1e300")), "stages[0].module_mm: must be <= 100 mm"),
    ("module-tiny", demo((r"^module_mm = 3.0", "module_mm = 1e-300")), "stages[0].module_mm: must be >= 0.01 mm"),
    ("teeth-1e300", demo((r"^teeth = 22", "teeth = 1e300")), "stages[0].sun.teeth: must be an integer, got 1e+300"),
    ("teeth-float", demo((r"^teeth = 22", "teeth = 22.0")), "stages[0].sun.teeth: must be an integer, got 22.0"),
    ("teeth-huge-int", demo((r"^teeth = 22", "teeth = 100000")), "must be an integer <= 1000, got 100000"),
    ("planets-1e9", demo((r"^planets = 3", "planets = 1000000000")), "stages[0].planets: must be an integer <= 32"),
    ("planets-float", demo((r"^planets = 3", "planets = 2.5")), "stages[0].planets: must be an integer, got 2.5"),
    ("speed-1e300", demo((r"^input_speed_rpm = .*", "input_speed_rpm = 1e300")),
     "operating.input_speed_rpm: must be <= 1e+06 rpm"),
    ("speed-pitch-line", demo((r"^input_speed_rpm = .*", "input_speed_rpm = 200000.0")),
     "operating.input_speed_rpm: the stage1.sun mesh would run at a pitch-line speed of"),
    ("speed-minus-inf", demo((r"^input_speed_rpm = .*", "input_speed_rpm = -inf")),
     "operating.input_speed_rpm: must be finite, got -inf"),
    ("speed-nan", demo((r"^input_speed_rpm = .*", "input_speed_rpm = nan")), "must be finite, got nan"),
    ("mass-1e-300", demo((r"^mass = 0.9757", "mass = 1e-300")), "stages[0].sun.mass: must be >= 1e-09 kg"),
    ("mass-1e300", demo((r"^mass = 0.9757", "mass = 1e300")), "stages[0].sun.mass: must be <= 1e+06 kg"),
    ("mass-string", demo((r"^mass = 0.9757", 'mass = "heavy"')), "stages[0].sun.mass: must be a number, got 'heavy'"),
    ("mass-boolean", demo((r"^mass = 0.9757", "mass = true")), "stages[0].sun.mass: must be a number, got True"),
    ("inertia-1e300", demo((r"^inertia = 5.802e-4", "inertia = 1e300")), "stages[0].sun.inertia: must be <= 1e+08"),
    ("mesh-stiffness-1e300", demo((r"mean = 8.0e8", "mean = 1e300")),
     "stages[0].mesh.stiffness.mean: must be <= 1e+18 N/m"),
    ("support-negative", demo((r"radial_stiffness = 1.0e8", "radial_stiffness = -1e300")),
     "stages[0].sun.support.radial_stiffness: must be > 0 N/m"),
    ("damping-ratio-20", demo((r"damping = \{ ratio = 0.05 \}", "damping = { ratio = 20.0 }")),
     "stages[0].mesh.damping.ratio: must be <= 1, got 20"),
    ("torque-1e300", demo((r"^output_torque = .*", "output_torque = 1e300")),
     "operating.output_torque: must be <= 1e+09 N·m"),
    ("shaft-1e300", demo((r"^input_shaft_stiffness = .*", "input_shaft_stiffness = 1e300")),
     "operating.input_shaft_stiffness: must be <= 1e+18"),
    ("backlash-1e300", demo((r"^damping = \{ ratio = 0.05 \}", "damping = { ratio = 0.05 }\nbacklash_um = 1e300")),
     "stages[0].mesh.backlash_um: must be <= 10000 µm"),
    ("backlash-over-half-module", demo((r"^damping = \{ ratio = 0.05 \}",
                                        "damping = { ratio = 0.05 }\nbacklash_um = 2000.0")),
     "stages[0].sun.mesh.backlash_um: backlash 2000 µm is over 0.5 of the module 3 mm"),
    ("ste-1e6", demo((r"^damping = \{ ratio = 0.05 \}",
                      "damping = { ratio = 0.05 }\nste = [{ harmonic = 1, amplitude_um = 1e6 }]")),
     "stages[0].mesh.ste[0].amplitude_um: must be <= 10000 µm"),
    ("ste-over-module", demo((r"^damping = \{ ratio = 0.05 \}",
                              "damping = { ratio = 0.05 }\nste = [{ harmonic = 1, amplitude_um = 500.0 }]")),
     "stages[0].sun.mesh.ste[0].amplitude_um: transmission error amplitude 500 µm is over 0.1 of the module"),
    ("ste-harmonic-zero", demo((r"^damping = \{ ratio = 0.05 \}",
                                "damping = { ratio = 0.05 }\nste = [{ harmonic = 0, amplitude_um = 1.0 }]")),
     "stages[0].mesh.ste[0].harmonic: must be an integer >= 1, got 0"),
    ("eccentricity-over-module", demo((r"^teeth = 22", "teeth = 22\neccentricity_um = 1000.0")),
     "stages[0].sun.eccentricity_um: eccentricity 1000 µm is over 0.1 of the module"),
    ("face-width-tiny", demo((r"^face_width_mm = 40.0", "face_width_mm = 1e-300")),
     "stages[0].face_width_mm: must be >= 0.01 mm"),
    ("pressure-angle-zero", demo((r"^pressure_angle_deg = 20.0", "pressure_angle_deg = 0.0")),
     "stages[0].pressure_angle_deg: must be > 0 deg"),
    ("planet-angle-1e300", demo((r"^planets = 3", "planets = 3\nplanet_angles_deg = [0.0, 1e300, 240.0]")),
     "stages[0].planet_angles_deg[1]: must be <= 3600 deg"),
    ("ripple-1e300", demo((r"^input_shaft_damping = .*",
                           "input_shaft_damping = 2.0\n"
                           "ripple = [{ member = \"output\", order = 3.0, amplitude = 1e300 }]")),
     "operating.ripple[0].amplitude: must be <= 100"),
    ("ramp-1e300", demo((r"^input_shaft_damping = .*", "input_shaft_damping = 2.0\nramp_s = 1e300")),
     "operating.ramp_s: must be <= 10000 s"),
    ("slices-1e9", demo((r'stiffness = \{ model = "rectangular", mean = 8.0e8 \}',
                         'stiffness = { model = "energy", slices = 1000000000 }')),
     "stages[0].mesh.stiffness.slices: must be an integer <= 10000"),
    ("youngs-1e300", demo((r'stiffness = \{ model = "rectangular", mean = 8.0e8 \}',
                           'stiffness = { model = "energy", youngs_modulus = 1e300 }')),
     "stages[0].mesh.stiffness.youngs_modulus: must be <= 1e+13 Pa"),
    ("tolerance-1e300", demo((r"^\[\[stages\]\]", "[tolerances]\nmesh_force.nrmse = 1e300\n\n[[stages]]")),
     "tolerances.mesh_force.nrmse: must be a positive number up to 1e+06"),
]

# impossible geometry that a schema cannot see
GEOMETRY = [
    ("tip-interference-9-27-63", gears(9, 27, 63), "stages[0].sun.teeth: undercut: 9 teeth"),
    ("pointed-teeth-44-deg", demo((r"^pressure_angle_deg = 20.0", "pressure_angle_deg = 44.0")), "pointed teeth"),
    ("pointed-teeth-shift", demo((r"^teeth = 22", "teeth = 22\nprofile_shift = 2.5")),
     "stages[0].sun.addendum_coefficient: pointed teeth"),
    ("ring-tip-inside-base", demo((r"^teeth = 62 .*", "teeth = 62\naddendum_coefficient = 3.0")),
     "stages[0].ring.addendum_coefficient: tip circle r_a = 84 mm lies inside the base circle"),
    ("pressure-angle-7-deg", demo((r"^pressure_angle_deg = 20.0", "pressure_angle_deg = 7.0")),
     "stages[0].planet.teeth: undercut: 20 teeth at 7 deg"),
    ("undercut-14", gears(14, 24, 62), "stages[0].sun.teeth: undercut: 14 teeth"),
    ("undercut-negative-shift", demo((r"^teeth = 20", "teeth = 20\nprofile_shift = -0.5")),
     "stages[0].planet.teeth: undercut"),
    ("contact-ratio-low", demo((r"^face_width_mm = 40.0", "face_width_mm = 40.0\naddendum_coefficient = 0.4")),
     "transverse contact ratio"),
    ("tip-hits-root", demo((r"^teeth = 22", "teeth = 22\naddendum_coefficient = 1.1"),
                           (r"^teeth = 20", "teeth = 20\ndedendum_coefficient = 1.0")),
     "stages[0].sun.teeth: meshing sun with the planet: the sun tip hits the mate's root circle"),
    ("ring-as-small-as-planet", gears(20, 20, 20), "stages[0].ring"),
    ("base-radius-too-big", demo((r"^teeth = 22", "teeth = 22\nbase_radius_mm = 40.0")),
     "stages[0].sun.base_radius_mm: base radius 40 mm does not fit the pitch radius 33 mm"),
    ("base-pitches-disagree", demo((r"^teeth = 62", "teeth = 62\nbase_radius_mm = 88.0")),
     "stages[0].ring.base_radius_mm: meshing ring with the planet: base pitch 8.91807 mm, planet gear planet's "
     "8.85639 mm: gears in mesh share one base pitch"),
    ("ring-internal-interference", gears(22, 20, 62, (r"^teeth = 62$", "teeth = 62\naddendum_coefficient = 1.3")),
     "involute interference"),
]

# the structure of a train and its files
STRUCTURE = [
    ("held-twice", demo((r'^held = .*', 'held = ["stage1.ring", "stage1.ring"]')),
     "train.held[1]: stage1.ring is held twice"),
    ("torque-function-untrusted", demo((r"^input_shaft_damping = .*",
                                        'input_shaft_damping = 2.0\ntorque_function = "math:ldexp"')),
     "operating.torque_function: 'math:ldexp' is Python code named by a train file, which is data and runs no code "
     "unless you allow it: --trust math"),
    ("coupling-to-a-planet", demo((r"\Z", '\n[[couplings]]\nname = "c"\nfrom = "stage1.planet1"\nto = "stage1.sun"\n'
                                          "torsional_stiffness = 1e6\n")),
     "couplings[0].from: stage1.planet1 is a planet"),
    ("empty-file", "", "train: missing required field"),
    ("duplicate-key", DEMO.replace("planets = 3", "planets = 3\nplanets = 4"), "not valid TOML"),
    ("deeply-nested", "x = " + "[" * 100_000 + "]" * 100_000 + "\n", "not valid TOML: nested too deeply"),
    ("unknown-reference", demo((r'^source = .*', 'source = "x"\nreferences = ["lin-parker-1998"]')),
     "train.references[0]: must be one of"),
    ("measurements-file-missing", demo((r'^held = .*', 'held = ["stage1.ring"]\nmeasurements_file = "none.toml"')),
     "train.measurements_file: "),
    ("torque-csv-missing", demo((r"^input_shaft_damping = .*", 'input_shaft_damping = 2.0\ntorque_csv = "none.csv"')),
     "operating.torque_csv: "),
    ("tolerance-unknown-kind", demo((r"^\[\[stages\]\]", "[tolerances]\nmesh_forse.nrmse = 0.01\n\n[[stages]]")),
     "tolerance 'mesh_forse.nrmse': 'mesh_forse' is neither a kind nor a compared quantity "
     "(did you mean 'mesh_force'?)"),
    ("tolerance-unknown-metric", demo((r"^\[\[stages\]\]", "[tolerances]\nmesh_force.rms = 0.01\n\n[[stages]]")),
     "tolerance 'mesh_force.rms': the metric must be one of nrmse, rel_error"),
    ("measurement-unknown-quantity", demo((r"\Z", '\n[[measurements]]\nquantity = "stage1.ring.az.world"\n'
                                                  'metric = "peak"\nvalue = 1.0\n')),
     "measurement of 'stage1.ring.az.world': no such compared quantity (did you mean 'stage1.ring.a"),
    ("measurement-band-reversed", demo((r"\Z", '\n[[measurements]]\nquantity = "stage1.ring.ax.world"\n'
                                               'metric = "peak"\nvalue = 1.0\nsensor_band_hz = [5000.0, 5.0]\n')),
     "measurements[0].sensor_band_hz: must increase"),
]


def coupling_between_speeds() -> str:
    from gearcheck.train.variants import chained_text

    return chained_text(2) + ('\n[[couplings]]\nname = "locks"\nfrom = "stage1.sun"\nto = "stage2.sun"\n'
                              "torsional_stiffness = 1e6\n")


CASES = NUMBERS + GEOMETRY + STRUCTURE + [
    ("coupling-between-speeds", coupling_between_speeds(),
     "couplings: the train is locked: spline1 (couplings[0]) joins stage1.carrier and stage2.sun, which turn at "
     "392.857 and 1500 rpm without it; locks (couplings[1]) joins stage1.sun and stage2.sun, which turn at 1500 and "
     "392.857 rpm without it"),
]


def assert_refused(argv, expected, capsys, out: Path):
    assert main([str(a) for a in argv]) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("gearcheck: error: ") and "Traceback" not in captured.err
    assert expected in lines[0], lines[0]
    assert not out.exists(), "something was written"
    assert not [p for p in out.parent.iterdir() if p.name.startswith(f".{out.name}.")], "a partial output was left"


@pytest.mark.parametrize("text, expected", [case[1:] for case in CASES], ids=[case[0] for case in CASES])
def test_a_bad_train_file_is_refused_with_one_line(text, expected, tmp_path, capsys):
    path = tmp_path / "train.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    assert_refused(["crosscheck", path, "--duration", "0.01", "--out", out], expected, capsys, out)


def test_the_line_names_the_file(tmp_path, capsys):
    path = tmp_path / "train.toml"
    path.write_text(demo((r"^mass = 0.9757", "mass = 1e300")), encoding="utf-8")
    assert main(["show", str(path)]) == 2
    assert capsys.readouterr().err.startswith(f"gearcheck: error: {path}: stages[0].sun.mass: ")


def raw_file(name: str, data: bytes):
    def make(tmp: Path) -> Path:
        (tmp / name).write_bytes(data)
        return tmp / name
    return make


FILES = [
    ("train-not-utf8", raw_file("t.toml", DEMO.replace("Single-stage", "Einstufiges \xfcber").encode("latin-1")),
     lambda f: ["show", f], "the train file is not UTF-8 text (byte"),
    ("train-binary", raw_file("t.toml", bytes(range(256)) * 4), lambda f: ["show", f], "not UTF-8"),
    ("train-is-a-folder", lambda tmp: tmp, lambda f: ["show", f], "is a directory, not a train file"),
    ("train-missing", lambda tmp: tmp / "none.toml", lambda f: ["show", f], "no such train file or preset"),
    ("train-too-large", raw_file("t.toml", b"# " + b"x" * (17 * 2**20) + b"\n"), lambda f: ["show", f],
     "MiB is too large for a train file (at most 16 MiB)"),
    ("measurements-not-utf8", raw_file("m.toml", b'[[measurements]]\nquantity = "\xff"\n'),
     lambda f: ["crosscheck", "demo-3p", "--measurements", f], "the measurements file is not UTF-8 text"),
    ("measurements-not-toml", raw_file("m.toml", b"[[measurements]\n"),
     lambda f: ["crosscheck", "demo-3p", "--measurements", f], "not valid TOML"),
    ("measurements-wrong-metric", raw_file("m.toml", b'[[measurements]]\nquantity = "stage1.ring.ay.world"\n'
                                                     b'metric = "median"\nvalue = 1.0\n'),
     lambda f: ["crosscheck", "demo-3p", "--measurements", f], "measurements[0].metric: must be one of peak"),
    ("measurements-empty", raw_file("m.toml", b""),
     lambda f: ["crosscheck", "demo-3p", "--measurements", f], "measurements: missing required field"),
    ("tolerances-extra-table", raw_file("t.toml", b"[tolerances]\nmesh_force.nrmse = 0.1\n[other]\nx = 1\n"),
     lambda f: ["crosscheck", "demo-3p", "--tolerances", f], "expected a single [tolerances] table"),
    ("tolerances-not-utf8", raw_file("t.toml", b"[tolerances]\n# \xfe\n"),
     lambda f: ["crosscheck", "demo-3p", "--tolerances", f], "the tolerances file is not UTF-8 text"),
    ("baseline-not-json", raw_file("b.json", b"{"), lambda f: ["crosscheck", "demo-3p", "--baseline", f],
     "the baseline is not JSON"),
    ("baseline-a-list", raw_file("b.json", b"[1, 2]"), lambda f: ["crosscheck", "demo-3p", "--baseline", f],
     "not a gearcheck baseline of version 2 or 1 (found 'list')"),
    ("baseline-truncated", raw_file("b.json", b'{"baseline_version": 1, "train": "demo-3p", "duration_s": 0.05}'),
     lambda f: ["crosscheck", "demo-3p", "--baseline", f], "not a valid baseline: input_speed_rpm missing"),
    ("torque-csv-not-numbers", raw_file("p.csv", b"time,torque\n0,a\n1,b\n"),
     lambda f: ["show", _train_with(f, 'torque_csv = "p.csv"')], "operating.torque_csv:"),
    ("torque-csv-one-row", raw_file("p.csv", b"0,1\n"),
     lambda f: ["show", _train_with(f, 'torque_csv = "p.csv"')],
     "needs two columns (time, torque) and at least two rows"),
    ("torque-csv-time-backwards", raw_file("p.csv", b"0,1\n1,2\n0.5,3\n"),
     lambda f: ["show", _train_with(f, 'torque_csv = "p.csv"')], "times must increase strictly"),
    ("measurements-file-not-utf8", raw_file("m.toml", b"\xff\xfe"),
     lambda f: ["show", _train_with(f, "", 'measurements_file = "m.toml"')], "train.measurements_file:"),
    *[(f"natural-frequency-{name}", raw_file("m.toml", b"[[natural_frequencies]]\n" + entry),
       lambda f: ["calibrate", "rv-reducer", "--fit", "stages[0].carrier.inertia", "--measurements", f],
       f"m.toml: natural_frequencies[0]{expected}")
      for name, entry, expected in [
          ("past-the-modes", b"frequency_hz = 150.0\nmode = 40\n", ".mode: 40 but the model has 30 modes"),
          ("no-such-coordinate", b'frequency_hz = 150.0\nshape = { "rv.sun.thta" = 1.0 }\n',
           ".shape: the model has no coordinate 'rv.sun.thta' (did you mean 'rv.sun.theta'?)"),
          ("zero-shape", b'frequency_hz = 150.0\nshape = { "rv.sun.theta" = 0.0 }\n', ".shape: is zero everywhere"),
          ("two-pairings", b'frequency_hz = 150.0\nmode = 1\ntype = "mixed"\n',
           ".mode: 1 pairs by number, type by type and order: give one"),
          ("order-without-type", b"frequency_hz = 150.0\norder = 2\n", ".order: 2 counts within a type: give type"),
          ("unpaired", b"frequency_hz = 150.0\n", ": needs mode, type (with order) or shape"),
          ("no-such-type", b'frequency_hz = 150.0\ntype = "rotatonal"\n',
           ".type: must be one of rotational, translational, planet, mixed, elastic; got 'rotatonal'"),
          ("past-the-type", b'frequency_hz = 150.0\ntype = "translational"\norder = 20\n',
           ".order: 20 but the model has 18 translational frequencies"),
          ("negative", b"frequency_hz = -150.0\nmode = 1\n", ".frequency_hz: must be > 0 Hz, got -150"),
          ("bad-role", b'frequency_hz = 150.0\nmode = 1\nrole = "check"\n',
           ".role: must be one of fit, predict; got 'check'")]],
    ("natural-frequency-only-predicted", raw_file("m.toml", b'[[natural_frequencies]]\nfrequency_hz = 150.0\n'
                                                            b'mode = 1\nrole = "predict"\n'),
     lambda f: ["calibrate", "rv-reducer", "--fit", "stages[0].carrier.inertia", "--measurements", f],
     "nothing to fit: every natural frequency has role = 'predict'"),
]


def _train_with(data_file: Path, operating: str, train: str = "") -> Path:
    """A demo-3p train file next to ``data_file`` with a line added to [operating] and/or [train]."""
    text = demo((r"^input_shaft_damping = .*", f"input_shaft_damping = 2.0\n{operating}"),
                (r'^held = .*', f'held = ["stage1.ring"]\n{train}'))
    path = data_file.parent / "train.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("make, argv, expected", [case[1:] for case in FILES], ids=[case[0] for case in FILES])
def test_a_bad_file_is_refused_with_one_line(make, argv, expected, tmp_path, capsys):
    (tmp_path / "data").mkdir()
    out = tmp_path / "out"
    command = argv(make(tmp_path / "data"))
    assert_refused(command + (["--out", out] if command[0] in ("crosscheck", "calibrate") else []), expected, capsys,
                   out)


OPTIONS = [
    (["run", "demo-3p", "--duration", "1e9"], "steps, more than the 2e+08 gearcheck runs in one go"),
    (["run", "demo-3p", "--dt", "1e-15"], "steps, more than the 2e+08 gearcheck runs in one go"),
    (["run", "hub-drive", "--duration", "100"], "GiB of series of the lumped model of hub-drive"),
    (["run", "demo-3p", "--output-dt", "1e308"], "--output-dt 1e+308: a sampling interval longer than the duration"),
    (["run", "demo-3p", "--output-dt", "-1"], "argument --output-dt: must be a positive number of seconds, got -1"),
    (["run", "demo-3p", "--dt", "-1e-6"], "argument --dt: must be a positive number of seconds, got -1e-6"),
    (["run", "demo-3p", "--dt", "1e-3"], "time step 0.001 s is unstable for the lumped model of demo-3p"),
    (["run", "demo-3p", "--solver", "mujoco", "--dt", "1e-3"], "is unstable for the MuJoCo model of demo-3p"),
    (["run", "demo-3p", "--duration", "0"], "argument --duration: must be a positive number of seconds, got 0"),
    (["run", "demo-3p", "--duration", "nan"], "argument --duration: must be a positive number of seconds, got nan"),
    (["run", "demo-3p", "--duration", "-inf"], "argument --duration: must be a positive number of seconds, got -inf"),
    (["run", "demo-3p", "--duration", "ten"], "argument --duration: must be a number of seconds, got 'ten'"),
    (["run", "demo-3p", "--speed", "0"], "argument --speed: must be a positive number of rpm, got 0"),
    (["run", "demo-3p", "--speed", "-5"], "argument --speed: must be a positive number of rpm, got -5"),
    (["run", "demo-3p", "--speed", "inf"], "argument --speed: must be a positive number of rpm, got inf"),
    (["run", "demo-3p", "--speed", "1e300"], "speed must be <= 1e+06 rpm, got 1e+300"),
    (["run", "demo-3p", "--speed", "500000"], "speed 500000 rpm for demo-3p: the stage1.sun mesh would run at"),
    (["run", "demo-3p", "--method", "Euler"], "unknown method 'Euler'"),
    (["run", "demo-3p", "--solver", "mujoco", "--method", "RK45"], "method 'RK45' applies to the lumped solver only"),
    (["run", "demo-3p", "--solver", "abaqus"], "argument --solver: invalid choice: 'abaqus'"),
    (["run", "demo-3p", "--frobnicate"], "unrecognized arguments: --frobnicate"),
    (["show"], "the following arguments are required: TRAIN"),
    (["bake", "demo-3p"], "argument command: invalid choice: 'bake'"),
    (["crosscheck"], "give TRAIN (one or more) or --all, not both"),
    (["crosscheck", "demo-3p", "--all"], "give TRAIN (one or more) or --all, not both"),
    (["crosscheck", "--all", "--speed", "100"], "--speed applies to one train"),
    (["crosscheck", "demo-3p", "--model", "as-printed"], "unknown model 'as-printed': choose one of general"),
    (["crosscheck", "demo-3p", "--model", "as-published"], "demo-3p: the 4-DOF model needs the carrier as input"),
    (["crosscheck", "demo-3p", "--sensor-band", "1000", "100"], "sensor band 1000 100 Hz: needs 0 < LOW < HIGH"),
    (["crosscheck", "demo-3p", "--sensor-band", "-5", "100"],
     "argument --sensor-band: must be a positive number of Hz"),
    (["crosscheck", "demo-3p", "--dt-lumped", "1"], "time step 1 s is unstable for the lumped model of demo-3p"),
    (["crosscheck", "demo-3p", "--duration", "0.02", "--baseline"],
     "baseline of demo-3p was taken at 1500 rpm over 0.05 s"),
    (["crosscheck", "demo-3p", "--tolerances", "none.toml"], "none.toml: no such tolerances file"),
    (["crosscheck", "no-such-train"], "no-such-train: no such train file or preset"),
    (["show", "demo3p"], "demo3p: no such train file or preset (did you mean 'demo-3p'?)"),
    (["calibrate", "demo-3p", "--fit", "stages[0].mass"], "calibrate needs measurements"),
    (["calibrate", "hub-drive", "--fit", "stages[0].nothing"], "--fit stages[0].nothing: no such field"),
    (["calibrate", "hub-drive", "--fit", "stages[0].mesh.ste[0].amplitude_um=5:1"], "need 0 < LOW < HIGH"),
    (["calibrate", "hub-drive", "--fit", "x..y"], "--fit 'x..y': '' is not a key or key[index]"),
    (["calibrate", "hub-drive", "--fit", "operating.output_torque", "--fit-speed", "-606"],
     "argument --fit-speed: must be a positive number of rpm"),
    (["calibrate", "hub-drive", "--fit", "operating.output_torque", "--fit-speed", "700"],
     "no measurement at the fit speeds [700.0] rpm"),
    (["sensitivity", "rv-reducer", "--parameter", "stages[0].crank.nothing"],
     "--parameter stages[0].crank.nothing: no such field"),
    (["sensitivity", "demo-3p", "--parameter", "stages[0].sun.mass", "--orders", "3", "2"],
     "--orders (3, 2): give 1 whole non-negative number, one per clock of this train (mesh), not all 0"),
    (["sensitivity", "demo-3p", "--parameter", "stages[0].sun.mass", "--coordinate", "sun.x"],
     "--coordinate 'sun.x': not a coordinate of demo-3p"),
    (["sensitivity", "hub-drive", "--parameter", "stages[0].sun.mass"],
     "hub-drive: the harmonic methods solve a linear problem with constant load; this train has backlash"),
    (["sensitivity", "rv-reducer", "--parameter", "stages[0].sun.mass", "--speeds", "0:1000:3"],
     "--speeds: every speed must be a positive number of rpm, got 0"),
    (["calibrate", "rv-reducer", "--fit", "stages[0].carrier.inertia", "--measurements", TABLE3, "--starts", "0"],
     "--starts 0: must be a whole number from 1 to 1000"),
    (["pins", "demo-3p"], "demo-3p has no cycloid-pin stage"),
    (["pins", "rv-reducer", "--samples", "0"], "--samples 0: a whole number of frozen times from 1 to 10000"),
]


@pytest.mark.parametrize("argv, expected", OPTIONS,
                         ids=[" ".join(a[:4]) + f" #{i}" for i, (a, _) in enumerate(OPTIONS)])
def test_a_bad_option_is_refused_with_one_line(argv, expected, tmp_path, capsys):
    out = tmp_path / "out"
    assert_refused(argv + (["--out", str(out)] if argv[0] in ("run", "crosscheck", "calibrate", "sensitivity")
                           else ["-o", str(out)] if argv[0] == "pins" else []), expected, capsys, out)


def places(tmp: Path):
    (tmp / "file").write_text("not a folder")
    return {
        "out-is-a-file": (["run", "demo-3p", "--duration", "0.001", "--out", tmp / "file"],
                          f"--out {tmp / 'file'}: exists and is not a folder"),
        "out-under-a-file": (["crosscheck", "demo-3p", "--out", tmp / "file" / "sub"],
                             f"{tmp / 'file'} is a file, not a folder"),
        "out-not-writable": (["crosscheck", "demo-3p", "--out", "/proc/gearcheck-out"], "/proc is not writable"),
        "calibrate-out-under-a-file": (["calibrate", "hub-drive", "--fit", "operating.output_torque", "--out",
                                        tmp / "file" / "x"], "is a file, not a folder"),
        "mjcf-onto-a-folder": (["mjcf", "demo-3p", "-o", tmp], f"-o {tmp}: exists and is a folder"),
        "mjcf-under-a-file": (["mjcf", "demo-3p", "-o", tmp / "file" / "m.xml"], "is a file, not a folder"),
        "stiffness-not-writable": (["stiffness", "demo-3p", "-o", "/proc/gearcheck.png"], "/proc is not writable"),
    }


@pytest.mark.parametrize("case", ["out-is-a-file", "out-under-a-file", "out-not-writable", "calibrate-out-under-a-file",
                                  "mjcf-onto-a-folder", "mjcf-under-a-file", "stiffness-not-writable"])
def test_an_output_place_that_cannot_be_written_is_refused_before_any_work(case, tmp_path, capsys):
    argv, expected = places(tmp_path)[case]
    before = sorted(p.name for p in tmp_path.iterdir())
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and expected in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert (tmp_path / "file").read_text() == "not a folder"


def test_corpus_size():
    assert len(CASES) + len(FILES) + len(OPTIONS) + len(SHORT) + 7 >= 80


SHORT = [
    (["crosscheck", "demo-3p", "--duration", "1e-5"], "duration 1e-05 s is shorter than a cycle of 0.002463 s"),
    (["crosscheck", "double-planet", "--model", "as-published", "--duration", "1e-6"],
     "duration 1e-06 s is shorter than a cycle of 0.0003298 s"),
    (["calibrate", "hub-drive", "--fit", "operating.output_torque", "--duration", "0.001"],
     "duration 0.001 s is shorter than a cycle of the slowest mesh (0.03166 s)"),
]


@pytest.mark.parametrize("argv, expected", SHORT, ids=["crosscheck", "published", "calibrate"])
def test_a_run_too_short_to_compare_is_refused(argv, expected, tmp_path, capsys):
    out = tmp_path / "out"
    assert_refused(argv + ["--out", str(out)], expected, capsys, out)
