"""``operating.torque_expression``: a time function written as data.  Its grammar computes numbers and nothing
else (every escape a hostile file would try is refused by name), it evaluates to the closed form it writes, and a
run driven by it is the run driven by the same function given as trusted code, to the last bit."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gearcheck
from gearcheck.shared.errors import GearcheckError
from gearcheck.shared.trust import granted
from gearcheck.train.expression import Expression

T = np.linspace(0.0, 0.05, 101)


@pytest.mark.parametrize("text, exact", [
    ("50 * sin(2 * pi * 12.5 * t) * exp(-t / 0.2)", lambda t: 50 * np.sin(2 * np.pi * 12.5 * t) * np.exp(-t / 0.2)),
    ("100 * (t >= 0.01) - 20 * (t > 0.03)", lambda t: 100.0 * (t >= 0.01) - 20.0 * (t > 0.03)),
    ("max(0, 1 - t / 0.02) ** 2 + min(t, 0.01)", lambda t: np.maximum(0, 1 - t / 0.02) ** 2 + np.minimum(t, 0.01)),
    ("-abs(cos(t)) + sqrt(t + 1) + log(t + e) + tanh(t) + sign(t - 0.02) + floor(t * 100)",
     lambda t: -np.abs(np.cos(t)) + np.sqrt(t + 1) + np.log(t + math.e) + np.tanh(t) + np.sign(t - 0.02)
     + np.floor(t * 100)),
    ("250", lambda t: np.full_like(t, 250.0)),
])
def test_an_expression_is_its_closed_form(text, exact):
    np.testing.assert_array_equal(Expression(text, "x")(T), exact(T))


@pytest.mark.parametrize("text, said", [
    ("__import__('os').system('true')", "\"__import__('os').system('true')\" is not in the grammar"),
    ("sin(__import__('os'))", "\"__import__('os')\" is not in the grammar"),
    ("t.__class__", "'t.__class__' is not in the grammar"),
    ("(lambda: 1)()", "is not in the grammar"),
    ("[t for t in (1,)][0]", "is not in the grammar"),
    ("open", "'open' is not in the grammar"),
    ("'text'", "\"'text'\" is not in the grammar"),
    ("sin(t, t)", "'sin(t, t)' is not in the grammar"),
    ("sin(x=t)", "is not in the grammar"),
    ("0 < t < 1", "is not in the grammar"),
    ("t if t else 0", "is not in the grammar"),
    ("1 +", "is no expression"),
    ("", "an expression of t of 1 to 1000 characters"),
    ("t" + " + t" * 400, "an expression of t of 1 to 1000 characters"),
    ("-" * 60 + "t", "nested deeper than 50 operations"),
])
def test_an_expression_outside_the_grammar_is_refused_by_name(text, said):
    with pytest.raises(GearcheckError, match="^x: ") as caught:
        Expression(text, "x")
    assert said in str(caught.value)


def test_a_value_that_is_not_finite_is_refused_naming_the_time():
    with pytest.raises(GearcheckError, match=r"'10 \*\* 10 \*\* 10 \* t' is not finite at t = 0 s"):
        Expression("10 ** 10 ** 10 * t", "x")(T)  # a float power, no billion-digit integer: inf, times 0 NaN
    with pytest.raises(GearcheckError, match=r"'1 / \(t - 0.01\)' is not finite at t = 0.01 s"):
        Expression("1 / (t - 0.01)", "x")(T)
    with pytest.raises(GearcheckError, match=r"not finite at t = 0 s"):
        Expression("log(t)", "x")(T)


def train_with(folder, line: str):
    text = gearcheck.preset_text("demo-3p").replace("[operating]\n", f"[operating]\n{line}\n", 1)
    path = folder / "train.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_run_driven_by_an_expression_is_the_run_driven_by_the_same_function(tmp_path, monkeypatch):
    (tmp_path / "steps.py").write_text("def torque(t):\n    return 100.0 * (t >= 0.002) - 30.0 * (t > 0.004)\n",
                                       encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    by_expression = gearcheck.simulate(train_with(tmp_path, 'torque_expression = "100 * (t >= 0.002) - 30 * '
                                                            '(t > 0.004)"'), "lumped", duration=0.006)
    plain = gearcheck.simulate("demo-3p", "lumped", duration=0.006)
    with granted(["steps"]):
        by_function = gearcheck.simulate(train_with(tmp_path, 'torque_function = "steps:torque"'), "lumped",
                                         duration=0.006)
    sys.modules.pop("steps", None)
    np.testing.assert_array_equal(by_expression.values, by_function.values)
    assert not np.array_equal(by_expression.values, plain.values)  # the torque acted


def test_a_bad_expression_in_a_train_file_is_one_line(tmp_path, capsys):
    from gearcheck.cli import main

    path = train_with(tmp_path, 'torque_expression = "__import__(\'os\')"')
    assert main(["show", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "operating.torque_expression: " in err and "is not in the grammar" in err


@settings(max_examples=1000, derandomize=True, deadline=None)
@given(st.text(alphabet="t0123456789.+-*/()<>= eEpisncoxaqrtlgbmfh_'[],:.", max_size=40))
def test_any_text_is_an_expression_or_refused_in_one_line(text):
    try:
        values = Expression(text, "x")(T)
        assert values.shape == T.shape and np.all(np.isfinite(values))
    except GearcheckError as exc:
        assert "\n" not in str(exc)
