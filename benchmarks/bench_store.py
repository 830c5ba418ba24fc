"""Time the checks of a sweep store (issue 28): fivdisc's against reading it through Zarr.

Run ``python benchmarks/bench_store.py`` (about a minute) or with ``--empty N --full M
--previous COMMIT``.
Every point's check needs one chunk of each stored variable; Zarr reads a chunk (or
finds it missing) at about half a millisecond, so checking a 300 x 300 store through it
took over a minute, before the sweep's first point and on every resume and ``--verify``.
Printed, per store, the wall time of :func:`fivdisc.sweep.verify_store` and of reading
the same variables through Zarr (the former method, the baseline), both per 100,000
points, and their ratio:

1. an empty N x N store (a sweep's start: nothing to read but the ``done`` listing);
2. a full M x M store (every point written, a seventh of them failed);
3. the empty 300 x 300 store of the fault probe, fivdisc's check alone;
4. the full M x M store checked by this fivdisc and by the store module of ``--previous``
   (default ``278cbee``: one chunk file per point and variable tried through Python file
   objects, hashing point by point), taken from this repository's history and imported
   beside it; checked in turns, three times each, the medians and their ratio.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from types import ModuleType
from typing import Any

from fivdisc.case import Case
from fivdisc.sweep import Sweep, SweepStore, store_lock, verify_store
from fivdisc.sweep.store import PointOutcome, checksummed

PER = 100_000  # points, the unit of the reported costs
REPO = Path(__file__).resolve().parents[1]
# The commit before the check read only the chunk files listed, each distinct content
# decoded once, and hashed a column at a time.
PREVIOUS = "278cbee"


def _spec(n: int) -> Sweep:
    return Sweep(base=Case(simulation={"duration": 0.01}),
                 axes={"slider.normal_damping": f"0.1:1.0:{n}", "speed.value": f"1.0:30.0:{n}"},
                 keep=["separated", "max_normal_force"])


def make_store(path: Path, n: int, full: bool) -> Sweep:
    """An n x n store, empty or with every point written (made-up outcomes)."""
    spec = _spec(n)
    with store_lock(path):
        store = SweepStore.open(path, spec)
        if full:
            store.write([PointOutcome(i, {"separated": i % 2 == 0, "max_normal_force": 1.0 * i})
                         if i % 7 else PointOutcome(i, None, "failed on purpose")
                         for i in range(spec.n_points)])
    return spec


def through_zarr(path: Path, spec: Sweep) -> float:
    """Wall time [s] of reading every checked variable through Zarr."""
    import zarr

    start = time.perf_counter()
    for name in [*checksummed(spec), "checksum", "done"]:
        zarr.open_array(path / name, mode="r")[...]
    return time.perf_counter() - start


def fivdisc_check(path: Path) -> float:
    start = time.perf_counter()
    verify_store(path)
    return time.perf_counter() - start


def previous_store_module(commit: str) -> ModuleType:
    """``fivdisc.sweep.store`` as it was at `commit` (from this repository's history),
    imported beside the current one (its imports resolve to the current fivdisc)."""
    source = subprocess.run(["git", "show", f"{commit}:src/fivdisc/sweep/store.py"], cwd=REPO,
                            check=True, capture_output=True, text=True).stdout
    name = f"store_at_{commit}"
    module = ModuleType(name)
    sys.modules[name] = module  # dataclasses look their module up
    exec(compile(source, f"{commit}:store.py", "exec"), module.__dict__)
    return module


def alternate(path: Path, previous: ModuleType, rounds: int = 3) -> tuple[float, float]:
    """Median wall times [s] of this check and the previous one on the store at `path`,
    run in turns (the file system's cache warm for both)."""
    from fivdisc.sweep import store

    times: dict[Any, list[float]] = {store: [], previous: []}
    for module in times:
        module.verify_store(path)
    for _ in range(rounds):
        for module, spent in times.items():
            start = time.perf_counter()
            module.verify_store(path)
            spent.append(time.perf_counter() - start)
    return statistics.median(times[store]), statistics.median(times[previous])


def compare(label: str, path: Path, spec: Sweep) -> None:
    ours, theirs = fivdisc_check(path), through_zarr(path, spec)
    scale = PER / spec.n_points
    print(f"{label} ({spec.n_points} points): fivdisc {ours * scale:.3g} s, Zarr "
          f"{theirs * scale:.3g} s per {PER:,} points; ratio fivdisc / Zarr {ours / theirs:.3g}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--empty", type=int, default=100, help="side of the empty store")
    parser.add_argument("--full", type=int, default=40, help="side of the full store")
    parser.add_argument("--previous", default=PREVIOUS, help="commit of the earlier check")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        empty = Path(tmp) / "empty.zarr"
        compare("empty store", empty, make_store(empty, args.empty, full=False))
        full = Path(tmp) / "full.zarr"
        spec = make_store(full, args.full, full=True)
        compare("full store", full, spec)
        ours, before = alternate(full, previous_store_module(args.previous))
        scale = PER / spec.n_points
        print(f"full store ({spec.n_points} points): fivdisc {ours * scale:.3g} s, fivdisc at "
              f"{args.previous} {before * scale:.3g} s per {PER:,} points; ratio "
              f"{ours / before:.3g}")
        big = Path(tmp) / "big.zarr"
        make_store(big, 300, full=False)
        print(f"empty 300 x 300 store: fivdisc {fivdisc_check(big):.3g} s")


if __name__ == "__main__":
    main()
