"""Cost of a bifurcation curve in two keys and of a bistable region, side by side with
one orbit solve and one point of a one-parameter branch in the same process.

Run ``python benchmarks/bench_codim2.py [--points 100]``. On the packaged ``damped-disc``
case (the paper's first example with 0.2 % modal damping) it times

1. the baselines: one ``periodic_orbit`` call (a 5 s transient, the first return,
   Newton shooting) at 12.3 rad/s, and a one-parameter branch of that orbit in the speed
   through its fold of cycles near 12.53 rad/s, per point;
2. the fold followed in the disc's damping ratio from 0.002 to 0.0025 over ``--points``
   points (``fivdisc continue --key2``);
3. ``bistable_region`` over speed 18-100 rad/s and damping ratio 0.001-0.003 with the
   command's defaults (12 points per side, a 41 x 21 grid),

and prints the wall times, their ratios to the baselines, and whether the targets of
issue 39 hold: a curve of 100 points in under a minute, the region in under five minutes
(2 cores). Each figure is the fastest of ``--rounds`` runs.

Measured on the development machine (2 shared cores, Python 3.11): one orbit solve
1.93 s, a branch point 0.154 s; the fold curve of 100 points 15.9 s (8.3 orbit solves,
104 branch points: 0.16 s a point); the region 21.5 s (11 orbit solves). Issue 36's three
pads, the tutorial's coarser box, take about 280 s, most of it in the vibration's branch
(110 s) and the one-parameter walks that locate its end at each damping (160 s).
"""

from __future__ import annotations

import argparse
import os
import platform

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from fivdisc import examples, load_case
from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.continuation.codim2 import curve_from_branch
from fivdisc.continuation.region import bistable_region
from fivdisc.continuation.walk import continue_orbit
from timing import fastest


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=100)
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument("--no-region", action="store_true", help="leave out the region")
    args = parser.parse_args()
    print(f"python {platform.python_version()}, {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} cores")
    base = load_case(examples.path("damped-disc"))
    case = base.replace({"speed.value": 12.3})
    periodic_orbit(case, transient=5.0)  # warm-up: the mode cache, the core
    one, orbit = fastest(args.rounds, lambda: periodic_orbit(case, transient=5.0))
    t_branch, branch = fastest(args.rounds, lambda: continue_orbit(
        case, "speed.value", 12.8, orbit=orbit, max_points=16))
    per_point = t_branch / len(branch)
    (k,) = [i for i, b in enumerate(branch.bifurcations()) if b["kind"] == "fold"]
    print(f"baseline: one orbit solve {one:.2f} s; one-parameter branch {len(branch)} points "
          f"in {t_branch:.2f} s ({per_point:.3f} s a point, the fold located on the way)")
    t_curve, curve = fastest(args.rounds, lambda: curve_from_branch(
        branch, k, "disc.damping_ratio", 0.0025, points=args.points))
    print(f"fold curve in the damping ratio: {len(curve)} points in {t_curve:.2f} s "
          f"({t_curve / len(curve):.3f} s a point) = {t_curve / one:.1f} orbit solves = "
          f"{t_curve / per_point:.0f} branch points; largest residual "
          f"{curve.dataset['residual'].values.max():.1e}, |condition| "
          f"{abs(curve.condition).max():.1e}")
    verdict = "meets" if t_curve * 100.0 / len(curve) < 60.0 else "misses"
    print(f"  {verdict} the target of 100 points in under 60 s")
    if args.no_region:
        return
    t_region, ds = fastest(args.rounds, lambda: bistable_region(
        base, ("speed.value", (18.0, 100.0)), ("disc.damping_ratio", (0.001, 0.003))))
    print(f"bistable region, 2 keys, defaults: {t_region:.1f} s = {t_region / one:.0f} orbit "
          f"solves = {t_region / per_point:.0f} branch points "
          f"({int((ds['region'].values == 1).sum())} of {ds['region'].size} grid points "
          "bistable)")
    verdict = "meets" if t_region < 300.0 else "misses"
    print(f"  {verdict} the target of under 5 minutes")


if __name__ == "__main__":
    main()
