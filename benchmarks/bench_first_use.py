"""First use of each command from an empty numba cache, side by side with an earlier commit.

Run ``python benchmarks/bench_first_use.py`` (``--baseline COMMIT``, default ``278cbee``,
the commit before issue 29; ``--now COMMIT`` to time a commit's sources instead of the
fivdisc on ``PYTHONPATH``; ``--rounds N``, default 1; ``--only NAME`` for some of the
commands; ``--warmup`` also times ``fivdisc warmup`` from an empty cache and then each
command on the cache it filled). Each command runs as a whole process, the way a new user
starts it, with ``NUMBA_CACHE_DIR`` set to a new empty directory, so that every kernel it
needs compiles; the earlier commit runs from its unpacked sources
(``previous.source_tree``) on the same interpreter and libraries. The two alternate, so
that a change in the machine's load falls on both. It prints each process's wall time
[s], the ratio of the medians (now / before) and the target of issue 29, item 1, with the
load average before and after, and each process's processor time (with its helpers'):
on a machine shared with other work the absolute times say little, the ratios more.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from previous import source_tree

# The console script `fivdisc` runs exactly this; through the interpreter being timed.
_CLI = "from fivdisc.cli import main; main()"

# name: (arguments, target [s] of issue 29, item 1); short runs, so that the time is the
# compilation's and the command's start.
COMMANDS: dict[str, tuple[tuple[str, ...], float]] = {
    "simulate": (("simulate", "fig10", "-o", "fig10.nc", "--no-progress"), 15.0),
    "orbit": (("orbit", "fig13", "--transient", "5", "--no-progress"), 25.0),
    "lyapunov": (("lyapunov", "fig13", "--transient", "1", "--duration", "1",
                  "--no-progress"), 25.0),
    "continue": (("continue", "fig13", "--key", "speed.value", "--to", "6.35", "--points",
                  "3", "--transient", "5", "--no-progress"), 25.0),
    "stability": (("stability",), 5.0),
}
WARMUP = ("warmup",)
# Processor time of each process timed, in order [s].
CPU: list[float] = []


def _cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _seconds(args: tuple[str, ...], pythonpath: str, cache: Path, workdir: Path) -> float:
    """Wall time of one process running the command line with ``args`` [s]; its processor
    time (with its helper processes') goes to ``CPU``."""
    env = {**os.environ, "PYTHONPATH": pythonpath, "NUMBA_CACHE_DIR": str(cache),
           "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    cpu = _cpu()
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", _CLI, *args], env=env, cwd=workdir,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    seconds = time.perf_counter() - start
    CPU.append(_cpu() - cpu)
    # Exit status 1 is a result (an orbit not converged, an inconclusive exponent), not
    # a failure of the benchmark.
    if out.returncode not in (0, 1):
        raise SystemExit(f"fivdisc {' '.join(args)} failed ({out.returncode}):\n"
                         f"{out.stderr}")
    return seconds


def _first_use(args: tuple[str, ...], pythonpath: str) -> float:
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as work:
        return _seconds(args, pythonpath, Path(cache), Path(work))


def _after_warmup(names: list[str], pythonpath: str) -> tuple[float, dict[str, float]]:
    """``fivdisc warmup`` on an empty cache, then each command on what it filled [s]."""
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as work:
        warmup = _seconds(WARMUP, pythonpath, Path(cache), Path(work))
        return warmup, {name: _seconds(COMMANDS[name][0], pythonpath, Path(cache), Path(work))
                        for name in names}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default="278cbee", help="earlier commit")
    parser.add_argument("--now", metavar="COMMIT",
                        help="time this commit's sources instead of the fivdisc on "
                             "PYTHONPATH (so that editing the tree meanwhile changes nothing)")
    parser.add_argument("--rounds", type=int, default=1, help="processes per command")
    parser.add_argument("--only", action="append", choices=sorted(COMMANDS),
                        help="time this command (repeatable; default: all)")
    parser.add_argument("--warmup", action="store_true",
                        help="also time fivdisc warmup, then each command after it")
    args = parser.parse_args()
    names = args.only or list(COMMANDS)
    now = str(source_tree(args.now)) if args.now else os.environ.get("PYTHONPATH", "")
    before = str(source_tree(args.baseline))
    load = os.getloadavg()[0]
    times: dict[str, tuple[list[float], list[float]]] = {n: ([], []) for n in names}
    warm: list[tuple[float, dict[str, float]]] = []
    for round_ in range(args.rounds):
        for name in names:
            cmd = COMMANDS[name][0]
            # The order alternates between rounds, so neither side always goes first.
            pair = [(now, 0), (before, 1)][:: 1 if round_ % 2 == 0 else -1]
            cpu = {}
            for pythonpath, side in pair:
                times[name][side].append(_first_use(cmd, pythonpath))
                cpu[side] = CPU[-1]
            print(f"{name:<10} now {times[name][0][-1]:7.1f} s (cpu {cpu[0]:.1f} s), at "
                  f"{args.baseline} {times[name][1][-1]:7.1f} s (cpu {cpu[1]:.1f} s); load "
                  f"{os.getloadavg()[0]:.1f}", flush=True)
        if args.warmup:
            warm.append(_after_warmup(names, now))
            print(f"fivdisc warmup {warm[-1][0]:.1f} s, then "
                  + ", ".join(f"{n} {s:.1f} s" for n, s in warm[-1][1].items()), flush=True)
    print(f"\nfirst use from an empty numba cache, median of {args.rounds} process(es); "
          f"load average {load:.2f} before, {os.getloadavg()[0]:.2f} after "
          f"({os.cpu_count()} cores)")
    print(f"{'command':<10} {'now [s]':>9} {args.baseline + ' [s]':>13} {'ratio':>7} "
          f"{'target [s]':>11}")
    for name in names:
        mine, theirs = (statistics.median(t) for t in times[name])
        print(f"{name:<10} {mine:>9.1f} {theirs:>13.1f} {mine / theirs:>7.2f} "
              f"{COMMANDS[name][1]:>11.0f}")
    if warm:
        print(f"fivdisc warmup, empty cache: {statistics.median(w[0] for w in warm):.1f} s; "
              "then each command: " + ", ".join(
                  f"{n} {statistics.median(w[1][n] for w in warm):.1f} s" for n in names))


if __name__ == "__main__":
    main()
