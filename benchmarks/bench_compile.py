"""The one-off compilation of the kernels, side by side with an earlier commit's.

Run ``python benchmarks/bench_compile.py`` (``--commit C`` for the earlier fivdisc,
default ``ca55043``, the model-family kernel before its compile time was tuned;
``--rounds N``, default 2). Each round times, in fresh processes with an empty numba
cache each, the import of fivdisc and a first 0.01 s simulation of the default case:
once with the fivdisc on ``sys.path``, once with the earlier commit installed into its own
virtual environment (``previous.py``). It prints each pair and the ratio of their
medians. The processes alternate, so that a change in the machine's load falls on both.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile

from previous import environment

_CODE = """
import time
t0 = time.perf_counter()
from fivdisc import Case, simulate
simulate(Case(simulation={"duration": 0.01}))
print(time.perf_counter() - t0)
"""


def _first_run(python: str) -> float:
    """Seconds from import to the end of a first simulation, with an empty cache [s]."""
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "OMP_NUM_THREADS": "1"}
        out = subprocess.run([python, "-c", _CODE], check=True, capture_output=True,
                             text=True, env=env, cwd=tempfile.gettempdir())
    return float(out.stdout.split()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--commit", default="ca55043", help="earlier commit (default ca55043)")
    parser.add_argument("--rounds", type=int, default=2, help="pairs of runs (default 2)")
    args = parser.parse_args()
    before_python = str(environment(args.commit))
    now, before = [], []
    for _ in range(args.rounds):
        before.append(_first_run(before_python))
        now.append(_first_run(sys.executable))
        print(f"first compile and run: {before[-1]:.1f} s at {args.commit}, "
              f"{now[-1]:.1f} s now")
    ratio = statistics.median(now) / statistics.median(before)
    print(f"ratio now / {args.commit}: {ratio:.2f} (target of issue 11, item 4: <= 0.5)")


if __name__ == "__main__":
    main()
