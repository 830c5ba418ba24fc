"""Cost of the tangent dynamics, side by side with plain runs in one process.

Run ``python benchmarks/bench_tangent.py``. It prints, each as a ratio against a
baseline measured in the same run:

1. the cost per accepted step of a run carrying n tangent vectors (n = 1, 2, 4) against
   the same run without them, on the paper's Fig. 8 case (the steps are the same: the
   tangents do not change the step sequence); the target is at most 1 + n;
2. the largest Lyapunov exponent of the Fig. 8 case over 10 s of simulated time
   (``fivdisc.analysis.lyapunov.lyapunov``, one vector) against the plain run of the
   same 10 s; the target is at most 2.5.

The runs are interleaved after a warm-up that compiles (in each round the baseline, then
the runs with tangents), and each figure is the ratio of the fastest run of each kind
over the rounds: the work is deterministic, so the fastest run is the one least
disturbed by the rest of the machine (the advice of :mod:`timeit`); the median of the
rounds' own ratios is printed beside it.
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


def _figure(walls, bases) -> str:
    ratios = [w / b for w, b in zip(walls, bases, strict=True)]
    return f"{min(walls) / min(bases):5.2f} x (median of the rounds {_median(ratios):.2f})"


def per_step(case, repeat=7) -> None:
    """Runs with 0, 1, 2 and 4 vectors interleaved, ``repeat`` rounds."""
    model = build_model(case)
    y0 = initial_state(model)
    cap = tangent_step(model)
    for n in (0, 1, 2, 4):  # warm-up: compile both specialisations
        _run(model, y0, 0.01, n, cap)
    walls = {1: [], 2: [], 4: []}
    bases = []
    steps = None
    for _ in range(repeat):
        base, steps = _run(model, y0, SPAN, 0, cap)
        bases.append(base)
        for n in walls:
            wall, steps_n = _run(model, y0, SPAN, n, cap)
            assert steps_n == steps
            walls[n].append(wall)
    base = min(bases)
    print(f"plain run, {SPAN:g} s, step cap {cap:.2e} s: {base:.3f} s, {steps} steps, "
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


def main() -> None:
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, {platform.python_version()}")
    case = load_case(DIRECTORY / "fig08.toml")
    per_step(case)
    exponent(case)


if __name__ == "__main__":
    main()
