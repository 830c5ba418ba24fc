"""Every benchmark behind the README's speed table, in one sitting, into one log.

Run ``python benchmarks/speed_table.py -o speed-table.log`` on a quiet machine (about
20 minutes on 2 cores, more the first time, when the earlier commits' environments are
built). It runs each script of :data:`RUNS` in turn, with the arguments the README's row
names, from the ``benchmarks`` directory and with the fivdisc on ``PYTHONPATH`` (set
``PYTHONPATH=src`` for a clone), and writes to the log, for each: the command, the
start, the load average before and after, the seconds it took and everything it printed.
The log opens with the commit, the interpreter and the machine's cores. Each row of the
README's table is that script's printed figure; a row that cannot be read off the log
does not belong in the table. ``--only SCRIPT`` (repeatable) runs some of them.

The scripts time their baselines in the same run; none of their figures is compared
across scripts, so the order only matters for the machine's temperature and load, which
the log records.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: (script, arguments), in the order of the README's table.
RUNS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("floor.py", ()),
    ("floor.py", ("--only", "sliders", "--cpu-time")),
    ("bench_core.py", ()),
    ("compare_core.py", ()),
    ("bench_family.py", ()),
    ("bench_tangent.py", ("--cpu-time", "--span", "2", "--rounds", "21")),
    ("bench_sweep.py", ()),
    ("bench_sweep_pool.py", ("--repeat", "5", "--baseline", "c312c11")),
    ("bench_store.py", ()),
    ("bench_continuation.py", ("--rounds", "2")),
    ("bench_stability_boundary.py", ()),
    ("bench_first_use.py", ()),
    ("bench_startup.py", ("--repeat", "7", "--baseline", "a96e870", "--reference")),
)


def _commit() -> str:
    out = subprocess.run(["git", "describe", "--always", "--dirty"], cwd=HERE,
                         capture_output=True, text=True)
    return out.stdout.strip() or "unknown"


def _load() -> str:
    return "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, required=True, help="the log to write")
    parser.add_argument("--only", action="append", metavar="SCRIPT",
                        choices=sorted({script for script, _ in RUNS}),
                        help="run this script's rows only (repeatable)")
    args = parser.parse_args()
    runs = [(s, a) for s, a in RUNS if not args.only or s in args.only]
    with args.output.open("w", encoding="utf-8") as log:
        log.write(f"# speed table sitting: commit {_commit()}, {sys.executable}, "
                  f"{os.cpu_count()} cores, started {datetime.now(UTC):%Y-%m-%d %H:%M} UTC\n")
        for script, extra in runs:
            command = [sys.executable, script, *extra]
            shown = " ".join(["python", script, *extra])
            print(f"{shown} ...", file=sys.stderr, flush=True)
            log.write(f"\n## {shown}\n# started {datetime.now(UTC):%H:%M:%S} UTC, "
                      f"load average {_load()}\n")
            log.flush()
            start = time.perf_counter()
            done = subprocess.run(command, cwd=HERE, stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, text=True)
            seconds = time.perf_counter() - start
            log.write(done.stdout)
            log.write(f"# took {seconds:.0f} s, exit status {done.returncode}, "
                      f"load average {_load()}\n")
            log.flush()
            if done.returncode:
                print(f"{shown} failed (exit status {done.returncode}); see {args.output}",
                      file=sys.stderr)


if __name__ == "__main__":
    main()
