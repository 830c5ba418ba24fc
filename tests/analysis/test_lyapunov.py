"""Lyapunov exponents against linear eigenvalues, Floquet multipliers and Liouville's
formula."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.integrate import simpson

import fivdisc
from fivdisc.analysis.exponents import lyapunov
from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.analysis.stability import linear_stability
from fivdisc.case import Case
from fivdisc.core import core_model, jacobian
from fivdisc.errors import FivdiscError
from fivdisc.model.build import build_model

from support.cli import run_cli

LIGHT = Case(disc={"density": 720.0, "modes": [[0, 0]]},
             slider={"mass": 1.0, "normal_damping": 20.0}, speed={"value": 1.0},
             simulation={"initial_state": "equilibrium"})
RIGID = Case(
    disc={"modes": [[0, 0]]},
    slider={"rotational_damping": 0.0, "normal_damping": 5.0},
    friction={"static": 0.8, "kinetic_max": 0.5, "kinetic_min": 0.5, "decay": 0.0},
    speed={"value": 1.0},
)


def test_exponents_of_a_stable_equilibrium_are_the_eigenvalues_real_parts():
    """A light disc whose sliding equilibrium is stable (two complex pairs, rates -9.6
    and -171 1/s): the trajectory from the perturbed equilibrium settles on it without a
    switch, and the tangent dynamics becomes the linearisation. Over a finite time T the
    QR exponents of a linear system differ from the real parts by at most about
    log(kappa) / T, kappa the condition number of the eigenvector basis (in the energy
    norm the exponents are measured in); each complex pair is split by its rotation by
    that much."""
    case = LIGHT.replace({"friction.decay": 0.5, "slider.rotational_damping": 4.0})
    lin = linear_stability(case)
    assert lin.stable
    duration = 20.0
    spec = lyapunov(case, n=4, transient=1.0, duration=duration)
    ref = np.sort(lin.eigenvalues.real)[::-1]
    model = build_model(case)
    from fivdisc.analysis.orbits import energy_scales

    idx = np.r_[0 : model.n + 1, model.state_size // 2 : model.state_size // 2 + model.n + 1]
    basis = lin.eigenvectors / energy_scales(model)[idx][:, None]
    bound = np.log(np.linalg.cond(basis)) / duration
    assert spec.exponents == pytest.approx(ref, abs=bound)
    assert bound < 0.5  # the test can tell -9.6 from -171 and from 0


def test_exponents_on_a_periodic_orbit_are_the_floquet_exponents():
    """On the rigid-disc stick-slip orbit: 0 for the flow direction (autonomous), then
    the disc mode's pair log|mu| / T; the sticking direction's -inf is not among the
    first three. Same finite-time bound as above: the pair's rotation splits it by about
    0.1 1/s over 20 s; the flow direction's estimate is off by log(max |f| / min |f|)
    over the orbit divided by the duration."""
    orbit = periodic_orbit(RIGID, transient=4.0)
    floquet = np.sort(orbit.exponents())[::-1][:3]
    spec = lyapunov(RIGID, n=3, transient=4.0, duration=20.0)
    assert floquet[0] == pytest.approx(0.0, abs=1e-6)
    assert spec.exponents == pytest.approx(floquet, abs=0.25)
    assert np.all(np.abs(spec.exponents - floquet) <= 3 * spec.uncertainty + 0.02)


def test_sum_of_all_exponents_is_the_mean_divergence():
    """Liouville: over a run without switches, the sum of all finite-time exponents times
    the run's length is log det of the tangent map, the integral of the trace of the
    Jacobian along the trajectory. The trace is integrated (Simpson, 4000 samples of
    the recorded trajectory, its complex-step Jacobian at each) independently of the
    tangent integration. The window ends before the first stick of a growing slip
    oscillation; its sampling error is below 1e-8 of the integral."""
    case = LIGHT.replace({"friction.decay": 2.0, "slider.rotational_damping": 1.0,
                          "disc.modes": [[0, 0], [0, 1]],
                          "simulation.rtol": 1e-12, "simulation.atol": 1e-16})
    first = fivdisc.simulate(case.replace({"simulation.duration": 0.2})).dataset
    assert first.event_kind.values[0] == "stick"
    rate = 2e5
    duration = np.floor(0.9 * first.event_time.values[0] * rate) / rate
    model = build_model(case)
    half = model.state_size // 2
    free = np.r_[0 : model.n + 1, half : half + model.n + 1]
    spec = lyapunov(case, n=free.size, transient=0.0, duration=duration,
                    interval=duration / 20)
    ds = fivdisc.simulate(case.replace({"simulation.duration": duration,
                                        "simulation.output_rate": rate})).dataset
    assert ds.event_time.size == 0
    nt = ds.time.size
    states = np.concatenate([ds[v].values.reshape(nt, -1)
                             for v in ("q", "phi", "z", "q_dot", "phi_dot", "z_dot")], axis=1)
    trace = np.empty(nt)
    for i in range(nt):
        sign = 1 if 1.0 - states[i, model.index("phi_dot")] > 0 else -1
        jac = jacobian(core_model(model), float(ds.time[i]), states[i].copy(),
                       np.array([0]), np.array([sign]))
        trace[i] = np.trace(jac[np.ix_(free, free)])
    integral = simpson(trace, x=ds.time.values)
    assert ds.time.values[-1] == pytest.approx(duration, abs=1e-12)
    assert spec.exponents.sum() * spec.times[-1] == pytest.approx(integral, rel=1e-7)


def test_sum_of_all_exponents_adds_the_saltation_determinants():
    """Liouville across switches: over a window of slip reversals (no stick, so no
    direction collapses), the sum of all finite-time exponents times the window's length
    is the integral of the Jacobian's trace over the smooth stretches plus, at each
    reversal, log |det S| of its saltation matrix. For a switch that keeps the state
    and has the event function h = s (Omega - phidot), S = I + (f+ - f-) grad h^T /
    (grad h . f- + dh/dt), so det S = (dOmega/dt - phi''+) / (dOmega/dt - phi''-).

    Independent of the tangent code: switch times, states and both sides'
    accelerations come from the slow scipy reference (tests/reference/model.py); the
    trace is integrated by Simpson on each stretch (601 points of the reference's
    dense output, the kernel's complex-step Jacobian at each, as in the test above),
    whose error is below 1e-9 of the total. The slider starts far behind its
    equilibrium, so every crossing of phidot = Omega is a reversal."""
    from reference.model import reference_simulate

    case = LIGHT.replace({"friction.static": 0.5, "friction.kinetic_max": 0.5,
                          "friction.kinetic_min": 0.3, "friction.decay": 1.0,
                          "slider.rotational_damping": 0.5,
                          "disc.modes": [[0, 0], [0, 1]], "simulation.initial_state": "rest",
                          "simulation.rtol": 1e-12, "simulation.atol": 1e-16})
    model = build_model(case)
    n = model.n
    half = model.state_size // 2
    free = np.r_[0 : n + 1, half : half + n + 1]
    transient, duration = 0.001, 0.03
    initial = {"phi": -0.2}
    spec = lyapunov(case, n=free.size, transient=transient, duration=duration,
                    interval=duration / 20, initial=initial)

    y0 = np.zeros(2 * n + 4)
    y0[2 * n] = -0.2
    ref = reference_simulate(case, transient + duration, y0=y0, phase0=[0])
    # The measurement starts where the transient's last step ended, ends at the end.
    end = transient + duration
    start = end - spec.times[-1]
    assert transient <= start < transient + 1e-4
    window = [e for e in ref.events if start < e[0] < end]
    assert len(window) >= 3 and all(e[3] == "reversal" for e in window)
    assert all(e[3] == "reversal" for e in ref.events)

    def kernel_state(y):
        out = np.zeros(model.state_size)
        out[:n], out[half : half + n] = y[:n], y[n : 2 * n]
        out[n], out[half + n] = y[2 * n], y[2 * n + 1]
        return out

    integral = 0.0
    for seg in ref.segments:
        a, b = max(seg.t0, start), min(seg.t1, end)
        if b <= a:
            continue
        times = np.linspace(a, b, 601)
        trace = np.empty(times.size)
        for i, t in enumerate(times):
            jac = jacobian(core_model(model), float(t), kernel_state(seg.sol(t)),
                           np.array([0]), np.array([int(seg.signs[0])]))
            trace[i] = np.trace(jac[np.ix_(free, free)])
        integral += simpson(trace, x=times)
    jumps = 0.0
    for t, *_ in window:
        before = next(s for s in ref.segments if s.t1 == t)
        after = next(s for s in ref.segments if s.t0 == t)
        y = after.sol(t)
        acc = [ref._model.solve(list(s.phases), list(s.signs), t, y, s.piece)["phidd"][0]
               for s in (before, after)]
        jumps += np.log(abs(acc[1] / acc[0]))  # dOmega/dt = 0
    assert abs(jumps) > 0.1 * abs(integral)  # the switches matter (about 40 % here)
    assert spec.exponents.sum() * spec.times[-1] == pytest.approx(integral + jumps, rel=1e-7)


def test_lyapunov_rejects_bad_input():
    with pytest.raises(FivdiscError, match="n = 0 is invalid"):
        lyapunov(RIGID, n=0)
    with pytest.raises(FivdiscError, match="n = 9 is invalid: must be at most"):
        lyapunov(RIGID, n=9, transient=0.0, duration=0.01)
    with pytest.raises(FivdiscError, match=r"interval = 2\.0 is invalid"):
        lyapunov(RIGID, duration=1.0, interval=2.0)


def test_lyapunov_command(tmp_path):
    path = tmp_path / "rigid.toml"
    path.write_text(RIGID.to_toml())
    out = tmp_path / "lyap.nc"
    res = run_cli(["lyapunov", str(path), "--n", "2", "--transient", "1",
                                   "--duration", "2", "--json", "--no-progress", "-o", str(out)])
    data = json.loads(res.stdout)
    # The exit status says whether the largest exponent is decided (issues 28, 40).
    assert res.exit_code == (0 if data["verdict"] != "undecided" else 1), res.output
    assert len(data["exponents"]) == 2 and len(data["uncertainty"]) == 2
    assert data["exponents"][0] >= data["exponents"][1]
    import xarray as xr

    with xr.open_dataset(out) as ds:
        assert ds["exponent"].attrs["units"] == "s-1"
        assert ds["running"].shape[1] == 2
