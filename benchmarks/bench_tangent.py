"""Cost of the tangent dynamics, side by side with plain runs in one process.

Run ``python benchmarks/bench_tangent.py``. It prints, each as a ratio against a
baseline measured in the same run:

1. the cost per accepted step of a run carrying n tangent vectors (n = 1, 2, 4) against
   the same run without them, on the paper's Fig. 8 case (the steps are the same: the
   tangents do not change the step sequence); the target is at most 1 + n;
2. the largest Lyapunov exponent of the Fig. 8 case over 10 s of simulated time
   (``fivdisc.analysis.exponents.lyapunov``, one vector) against the plain run of the
   same 10 s; the target is at most 2.5;
3. with ``--processes N``, the one-vector figure again in N fresh processes (it varies
   from process to process by more than between the rounds of one).

The runs are interleaved after a warm-up (in each round the baseline, then
the runs with tangents), and each figure is the ratio of the fastest run of each kind
over the rounds: the work is deterministic, so the fastest run is the one least
disturbed by the rest of the machine (the advice of :mod:`timeit`); the median of the
rounds' own ratios is printed beside it.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from fivdisc.analysis.exponents import lyapunov
from fivdisc.case import load_case
from fivdisc.engine.integration import Integration, tangent_step
from fivdisc.engine.simulation import initial_state
from fivdisc.examples import DIRECTORY
from fivdisc.model.build import build_model

SPAN = 10.0  # [s] of simulated time per timed run (item 1)
MEASURE = 10.0  # [s] of simulated time for the exponent (item 2)


# The clock of the timed runs; ``--cpu-time`` takes this thread's CPU time instead, which
# a machine busy with other work disturbs far less than the wall time.
CLOCK = {"clock": time.perf_counter}


def _run(model, y0, span, vectors, max_step):
    run = Integration(model, y0, duration=span, max_step=max_step)
    if vectors:
        run.set_tangents(np.eye(vectors, model.state_size))
    clock = CLOCK["clock"]
    start = clock()
    run.run_to(span)
    return clock() - start, run.stats["steps"]


def _median(values):
    return sorted(values)[len(values) // 2]


def _figure(walls, bases) -> str:
    ratios = [w / b for w, b in zip(walls, bases, strict=True)]
    return f"{min(walls) / min(bases):5.2f} x (median of the rounds {_median(ratios):.2f})"


def per_step(case, repeat=7, counts=(1, 2, 4), span=SPAN) -> None:
    """Runs with 0 and ``counts`` vectors interleaved, ``repeat`` rounds."""
    model = build_model(case)
    y0 = initial_state(model)
    cap = tangent_step(model)
    for n in (0, *counts):  # warm-up
        _run(model, y0, 0.01, n, cap)
    walls: dict[int, list[float]] = {n: [] for n in counts}
    bases = []
    steps = None
    for _ in range(repeat):
        base, steps = _run(model, y0, span, 0, cap)
        bases.append(base)
        for n in walls:
            wall, steps_n = _run(model, y0, span, n, cap)
            assert steps_n == steps
            walls[n].append(wall)
    base = min(bases)
    print(f"plain run, {span:g} s, step cap {cap:.2e} s: {base:.3f} s, {steps} steps, "
          f"{1e6 * base / steps:.2f} us/step (fastest of {repeat})")
    for n, values in walls.items():
        print(f"  {n} tangent vector(s): {_figure(values, bases)} the plain run per step "
              f"(target <= {1 + n})")


def exponent(case, repeat=7) -> None:
    """The largest exponent against the plain run of the same span, interleaved."""
    model = build_model(case)
    y0 = initial_state(model)
    lyapunov(case, n=1, transient=0.0, duration=0.05)  # warm-up
    _run(model, y0, 0.01, 0, None)
    walls = []
    bases = []
    for _ in range(repeat):
        bases.append(_run(model, y0, MEASURE, 0, None)[0])
        walls.append(_timed(lambda: lyapunov(case, n=1, transient=0.0, duration=MEASURE)))
    print(f"largest exponent over {MEASURE:g} s: {min(walls):.2f} s vs plain run "
          f"{min(bases):.2f} s: {_figure(walls, bases)} (target <= 2.5)")


def _timed(f) -> float:
    start = time.perf_counter()
    f()
    return time.perf_counter() - start


def processes(count: int, cpu_time: bool = False) -> None:
    """The one-vector figure of :func:`per_step` (3 rounds) in ``count`` fresh processes,
    timed by the same clock as this process's figures.

    Within a process the rounds agree to about 1 %, but the figure moves by several per
    cent from one process to the next (the same code, the same steps): this shows the
    spread a single run of this script can land anywhere in."""
    figures = []
    clock = ["--cpu-time"] if cpu_time else []
    for _ in range(count):
        out = subprocess.run([sys.executable, __file__, "--one", *clock], check=True,
                             capture_output=True, text=True).stdout
        figures.append(float(out.split("1 tangent vector(s):")[1].split("x")[0]))
    print(f"1 tangent vector in {count} fresh processes: "
          + ", ".join(f"{f:.2f}" for f in sorted(figures)) + " x the plain run per step")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--processes", type=int, default=0,
                        help="also repeat the one-vector figure in N fresh processes")
    parser.add_argument("--span", type=float, default=SPAN,
                        help=f"simulated time of each timed run [s] (default {SPAN:g})")
    parser.add_argument("--rounds", type=int, default=7,
                        help="rounds of the per-step figures (default 7)")
    parser.add_argument("--no-exponent", action="store_true",
                        help="leave out the largest exponent's figure")
    parser.add_argument("--cpu-time", action="store_true",
                        help="time the runs by this thread's CPU time, not the wall time")
    parser.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.cpu_time:
        CLOCK["clock"] = time.thread_time
    case = load_case(DIRECTORY / "fig08.toml")
    if args.one:
        per_step(case, repeat=3, counts=(1,))
        return
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, {platform.python_version()}")
    per_step(case, repeat=args.rounds, span=args.span)
    if not args.no_exponent:
        exponent(case)
    if args.processes:
        processes(args.processes, args.cpu_time)


if __name__ == "__main__":
    main()
