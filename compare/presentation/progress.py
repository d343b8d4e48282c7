"""A progress bar for long runs: drawn on a terminal, silent in CI and pipes."""

from __future__ import annotations

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
