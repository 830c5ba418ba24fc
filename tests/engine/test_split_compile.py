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
from fivdisc.engine.integration import Integration
from fivdisc.engine.simulation import initial_state
from fivdisc.model.build import build_model

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


def test_no_split_when_cached_or_on_one_core(monkeypatch):
    simulate(Case(**_CASE))  # the kernel is in memory now
    run = _integration()
    assert not split_compile.compile_split(run)
    run.set_tangents(np.eye(1, run.model.state_size))
    run.run_to(1e-3)  # the kernel with tangents too
    assert not split_compile.compile_split(run)
    assert not split_compile.compile_split_tangents()

    monkeypatch.setattr("fivdisc.engine.compilation.needs_compiling", lambda dispatcher: True)
    monkeypatch.setattr(split_compile, "_cores", lambda: 1)
    assert not split_compile.compile_split(run)
    assert not split_compile.compile_split_tangents()


def test_each_function_of_a_share_is_typed_with_all_its_arguments():
    """The predicted types name every parameter of each function the shares compile (a
    kernel that gains a parameter must have its prediction extended)."""
    import inspect

    run = split_compile.default_run(tangents=True)
    types = split_compile.callee_types(run)
    dispatchers = split_compile._dispatchers()
    shares = (split_compile.HELPER_KERNELS + split_compile.OWN_KERNELS
              + split_compile.TANGENT_HELPER_KERNELS + split_compile.TANGENT_OWN_KERNELS
              + split_compile.TANGENT_HELPER_AHEAD
              + split_compile.RHS_HELPER_KERNELS + split_compile.RHS_OWN_KERNELS)
    assert set(types) == set(shares) == set(dispatchers)
    for name in shares:
        parameters = inspect.signature(dispatchers[name].py_func).parameters
        assert len(types[name]) == len(parameters), name


_COLD_TANGENTS = """
import json
from fivdisc.engine import split_compile
from fivdisc.analysis.exponents import lyapunov
from fivdisc.case import Case
spectrum = lyapunov(Case(**json.loads({case!r})), transient=0.0, duration=0.01,
                    interval=0.005, seed=1)
stats = {{name: [sum(d.stats.cache_hits.values()), sum(d.stats.cache_misses.values())]
         for name, d in split_compile._dispatchers().items()}}
print(json.dumps({{"stats": stats, "exponents": spectrum.exponents.tolist()}}))
"""


@pytest.mark.slow
@pytest.mark.skipif(split_compile._cores() < 2, reason="the split needs two cores")
def test_a_cold_compile_with_tangents_loads_the_helpers_parts_from_the_cache(tmp_path):
    """lyapunov from an empty cache: the plain kernel, then the one with tangents, each
    shared with a helper whose part this process only loads; the exponents are this
    process's own (a few minutes: two whole compilations)."""
    from fivdisc.analysis.exponents import lyapunov

    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run(
        [sys.executable, "-c", _COLD_TANGENTS.format(case=json.dumps(_CASE))], env=env,
        check=True, capture_output=True, text=True, timeout=1800)
    cold = json.loads(out.stdout)
    stages = {"_stages", "tangent_stages"}  # one function, a signature for each kernel
    for name in set(split_compile.HELPER_KERNELS + split_compile.TANGENT_HELPER_KERNELS) - stages:
        assert cold["stats"][name] == [1, 0], name
    for name in set(split_compile.OWN_KERNELS + split_compile.TANGENT_OWN_KERNELS) - stages:
        assert cold["stats"][name] == [0, 1], name
    # The plain kernel's loaded from the helper's part, the tangent kernel's compiled here.
    assert cold["stats"]["_stages"] == [1, 1]
    # The right-hand side on a real state compiled here (for the plain kernel's switch),
    # on a complex one at a real time loaded: the helper compiled it first.
    assert cold["stats"]["jvp_rhs"] == [1, 1]
    here = lyapunov(Case(**_CASE), transient=0.0, duration=0.01, interval=0.005, seed=1)
    assert np.array_equal(np.asarray(cold["exponents"]), here.exponents)


_COLD_RHS = """
import json
from fivdisc.engine import split_compile
from fivdisc.analysis.stability import linear_stability
from fivdisc.case import Case
result = linear_stability(Case())
stats = {name: [sum(d.stats.cache_hits.values()), sum(d.stats.cache_misses.values())]
         for name, d in split_compile._dispatchers().items()}
print(json.dumps({"stats": stats, "eigenvalues": [[z.real, z.imag] for z in
                                                  result.eigenvalues.tolist()]}))
"""


@pytest.mark.skipif(split_compile._cores() < 2, reason="the split needs two cores")
def test_a_cold_stability_loads_the_helper_s_jacobian_from_the_cache(tmp_path):
    """fivdisc stability from an empty cache: the right-hand side compiled here, its
    complex-step Jacobian by the helper, for the types the equilibrium then calls them
    with; the eigenvalues are this process's own."""
    from fivdisc.analysis.stability import linear_stability
    from fivdisc.case import Case

    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", _COLD_RHS], env=env, check=True,
                         capture_output=True, text=True, timeout=900)
    cold = json.loads(out.stdout)
    for name in split_compile.RHS_HELPER_KERNELS:
        assert cold["stats"][name] == [1, 0], name
    for name in split_compile.RHS_OWN_KERNELS:
        assert cold["stats"][name] == [0, 1], name
    here = linear_stability(Case()).eigenvalues
    assert np.array_equal(np.array(cold["eigenvalues"]),
                          np.column_stack([here.real, here.imag]))


def test_a_failing_helper_costs_time_only(monkeypatch):
    monkeypatch.setattr("fivdisc.engine.compilation.needs_compiling", lambda dispatcher: True)
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
    # A helper asked to go on with the tangent kernel's share that ended in the plain one
    # is not waited for (the kernel with tangents then compiles in this process).
    assert split_compile.compile_split(_integration(), tangents=True)
    assert split_compile._pending is not None
    assert split_compile.compile_split_tangents()
    assert split_compile._pending is None
