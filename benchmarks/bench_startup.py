"""Start-up time of fresh processes: ``import fivdisc``, the command line's help, and the
whole Fig. 10 command, side by side with the interpreter's own start in the same run.

Run ``python benchmarks/bench_startup.py`` (``--repeat N`` processes per command, default
15; ``--no-fig10`` leaves out the slow Fig. 10 command; it runs twice, the second time
with the garbage collector's default thresholds, which the command line raises;
``--reference`` also times the slow scipy reference on it, once, as a whole process;
``--baseline COMMIT`` also times each fivdisc command with the fivdisc of an earlier
commit). The fivdisc on ``sys.path`` is timed: set ``PYTHONPATH=src`` to time a clone.

The baseline's commands run with the Python of the commit's own virtual environment,
``previous.environment`` (built once and cached; a minute or two the first time), without
``PYTHONPATH``: the numba commits need numba, which the working tree no longer depends on
and its environment need not have, so their sources on this interpreter would end in an
ImportError. That environment is a virtual environment of the same interpreter with the
same libraries plus numba (their versions, both sides', are printed; for
``previous.LAST_NUMBA`` numpy, scipy and pydantic are the same), so that mostly fivdisc's
own code, and its kernel, differ. The run before the timing fills the numba cache of the
baseline's installed copy, if it is empty: its commands are timed with their kernels
cached, as a user's second run would be (``bench_first_use.py`` times the first).

It prints, per command, the median wall time of its fresh processes [s], its ratio to the
interpreter's start (``python -c pass``), to ``python -c "import numpy"`` and to the
baseline's, the median processor time (user and system, all threads) and its ratio to the
baseline's, and its target (issue 11, item 3; issue 29, item 2 for the Fig. 10 command).
The commands take turns, so that a change in the machine's load during the run falls on
all of them alike; each runs once before the timing (compiled bytecode, the file cache).
The Fig. 10 command is compared, last, with the sum of ``python -c "import numpy"`` and
the integration it prints (its median): issue 37, item 5 asks for at most 1.3 x that, and
at most 0.45 x the numba kernel's command (``--baseline`` a numba commit such as
``previous.LAST_NUMBA``).
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from previous import environment, versions, without_pythonpath

# The console script `fivdisc` runs exactly this; through the interpreter being timed, so
# that no installed copy of fivdisc stands in for the one on sys.path.
_CLI = "from fivdisc.cli import main; main()"
# The same with Python's default thresholds of the garbage collector, which ``main`` raises.
_FIG10 = "fivdisc simulate fig10 -o fig10.nc"
# The slow reference (benchmarks/baseline.py) integrating the same case, as a process.
_REFERENCE = (f"import sys; sys.path.insert(0, {str(Path(__file__).resolve().parent)!r}); "
              "from baseline import baseline_simulate; from fivdisc import load_case, "
              "examples; baseline_simulate(load_case(examples.path('fig10')))")
_CLI_DEFAULT_GC = ("import gc, fivdisc.cli as c; c._GC_THRESHOLDS = gc.get_threshold(); "
                   "c.main()")


# What fivdisc simulate prints of the integration alone.
_INTEGRATION = re.compile(r"wall time: ([0-9.]+) s \(integration only")


def _commands(workdir: Path, fig10: bool) -> list[tuple[str, list[str], float | None]]:
    """(label, argv, target [s] or None) of each command timed; the first two are the
    interpreter's alone."""
    python = sys.executable
    commands = [
        ('python -c "pass"', [python, "-c", "pass"], None),
        ('python -c "import numpy"', [python, "-c", "import numpy"], None),
        ('python -c "import fivdisc"', [python, "-c", "import fivdisc"], 0.4),
        ("fivdisc --help", [python, "-c", _CLI, "--help"], 0.15),
        ("fivdisc simulate --help", [python, "-c", _CLI, "simulate", "--help"], 0.3),
    ]
    if fig10:
        out = str(workdir / "fig10.nc")
        commands.append((_FIG10,
                         [python, "-c", _CLI, "simulate", "fig10", "-o", out, "--no-progress"],
                         None))
        commands.append(("  the same, default gc thresholds",
                         [python, "-c", _CLI_DEFAULT_GC, "simulate", "fig10", "-o", out,
                          "--no-progress"], None))
    return commands


