"""Wall and CPU seconds of the everyday commands, side by side in one run: ``gearcheck --version``, ``gearcheck
--help``, the README's main job (hub-drive's cross-check at 0.6 s) and ``gearcheck crosscheck --all``, each into a
fresh temporary folder, one untimed warm-up then ``--repeats`` timed runs (min and median), with the machine's load
average before and after.

    python bench/bench_commands.py [--gearcheck .venv/bin/gearcheck ...] [--repeats 3] [--quick]

Several ``--gearcheck`` executables (installs of two commits) run in turn, run by run, each row's median wall time
then also as a ratio to the first's.  ``--env NAME=VALUE`` adds each executable again with that variable set, in
the same turns: ``--env NUMPY_MADVISE_HUGEPAGE=0`` measures what numpy's huge-page advice costs a host (see
"Where the time goes" in ``docs/developer.md``).  ``--quick`` leaves out ``crosscheck --all``.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

COMMANDS = {  # name: arguments; "OUT" is replaced by a fresh temporary folder
    "--version": ["--version"],
    "--help": ["--help"],
    "README main job (hub-drive, 0.6 s)": ["crosscheck", "hub-drive", "--duration", "0.6", "--out", "OUT"],
    "crosscheck --all": ["crosscheck", "--all", "--out", "OUT"],
}


def timed(executable: str, arguments: list[str], env: dict | None = None) -> tuple[float, float, int]:
    """(wall seconds, CPU seconds of the process and its children, exit status) of one run, with the variables
    ``env`` added to this process's environment."""
    with tempfile.TemporaryDirectory() as folder:
        command = [executable, *(str(Path(folder) / "out") if a == "OUT" else a for a in arguments)]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        started = time.perf_counter()
        done = subprocess.run(command, capture_output=True, env={**os.environ, **(env or {})})
        wall = time.perf_counter() - started
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return wall, cpu, done.returncode


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gearcheck", action="append", help="a gearcheck executable (repeatable; default "
                                                             ".venv/bin/gearcheck)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="leave out crosscheck --all")
    parser.add_argument("--env", action="append", default=[], metavar="NAME=VALUE",
                        help="also run each executable with this variable set (repeatable)")
    args = parser.parse_args()
    bad = [e for e in args.env if "=" not in e or not e.split("=", 1)[0]]
    if bad:
        parser.error(f"--env {bad[0]!r}: expected NAME=VALUE")
    settings = [{}] + [dict([e.split("=", 1)]) for e in args.env]
    variants = [(f"{exe[-28:]}{' ' + ' '.join(f'{k}={v}' for k, v in env.items()) if env else ''}", exe, env)
                for exe in args.gearcheck or [".venv/bin/gearcheck"] for env in settings]
    commands = {k: v for k, v in COMMANDS.items() if not (args.quick and k == "crosscheck --all")}
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())} (1, 5, 15 min) on {os.cpu_count()} cores; "
          f"{args.repeats} runs each after one warm-up")
    width = max(28, *(len(label) for label, _, _ in variants))
    print(f"{'command':36} {'gearcheck':{width}} {'wall min':>9} {'median':>8} {'CPU min':>8} {'median':>8} "
          f"{'ratio':>6}  exit")
    for name, arguments in commands.items():
        runs: dict[str, list[tuple[float, float, int]]] = {label: [] for label, _, _ in variants}
        for repeat in range(args.repeats + 1):
            for label, exe, env in variants:
                run = timed(exe, arguments, env)
                if repeat:
                    runs[label].append(run)
        first = statistics.median(w for w, _, _ in runs[variants[0][0]])
        for label, _, _ in variants:
            walls, cpus, codes = zip(*runs[label])
            wall = statistics.median(walls)
            print(f"{name:36} {label:{width}} {min(walls):9.2f} {wall:8.2f} {min(cpus):8.2f} "
                  f"{statistics.median(cpus):8.2f} {wall / first:6.2f}  {sorted(set(codes))}", flush=True)
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())} (1, 5, 15 min) after")


if __name__ == "__main__":
    main()
