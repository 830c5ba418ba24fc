"""The local pools of a sweep side by side: threads against processes, as whole commands.

Run ``python benchmarks/bench_sweep_pool.py`` (``--repeat N`` commands per pool and sweep,
default 3; ``--workers`` of each pool, default 2; ``--baseline COMMIT`` also times the
command of an earlier commit, on its default pool, e.g. the commit before the thread
pool). The fivdisc on ``sys.path`` is timed: set ``PYTHONPATH=src`` to time a clone.

Each command is ``fivdisc sweep SWEEP -o STORE --pool POOL --workers 2`` into a new store,
in a fresh process; the pools take turns (thread, process, thread, ...), so that a change
of the machine's load falls on both alike. Per sweep it prints the medians of

- ``first start``, ``first end``: from the command's start (before its process is
  created) until the first point starts, and ends, in a worker [s] (issue 37, item 5:
  the first point starts within 0.5 s);
- ``span``: from the first point's start to the last point's end [s], and
  ``in span`` = points / span, the pool's throughput without its start (on threads the
  span includes the coordinator loading Zarr and creating the store, in the same
  process: the points take turns with it for the GIL);
- ``wall``: the whole command [s], and ``points/s`` = points / wall;
- ``cpu``: processor time of the command and its worker processes (user and system) [s],
  which says more than the wall time on a loaded machine;

and the ratios thread / process of each (< 1: threads better). The sweeps: ``short``,
40 points of 0.05 s simulated (about 10 ms each: the pool's overhead dominates);
``separation``, a 6 x 6 Fig. 27 map (0.1-0.5 s a point, runs ending at their first
separation); ``long``, 8 points of 100 s simulated (about 1 s each: the integration,
GIL released, dominates).

Then, in this process, the throughput of warm pools alone (``--steady``, on by default):
the points of each sweep mapped over a thread pool and a process pool started and warmed
beforehand, taking turns, without a store; wall and processor time (this process and
the pool's processes) per pool, and the ratios thread / process.

The workers' points are timed by a ``sitecustomize`` module put on ``PYTHONPATH`` (in
a temporary directory; every process of the command loads it, spawned workers too),
which wraps ``run_point`` and appends each point's start and end to a log file.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import Executor, ProcessPoolExecutor, ThreadPoolExecutor
from multiprocessing import get_context
from pathlib import Path

import psutil

from fivdisc import examples
from fivdisc.sweep import load_sweep
from fivdisc.sweep.point import run_point
from previous import source_tree

_CLI = "from fivdisc.cli import main; main()"
POOLS = ("thread", "process")

# Loaded by every Python process of a timed command (spawned workers included) when its
# directory is on PYTHONPATH: wraps fivdisc.sweep.point.run_point (fivdisc.sweep.run's
# before the thread pool) once that module is executed, to log each point's start and
# end (time.time()) to $FIVDISC_POINT_LOG.
_PROBE = '''
import importlib.abc
import importlib.machinery
import os
import sys
import time

_LOG = os.environ.get("FIVDISC_POINT_LOG")
_MODULES = ("fivdisc.sweep.point", "fivdisc.sweep.run")


def _log(what):
    with open(_LOG, "a") as log:
        log.write(f"{time.time():.6f} {os.getpid()} {what}\\n")


class _Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name not in _MODULES:
            return None
        spec = importlib.machinery.PathFinder.find_spec(name, path)
        if spec is None or not hasattr(spec.loader, "exec_module"):
            return spec
        execute = spec.loader.exec_module

        def exec_module(module):
            execute(module)
            original = module.__dict__.get("run_point")
            if original is None or original.__module__ != module.__name__:
                return  # a re-export: wrapped where it is defined

            def run_point(index, *args, **kwargs):
                _log(f"start {index}")
                try:
                    return original(index, *args, **kwargs)
                finally:
                    _log(f"end {index}")

            run_point.__module__, run_point.__qualname__ = module.__name__, "run_point"
            module.run_point = run_point

        spec.loader.exec_module = exec_module
        return spec


if _LOG:
    sys.meta_path.insert(0, _Finder())
'''


def _sweeps(workdir: Path) -> dict[str, tuple[Path, int]]:
    """Name -> (sweep file, points)."""
    base = examples.path("fig27_base")
    texts = {
        "short": ('[base.simulation]\nduration = 0.05\n[axes]\n'
                  '"speed.value" = "1.0:6.0:40"\n[reduce]\nkeep = ["separated"]\n', 40),
        "separation": (f'base = "{base}"\n[axes]\n"speed.initial" = "2.0:20.0:6"\n'
                       '"speed.duration" = "1.0:40.0:6"\n[link]\n'
                       '"simulation.duration" = "speed.duration"\n[reduce]\n'
                       'keep = ["separated", "first_separation_time"]\n', 36),
        "long": ('[base.simulation]\nduration = 100.0\noutput_rate = 1000.0\n[axes]\n'
                 '"speed.value" = "2.0:6.0:8"\n[reduce]\n'
                 'keep = ["max_normal_force", "stick_fraction"]\n', 8),
    }
    sweeps = {}
    for name, (text, n) in texts.items():
        path = workdir / f"{name}.toml"
        path.write_text(text, encoding="utf-8")
        sweeps[name] = (path, n)
    return sweeps


def _command(sweep: Path, store: Path, pool: str | None, workers: int,
             env: dict[str, str], log: Path) -> dict[str, float]:
    """Run one sweep command into a new store; its timings [s]."""
    shutil.rmtree(store, ignore_errors=True)
    log.unlink(missing_ok=True)
    argv = [sys.executable, "-c", _CLI, "sweep", str(sweep), "-o", str(store),
            "--workers", str(workers), "--no-progress"]
    if pool is not None:
        argv += ["--pool", pool]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start, wall0 = time.time(), time.perf_counter()
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL, env=env)
    wall = time.perf_counter() - wall0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    starts, ends = [], []
    for line in log.read_text().splitlines():
        stamp, _, what, _ = line.split()
        (starts if what == "start" else ends).append(float(stamp) - start)
    return {"first start": min(starts), "first end": min(ends),
            "span": max(ends) - min(starts), "wall": wall,
            "cpu": (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)}


def _warm() -> None:
    import fivdisc.engine.simulation  # noqa: F401


def _cpu() -> float:
    """Processor time of this process (all threads) and its live children [s]."""
    me = psutil.Process()
    total = sum(me.cpu_times()[:2])
    for child in me.children(recursive=True):
        try:
            total += sum(child.cpu_times()[:2])
        except psutil.NoSuchProcess:
            pass
    return total


def _mapped(pool: Executor, sweep: Path) -> tuple[float, float]:
    """Wall and processor time [s] of the sweep's points mapped over `pool`."""
    spec = load_sweep(sweep)
    work = (tuple(spec.keep), spec.sections, spec.lyapunov)
    n = spec.n_points
    cpu, start = _cpu(), time.perf_counter()
    list(pool.map(run_point, range(n), spec.cases, *([w] * n for w in work)))
    return time.perf_counter() - start, _cpu() - cpu


