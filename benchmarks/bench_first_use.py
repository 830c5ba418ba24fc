"""First use of each command against later use, from a fresh install of the working tree,
side by side with the last numba kernel's first use from an empty numba cache.

Run ``python benchmarks/bench_first_use.py`` (``--baseline COMMIT``, default
``previous.LAST_NUMBA``; ``--rounds N``, default 1; ``--only NAME`` for some of the
commands; ``--installed`` to time the fivdisc of this interpreter instead of a fresh
install). The working tree is installed with ``pip install`` into a new virtual
environment (about a minute: the compiled core is built then), and each command runs as
a whole process the way a new user starts it: its first use in that installation, then
its later use (the same command again, ``--rounds`` times). A single process varies by
about 10 %, so there are ``--installs`` installations (default 5: the fresh install and
copies of it, file for file), each giving one first use per command and its later uses
right after it, so that first and later uses alternate in time and a drift of the
machine's speed during the run falls on both alike; the median first use is compared
with the median later use, and each installation's first use with its own later use.
Every installation's commands start from an empty cache of disc modes
(``FIVDISC_CACHE_DIR`` set to a new directory: a new user's machine), with Python writing
its bytecode (its default, whatever the calling shell says).

The earlier commit runs with the Python of its own virtual environment,
``previous.environment`` (built once and cached under ``~/.cache/fivdisc-bench``; with
the ``distributed`` extra when ``sweep`` is timed), without ``PYTHONPATH``: its kernel is
numba, which the working tree no longer depends on and its environment need not have
(its sources on this interpreter end in an ImportError). That environment is a virtual
environment of the same interpreter with the same libraries plus numba (both sides'
versions are printed; for ``previous.LAST_NUMBA`` numpy, scipy and pydantic are the
same), so that the difference is fivdisc's own code and its kernel. Each of its
processes gets ``NUMBA_CACHE_DIR`` set to a new empty directory, which that commit's
kernels look in first (``fivdisc._kernels.cache``), before the ``__pycache__`` of the
installed copy that other runs may have filled: every kernel the command needs compiles,
the way it did after a fresh install then (the number of kernels compiled into the
directory is printed as a check). Its other cache, the plate's modes, goes to the same
directory unless ``FIVDISC_CACHE_DIR`` is set.

It prints each process's wall time [s], first use / later use (target of issue 37, item
5: within 10 %) and first use now / first use then, with the load average before and
after and each process's processor time: on a machine shared with other work the
absolute times say little, the ratios more.
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
from pathlib import Path

from previous import LAST_NUMBA, environment, versions, without_pythonpath

REPO = Path(__file__).resolve().parents[1]
# The console script `fivdisc` runs exactly this; through the interpreter being timed.
_CLI = "from fivdisc.cli import main; main()"

# name: arguments; short runs, so that the time is mostly the command's start.
COMMANDS: dict[str, tuple[str, ...]] = {
    "simulate": ("simulate", "fig10", "-o", "fig10.nc", "--no-progress"),
    "orbit": ("orbit", "fig13", "--transient", "5", "--no-progress"),
    "lyapunov": ("lyapunov", "fig13", "--transient", "1", "--duration", "1", "--no-progress"),
    "continue": ("continue", "fig13", "--key", "speed.value", "--to", "6.35", "--points",
                 "3", "--transient", "5", "--no-progress"),
    "stability": ("stability",),
    "sweep": ("sweep", "small-sweep.toml", "-o", "sweep.zarr", "--no-progress", "--workers",
              "2"),
}
# A sweep of 2 x 2 short runs of a decelerating disc, written into each working directory;
# its store is removed before each run, so that every run computes every point.
_SWEEP = """\
[base.speed]
profile = "decelerating"
initial = 6.0
duration = 5.0

[base.simulation]
duration = 0.2
output_rate = 100.0

[axes]
"speed.initial" = "2.0:6.0:2"
"speed.duration" = "5.0:20.0:2"

