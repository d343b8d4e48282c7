"""Wall time of the same commands under two installs of gearcheck, side by side: the README's main job and the
cross-check of every preset, each run alternately under the two, the ratio printed.

    python bench/bench_versions.py --before /path/to/old/.venv/bin/gearcheck [--after .venv/bin/gearcheck]
        [--repeats N] [--quick]

``--quick`` times each preset's 0.05 s cross-check instead.  Each command writes into a fresh
temporary folder; the best of ``--repeats`` runs is kept.
"""

from __future__ import annotations

import argparse
import subprocess
import tempfile
import time
from pathlib import Path

JOBS = {
    "README main job (hub-drive, 0.6 s)": ["crosscheck", "hub-drive", "--duration", "0.6"],
    "crosscheck --all --baseline": ["crosscheck", "--all", "--baseline"],
}
QUICK = {f"crosscheck {name}, 0.05 s": ["crosscheck", name, "--duration", "0.05"]
         for name in ("demo-3p", "demo-4p", "double-planet", "helical-planetary", "hub-drive", "rv-reducer")}


def wall(executable: str, command: list[str]) -> tuple[float, int]:
    """(seconds, exit status) of one run of ``executable command --out TMP``."""
    with tempfile.TemporaryDirectory() as folder:
        started = time.perf_counter()
        done = subprocess.run([executable, *command, "--out", str(Path(folder) / "out")], capture_output=True)
        return time.perf_counter() - started, done.returncode


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", required=True, help="the gearcheck executable of the install to compare with")
    parser.add_argument("--after", default=".venv/bin/gearcheck")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    print(f"{'job':40} {'before [s]':>11} {'after [s]':>10} {'ratio':>6}  exit (before, after)")
    for name, command in (QUICK if args.quick else JOBS).items():
        best = {"before": (float("inf"), None), "after": (float("inf"), None)}
        for _ in range(args.repeats):
            for label in ("before", "after"):
                seconds, status = wall(getattr(args, label), command)
                best[label] = min(best[label], (seconds, status))
        (b, rb), (a, ra) = best["before"], best["after"]
        print(f"{name:40} {b:11.1f} {a:10.1f} {a / b:6.2f}  ({rb}, {ra})", flush=True)


if __name__ == "__main__":
    main()