def steady(sweeps: dict[str, tuple[Path, int]], names: list[str], workers: int,
           repeat: int) -> None:
    """Print the throughput of warm pools, taking turns."""
    pools = {"thread": ThreadPoolExecutor(workers),
             "process": ProcessPoolExecutor(workers, mp_context=get_context("spawn"))}
    for future in [pools["process"].submit(_warm) for _ in range(2 * workers)]:
        future.result()
    print(f"\nwarm pools, points mapped without a store, median of {repeat} each")
    print(f"{'sweep':<12}{'thread [s]':>12}{'process [s]':>12}{'wall t/p':>10}"
          f"{'cpu t/p':>9}  wall t/p per pair; load average")
    for name in names:
        sweep = sweeps[name][0]
        for pool in pools.values():  # once before the timing: caches, the file cache
            _mapped(pool, sweep)
        samples: dict[str, list[tuple[float, float]]] = {k: [] for k in pools}
        for _ in range(repeat):
            for kind, pool in pools.items():
                samples[kind].append(_mapped(pool, sweep))
        wall = {k: statistics.median(w for w, _ in v) for k, v in samples.items()}
        cpu = {k: statistics.median(c for _, c in v) for k, v in samples.items()}
        pairs = ", ".join(f"{t[0] / p[0]:.2f}" for t, p in zip(samples["thread"],
                                                               samples["process"],
                                                               strict=True))
        print(f"{name:<12}{wall['thread']:>12.3f}{wall['process']:>12.3f}"
              f"{wall['thread'] / wall['process']:>10.2f}"
              f"{cpu['thread'] / cpu['process']:>9.2f}  {pairs}; "
              f"{os.getloadavg()[0]:.2f}")
    for pool in pools.values():
        pool.shutdown()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="commands per pool and sweep")
    parser.add_argument("--workers", type=int, default=2, help="threads or processes")
    parser.add_argument("--sweeps", default="short,separation,long",
                        help="which sweeps, comma separated (default: all three)")
    parser.add_argument("--no-steady", dest="steady", action="store_false",
                        help="leave out the throughput of warm pools")
    parser.add_argument("--baseline", metavar="COMMIT",
                        help="also time the command of this earlier commit (default pool)")
    args = parser.parse_args()
    # One core per process, as in the other benchmarks.
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    import fivdisc

    here = str(Path(fivdisc.__file__).resolve().parents[1])
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        (workdir / "probe").mkdir()
        (workdir / "probe" / "sitecustomize.py").write_text(_PROBE, encoding="utf-8")
        log = workdir / "points.log"

        def environment(tree: str) -> dict[str, str]:
            return {**os.environ, "FIVDISC_POINT_LOG": str(log),
                    "PYTHONPATH": os.pathsep.join([str(workdir / "probe"), tree])}

        runs: list[tuple[str, str | None, dict[str, str]]] = [
            (pool, pool, environment(here)) for pool in POOLS]
        if args.baseline:
            tree = source_tree(args.baseline)
            # The compiled core is built, not committed: the working tree's, if the
            # commit's core sources are the same (the caller's to know).
            core = Path(fivdisc.__file__).parent / "core"
            for built in core.glob("_core*.so"):
                if not (tree / "fivdisc" / "core" / built.name).exists():
                    shutil.copy2(built, tree / "fivdisc" / "core" / built.name)
            runs.append((f"@{args.baseline}", None, environment(str(tree))))
        sweeps = _sweeps(workdir)
        print(f"{args.workers} workers, median of {args.repeat} commands each, pools "
              f"alternating; {os.cpu_count()} CPUs; {sys.executable}")
        names = args.sweeps.split(",")
        for name in names:
            sweep, n = sweeps[name]
            store = workdir / f"{name}.zarr"
            load = os.getloadavg()[0]
            # Once before the timing: compiled bytecode, the file cache.
            _command(sweep, store, runs[0][1], args.workers, runs[0][2], log)
            samples: dict[str, list[dict[str, float]]] = {label: [] for label, _, _ in runs}
            for _ in range(args.repeat):
                for label, pool, env in runs:
                    samples[label].append(_command(sweep, store, pool, args.workers, env, log))
            print(f"\n{name}: {n} points; load average {load:.2f} before, "
                  f"{os.getloadavg()[0]:.2f} after")
            keys = ("first start", "first end", "span", "wall", "cpu")
            print(f"{'pool':<12}" + "".join(f"{k + ' [s]':>16}" for k in keys)
                  + f"{'points/s':>10}{'in span':>9}")
            medians = {label: {k: statistics.median(s[k] for s in runs_)
                               for k in keys} for label, runs_ in samples.items()}
            for label, m in medians.items():
                print(f"{label:<12}" + "".join(f"{m[k]:>16.3f}" for k in keys)
                      + f"{n / m['wall']:>10.2f}{n / m['span']:>9.2f}")
            thread, process = medians["thread"], medians["process"]
            print(f"{'thread/proc':<12}" + "".join(f"{thread[k] / process[k]:>16.2f}"
                                                  for k in keys)
                  + f"{process['wall'] / thread['wall']:>10.2f}"
                  f"{process['span'] / thread['span']:>9.2f}")
            # Each pair (thread, process) ran back to back: its ratios are the least
            # affected by a load that changes during the run.
            for key in ("wall", "span", "cpu"):
                pairs = [t[key] / p[key] for t, p in zip(samples["thread"],
                                                         samples["process"], strict=True)]
                print(f"  {key} thread/process per pair: "
                      f"{', '.join(f'{r:.2f}' for r in pairs)}")
        if args.steady:
            steady(sweeps, names, args.workers, args.repeat)


if __name__ == "__main__":
    main()
