"""Time the checks of a sweep store (issue 28): fivdisc's against reading it through Zarr,
and against the checks of earlier commits on the stores they wrote.

Run ``python benchmarks/bench_store.py`` (about two minutes) or with ``--empty N --full M
--previous COMMIT ...``.
A check reads every chunk file of every stored variable. Up to store format 4 a chunk
held one point: Zarr reads a chunk (or finds it missing) at about half a millisecond, so
checking a 300 x 300 store through it took over a minute, before the sweep's first point
and on every resume and ``--verify``, and fivdisc's own reading of the files still cost
some 12 s per 100,000 full points (file opens). Format 5 chunks blocks of up to 1024
points. Printed, per store, wall times per 100,000 points and their ratios:

1. an empty N x N store (a sweep's start: nothing to read but the ``done`` listing):
   :func:`fivdisc.sweep.verify_store` against reading the same variables through Zarr;
2. a full M x M store (every point written, a seventh of them failed), likewise;
3. the full M x M store, written and checked by this fivdisc, against the same points
   written and checked by the store module of each ``--previous`` commit (default
   ``278cbee``, one chunk file per point and variable tried through Python file objects,
   hashing point by point; and ``9d68a9a``, the last commit of format 4: only the chunk
   files listed opened, through the operating system), taken from this repository's
   history and imported beside it; checked in turns, three times each, the medians and
   their ratio;
4. the empty 300 x 300 store of the fault probe, fivdisc's check alone.
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
from fivdisc.sweep import Sweep, verify_store
from fivdisc.sweep.store.checksum import checksummed
from fivdisc.sweep.store.sweep_store import PointOutcome

PER = 100_000  # points, the unit of the reported costs
REPO = Path(__file__).resolve().parents[1]
# The commit before the check read only the chunk files listed, each distinct content
# decoded once, and hashed a column at a time; and the last commit of one point per chunk.
PREVIOUS = ("278cbee", "9d68a9a")


def _spec(n: int) -> Sweep:
    return Sweep(base=Case(simulation={"duration": 0.01}),
                 axes={"slider.normal_damping": f"0.1:1.0:{n}", "speed.value": f"1.0:30.0:{n}"},
                 keep=["separated", "max_normal_force"])


def current_store_module() -> ModuleType:
    """This fivdisc's store functions, as one module like the earlier commits' store.py."""
    from fivdisc.sweep.store.health import verify_store
    from fivdisc.sweep.store.lock import store_lock
    from fivdisc.sweep.store.sweep_store import SweepStore

    module = ModuleType("current")
    module.store_lock, module.SweepStore, module.verify_store = (store_lock, SweepStore,
                                                                 verify_store)
    return module


def make_store(path: Path, n: int, full: bool, module: Any = None) -> Sweep:
    """An n x n store, empty or with every point written (made-up outcomes), by the store
    module `module` (default: this fivdisc's)."""
    module = module or current_store_module()
    spec = _spec(n)
    with module.store_lock(path):
        store = module.SweepStore.open(path, spec)
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


def alternate(stores: dict[Any, Path], rounds: int = 3) -> dict[Any, float]:
    """Median wall times [s] of each store module's check of its store (module -> store
    path), run in turns (the file system's cache warm for all)."""
    times: dict[Any, list[float]] = {module: [] for module in stores}
    for module, path in stores.items():
        if not module.verify_store(path).complete.any():
            raise SystemExit(f"{module.__name__} finds no complete point in its store {path}")
    for _ in range(rounds):
        for module, spent in times.items():
            start = time.perf_counter()
            module.verify_store(stores[module])
            spent.append(time.perf_counter() - start)
    return {module: statistics.median(spent) for module, spent in times.items()}


def compare(label: str, path: Path, spec: Sweep) -> None:
    ours, theirs = fivdisc_check(path), through_zarr(path, spec)
    scale = PER / spec.n_points
    print(f"{label} ({spec.n_points} points): fivdisc {ours * scale:.3g} s, Zarr "
          f"{theirs * scale:.3g} s per {PER:,} points; ratio fivdisc / Zarr {ours / theirs:.3g}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--empty", type=int, default=100, help="side of the empty store")
    parser.add_argument("--full", type=int, default=100, help="side of the full store")
    parser.add_argument("--previous", nargs="+", default=PREVIOUS,
                        help="commits of the earlier checks")
    args = parser.parse_args()
    current = current_store_module()

    with tempfile.TemporaryDirectory() as tmp:
        empty = Path(tmp) / "empty.zarr"
        compare("empty store", empty, make_store(empty, args.empty, full=False))
        full = Path(tmp) / "full.zarr"
        spec = make_store(full, args.full, full=True)
        compare("full store", full, spec)
        stores = {current: full}
        for commit in args.previous:
            module = previous_store_module(commit)
            stores[module] = Path(tmp) / f"full-{commit}.zarr"
            make_store(stores[module], args.full, full=True, module=module)
        times = alternate(stores)
        scale = PER / spec.n_points
        ours = times.pop(current)
        for commit, before in zip(args.previous, times.values(), strict=True):
            print(f"full store ({spec.n_points} points): fivdisc {ours * scale:.3g} s, fivdisc "
                  f"at {commit} {before * scale:.3g} s per {PER:,} points (each on the store "
                  f"it writes); ratio {ours / before:.3g}")
        big = Path(tmp) / "big.zarr"
        make_store(big, 300, full=False)
        print(f"empty 300 x 300 store: fivdisc {fivdisc_check(big):.3g} s")


if __name__ == "__main__":
    main()
