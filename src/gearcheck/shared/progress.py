"""Progress of long runs: a bar on a terminal, a bar in a notebook, nothing in CI and pipes.

The front door's long functions take ``progress``: None (nothing), a callable of the fraction done in [0, 1],
or True, a bar for the person watching (:func:`shows_progress`): tqdm's ``tqdm.auto`` (a widget in Jupyter, a
text bar elsewhere), well kept and what notebook users already see elsewhere.  The command line draws its own
:class:`ProgressBar` on a terminal.
"""

from __future__ import annotations

import functools
import inspect
import logging
import os
import sys
import time


class ProgressBar:
    """Callable with a fraction in [0, 1]; draws to stderr only when it is a terminal, not in CI, and not quiet
    (the command line's ``-q`` raises gearcheck's logger above warnings)."""

    def __init__(self, label: str, stream=None, width: int = 30):
        self.stream = stream or sys.stderr
        self.enabled = (self.stream.isatty() and not os.environ.get("CI")
                        and logging.getLogger("gearcheck").isEnabledFor(logging.WARNING))
        self.label = label
        self.width = width
        self.start = time.perf_counter()
        self.drawn = False

    def __call__(self, fraction: float) -> None:
        if not self.enabled:
            return
        filled = int(round(self.width * fraction))
        elapsed = time.perf_counter() - self.start
        eta = elapsed * (1 - fraction) / fraction if fraction > 0 else float("nan")
        self.stream.write(f"\r{self.label} [{'#' * filled}{'.' * (self.width - filled)}] {100 * fraction:5.1f}% "
                          f"{elapsed:6.1f}s elapsed, {eta:6.1f}s left")
        self.stream.flush()
        self.drawn = True

    def close(self) -> None:
        if self.drawn:
            self.stream.write("\n")
            self.stream.flush()


class NotebookBar:
    """Callable with a fraction in [0, 1]: ``tqdm.auto``'s bar in per mille, closed by :meth:`close`."""

    STEPS = 1000

    def __init__(self, label: str):
        from tqdm.auto import tqdm

        self.bar = tqdm(total=self.STEPS, desc=label, bar_format="{desc}: {percentage:3.0f}%|{bar}| "
                                                                 "[{elapsed}<{remaining}]")

    def __call__(self, fraction: float) -> None:
        done = min(self.STEPS, max(0, round(self.STEPS * fraction)))
        if done > self.bar.n:
            self.bar.update(done - self.bar.n)

    def close(self) -> None:
        self.bar.close()


def shows_progress(function):
    """Decorator of a face function with a ``progress`` parameter: ``progress=True`` draws a :class:`NotebookBar`
    for the call, closed however the call ends, labelled with the function and the train (its ``train``
    argument when a name, or the session's)."""
    signature = inspect.signature(function)

    @functools.wraps(function)
    def call(*args, **kwargs):
        bound = signature.bind(*args, **kwargs)
        if bound.arguments.get("progress") is not True:
            return function(*args, **kwargs)
        train = bound.arguments.get("train")
        session = bound.arguments.get("self")
        name = train if isinstance(train, str) else (session.spec.name if session is not None else None)
        label = function.__name__ + (f" {name}" if name else "")
        bar = NotebookBar(label)
        bound.arguments["progress"] = bar
        try:
            return function(*bound.args, **bound.kwargs)
        finally:
            bar.close()
    return call