def _seconds(argv: list[str], workdir: Path, env: dict[str, str] | None = None
             ) -> tuple[float, float, float | None]:
    """Wall time and processor time (user and system, all threads) of one process [s],
    and the integration's wall time it printed [s] (None if it printed none)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    out = subprocess.run(argv, check=True, stdout=subprocess.PIPE, cwd=workdir, env=env,
                         text=True).stdout
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    found = _INTEGRATION.search(out)
    return (wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime),
            float(found.group(1)) if found else None)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15, help="processes per command")
    parser.add_argument("--no-fig10", dest="fig10", action="store_false",
                        help="leave out fivdisc simulate fig10 (about 2 s a process)")
    parser.add_argument("--baseline", metavar="COMMIT",
                        help="also time each fivdisc command at this earlier commit")
    parser.add_argument("--reference", action="store_true",
                        help="also time one process running the slow scipy reference on "
                             "the Fig. 10 case (about 2.5 min), against the command")
    args = parser.parse_args()
    # One core per process, as in the other benchmarks.
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    load = os.getloadavg()[0]
    # Each run: (label, argv, target, environment or None for this one's).
    baseline_env = baseline_python = None
    if args.baseline:
        baseline_python = str(environment(args.baseline))
        baseline_env = without_pythonpath()
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        commands = _commands(workdir, args.fig10)
        runs = [(label, argv, target, None) for label, argv, target in commands]
        if baseline_env is not None:
            # The same commands, the interpreter replaced by the baseline environment's.
            runs += [(f"{label} @{args.baseline}", [baseline_python, *argv[1:]], None,
                      baseline_env) for label, argv, _ in commands[2:]]
        for _, argv, _, env in runs:
            _seconds(argv, workdir, env)
        times: list[list[tuple[float, float]]] = [[] for _ in runs]
        for _ in range(args.repeat):
            for (_, argv, _, env), samples in zip(runs, times, strict=True):
                samples.append(_seconds(argv, workdir, env))
        reference = _seconds([sys.executable, "-c", _REFERENCE], workdir)[0] if (
            args.reference and args.fig10) else None
    medians = [statistics.median(wall for wall, _, _ in samples) for samples in times]
    cpus = [statistics.median(cpu for _, cpu, _ in samples) for samples in times]
    interpreter, numpy = medians[0], medians[1]
    n = len(commands)
    # Without a baseline there is nothing after the commands' own runs.
    before = dict(zip(range(2, n), medians[n:], strict=len(runs) > n))
    cpu_before = dict(zip(range(2, n), cpus[n:], strict=len(runs) > n))
    print(f"fresh processes, median of {args.repeat} each ({sys.executable}); "
          f"load average {load:.2f} before the run, {os.getloadavg()[0]:.2f} after")
    if baseline_python is not None:
        print(f"libraries: {versions(sys.executable)}; @{args.baseline} "
              f"({baseline_python}): {versions(baseline_python)}")
    # On a loaded machine the processor time (all threads) says more than the wall time.
    print(f"{'command':<44} {'median [s]':>10} {'/ pass':>8} {'/ numpy':>8} "
          f"{'/ before':>9} {'cpu [s]':>8} {'/ before':>9} {'target [s]':>11}")
    for index, ((label, _, target, _), median, cpu) in enumerate(
            zip(runs, medians, cpus, strict=True)):
        goal = f"{target:.1f}" if target is not None else ""
        ratio = f"{median / before[index]:.2f}" if index in before else ""
        cpu_ratio = f"{cpu / cpu_before[index]:.2f}" if index in cpu_before else ""
        print(f"{label:<44} {median:>10.3f} {median / interpreter:>8.1f} "
              f"{median / numpy:>8.2f} {ratio:>9} {cpu:>8.3f} {cpu_ratio:>9} {goal:>11}")
    labels = [label for label, _, _ in commands]
    if args.fig10:
        # A process that imports numpy and integrates this run: the floor of the command.
        integration = statistics.median(
            seconds for _, _, seconds in times[labels.index(_FIG10)] if seconds is not None)
        floor = numpy + integration
        print(f"of the Fig. 10 command: the integration {integration:.3f} s (as it prints "
              f"it); with numpy's import, {floor:.3f} s; the command is "
              f"{medians[labels.index(_FIG10)] / floor:.2f} x that (target <= 1.3)")
        if baseline_env is not None:
            then = medians[n + labels.index(_FIG10) - 2]
            print(f"the Fig. 10 command against @{args.baseline}: "
                  f"{medians[labels.index(_FIG10)] / then:.2f} x (target <= 0.45)")
    if reference is not None:
        command = medians[labels.index(_FIG10)]
        print(f"the slow scipy reference on the Fig. 10 case, one process: {reference:.1f} s, "
              f"{reference / command:.0f} x the command (target of issue 11, item 3: >= 200)")


if __name__ == "__main__":
    main()
