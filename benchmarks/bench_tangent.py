"""Cost of the tangent dynamics, side by side with plain runs in one process.

Run ``python benchmarks/bench_tangent.py``. It prints, each as a ratio against a
baseline measured in the same run:

1. the cost per accepted step of a run carrying n tangent vectors (n = 1, 2, 4) against
   the same run without them, on the paper's Fig. 8 case (the steps are the same: the
   tangents do not change the step sequence); the target is at most 1 + n;
2. the largest Lyapunov exponent of the Fig. 8 case over 10 s of simulated time
   (``fivdisc.analysis.lyapunov.lyapunov``, one vector) against the plain run of the
   same 10 s; the target is at most 2.5.

The runs are interleaved after a warm-up that compiles (baseline, then the runs with
tangents, in each round), and each figure is the median over the rounds of that round's
ratio, with the range of the rounds.
"""

from __future__ import annotations

import os
import platform
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from fivdisc.analysis.lyapunov import lyapunov
from fivdisc.case import load_case
from fivdisc.examples import DIRECTORY
from fivdisc.integration import Integration, tangent_step
from fivdisc.model import build_model
from fivdisc.simulate import initial_state

SPAN = 10.0  # [s] of simulated time per timed run (item 1)
MEASURE = 10.0  # [s] of simulated time for the exponent (item 2)


def _run(model, y0, span, vectors, max_step):
    run = Integration(model, y0, duration=span, max_step=max_step)
    if vectors:
        run.set_tangents(np.eye(vectors, model.state_size))
    start = time.perf_counter()
    run.run_to(span)
    return time.perf_counter() - start, int(run.ist[1])


def _median(values):
    return sorted(values)[len(values) // 2]


def per_step(case, repeat=7) -> None:
    """Runs with 0, 1, 2 and 4 vectors interleaved, ``repeat`` rounds: a drift of the
    machine's speed (other jobs, frequency) then hits each round's baseline and its
    tangent runs alike, and the median over rounds of each round's ratio is the figure."""
    model = build_model(case)
    y0 = initial_state(model)
    cap = tangent_step(model)
    for n in (0, 1, 2, 4):  # warm-up: compile both specialisations
        _run(model, y0, 0.01, n, cap)
    ratios = {1: [], 2: [], 4: []}
    bases = []
    steps = None
    for _ in range(repeat):
        base, steps = _run(model, y0, SPAN, 0, cap)
        bases.append(base)
        for n in ratios:
            wall, steps_n = _run(model, y0, SPAN, n, cap)
            assert steps_n == steps
            ratios[n].append(wall / base)
    base = _median(bases)
    print(f"plain run, {SPAN:g} s, step cap {cap:.2e} s: {base:.3f} s, {steps} steps, "
          f"{1e6 * base / steps:.2f} us/step (median of {repeat})")
    for n, values in ratios.items():
        print(f"  {n} tangent vector(s): {_median(values):5.2f} x the plain run per step "
              f"(target <= {1 + n}; rounds {min(values):.2f} to {max(values):.2f})")


def exponent(case, repeat=5) -> None:
    """The largest exponent against the plain run of the same span, interleaved."""
    model = build_model(case)
    y0 = initial_state(model)
    lyapunov(case, n=1, transient=0.0, duration=0.05)  # warm-up
    _run(model, y0, 0.01, 0, None)
    ratios = []
    walls = []
    for _ in range(repeat):
        base, _ = _run(model, y0, MEASURE, 0, None)
        wall = _timed(lambda: lyapunov(case, n=1, transient=0.0, duration=MEASURE))
        walls.append((wall, base))
        ratios.append(wall / base)
    wall, base = _median(walls)
    print(f"largest exponent over {MEASURE:g} s: {wall:.2f} s vs plain run {base:.2f} s: "
          f"{_median(ratios):.2f} x (target <= 2.5; rounds {min(ratios):.2f} to "
          f"{max(ratios):.2f})")


def _timed(f) -> float:
    start = time.perf_counter()
    f()
    return time.perf_counter() - start


def main() -> None:
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, {platform.python_version()}")
    case = load_case(DIRECTORY / "fig08.toml")
    per_step(case)
    exponent(case)


if __name__ == "__main__":
    main()
