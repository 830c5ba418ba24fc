"""Every benchmark script starts: its imports resolve and its options parse (``--help``).
The layer move left ``benchmarks/baseline.py`` importing the reference model from its old
place, which broke five of the speed table's scripts without a test noticing."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
SCRIPTS = sorted(p.name for p in BENCHMARKS.glob("*.py")
                 if p.name not in ("baseline.py", "previous.py"))


@pytest.mark.parametrize("script", SCRIPTS)
def test_a_benchmark_starts(script):
    # the fivdisc this interpreter imports (installed, as in CI, or editable)
    done = subprocess.run([sys.executable, script, "--help"], cwd=BENCHMARKS,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
