"""The compiled core driven directly with random models, states and settings for a bounded
time: every call returns, or raises the library's own error with a one-line message;
nothing crashes the process, whatever the numbers (huge, tiny, zero, negative)."""

from __future__ import annotations

import time

import numpy as np
import pytest

from fivdisc.core import _core
from fivdisc.errors import FivdiscError

# Wall time [s] each fuzz test may spend.
BUDGET = 3.0


def _value(rng, scale=1.0):
    """A number of any size and sign, now and then zero."""
    kind = rng.integers(0, 6)
    if kind == 0:
        return 0.0
    mag = scale * 10.0 ** rng.uniform(-12, 12) if kind == 1 else scale * rng.uniform(0.1, 10)
    return float(mag * rng.choice([-1.0, 1.0]) if kind < 4 else mag)


def random_arrays(rng):
    """The six arrays of a random, structurally valid model."""
    ls = list(rng.integers(0, 4, size=rng.integers(0, 4)))
    l_col, sgn, partner = [], [], []
    for l in ls:
        base = len(l_col)
        kinds = (1.0, -1.0) if l > 0 else (1.0,)
        for j, s in enumerate(kinds):
            l_col.append(l)
            sgn.append(s)
            partner.append(base + 1 - j if l > 0 else -1)
    n = len(l_col)
    n_sl = int(rng.integers(1, 5))
    disc = np.zeros((10, n))
    disc[0], disc[1], disc[2] = sgn, l_col, partner
    for r in range(3, 10):
        disc[r] = [abs(_value(rng)) if r == 3 else _value(rng) for _ in range(n)]
    slider = np.array([[_value(rng) for _ in range(n_sl)] for _ in range(16)])
    slider[1] = rng.choice([-1.0, 1.0], size=n_sl)
    shape = np.array([[_value(rng) for _ in range(n)] for _ in range(n_sl)]).reshape(n_sl, n)
    k = int(rng.integers(1, 4))
    table = np.column_stack([np.cumsum(rng.uniform(0.1, 2.0, k)),
                             [[_value(rng) for _ in range(4)] for _ in range(k)]])
    speed = np.column_stack([np.cumsum(rng.uniform(0.01, 1.0, k)) - 0.5,
                             [[_value(rng, 10.0) for _ in range(4)] for _ in range(k)]])
    opts = np.array([rng.integers(0, 3)] + [_value(rng) for _ in range(7)]
                    + [rng.integers(0, 2), rng.integers(0, 2), max(ls, default=0),
                       rng.integers(0, 2), abs(_value(rng, 1e-11))], dtype=float)
    return disc, slider, shape, table, speed, opts


def _one_line(err: Exception) -> None:
    assert isinstance(err, FivdiscError) and isinstance(err, ValueError)
    message = str(err)
    assert message and "\n" not in message


def test_random_models_and_states_never_crash():
    rng = np.random.default_rng(20261128)
    end = time.perf_counter() + BUDGET
    runs = 0
    while time.perf_counter() < end:
        arrays = random_arrays(rng)
        model = _core.Model(*arrays)
        nd = 2 * (model.n + 2 * model.n_sliders)
        energy = rng.integers(0, 2) * _core.N_ENERGY
        y0 = np.array([_value(rng, 1e-3) for _ in range(nd + energy)])
        phases = rng.integers(0, 3, size=model.n_sliders)
        signs = rng.choice([-1, 1], size=model.n_sliders)
        _core.rhs(model, 0.1, y0, phases, signs)
        _core.evaluate(model, 0.1, y0, phases, signs, False)
        _core.jacobian(model, 0.0, y0, phases, signs)
        _core.jvp(model, 0.0, y0, y0[:nd], phases, signs)
        _core.unslaved(model, 0.0, y0, phases, signs, y0[None, :nd])
        _core.event_values(model, 0.0, y0, phases, signs)
        run = _core.Integrator(model, y0, phases, t_final=float(rng.uniform(0, 0.05)),
                               rtol=10.0 ** rng.uniform(-10, -2), atol=1e-9,
                               max_step=float(rng.choice([0.0, 1e-4])), out_dt=1e-3,
                               n_out=int(rng.integers(0, 5)), breaks=np.array([0.01, 0.02]))
        if rng.integers(0, 2):
            run.set_tangents(rng.normal(size=(int(rng.integers(1, 4)), nd)))
        for _ in range(5):
            status = run.advance(1.0, 40)
            run.take_events()
            assert 0 <= status <= 6
            if status != 0:
                break
        if run.has_tangents:
            run.tangents(True)
        assert run.out_y.shape[0] >= run.n_samples
        runs += 1
    assert runs > 5


