"""Speed of stability maps (paper Fig. 3), beside a plain per-point baseline in the same run.

Run ``python benchmarks/bench_stability_map.py [--n 200]``. It times an n x n map of the
largest growth rate over (c_z, r0^2 c_phi) at 1 rad/s with ``fivdisc.stability_map``
(equilibrium reused where damping cannot change it, parameters patched, eigenvalues in
batches) and, on a sub-grid, the baseline that validates a case, builds the model and
solves the equilibrium and eigenproblem afresh at every point; the ratio is per point.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from fivdisc import Case, linear_stability, stability_map


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=200, help="map size n x n (default 200)")
    parser.add_argument("--baseline-n", type=int, default=20, help="baseline sub-grid size")
    args = parser.parse_args()
    case = Case(speed={"value": 1.0})
    x = ("slider.normal_damping", np.linspace(0.0, 12.0, args.n))
    y = ("slider.rotational_damping", np.linspace(0.0, 3.0, args.n))
    stability_map(case, (x[0], x[1][:2]), (y[0], y[1][:2]))  # compile / load the kernel

    start = time.perf_counter()
    ds = stability_map(case, x, y)
    fast = time.perf_counter() - start

    xs = np.linspace(0.0, 12.0, args.baseline_n)
    ys = np.linspace(0.0, 3.0, args.baseline_n)
    start = time.perf_counter()
    for cz in xs:
        for cphi in ys:
            linear_stability(case.replace({x[0]: float(cz), y[0]: float(cphi)}))
    slow = time.perf_counter() - start

    per_fast = fast / args.n**2
    per_slow = slow / args.baseline_n**2
    print(f"{args.n} x {args.n} map: {fast:.2f} s ({per_fast * 1e6:.0f} us per point); "
          f"stable at {ds['stable'].values.mean():.1%} of the grid")
    print(f"baseline, {args.baseline_n} x {args.baseline_n} points rebuilt one by one: "
          f"{slow:.2f} s ({per_slow * 1e6:.0f} us per point)")
    print(f"speed-up per point: {per_slow / per_fast:.1f}x")


if __name__ == "__main__":
    main()
