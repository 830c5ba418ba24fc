"""Physical checks of the compiled simulator against analytic results and invariants."""

from __future__ import annotations

import numpy as np
import pytest

from fivdisc.case import Case
from fivdisc.core import core_model, evaluate, single_impact
from fivdisc.engine.equilibrium import sliding_equilibrium
from fivdisc.engine.result import select_slider
from fivdisc.engine.simulation import simulate
from fivdisc.errors import SimulationError
from fivdisc.model import layout as lay
from fivdisc.model.build import build_model
from fivdisc.model.layout import Phase
from fivdisc.model.speed import SpeedProfile

from reference.model import jacobi_integral, mode_data_from_case


def _belt_period(case: Case, omega: float) -> float:
    """Stick-slip limit cycle of a 1-DOF oscillator on a belt with Coulomb friction:
    stick while the spring loads from mu0 N0 + ... to mu_s N0, then a free half-swing."""
    s, fr = case.slider, case.friction
    inertia = s.mass * s.track_radius**2
    w = np.sqrt(s.rotational_stiffness / inertia)
    amp = s.track_radius * (fr.static - fr.kinetic_max) * s.preload / s.rotational_stiffness
    return 2 * amp / omega + (np.pi + 2 * np.arctan(omega / (w * amp))) / w


@pytest.mark.parametrize("omega", [2.0, 2 * np.pi])
def test_rigid_disc_stick_slip_period(omega):
    case = Case(
        disc={"modes": []},
        friction={"decay": 0.0},
        slider={"rotational_damping": 0.0},
        speed={"value": omega},
        simulation={"duration": 0.12, "output_rate": 1000.0, "rtol": 1e-11, "atol": 1e-14},
    )
    res = simulate(case)
    sticks = res.events("stick")
    assert sticks.size >= 8
    period = np.diff(sticks)[2:]
    # Switch times are located to ~1e-13 s and the in-slip error is ~1e-11 relative, so the
    # period is exact to far better than the required 1e-8.
    np.testing.assert_allclose(period, _belt_period(case, omega), rtol=1e-8)
    np.testing.assert_allclose(res.dataset["normal_force"].values, case.slider.preload, rtol=0)


def test_jacobi_integral_conserved_without_friction_and_damping():
    case = Case(
        slider={"normal_damping": 0.0, "rotational_damping": 0.0},
        friction={"static": 0.0, "kinetic_max": 0.0, "kinetic_min": 0.0},
        speed={"value": 50.0},
        simulation={"duration": 1.0, "output_rate": 2000.0, "rtol": 1e-11, "atol": 1e-14},
    )
    # Start near the static deflection with every modal coordinate disturbed (contact is
    # kept: N stays well above 0). phi = phidot = 0 and f = 0 keep the slider still, the
    # condition under which equations.md's model is conservative.
    eq = sliding_equilibrium(case)
    q = eq.q * (1.0 + 0.2 * np.cos(np.arange(eq.q.size)))
    res = simulate(case, initial={"q": q, "q_dot": 0.05 * np.sin(np.arange(q.size))})
    ds = select_slider(res.dataset)
    assert res.status == "success" and ds["normal_force"].min() > 100.0
    state = {
        "q": ds["q"].values,
        "q_dot": ds["q_dot"].values,
        "phi": ds["phi"].values,
        "phi_dot": ds["phi_dot"].values,
        "z": ds["z"].values,
        "z_dot": ds["z_dot"].values,
        "Omega": ds["disc_speed"].values,
    }
    h = jacobi_integral(case, state, mode_data=mode_data_from_case(case))
    # rtol 1e-11 per step over ~1e5 steps: drift ~1e-10 relative, inside the 1e-8 asked.
    assert np.max(np.abs(h - h[0])) <= 1e-8 * np.abs(h[0])