def _bad_inputs(rng):
    """Calls with one thing wrong each."""
    disc, slider, shape, table, speed, opts = random_arrays(rng)
    good = (disc, slider, shape, table, speed, opts)

    def swap(i, value):
        arrays = list(good)
        arrays[i] = value
        return lambda: _core.Model(*arrays)

    bad_disc = disc.copy()
    if disc.shape[1]:
        bad_disc[2, 0] = disc.shape[1] + 3  # a partner out of range
    nan_slider = slider.copy()
    nan_slider[2, 0] = np.nan
    big_l = opts.copy()
    big_l[10] = 1e9
    law = opts.copy()
    law[0] = 7
    unsorted = table.copy()
    unsorted[:, 0] = unsorted[::-1, 0]
    calls = [swap(0, disc[:5]), swap(1, slider[:, :0]), swap(2, shape.T[:, :, None]),
             swap(1, nan_slider), swap(5, big_l), swap(5, law), swap(3, np.zeros((0, 5))),
             swap(4, speed[:, :3])]
    if disc.shape[1]:
        calls.append(swap(0, bad_disc))
    if table.shape[0] > 1:
        calls.append(swap(3, unsorted))
    model = _core.Model(*good)
    nd = 2 * (model.n + 2 * model.n_sliders)
    y = np.zeros(nd)
    ph = np.zeros(model.n_sliders, np.int64)
    sg = np.ones(model.n_sliders, np.int64)
    calls += [lambda: _core.rhs(model, 0.0, y[:-1], ph, sg),
              lambda: _core.rhs(model, 0.0, y, ph + 5, sg),
              lambda: _core.rhs(model, 0.0, y, ph, sg * 0),
              lambda: _core.rhs(model, 0.0, y, ph[:0], sg),
              lambda: _core.jvp(model, 0.0, y, y[:-2], ph, sg),
              lambda: _core.unslaved(model, 0.0, y, ph, sg, y[None, :-1]),
              lambda: _core.kinetic_friction(model, 0.1, 0, 1.0),
              lambda: _core.Integrator(model, y * np.nan, ph, t_final=1.0, rtol=1e-6,
                                       atol=1e-9, breaks=np.zeros(0)),
              lambda: _core.Integrator(model, y, ph, t_final=1.0, rtol=-1.0, atol=1e-9,
                                       breaks=np.zeros(0)),
              lambda: _core.Integrator(model, y, ph, t_final=1.0, rtol=1e-6, atol=1e-9,
                                       breaks=np.array([0.5, 0.2])),
              lambda: _core.Integrator(model, y, ph, t_final=1.0, rtol=1e-6, atol=1e-9,
                                       out_dt=1e-3, n_out=10**12, breaks=np.zeros(0)),
              lambda: _core.solve_lcp(np.eye(2), np.zeros(3), np.zeros(3, bool))]
    run = _core.Integrator(model, y, ph, t_final=1.0, rtol=1e-6, atol=1e-9, breaks=np.zeros(0))
    calls += [lambda: run.set_tangents(np.ones((2, nd + 1))), lambda: run.tangents()]
    return calls


def test_bad_input_is_refused_in_one_line():
    rng = np.random.default_rng(7)
    end = time.perf_counter() + BUDGET / 2
    checked = 0
    while time.perf_counter() < end:
        for call in _bad_inputs(rng):
            with pytest.raises(FivdiscError) as info:
                call()
            _one_line(info.value)
            checked += 1
    assert checked > 20


def test_a_huge_model_is_refused_before_any_work():
    opts = np.zeros(13)
    opts[10] = 100000  # the largest l the core takes, over a very wide work array
    with pytest.raises(FivdiscError, match="too large"):
        _core.Model(np.zeros((10, 10**7)), np.ones((16, 2)), np.zeros((2, 10**7)),
                    np.zeros((1, 5)), np.zeros((1, 5)), opts)
