"""The first compilation shared between two processes (issue 11, item 4): the helper
process compiles its part for exactly the types ``run`` then asks for, so that this
process loads that part from numba's cache instead of compiling it again; and a helper
that fails costs time only, never a result."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from fivdisc import Case, simulate, split_compile
from fivdisc.integration import Integration
from fivdisc.model import build_model
from fivdisc.simulate import initial_state

_CASE = {"simulation": {"duration": 0.01}}

_COLD = """
import json
from fivdisc import Case, simulate, split_compile
result = simulate(Case(**json.loads({case!r})))
stats = {{name: [sum(d.stats.cache_hits.values()), sum(d.stats.cache_misses.values())]
         for name, d in split_compile._dispatchers().items()}}
print(json.dumps({{"stats": stats,
                  "final": result.dataset.attrs["final_state"].tolist()}}))
"""


@pytest.mark.skipif(split_compile._cores() < 2, reason="the split needs two cores")
def test_a_cold_compile_loads_the_helper_s_part_from_the_cache(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", _COLD.format(case=json.dumps(_CASE))],
                         env=env, check=True, capture_output=True, text=True, timeout=900)
    cold = json.loads(out.stdout)
    for name in split_compile.HELPER_KERNELS:
        # One cache hit and no compilation: the predicted types were the ones run used.
        assert cold["stats"][name] == [1, 0], name
    for name in split_compile.OWN_KERNELS:
        assert cold["stats"][name] == [0, 1], name
    # The kernel put together from two processes computes what this process's does.
    here = simulate(Case(**_CASE)).dataset.attrs["final_state"]
    assert np.array_equal(np.asarray(cold["final"]), here)


def _integration() -> Integration:
    model = build_model(Case(**_CASE))
    return Integration(model, initial_state(model), duration=0.01, output_rate=1000.0)


def test_no_split_when_cached_on_one_core_or_with_tangents(monkeypatch):
    simulate(Case(**_CASE))  # the kernel is in memory now
    run = _integration()
    assert not split_compile.compile_split(run)

    monkeypatch.setattr("fivdisc.compilation.needs_compiling", lambda dispatcher: True)
    monkeypatch.setattr(split_compile, "_cores", lambda: 1)
    assert not split_compile.compile_split(run)
    monkeypatch.setattr(split_compile, "_cores", lambda: 2)
    run.set_tangents(np.eye(run.model.state_size)[:1])
    assert not split_compile.compile_split(run)


def test_a_failing_helper_costs_time_only(monkeypatch):
    monkeypatch.setattr("fivdisc.compilation.needs_compiling", lambda dispatcher: True)
    monkeypatch.setattr(split_compile, "_cores", lambda: 2)
    # The helper's interpreter exits at once with an error.
    monkeypatch.setattr(sys, "executable", "/bin/false")
    run = _integration()
    assert split_compile.compile_split(run)
    run.run_to(0.01)
    plain = _integration()
    plain.run_to(0.01)
    assert run.t == plain.t == pytest.approx(0.01)
    assert np.array_equal(run.y, plain.y)
