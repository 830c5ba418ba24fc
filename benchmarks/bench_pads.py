"""Cost of the three-pad branch of issue 36, side by side with one orbit solve in one process.

Run ``python benchmarks/bench_pads.py [--points 40] [--rounds 1]``. On the issue's case
(three identical pads at 0, 120 and 240 degrees, Stribeck friction, four disc modes;
after a warm-up run) it times

1. the baseline: one ``periodic_orbit`` call as ``fivdisc orbit bist-22-large.toml
   --transient 10`` makes it (a 10 s transient, the first return, Newton shooting, the
   minimal-period check, the orbit's symmetry), and
2. ``continue_orbit`` of that orbit in the disc speed, downwards from 22 rad/s, for
   ``--points`` points: every point's multipliers, event signature, measures and symmetry
   (with its reduced map's multipliers), the anchor kept away from the switches, and the
   bifurcations met on the way located, the jump at the border at 11.838233 rad/s (where
   the pads' releases meet the next pads' sticks) included when the branch gets there,

and prints both wall times, the points per second of the branch and the ratio of the
branch's time per point to the single solve. Each figure is the fastest of ``--rounds``
runs (the work is deterministic). ``--confirm`` sets the forward run that confirms an end
(periods; 0: none).
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.case import load_case
from fivdisc.continuation.walk import continue_orbit

#: The issue's three-pad case at 22 rad/s (``bist-22-large.toml``), as the tests keep it.
CASE = Path(__file__).resolve().parents[1] / "tests" / "data" / "three_pads_issue36.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument("--to", type=float, default=1.0,
                        help="disc speed the branch heads for [rad/s]")
    parser.add_argument("--confirm", type=int, default=400,
                        help="periods of the forward run that confirms an end")
    args = parser.parse_args()
    case = load_case(CASE)
    print(f"python {platform.python_version()}, {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} cores")
    start = time.perf_counter()
    orbit = periodic_orbit(case, transient=10.0)
    print(f"warm-up (transient, first return, Newton; the first run of the process): "
          f"{time.perf_counter() - start:.1f} s; T = {orbit.period * 1e3:.6f} ms, "
          f"{orbit.symmetry}")
    solves, branches = [], []
    branch = None
    for _ in range(args.rounds):
        start = time.perf_counter()
        periodic_orbit(case, transient=10.0)
        solves.append(time.perf_counter() - start)
        start = time.perf_counter()
        branch = continue_orbit(case, "speed.value", args.to, orbit=orbit,
                                max_points=args.points, confirm_periods=args.confirm)
        branches.append(time.perf_counter() - start)
    assert branch is not None
    one, whole = min(solves), min(branches)
    per_point = whole / len(branch)
    print(f"one orbit call (fivdisc orbit bist-22-large.toml --transient 10): {one:.2f} s")
    print(f"branch of {len(branch)} points, {len(branch.bifurcations())} bifurcations "
          f"located, from {branch.parameter[0]:.6g} to {branch.parameter[-1]:.6g} rad/s: "
          f"{whole:.1f} s, {len(branch) / whole:.2f} points per second "
          f"({per_point:.2f} s per point)")
    print(f"ratio of a point to one orbit call: {per_point / one:.3f} "
          f"(a branch point costs {per_point / one:.1%} of an orbit solve)")
    for b in branch.bifurcations():
        print(f"  {b['kind']} at {b['parameter']:.9g} rad/s")
    print(f"stopped: {branch.stop_reason}")


if __name__ == "__main__":
    main()
