"""Cost of a branch of periodic orbits, side by side with one orbit solve in one process.

Run ``python benchmarks/bench_continuation.py [--points 100]``. On the paper's Fig. 13
case (after a warm-up run) it times

1. the baseline: one ``periodic_orbit`` call as ``fivdisc orbit fig13 --transient 5``
   makes it (a 5 s transient, the first return, Newton shooting, the minimal-period
   check), and
2. ``continue_orbit`` of that orbit in the disc speed, downwards, for ``--points`` points
   with every point's multipliers, event signature and measures, and the location of the
   bifurcations met on the way,

and prints both wall times, the time per point and the ratio of the branch to the single
solve. The target of the issue that asked for continuation: 100 points in under 30 s on
2 cores. Each figure is the fastest of ``--rounds`` runs (the work is deterministic).
"""

from __future__ import annotations

import argparse
import os
import platform
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.continuation.walk import continue_orbit
from fivdisc.paper.cases import FIGURES


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=100)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--to", type=float, default=1.0,
                        help="disc speed the branch heads for [rad/s]")
    args = parser.parse_args()
    case = FIGURES[13].case
    print(f"python {platform.python_version()}, {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} cores")
    start = time.perf_counter()
    orbit = periodic_orbit(case, transient=5.0, window=0.05)
    print(f"warm-up (transient, first return, Newton; kernels loaded or compiled): "
          f"{time.perf_counter() - start:.1f} s; T = {orbit.period * 1e3:.6f} ms")
    solves, branches = [], []
    branch = None
    for _ in range(args.rounds):
        start = time.perf_counter()
        periodic_orbit(case, transient=5.0, window=0.05)
        solves.append(time.perf_counter() - start)
        start = time.perf_counter()
        branch = continue_orbit(case, "speed.value", args.to, orbit=orbit,
                                max_points=args.points)
        branches.append(time.perf_counter() - start)
    assert branch is not None
    one, whole = min(solves), min(branches)
    print(f"one orbit call (fivdisc orbit fig13 --transient 5): {one:.2f} s")
    print(f"branch of {len(branch)} points, {len(branch.bifurcations())} bifurcations "
          f"located, from {branch.parameter[0]:.4g} to {branch.parameter[-1]:.4g} rad/s: "
          f"{whole:.1f} s ({whole / len(branch):.3f} s per point)")
    print(f"ratio branch / one orbit call: {whole / one:.2f}")
    print(f"stopped: {branch.stop_reason}")


if __name__ == "__main__":
    main()