def _energy(model, y, omega):
    """Mechanical energy T + V (T with the disc's rotation terms) of a kernel state."""
    n = model.n
    q, qd, phi, phid, z, zd = y[:n], y[n + 2 : 2 * n + 2], y[n], y[2 * n + 2], y[n + 1], y[-1]
    md = mode_data_from_case(model.case)
    M, l, partner, sgn = md.M, md.l, model.partner, model.sgn
    qp = np.where(partner >= 0, q[np.maximum(partner, 0)], 0.0)
    kinetic = 0.5 * np.sum(M * (qd + sgn * l * omega * qp) ** 2)
    kern = model.kernel
    kinetic += 0.5 * kern.row("mass")[0] * zd**2 + 0.5 * kern.row("inertia")[0] * phid**2
    potential = 0.5 * np.sum(M * md.omega**2 * q**2) + 0.5 * kern.row("kphi")[0] * phi**2
    potential += 0.5 * kern.row("kz")[0] * z**2 + kern.row("n0")[0] * z
    return kinetic + potential


def test_impact_map_equal_velocities_and_energy_loss():
    model = build_model(Case())
    n, omega = model.n, 2 * np.pi
    rng = np.random.default_rng(7)
    cm = core_model(model)
    flying = np.array([Phase.SEPARATION])
    sign = np.array([1])
    for trial in range(50):
        y = np.zeros(model.state_size)
        y[:n] = rng.normal(0, 1e-3, n)
        y[n + 2 : 2 * n + 2] = rng.normal(0, 0.5, n)
        y[n] = rng.uniform(-0.5, 0.5)
        # Half the trials with the slider moving with the disc (v = 0).
        y[2 * n + 2] = omega if trial % 2 else rng.uniform(0, 2 * omega)
        _, aux = evaluate(cm, 0.0, y, flying, sign)
        y[n + 1] = aux["w"][0]
        # Slider approaching the disc surface.
        y[-1] = aux["w_rate"][0] - abs(rng.normal(0, 0.5))
        before = y.copy()
        y = single_impact(cm, y, 0)
        _, aux = evaluate(cm, 0.0, y, flying, sign)
        assert y[-1] == pytest.approx(aux["w_rate"][0], abs=1e-12 * abs(before[-1]))
        # Classical plastic-impact loss: u^2 / (2 K), K = 1/m + sum g^2/M, with u the
        # approach velocity; the normal impulse p on a surface sloped by g'.q that slides
        # at v = Omega - phidot under the slider also does work -p v (g'.q).
        g, gp = aux["g"][0], aux["g_prime"][0]
        m = model.kernel.slider[lay.S_MASS, 0]
        kk = 1 / m + np.sum(g**2 / model.modal_mass)
        u = before[-1] - (g @ before[n + 2 : 2 * n + 2] + before[2 * n + 2] * (gp @ before[:n]))
        p = -u / kk
        v = omega - before[2 * n + 2]
        loss = _energy(model, before, omega) - _energy(model, y, omega)
        assert loss == pytest.approx(u**2 / (2 * kk) + p * v * (gp @ before[:n]), rel=1e-9)
        if v == 0.0:
            assert loss >= 0.0


def test_tolerance_convergence():
    """Halving the tolerance changes the result by about what the error estimate predicts:
    the global error of a tolerance-proportional RK method scales like the tolerance."""
    base = {"duration": 0.05, "output_rate": 20000.0}

    def run(rtol):
        case = Case(simulation={**base, "rtol": rtol, "atol": rtol * 1e-3})
        return simulate(case).dataset["phi"].values

    exact = run(1e-12)
    errors = [np.max(np.abs(run(tol) - exact)) / np.max(np.abs(exact))
              for tol in (4e-8, 2e-8, 1e-8)]
    for coarse, fine, tol in zip(errors[:-1], errors[1:], (4e-8, 2e-8), strict=True):
        assert fine < coarse
        # Error per unit tolerance stays bounded (accumulation over ~1e3 steps).
        assert coarse < 1e4 * tol
        assert 1.2 < coarse / fine < 4.0


def test_deterministic():
    case = Case(simulation={"duration": 0.05})
    a, b = simulate(case).dataset, simulate(case).dataset
    for var in ("q", "phi", "phi_dot", "normal_force", "event_time"):
        assert np.array_equal(a[var].values, b[var].values)


def test_decelerating_disc_stops_and_stays_stopped():
    case = Case(
        speed={"profile": "decelerating", "initial": 2.0, "duration": 0.03},
        simulation={"duration": 0.08, "output_rate": 5000.0},
    )
    ds = select_slider(simulate(case).dataset)
    speed = ds["disc_speed"].values
    t = ds["time"].values
    np.testing.assert_allclose(speed[t >= 0.03], 0.0, atol=0)
    np.testing.assert_allclose(speed[t <= 0.03], 2.0 * (1 - t[t <= 0.03] / 0.03), rtol=1e-12)
    # In stick the slider moves with the disc.
    stick = ds["phase"].values == 1
    np.testing.assert_allclose(ds["phi_dot"].values[stick], speed[stick], atol=1e-9)


