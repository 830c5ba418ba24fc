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
   files listed opened, through the operating system); checked in turns, three times
   each, the medians and their ratio;
4. the empty 300 x 300 store of the fault probe, fivdisc's check alone.

An earlier commit's store runs as it was, with that commit's own package: in a process of
its own (one per commit, started once, asked for each check in its turn, timing it
itself), with the Python of the commit's virtual environment, ``previous.environment``
(built once and cached, with the ``distributed`` extra; a minute or two the first time).
Its store module alone, imported beside this fivdisc (as this benchmark did before), no
longer runs: its imports from the package resolve to today's modules, and one of them,
``fivdisc.conventions`` (the attributes of a new store), is gone since the package moved
into layer folders; the others (the sweep's spec, its reductions) would be today's, not
the commit's. Its whole package on this interpreter does not import either: it needs the
numba kernel, which this interpreter need not have. That environment is the same
interpreter with the same libraries (zarr, numcodecs, xarray, numpy, at this
interpreter's versions) plus numba, which the store does not use.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

from fivdisc.case import Case
from fivdisc.sweep import Sweep, verify_store
from fivdisc.sweep.store.checksum import checksummed
from fivdisc.sweep.store.sweep_store import PointOutcome
from previous import environment, without_pythonpath

PER = 100_000  # points, the unit of the reported costs
# The commit before the check read only the chunk files listed, each distinct content
# decoded once, and hashed a column at a time; and the last commit of one point per chunk.
PREVIOUS = ("278cbee", "9d68a9a")

# The sweep of every store: its base case's settings, axes and kept reductions.
_BASE = {"simulation": {"duration": 0.01}}
_KEEP = ["separated", "max_normal_force"]


def _axes(n: int) -> dict[str, str]:
    return {"slider.normal_damping": f"0.1:1.0:{n}", "speed.value": f"1.0:30.0:{n}"}


def _spec(n: int) -> Sweep:
    return Sweep(base=Case(**_BASE), axes=_axes(n), keep=_KEEP)


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
    """Wall time [s] of this fivdisc's check of the store at `path`."""
    start = time.perf_counter()
    verify_store(path)
    return time.perf_counter() - start


# Run by an earlier commit's Python, with its fivdisc (a store module of one file,
# ``fivdisc.sweep.store``, up to format 4): writes the full store as make_store does, checks
# it once, prints its number of points, then checks it once per line read, printing the
# check's wall time [s].
_PREVIOUS_STORE = """\
import json, sys, time
from pathlib import Path
from fivdisc.case import Case
from fivdisc.sweep import store as module
from fivdisc.sweep.spec import Sweep
path, (base, axes, keep) = Path(sys.argv[1]), json.loads(sys.argv[2])
spec = Sweep(base=Case(**base), axes=axes, keep=keep)
with module.store_lock(path):
    store = module.SweepStore.open(path, spec)
    store.write([module.PointOutcome(i, {"separated": i % 2 == 0, "max_normal_force": 1.0 * i})
                 if i % 7 else module.PointOutcome(i, None, "failed on purpose")
                 for i in range(spec.n_points)])
if not module.verify_store(path).complete.any():
    raise SystemExit(f"no complete point in its store {path}")
print(spec.n_points, flush=True)
for _ in sys.stdin:
    start = time.perf_counter()
    module.verify_store(path)
    print(time.perf_counter() - start, flush=True)
"""


class PreviousStore:
    """The store of an earlier commit, written and checked by that commit's fivdisc in a
    process of its own; ``check()`` has it checked once more and returns the wall time
    [s] that process measured."""

    def __init__(self, commit: str, path: Path, n: int) -> None:
        python = environment(commit, extras=("distributed",))
        self.commit = commit
        self.process = subprocess.Popen(
            [str(python), "-c", _PREVIOUS_STORE, str(path),
             json.dumps([_BASE, _axes(n), _KEEP])], stdin=subprocess.PIPE,
            stdout=subprocess.PIPE, text=True, env=without_pythonpath(), cwd=path.parent)
        if self._line() != str(n * n):
            raise SystemExit(f"the store of {commit} has not {n} x {n} points")

    def _line(self) -> str:
        line = self.process.stdout.readline()
        if not line:
            raise SystemExit(f"the store process of {self.commit} ended "
                             f"({self.process.wait()}); its error is above")
        return line.strip()

    def check(self) -> float:
        self.process.stdin.write("check\n")
        self.process.stdin.flush()
        return float(self._line())

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait()


def alternate(checks: dict[str, Callable[[], float]], rounds: int = 3) -> dict[str, float]:
    """Median wall times [s] of each check (name -> a function doing it once and returning
    its wall time), run in turns (the file system's cache warm for all)."""
    times: dict[str, list[float]] = {name: [] for name in checks}
    for _ in range(rounds):
        for name, spent in times.items():
            spent.append(checks[name]())
    return {name: statistics.median(spent) for name, spent in times.items()}


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

    with tempfile.TemporaryDirectory() as tmp:
        empty = Path(tmp) / "empty.zarr"
        compare("empty store", empty, make_store(empty, args.empty, full=False))
        full = Path(tmp) / "full.zarr"
        spec = make_store(full, args.full, full=True)
        compare("full store", full, spec)
        if not verify_store(full).complete.any():
            raise SystemExit(f"fivdisc finds no complete point in its store {full}")
        previous = [PreviousStore(commit, Path(tmp) / f"full-{commit}.zarr", args.full)
                    for commit in args.previous]
        try:
            times = alternate({"": lambda: fivdisc_check(full),
                               **{store.commit: store.check for store in previous}})
        finally:
            for store in previous:
                store.close()
        scale = PER / spec.n_points
        ours = times.pop("")
        for commit, before in zip(args.previous, times.values(), strict=True):
            print(f"full store ({spec.n_points} points): fivdisc {ours * scale:.3g} s, fivdisc "
                  f"at {commit} {before * scale:.3g} s per {PER:,} points (each on the store "
                  f"it writes); ratio {ours / before:.3g}")
        big = Path(tmp) / "big.zarr"
        make_store(big, 300, full=False)
        print(f"empty 300 x 300 store: fivdisc {fivdisc_check(big):.3g} s")


if __name__ == "__main__":
    main()
