"""Speed of the exact stability boundary of the paper's Fig. 3 box, beside the 40 x 40
grid map of the same box in the same run.

Run ``python benchmarks/bench_stability_boundary.py [--repeat 3]``. For each panel of
Fig. 3 (Omega_c = 1 and 10 rad/s, alpha = 1 s/m) it times
``fivdisc.analysis.boundary.stability_boundary`` over (c_z, r0^2 c_phi) in [0, 12] x
[0, 3] and ``fivdisc.stability_map`` on a 40 x 40 grid of that box, best of `repeat`
runs each, and prints the times, the eigen-solves each made and the ratio.
"""

from __future__ import annotations

import argparse

import numpy as np

from fivdisc import load_case
from fivdisc.analysis.boundary import stability_boundary
from fivdisc.analysis.stability import stability_map
from fivdisc.examples import path
from timing import fastest

X, Y = "slider.normal_damping", "slider.rotational_damping"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs of each, best kept")
    args = parser.parse_args()
    for name in ("fig03a", "fig03b"):
        case = load_case(path(name))
        stability_boundary(case, (X, (0.0, 12.0)), (Y, (0.0, 3.0)), seeds=3)  # load kernels
        exact, ds = fastest(args.repeat, lambda c=case: stability_boundary(
            c, (X, (0.0, 12.0)), (Y, (0.0, 3.0))))
        grid, _ = fastest(args.repeat, lambda c=case: stability_map(
            c, (X, np.linspace(0.0, 12.0, 40)), (Y, np.linspace(0.0, 3.0, 40))))
        print(f"{name}: exact boundary {exact:.2f} s ({ds.attrs['evaluations']} eigen-solves, "
              f"{ds.sizes['point']} points on {ds.sizes['curve']} curve(s)); "
              f"40 x 40 map {grid:.2f} s (1600 eigen-solves); "
              f"boundary / map = {exact / grid:.2f}")


if __name__ == "__main__":
    main()
