"""Property-based fuzzing of the other files a user hands gearcheck: a model file of matrices (the exported demo
model, its arrays replaced, reshaped, made complex, text or non-finite, removed or joined by unknown ones) and
another solver's recorded time series (a CSV, its cells and header mutated).  Each is either read and used or
refused with gearcheck's own one-line error; nothing else escapes.  Fixed seed, bounded examples."""

from __future__ import annotations

import numpy as np
import pandas as pd
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gearcheck
from gearcheck.compare.engine.recorded import read_time_series
from gearcheck.shared.errors import GearcheckError

SPEC = gearcheck.load("demo-3p")
OUTCOMES = {"used": 0, "refused": 0}


def tally(use) -> None:
    """Call ``use``: it works, or it is refused with gearcheck's own one-line error (counted in OUTCOMES); any
    other exception fails the test."""
    try:
        use()
        OUTCOMES["used"] += 1
    except GearcheckError as exc:
        assert "\n" not in str(exc)
        OUTCOMES["refused"] += 1


def _exported(tmp_path_factory) -> dict[str, np.ndarray]:
    path = tmp_path_factory.mktemp("model") / "demo.npz"
    gearcheck.export_model("demo-3p", path)
    with np.load(path) as archive:
        return {k: archive[k] for k in archive.files}


ARRAYS = st.one_of(
    st.sampled_from([np.array(np.nan), np.array(np.inf), np.array(-1.0), np.array(0.0), np.array(1e300),
                     np.array(["text"]), np.array([True, False]), np.zeros((0,)), np.zeros((2, 3, 4)),
                     np.eye(3) * 1j, np.array(2**62)]),
    st.integers(1, 5).map(lambda n: np.random.default_rng(n).normal(size=(n, n))),
)


@st.composite
def mutated_model(draw, base):
    data = dict(base)
    for _ in range(draw(st.integers(1, 3))):
        key = draw(st.sampled_from(sorted(data) + ["extra", "K_samples", "period", "F_samples"]))
        action = draw(st.sampled_from(["replace", "replace", "transpose", "scale", "delete"]))
        if action == "delete" and key in data:
            del data[key]
        elif action == "transpose" and key in data and np.ndim(data[key]) == 2:
            data[key] = data[key].T[:, :-1]
        elif action == "scale" and key in data and data[key].dtype.kind == "f":
            with np.errstate(over="ignore", under="ignore"):  # a matrix of infinities is one of the inputs tried
                data[key] = data[key] * draw(st.sampled_from([-1.0, 0.0, 1e-300, 1e300, np.nan]))
        else:
            data[key] = draw(ARRAYS)
    return data


def test_a_mutated_model_file_is_used_or_refused_with_one_line(tmp_path_factory):
    base = _exported(tmp_path_factory)
    folder = tmp_path_factory.mktemp("fuzz")
    OUTCOMES.update(used=0, refused=0)

    @settings(max_examples=120, derandomize=True, deadline=None, suppress_health_check=list(HealthCheck))
    @given(mutated_model(base))
    def use_or_refuse(data):
        path = folder / "model.npz"
        np.savez(path, **data)
        tally(lambda: gearcheck.mode_pairing(SPEC, model=str(path)))

    use_or_refuse()
    print(f"model-file fuzz outcomes: {OUTCOMES}")
    assert OUTCOMES["refused"] >= 60


CELLS = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=8),
                  st.sampled_from(["", "nan", "1e999", "-", "0x10", "1,5", '"'] ))


@st.composite
def mutated_series(draw):
    t = np.arange(0.0, 0.02, 1e-4)
    frame = pd.DataFrame({"t": t, "a": np.sin(2e3 * t)})
    text = frame.to_csv(index=False)
    lines = text.splitlines()
    for _ in range(draw(st.integers(1, 4))):
        row = draw(st.integers(0, len(lines) - 1))
        action = draw(st.sampled_from(["cell", "cell", "drop", "duplicate", "header", "truncate"]))
        if action == "cell":
            cells = lines[row].split(",")
            cells[draw(st.integers(0, len(cells) - 1))] = str(draw(CELLS))
            lines[row] = ",".join(cells)
        elif action == "drop" and len(lines) > 1:
            del lines[row]
        elif action == "duplicate":
            lines.insert(row, lines[row])
        elif action == "header":
            lines[0] = draw(st.sampled_from(["t,a,a", "t", "", "time,a", "t;a"]))
        else:
            lines = lines[:row + 1]
    return "\n".join(lines) + "\n"


def test_a_mutated_recorded_series_is_read_or_refused_with_one_line(tmp_path_factory):
    folder = tmp_path_factory.mktemp("series")
    columns = {"solver": "other", "time": "t", "signals": {"stage1.carrier.alpha": "a"}}
    OUTCOMES.update(used=0, refused=0)

    @settings(max_examples=200, derandomize=True, deadline=None, suppress_health_check=list(HealthCheck))
    @given(mutated_series())
    def read_or_refuse(text):
        path = folder / "run.csv"
        path.write_text(text, encoding="utf-8")
        tally(lambda: read_time_series(path, SPEC, columns))

    read_or_refuse()
    print(f"series fuzz outcomes: {OUTCOMES}")
    assert OUTCOMES["used"] >= 10 and OUTCOMES["refused"] >= 50