def test_callable_profile_matches_builtin():
    tmax = 0.03
    case = Case(
        speed={"profile": "decelerating", "initial": 2 * np.pi, "duration": tmax},
        simulation={"duration": 0.05, "rtol": 1e-10, "atol": 1e-13},
    )
    ref = simulate(case).dataset
    speed = (lambda t: 2 * np.pi * max(0.0, 1 - t / tmax),
             lambda t: -2 * np.pi / tmax if t < tmax else 0.0)
    profile = SpeedProfile.from_callables(*speed, t_end=0.05, breakpoints=[tmax])
    got = simulate(case, speed=profile).dataset
    np.testing.assert_allclose(got["event_time"].values, ref["event_time"].values, atol=1e-9)
    np.testing.assert_allclose(got["phi"].values, ref["phi"].values,
                               atol=1e-7 * np.max(np.abs(ref["phi"].values)))


def test_table_profile_kink_is_a_breakpoint():
    # Rigid disc at 2 rad/s sticks over [0.0195, 0.0245] s (period 7.6 ms, stick 2A/Omega =
    # 5 ms). A steep ramp from 0.022 s adds I Omegadot / r0 = 122 N to the stick reaction,
    # more than the ~50 N margin left, so the slider must slip exactly at the kink.
    kink = 0.022
    case = Case(
        disc={"modes": []},
        friction={"decay": 0.0},
        speed={"profile": "table", "times": [0.0, kink, 0.03], "values": [2.0, 2.0, 100.0]},
        simulation={"duration": 0.03},
    )
    res = simulate(case)
    stick_starts = res.events("stick")
    assert np.any((stick_starts > 0.019) & (stick_starts < kink))
    assert kink in res.events("slip")


def test_failure_status_keeps_data_and_names_time_and_phase():
    case = Case(simulation={"duration": 0.2, "max_switches": 5})
    res = simulate(case)
    assert res.status == "max_switches" and not res.ok
    assert "t = " in res.message and ("slip" in res.message or "stick" in res.message)
    ds = res.dataset
    assert 0 < ds.sizes["time"] < 2001
    assert ds["time"].values[-1] <= ds.attrs["end_time"]


def test_stop_on_separation_ends_early():
    case = Case(simulation={"duration": 0.1})
    n = build_model(case).n
    kick = {"q_dot": np.r_[5.0, np.zeros(n - 1)]}
    res = simulate(case, initial=kick, stop_on=("separation",))
    assert res.status == "stopped"
    assert res.events("separation").size == 1
    assert res.dataset.attrs["end_time"] == pytest.approx(res.events("separation")[0])


def test_bad_initial_state_is_rejected():
    case = Case(simulation={"duration": 0.01})
    with pytest.raises(SimulationError, match="initial"):
        simulate(case, initial={"q": [1.0, 2.0]})
    with pytest.raises(SimulationError, match="stop_on"):
        simulate(case, stop_on=("explosion",))


def test_the_kernel_lets_other_threads_run():
    """The integration kernel releases the GIL, so that the imports of fivdisc.engine.preload
    overlap it: a thread waking every millisecond keeps waking during one long kernel
    call. Holding the GIL, the call would let it wake at most once."""
    import threading
    import time

    from fivdisc.engine.integration import Integration
    from fivdisc.engine.simulation import initial_state

    model = build_model(Case())
    run = Integration(model, initial_state(model), duration=20.0)
    run.advance(0.0)  # loads the kernel
    run.call_steps = 10**9  # one call for the whole run, however long
    ticks: list[float] = []
    done = threading.Event()

    def tick() -> None:
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(1e-3)

    thread = threading.Thread(target=tick)
    thread.start()
    time.sleep(0.01)
    start = time.perf_counter()
    run.advance(20.0)
    end = time.perf_counter()
    done.set()
    thread.join()
    assert run.t == 20.0
    assert end - start > 0.05, "too short a call to tell"
    assert sum(start < t < end for t in ticks) >= 10
