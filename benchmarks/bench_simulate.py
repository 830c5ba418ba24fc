"""Speed of the compiled simulator, side by side with the scipy baseline in the same run.

Run ``python benchmarks/bench_simulate.py`` (``--quick`` for a shorter baseline span).
It prints:

1. the ratio of the scipy ``solve_ivp`` (RK45, numpy right-hand side, Python events)
   wall time to fivdisc's, same equations, same tolerances, same simulated span, one core;
2. the wall time of the paper's Fig. 10 case (decelerating from 2 pi rad/s over
   t_max = 35 s, 7 modal coordinates, output at 10 kHz) after a first run;
3. the time a fresh process needs to import fivdisc and finish a first short simulation;
4. the peak resident memory of a process running the Fig. 10 case.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import textwrap
import time

# One core, as in the targets: keep BLAS from spreading over the other.
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from baseline import baseline_simulate
from fivdisc import Case, simulate

FIG10 = Case(
    slider={"normal_damping": 0.1, "rotational_damping": 0.1},
    friction={"decay": 1.0},
    speed={"profile": "decelerating", "initial": 2 * np.pi, "duration": 35.0},
    simulation={"duration": 35.0, "output_rate": 10000.0},
)


def _median_time(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def against_baseline(span: float) -> None:
    """Same case (paper Fig. 8: stick-slip from rest), same tolerances, same span."""
    case = Case(simulation={"duration": span, "output_rate": 10000.0})
    fast = _median_time(lambda: simulate(case), 5)
    slow = _median_time(lambda: baseline_simulate(case, span), 1)
    ref = baseline_simulate(case, span)
    res = simulate(case).dataset
    # Both integrate at rtol 1e-6: their switch sequences must match for the ratio to
    # compare like with like.
    same = list(res["event_kind"].values) == [e[3] for e in ref.events]
    print(f"baseline (scipy RK45, rtol {case.simulation.rtol:g}) over {span} s: {slow:.3f} s")
    print(f"fivdisc over the same span:                      {fast:.4f} s")
    print(f"speed-up: {slow / fast:.0f}x   (same switch sequence: {same})")


def fig10() -> None:
    simulate(FIG10.replace({"simulation.duration": 0.01}))  # imports
    wall = _median_time(lambda: simulate(FIG10), 3)
    res = simulate(FIG10)
    a = res.dataset.attrs
    print(f"Fig. 10 case (35 s, 10 kHz output): {wall:.3f} s wall (median of 3); "
          f"{a['n_steps']} steps, {a['n_switches']} switches, status {res.status}")


def cold_process() -> None:
    code = textwrap.dedent(
        """
        import time
        t0 = time.perf_counter()
        import fivdisc
        fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.01}))
        print(time.perf_counter() - t0)
        """
    )
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)  # file cache
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                         text=True)
    total = time.perf_counter() - start
    print(f"fresh process: first simulation done {float(out.stdout):.2f} s "
          f"after start of import ({total:.2f} s including interpreter start-up)")


def peak_memory() -> None:
    code = textwrap.dedent(
        """
        import numpy as np, fivdisc
        case = fivdisc.Case(
            slider={"normal_damping": 0.1, "rotational_damping": 0.1},
            friction={"decay": 1.0},
            speed={"profile": "decelerating", "initial": 2 * np.pi, "duration": 35.0},
            simulation={"duration": 35.0, "output_rate": 10000.0},
        )
        fivdisc.simulate(case)
        """
    )
    subprocess.run([sys.executable, "-c", code], check=True)
    peak_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"peak resident memory of a process running the Fig. 10 case: {peak_mb:.0f} MB")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="0.2 s baseline span (else 0.5 s)")
    args = parser.parse_args()
    against_baseline(0.2 if args.quick else 0.5)
    fig10()
    cold_process()
    peak_memory()


if __name__ == "__main__":
    main()