[reduce]
keep = ["separated"]
"""
# Processor time of each process timed, in order [s].
CPU: list[float] = []


def _cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _seconds(python: str, args: tuple[str, ...], env: dict[str, str], workdir: Path) -> float:
    """Wall time of one process running the command line with ``args`` [s]; its processor
    time (with its workers') goes to ``CPU``."""
    env = {**env, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    (workdir / "small-sweep.toml").write_text(_SWEEP)
    shutil.rmtree(workdir / "sweep.zarr", ignore_errors=True)
    cpu = _cpu()
    start = time.perf_counter()
    out = subprocess.run([python, "-c", _CLI, *args], env=env, cwd=workdir,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    seconds = time.perf_counter() - start
    CPU.append(_cpu() - cpu)
    # Exit status 1 is a result (an orbit not converged, an inconclusive exponent), not
    # a failure of the benchmark; a traceback is (numba missing from the interpreter that
    # runs the numba commit's tree made its "first use" 0.3 s).
    if out.returncode not in (0, 1) or "Traceback (most recent call last)" in out.stderr:
        raise SystemExit(f"fivdisc {' '.join(args)} failed ({out.returncode}):\n"
                         f"{out.stderr}")
    return seconds


def _fresh_install(home: Path) -> str:
    """Python of a new virtual environment with the working tree installed (with the
    distributed extra, which `fivdisc sweep` needs)."""
    subprocess.run([sys.executable, "-m", "venv", str(home)], check=True)
    python = str(home / "bin" / "python")
    start = time.perf_counter()
    subprocess.run([python, "-m", "pip", "install", "-q", f"{REPO}[distributed]"], check=True)
    print(f"pip install of the working tree: {time.perf_counter() - start:.0f} s", flush=True)
    return python


def _installations(tmp: Path, count: int) -> list[tuple[str, dict[str, str]]]:
    """Python and environment of `count` installations of the working tree, each as a new
    user's machine has it: no disc modes stored yet (only those that ship with the
    package) and Python writing its bytecode as it does by default. One fresh install and
    `count` - 1 copies of it, file for file with their times (so that the bytecode pip
    compiled stays valid): each gives a first use."""
    env = without_pythonpath()
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    _fresh_install(tmp / "venv0")
    for k in range(1, count):
        shutil.copytree(tmp / "venv0", tmp / f"venv{k}", symlinks=True)
    return [(str(tmp / f"venv{k}" / "bin" / "python"),
             {**env, "FIVDISC_CACHE_DIR": str(tmp / f"cache{k}")}) for k in range(count)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default=LAST_NUMBA, help="earlier (numba) commit")
    parser.add_argument("--rounds", type=int, default=1,
                        help="later uses per command and installation")
    parser.add_argument("--installs", type=int, default=5,
                        help="installations, each giving one first use per command")
    parser.add_argument("--only", action="append", choices=sorted(COMMANDS),
                        help="time this command (repeatable; default: all)")
    parser.add_argument("--installed", action="store_true",
                        help="time the fivdisc of this interpreter, not a fresh install")
    args = parser.parse_args()
    names = args.only or list(COMMANDS)
    # `fivdisc sweep` needs the distributed extra, at that commit as now.
    before = str(environment(args.baseline,
                             extras=("distributed",) if "sweep" in names else ()))
    load = os.getloadavg()[0]
    first: dict[str, list[float]] = {n: [] for n in names}
    later: dict[str, list[float]] = {n: [] for n in names}
    then: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as tmp:
        if args.installed:
            installs = [(sys.executable, dict(os.environ))]
        else:
            installs = _installations(Path(tmp), args.installs)
        python = installs[0][0]
        for name in names:
            cmd = COMMANDS[name]
            pairs = []
            for k, (python_k, env_k) in enumerate(installs):
                with tempfile.TemporaryDirectory() as work:
                    first[name].append(_seconds(python_k, cmd, env_k, Path(work)))
                    if k == 0:
                        cpu = CPU[-1]
                    mine = [_seconds(python_k, cmd, env_k, Path(work))
                            for _ in range(args.rounds)]
                    later[name] += mine
                    pairs.append(first[name][-1] / statistics.median(mine))
            with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as work:
                then[name] = _seconds(before, cmd,
                                      {**without_pythonpath(), "NUMBA_CACHE_DIR": cache},
                                      Path(work))
                compiled = len(list(Path(cache).rglob("*.nbi")))
            print(f"{name:<10} first {_spread(first[name])} s (cpu {cpu:.1f} s), later "
                  f"{_spread(later[name])} s, first/later per installation "
                  f"{', '.join(f'{r:.2f}' for r in pairs)}; at {args.baseline} from an empty "
                  f"numba cache {then[name]:6.1f} s (cpu {CPU[-1]:.1f} s, {compiled} kernels "
                  f"compiled); load {os.getloadavg()[0]:.1f}", flush=True)
            if not compiled:
                print(f"  (at {args.baseline}, {name} compiled nothing into its empty numba "
                      "cache: not a first use of a numba kernel)", flush=True)
        # Read after the timing, so that it cannot warm anything a first use reads.
        libraries = f"now {versions(python)}; at {args.baseline} {versions(before)}"
    print(f"\nload average {load:.2f} before, {os.getloadavg()[0]:.2f} after "
          f"({os.cpu_count()} cores)")
    print(f"libraries: {libraries}")
    print(f"{'command':<10} {'first [s]':>10} {'later [s]':>10} {'first/later':>12} "
          f"{args.baseline + ' [s]':>13} {'now/then':>9}")
    for name in names:
        mine = statistics.median(later[name])
        new = statistics.median(first[name])
        print(f"{name:<10} {new:>10.2f} {mine:>10.2f} {new / mine:>12.2f} "
              f"{then[name]:>13.1f} {new / then[name]:>9.2f}")


def _spread(values: list[float]) -> str:
    """The median of `values` and, for several, all of them."""
    median = f"{statistics.median(values):6.2f}"
    return median if len(values) == 1 else f"{median} ({', '.join(f'{v:.2f}' for v in values)})"


if __name__ == "__main__":
    main()
