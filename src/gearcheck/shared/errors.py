"""The gearcheck exception family.

Every error a user can provoke with a train file or a command-line option is a
``GearcheckError``.  Messages name the file and the field path
(``demo.toml: stages[0].sun.teeth: ...``) so the command-line interface can print
them as one line and exit with status 2, never a traceback; a name that is not known ends
with :func:`did_you_mean`'s hint.
"""

from __future__ import annotations

import difflib


class GearcheckError(ValueError):
    """Base class of every error gearcheck raises on bad input or an impossible request."""


class TrainFileError(GearcheckError):
    """A train file that cannot be read or violates the schema or the geometry rules."""

    def __init__(self, source: str, field: str, message: str):
        self.source = source
        self.field = field
        self.reason = message
        where = f"{source}: {field}: " if field else f"{source}: "
        super().__init__(where + message)


class SolverError(GearcheckError):
    """A solver request that cannot be honoured (for instance a time step that is unstable)."""


class DivergenceError(SolverError):
    """A time integration that produced NaN or runaway energy."""

    def __init__(self, time: float, message: str):
        self.time = time
        super().__init__(f"diverged at t = {time:.6g} s: {message}")


class LongRunWarning(UserWarning):
    """A run that will take minutes, said before it starts (the command line prints it as a note)."""


class TrainNote(UserWarning):
    """A train file's value that a designer would want a word on, said when it is loaded (the command line prints
    it as a note)."""


def one_line(exc: BaseException, width: int = 200) -> str:
    """An exception's message as one line of at most ``width`` characters (its type's name when it has none)."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= width else text[:width - 3] + "..."


def shown(value, width: int = 40) -> str:
    """A value as a message shows it: its repr cut to ``width`` characters, an integer too long to print in
    full (Python refuses past 4300 digits) by its size."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 128:
        return f"an integer of some {int(value.bit_length() * 0.30103) + 1} digits"
    text = " ".join(repr(value.item() if hasattr(value, "item") and getattr(value, "shape", None) == () else value)
                    .split())
    return text if len(text) <= width else text[:width - 3] + "..."


def did_you_mean(name: str, choices, listing: str = "", *, n: int = 1, cutoff: float = 0.6) -> str:
    """The hint that follows an unknown ``name``: `` (did you mean 'x'?)`` with the entry of ``choices``
    closest to it (up to ``n`` of them, as near as ``cutoff``: :func:`difflib.get_close_matches`); with
    none close, `` (LISTING: a, b, ...)`` naming every choice when ``listing`` is given, else ``""``."""
    choices = list(choices)
    close = difflib.get_close_matches(name, choices, n=n, cutoff=cutoff)
    if close:
        return f" (did you mean {', '.join(map(repr, close))}?)"
    return f" ({listing}: {', '.join(choices)})" if listing else ""


class UnsupportedError(SolverError):
    """A side asked for a capability it does not have (modes at speed, mode shapes, ...)."""
