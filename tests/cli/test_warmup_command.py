"""``fivdisc warmup`` compiles every kernel, so that no command compiles at its first use
(issue 29, item 1)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import fivdisc

from support.cli import run_cli

# What each command's first use runs, short; then how many functions numba compiled
# (cache misses) and loaded (hits) over every kernel module.
_FIRST_USES = """
import json, sys
from numba.core.registry import CPUDispatcher
from fivdisc import Case, simulate
from fivdisc.analysis.exponents import lyapunov
from fivdisc.analysis.stability import linear_stability
case = Case(simulation={"duration": 0.01})
simulate(case)
lyapunov(case, transient=0.0, duration=0.01, interval=0.005, seed=1)
linear_stability(Case())
dispatchers = {id(d): d for name, module in list(sys.modules.items())
               if name.startswith("fivdisc.core") for d in vars(module).values()
               if isinstance(d, CPUDispatcher)}.values()
print(json.dumps([sum(sum(d.stats.cache_misses.values()) for d in dispatchers),
                  sum(sum(d.stats.cache_hits.values()) for d in dispatchers)]))
"""


def _env(cache: Path) -> dict[str, str]:
    source = str(Path(fivdisc.__file__).parents[1])
    return {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": os.pathsep.join(
        [source, *filter(None, [os.environ.get("PYTHONPATH")])])}


@pytest.mark.slow
def test_after_warmup_no_first_use_compiles(tmp_path):
    """From an empty cache (a few minutes: every kernel compiles)."""
    warm = subprocess.run([sys.executable, "-m", "fivdisc", "warmup"], env=_env(tmp_path),
                          capture_output=True, text=True, timeout=3600, check=True)
    assert "compiling the simulation kernel, once" in warm.stderr
    assert "compiling the kernel with tangent vectors, once" in warm.stderr
    assert "every kernel is compiled" in warm.stdout
    out = subprocess.run([sys.executable, "-c", _FIRST_USES], env=_env(tmp_path),
                         capture_output=True, text=True, timeout=600, check=True)
    compiled, loaded = json.loads(out.stdout)
    assert compiled == 0
    assert loaded > 0


def test_warmup_on_compiled_kernels_only_loads_them():
    # The first call compiles what this installation has not compiled yet.
    for _ in range(2):
        result = run_cli(["warmup"])
        assert result.exit_code == 0, result.output
        assert "every kernel is compiled" in result.output
    assert "compiling" not in result.output
