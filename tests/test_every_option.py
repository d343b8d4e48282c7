"""Every option of every command, given values no careful user gives (NaN, text, nothing, a 20-digit number, a
negative one): each invocation is refused in one line with exit status 2, or runs and ends as a run ends (0, 1 or
3); none raises, prints a traceback, or ends as an internal error (70).  Options that take a value are read from
the parser itself, so a new option is tried as soon as it exists."""

from __future__ import annotations

import contextlib
import io
import signal

import pytest

from gearcheck.cli import _parser, main

BASE = {  # each command's arguments that make a quick valid run; OUT stands for the test's output place
    "presets": [], "show": ["demo-3p"], "modes": ["demo-3p"], "campbell": ["demo-3p", "--out", "OUT"],
    "mac": ["demo-3p", "--out", "OUT"], "ste": ["demo-3p", "--out", "OUT"],
    "run": ["demo-3p", "--duration", "0.002", "--out", "OUT"],
    "crosscheck": ["demo-3p", "--duration", "0.01", "--out", "OUT"],
    "calibrate": ["demo-3p", "--fit", "operating.output_torque=100:2000", "--out", "OUT"],
    "sweep": ["demo-3p", "--speeds", "1000,1100", "--solver", "lumped", "--duration", "0.01", "--out", "OUT"],
    "sensitivity": ["demo-3p", "--parameter", "stages[0].sun.mass", "--out", "OUT"],
    "runup": ["demo-3p", "--from", "1500", "--to", "2000", "--duration", "0.05", "--solver", "lumped", "--quantity",
              "stage1.planet1.sun.force", "--out", "OUT"],
    "pins": ["rv-reducer", "-o", "OUT/p.png"], "stiffness": ["demo-3p", "-o", "OUT/s.png"],
    "animate": ["demo-3p", "-o", "OUT/a.gif", "--duration", "0.2"], "view": ["demo-3p"],
    "dashboard": ["STORE", "-o", "OUT"], "export": ["demo-3p", "-o", "OUT/m.npz"], "mjcf": ["demo-3p"],
}
VALUES = ("nan", "-inf", "1e308", "abc", "", "99999999999999999999", "-1")
SLOW = 20  # s: a value that is valid starts a run, which is stopped here (its outcome is not in question)


class Slow(BaseException):
    """A run that a valid value started, stopped."""


def _options(command: str):
    sub = next(a for a in _parser()._actions if a.dest == "command").choices[command]
    return [a for a in sub._actions if a.option_strings and a.nargs != 0 and a.dest != "help"]


def _stop(signum, frame):
    raise Slow()


@pytest.mark.parametrize("command", sorted(BASE))
def test_every_option_given_a_value_nobody_should_give(command, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a value taken for a relative path lands here
    assert set(BASE) == set(next(a for a in _parser()._actions if a.dest == "command").choices)
    out, store = str(tmp_path / "o"), str(tmp_path / "none.sqlite")
    previous = signal.signal(signal.SIGALRM, _stop)
    tried = 0
    try:
        for action in _options(command):
            flag = action.option_strings[-1]
            for value in VALUES:
                argv = [a.replace("OUT", out).replace("STORE", store) for a in BASE[command]]
                if flag in argv:
                    at = argv.index(flag)
                    del argv[at:at + 2]
                argv += [flag] + [value] * (action.nargs if isinstance(action.nargs, int) else 1)
                err = io.StringIO()
                signal.alarm(SLOW)
                try:
                    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                        status = main(argv)
                except Slow:
                    status = None
                finally:
                    signal.alarm(0)
                tried += 1
                text = err.getvalue()
                assert "Traceback" not in text and status in (None, 0, 1, 2, 3), (argv, status, text)
                if status == 2:
                    assert text.count("\n") == 1 and text.startswith("gearcheck: error: "), (argv, text)
    finally:
        signal.signal(signal.SIGALRM, previous)
    assert tried >= len(VALUES) or command == "presets"
