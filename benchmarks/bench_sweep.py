"""Time sweeps: the paper's Fig. 27 separation map, per-worker throughput, 2 vs 1 workers.

Run ``python benchmarks/bench_sweep.py`` (a 40 x 40 map, a few minutes on two cores) or
``python benchmarks/bench_sweep.py --n 12`` for a smaller map. Printed:

1. the speed of a single run in this process (simulated seconds per wall second);
2. a ``--ratio-n`` x ``--ratio-n`` sub-map computed serially in this process, then on a
   local pool of 1 and of 2 workers: throughput per worker against the serial rate,
   and the ratio of 2-worker to 1-worker wall time (0.5 is perfect scaling);
3. the wall time of the ``--n`` x ``--n`` map on ``--workers`` workers.

Pool wall times include starting the worker processes.
"""

from __future__ import annotations

import argparse
import resource
import tempfile
import time
from pathlib import Path

from fivdisc.engine.simulation import simulate
from fivdisc.plots import plot_separation_map
from fivdisc.sweep import (
    open_sweep,
    run_sweep,
    separation_sweep,
)
from fivdisc.sweep.reductions import evaluate
from fivdisc.sweep.separation import DEFAULT_RANGES

X_RANGE = (2.0, 20.0)  # Omega_0 [rad/s], as the default Fig. 27 map
Y_RANGE = (1.0, 40.0)  # t_max [s]


def _axis(bounds: tuple[float, float], n: int) -> str:
    return f"{bounds[0]}:{bounds[1]}:{n}"


def single_run_speed() -> float:
    """Simulated seconds per wall second of one run without separation (Omega_0 = 6 rad/s)."""
    case = separation_sweep(x=[6.0], y=[20.0]).cases[0]
    start = time.perf_counter()
    simulate(case, stop_on=("separation",))
    return case.simulation.duration / (time.perf_counter() - start)


def _cpu() -> float:
    """CPU time of this process (the coordinator, not its workers) [s]."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def timed_sweep(n: int, workers: int, store: Path) -> tuple[float, float, int]:
    """Wall time [s], coordinator CPU time [s] and separated points of an n x n map."""
    spec = separation_sweep(x=_axis(X_RANGE, n), y=_axis(Y_RANGE, n))
    start, cpu = time.perf_counter(), _cpu()
    run_sweep(spec, store, workers=workers, progress=False)
    wall, cpu = time.perf_counter() - start, _cpu() - cpu
    return wall, cpu, int(open_sweep(store)["separated"].sum())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=40, help="map size n x n (default 40)")
    parser.add_argument("--ratio-n", type=int, default=8, help="sub-map size for the scaling")
    parser.add_argument("--workers", type=int, default=2, help="workers of the full map")
    parser.add_argument("--figure", type=Path, help="draw the full map to this image")
    args = parser.parse_args()
    assert DEFAULT_RANGES["decelerating"] == (_axis(X_RANGE, 40), _axis(Y_RANGE, 40))

    speed = single_run_speed()
    print(f"single run: {speed:.1f} simulated s per wall s")

    m = args.ratio_n
    spec = separation_sweep(x=_axis(X_RANGE, m), y=_axis(Y_RANGE, m))
    start = time.perf_counter()
    for case in spec.cases:
        evaluate(case, spec.keep)
    serial = time.perf_counter() - start
    print(
        f"{m} x {m} sub-map, serial in this process: {serial:.2f} s "
        f"({spec.n_points / serial:.2f} points/s)"
    )

    with tempfile.TemporaryDirectory() as tmp:
        walls = {}
        for workers in (1, 2):
            wall, _, _ = timed_sweep(m, workers, Path(tmp) / f"ratio-{workers}.zarr")
            walls[workers] = wall
            rate = spec.n_points / wall / workers
            print(
                f"{m} x {m} sub-map, {workers} worker(s): {wall:.2f} s, "
                f"{rate:.2f} points/s per worker = {rate * serial / spec.n_points:.2f} x serial"
            )
        print(f"2-worker / 1-worker wall time: {walls[2] / walls[1]:.3f}")

        n = args.n
        store = Path(tmp) / "map.zarr"
        wall, cpu, separated = timed_sweep(n, args.workers, store)
        print(
            f"{n} x {n} Fig. 27 map, {args.workers} worker(s): {wall:.1f} s "
            f"({n * n / wall:.2f} points/s), {separated} of {n * n} points separate; "
            f"coordinator CPU {1e3 * cpu / (n * n):.1f} ms per point"
        )
        # The sub-map samples the same ranges, so its serial rate is the per-point speed
        # of single runs over this map.
        per_worker = n * n / wall / args.workers
        print(f"  per worker {per_worker:.2f} points/s = "
              f"{per_worker * serial / spec.n_points:.2f} x the serial rate")
        if args.figure:
            plot_separation_map(store, args.figure)
            print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
