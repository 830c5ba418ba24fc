"""Continuation with several pads (issue 36): issue 36's three identical pads at 0, 120
and 240 degrees (``tests/data/three_pads.toml``; the starts are orbits of
``tests/data/three_pads.npz``, written by ``make_three_pads.py`` as the issue's commands
find them), every verdict checked by a second route: forward runs of the plain
simulator, independent of the shooting, its monodromy and the continuation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fivdisc.analysis.orbits import Shooting, periodic_orbit
from fivdisc.case import Case
from fivdisc.continuation.borders import order_key, pad_classes
from fivdisc.continuation.walk import continue_orbit
from fivdisc.engine.integration import Integration
from fivdisc.errors import ConvergenceError
from fivdisc.model.build import build_model
from fivdisc.model.layout import Phase

DATA = Path(__file__).parents[1] / "data"
CASE = Case.from_toml((DATA / "three_pads.toml").read_text(encoding="utf-8"))
ORBITS = np.load(DATA / "three_pads.npz")


def start(name: str):
    """The case at the orbit's speed and the orbit, converged again from the saved one."""
    speed = float(ORBITS[f"{name}_speed"])
    case = CASE.replace({"speed.value": speed})
    orbit = periodic_orbit(case, ORBITS[f"{name}_state"], period=float(ORBITS[f"{name}_period"]),
                           phases=ORBITS[f"{name}_phases"])
    return case, orbit


def run_events(case: Case, state: np.ndarray, phases: np.ndarray, duration: float,
               speed: float | None = None):
    """A plain run (the simulator's default steps, rtol 1e-12) from ``state``: its
    events' times, kinds and sliders."""
    if speed is not None:
        case = case.replace({"speed.value": speed})
    model = build_model(case)
    x = np.array(state, dtype=float)
    rates = model.index("phi_dot") + np.flatnonzero(np.asarray(phases) == Phase.STICK)
    x[rates] = case.speed.value
    run = Integration(model, x, duration=duration, rtol=1e-12, atol=1e-19, phases=phases)
    run.run_to(duration)
    assert run.status_name == "success"
    times, rows = run.events()
    return times, rows[:, 0], rows[:, 3]


def stick_periods(times, kinds, sliders, pad: int = 0) -> np.ndarray:
    """The times between pad ``pad``'s successive sticks."""
    return np.diff(times[(kinds == 0) & (sliders == pad)])


def junction_gap(case: Case, state, phases, period, speed: float) -> float:
    """From a plain run of ten periods at ``speed``: the time from pad 0's release to the
    next stick of another pad, over the last period (negative: that stick comes first)."""
    times, kinds, sliders = run_events(case, state, phases, 10 * period, speed)
    last = times > times[-1] - 1.5 * period
    t, k, j = times[last], kinds[last], sliders[last]
    release = t[(k == 1) & (j == 0)][-1]
    sticks = t[(k == 0) & (j != 0)]
    return float(sticks[np.argmin(np.abs(sticks - release))] - release)


@pytest.mark.slow
def test_the_pads_in_turn_pass_the_false_end_and_jump_where_releases_meet_sticks():
    """From 11.9 rad/s down: the branch passes the issue's false end at 11.8504 and ends
    its piece where each pad's release meets the next pad's stick; there the flow map
    jumps (the stick relieves the releasing pad), and the branch goes on from the
    symmetric orbit with overlapping sticks past it.

    Second routes: the border is where the gap between pad 0's release and the next stick
    vanishes, extrapolated (a parabola) from the orbits at 11.85, 11.846 and 11.843
    rad/s (solved apart, over T/3 with the pads permuted), the gaps measured in plain
    runs from them (to 1e-6 rad/s); the orbit past the jump, run forward, keeps its
    period to 1e-7 and has the next pad stick before pad 0 releases (an overlap)."""
    case, orbit = start("S11.9")
    br = continue_orbit(case, "speed.value", 11.6, orbit=orbit, max_points=12,
                        confirm_periods=0)
    assert br.stop_reason.startswith("reached"), br.stop_reason
    (jump,) = [b for b in br.bifurcations() if b["kind"] == "discontinuity"]
    speeds, gaps = (11.85, 11.846, 11.843), []
    for p in speeds:
        there = periodic_orbit(case.replace({"speed.value": p}), orbit.state,
                               period=orbit.period, phases=orbit.phases, symmetric=True)
        gaps.append(junction_gap(case, there.state, there.phases, there.period, p))
    assert 0 < gaps[2] < gaps[1] < gaps[0] < 2e-6
    roots = np.roots(np.polyfit(speeds, gaps, 2))
    border = float(roots.real[np.argmin(np.abs(roots - 11.838))])
    assert jump["parameter"] == pytest.approx(border, abs=1e-6)
    assert jump["period_after"] - jump["period"] == pytest.approx(1.02e-6, rel=0.02)
    assert "it jumps up by 0.00102 there: a relief" in jump["note"]
    after = jump["point"] + 1
    assert br.parameter[after] == pytest.approx(jump["parameter"], abs=2e-6)
    assert br.symmetries()[after] == "pads stick in turn, T/3 apart"
    state, phases = br.dataset["state"].values[after], br.phases(after)
    times, kinds, sliders = run_events(case, state, phases, 20 * br.period[after],
                                       br.parameter[after])
    np.testing.assert_allclose(stick_periods(times, kinds, sliders), br.period[after],
                               rtol=1e-7)
    gap = junction_gap(case, state, phases, br.period[after], br.parameter[after])
    assert -2.2e-6 < gap < -1.7e-6
    _no_silent_jumps(case, br)
    # and back up from the overlapping orbit: it jumps back at its own border, where the
    # releasing pad's margin just before the next pad's stick reaches zero
    from fivdisc.analysis.orbits import PeriodicOrbit

    up_case = case.replace({"speed.value": float(br.parameter[after])})
    back = periodic_orbit(up_case, state, period=br.period[after], phases=phases)
    assert isinstance(back, PeriodicOrbit)
    up = continue_orbit(up_case, "speed.value", 11.86, orbit=back, max_points=8,
                        confirm_periods=0)
    (again,) = [b for b in up.bifurcations() if b["kind"] == "discontinuity"]
    assert again["parameter"] == pytest.approx(11.84254, abs=2e-5)
    assert again["period_after"] - again["period"] == pytest.approx(-1.02e-6, rel=0.02)


def _no_silent_jumps(case: Case, br) -> None:
    """Consecutive points share the order of all switches unless a bifurcation is
    recorded between them."""
    from fivdisc.analysis.orbits import orbit_symmetry
    from fivdisc.analysis.symmetry import case_symmetry
    from fivdisc.continuation.problem import Point

    marked = {b["point"] for b in br.bifurcations()}
    keys = []
    group = case_symmetry(build_model(case))
    for i in range(len(br)):
        model = build_model(case.replace({"speed.value": float(br.parameter[i])}))
        phases = br.phases(i)
        shooting = Shooting(model, phases, 1e-12, 1e-19)
        cycle = shooting.cycle(br.dataset["state"].values[i], br.period[i])
        sym = orbit_symmetry(group, model, br.dataset["state"].values[i], phases,
                             br.period[i])
        pt = Point(np.zeros(1), np.zeros(1), None, None, None, None, 0, 0.0, 0, phases=phases)
        pt.sym = sym
        keys.append(order_key(cycle, pad_classes(pt)))
    for i in range(len(br) - 1):
        if i not in marked:
            assert keys[i] == keys[i + 1], i


def test_the_asymmetric_orbit_ends_where_a_release_would_jump():
    """The asymmetric orbit of the issue's ss-11.8 run, up from 11.8 rad/s: it ends at
    11.873019, where pad 2's margin just before pad 1's stick reaches zero and pad 1's
    stick relieves it (a jump of 1e-3 in its margin): no orbit past it.

    Second routes: a plain run from the end's orbit at 1e-5 below the end is periodic
    (its stick periods agree to 1e-9 s over the last 20 periods); one 0.2 % past it is not
    (they spread by more than 1e-7 s over 200 periods), although its period stays
    within 1 % and each pad sticks once per period, the issue's criterion for "the
    same orbit"."""
    case, orbit = start("A11.8")
    br = continue_orbit(case, "speed.value", 13.0, orbit=orbit, max_points=20,
                        confirm_periods=200)
    assert "does not persist past the discontinuity" in br.stop_reason
    (end,) = [b for b in br.bifurcations() if b["kind"] == "discontinuity end"]
    assert end["parameter"] == pytest.approx(11.873019, abs=1.5e-6)
    assert "pad 2's static margin just before pad 1's stick" in end["note"]
    assert "a relief of 0.00102" in end["note"]
    assert "does not settle" in br.dataset.attrs["end_check"]
    state, phases, period = end["state"], end["phases"], end["period"]
    times, kinds, sliders = run_events(case, state, phases, 60 * period,
                                       end["parameter"] - 1e-5)
    before = stick_periods(times, kinds, sliders)[-20:]
    assert np.ptp(before) < 1e-9
    past = end["parameter"] * 1.002
    times, kinds, sliders = run_events(case, state, phases, 200 * period, past)
    periods = stick_periods(times, kinds, sliders)[-150:]
    assert np.ptp(periods) > 1e-7
    assert abs(periods.mean() / period - 1) < 0.01
    assert all(np.sum((kinds == 0) & (sliders == j)) >= 190 for j in range(3))
    # d/dp of the held flow map just below the end, where a difference step of 1e-6 of
    # the key straddles the jump: taken on the side away from it, as a much smaller
    # one-sided difference (1e-8 of the key) on that side gives it (to 1e-2), where the
    # central difference is off by far more
    from fivdisc.continuation.problem import OrbitProblem
    from fivdisc.continuation.settings import DP_STEP, ContinuationSettings

    problem = OrbitProblem(case, "speed.value", phases, period, ContinuationSettings())
    problem.point_at(problem.shooting.held(state), period, end["parameter"] - 4e-6, phases,
                     1.0)
    p = end["parameter"] - 4e-6
    column, near = problem.dgap_dp(problem.template, period, p)
    assert near
    def end_at(q):
        return problem.shooter(q).shoot(problem.template, period, tangents=False).end

    def scaled(diff):
        return diff[problem.free] / problem.scale[problem.free] * problem.ps / problem.xs

    h = 1e-8 * p
    fine = scaled((end_at(p) - end_at(p - h)) / h)
    assert np.linalg.norm(column - fine) < 1e-2 * np.linalg.norm(fine)
    wide = DP_STEP * problem.ps
    central = scaled((end_at(p + wide) - end_at(p - wide)) / (2 * wide))
    assert np.linalg.norm(central - fine) > 0.3 * np.linalg.norm(fine)


@pytest.mark.slow
def test_the_in_phase_orbit_ends_where_its_release_cascade_breaks():
    """The in-phase orbit of the issue's ss-5 run, up from 5.2 rad/s: the three pads
    release at one instant while the first release loads the others; at 5.2193 the load
    on the last turns into a relief, and the orbit ends there (a cascade end), not lost at
    5.2233 as before.

    Second route: plain runs: at 5.2 rad/s periodic, the pads releasing together; 0.2 %
    past the end the releases spread and the period changes from one period to the next
    (the motion is no orbit of one period; the forward run of the continuation finds it
    nearly periodic over ten)."""
    case, orbit = start("P5.2")
    assert orbit.symmetry == "in phase"
    br = continue_orbit(case, "speed.value", 12.0, orbit=orbit, max_points=30,
                        confirm_periods=200)
    assert "release cascade" in br.stop_reason
    (end,) = [b for b in br.bifurcations() if b["kind"] == "cascade end"]
    assert "the step halved to 1.0e-06" in end["note"]
    assert end["parameter"] == pytest.approx(5.2193, abs=1e-4)
    times, kinds, sliders = run_events(case, orbit.state, orbit.phases, 40 * orbit.period)
    assert np.ptp(stick_periods(times, kinds, sliders)[-20:]) < 1e-9
    releases = times[kinds == 1][-3:]
    assert np.ptp(releases) < 1e-12
    times, kinds, sliders = run_events(case, end["state"], end["phases"],
                                       300 * end["period"], end["parameter"] * 1.002)
    assert np.ptp(stick_periods(times, kinds, sliders)[-200:]) > 5e-9
    last = times[(kinds == 1) & (times > times[-1] - end["period"])]
    assert np.ptp(last) > 1e-10


def test_a_stall_on_a_discontinuity_of_the_shooting_map_names_the_switches():
    """At 8 rad/s the issue's "in-phase orbit" is no orbit: Newton shooting stalls at a
    residual of 7e-7, 1e5 times the integration's accuracy, where the release order of
    the pads flips. The error says so and names the switches.

    Second route: a plain run from the last iterate is not periodic: its stick periods
    spread by more than 1e-8 s over 100 periods."""
    case = CASE.replace({"speed.value": 8.0})
    with pytest.raises(ConvergenceError) as err:
        periodic_orbit(case, ORBITS["X8_state"], period=float(ORBITS["X8_period"]),
                       phases=ORBITS["X8_phases"])
    text = str(err.value)
    assert "the shooting map is discontinuous at the iterate" in text
    assert "release" in text and "pad " in text
    assert "times the integration's accuracy" in text
    times, kinds, sliders = run_events(case, ORBITS["X8_state"], ORBITS["X8_phases"],
                                       120 * float(ORBITS["X8_period"]))
    assert np.ptp(stick_periods(times, kinds, sliders)[-100:]) > 1e-8
    # with a tolerance above the stall it is accepted, and says why it goes no further
    loose = periodic_orbit(case, ORBITS["X8_state"], period=float(ORBITS["X8_period"]),
                           phases=ORBITS["X8_phases"], tol=1e-6)
    assert "the shooting map is discontinuous at the iterate" in loose.note


def test_the_pads_in_turn_solved_over_a_third_of_the_period(tmp_path):
    """The orbit at 22 rad/s has x(t + T/3) = P x(t): pads 0, 1 and 2 stick in turn. Solved
    over T/3 with the pads permuted it agrees with the full-period solve to 1e-12 s, with
    the same multipliers to 1e-9.

    Second route: a plain run from the orbit: each pad's sticks are the previous pad's a
    third of the period later, to 1e-9 s."""
    case, full = start("S22")
    assert full.symmetry == "pads stick in turn, T/3 apart"
    assert full.group == "Z3: 3 identical pads 120 degrees apart on the top face"
    third = periodic_orbit(case, full.state, period=full.period, phases=full.phases,
                           symmetric=True)
    assert abs(third.period - full.period) < 1e-12
    np.testing.assert_allclose(np.sort(np.abs(third.multipliers)),
                               np.sort(np.abs(full.multipliers)), atol=1e-9)
    # and from the command line
    import json

    from support.cli import run_cli

    saved = full.to_dataset()
    saved.attrs["case"] = case.to_toml()
    path = tmp_path / "orbit22.nc"
    saved.to_netcdf(path)
    res = run_cli(["orbit", "--from", path, "--symmetric", "--json", "--no-progress"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert abs(out["period"] - full.period) < 1e-12
    assert out["symmetry"] == "pads stick in turn, T/3 apart"
    assert "solved over T/3" in out["note"]
    times, kinds, sliders = run_events(case, full.state, full.phases, 4 * full.period)
    first = times[(kinds == 0) & (times > full.period) & (times <= 2 * full.period)]
    assert sorted(sliders[(kinds == 0) & (times > full.period)
                          & (times <= 2 * full.period)]) == [0, 1, 2]
    np.testing.assert_allclose(np.diff(np.sort(first)), full.period / 3, atol=1e-9)


@pytest.mark.slow
def test_the_torus_of_the_hopf_branch_is_a_symmetry_breaking():
    """The issue's "torus" at 19.7231 rad/s, on the orbits born at the subcritical Hopf
    point at 19.5731: the orbits have the pads moving in turn, T/3 apart, and the pair
    that leaves the unit circle is one of the T/3 map at 5.7e-6 turns from the 1:3
    resonance: a symmetry breaking, not a torus.

    Second route: at the located point, the reduced map computed apart (a run over T/3
    with tangents, mapped back by P) has a pair on the unit circle (to 1e-4) at that
    angle, whose cube is the full period's pair at +-1.7e-5 turns (to 1e-6)."""
    import cmath

    from fivdisc.analysis.hopf import hopf_points
    from fivdisc.analysis.orbits import orbit_symmetry
    from fivdisc.analysis.symmetry import case_symmetry
    from fivdisc.continuation.from_hopf import hopf_cycles

    found = hopf_points(CASE, "speed.value", np.linspace(1.0, 30.0, 59))
    hopf = next(h for h in found if h.on_boundary)
    assert hopf.value == pytest.approx(19.5731, abs=1e-3)
    br = hopf_cycles(hopf, 30.0, max_points=60, confirm_periods=0)
    kinds = [b["kind"] for b in br.bifurcations()]
    assert "torus" not in kinds
    (sb,) = [b for b in br.bifurcations() if b["kind"] == "symmetry breaking"]
    assert sb["parameter"] == pytest.approx(19.72305, abs=2e-5)
    assert "2 pi (1/3 - 5.7e-06)" in sb["note"] and "1:3 resonance" in sb["note"]
    assert set(br.symmetries()) == {"pads move in turn, T/3 apart"}
    case = CASE.replace({"speed.value": sb["parameter"]})
    model = build_model(case)
    sym = orbit_symmetry(case_symmetry(model), model, sb["state"], sb["phases"],
                         sb["period"], reduced=True)
    assert sym.k == 3
    mu = np.linalg.eigvals(sym.reduced)
    near = mu[np.argmin(np.abs(np.abs(mu) - 1.0) + np.abs(np.abs(np.angle(mu)) - 2 * np.pi / 3))]
    assert abs(abs(near) - 1.0) < 1e-4
    assert abs(np.angle(near)) / (2 * np.pi) == pytest.approx(1 / 3 - 5.7e-6, abs=5e-7)
    assert abs(cmath.phase(near**3)) / (2 * np.pi) == pytest.approx(1.7e-5, abs=1e-6)
    # the orbits that would break the symmetry: their direction is the pair's (M v =
    # mu v, mu within 1e-3 of 1), and from so near a resonance, but not at it, none
    # converges: the error says why
    from fivdisc.continuation.starts import broken_start

    start_orbit, along = broken_start(case, sb["state"], sb["period"], sb["phases"], sb)
    shot = Shooting(model, sb["phases"], 1e-12, 1e-19).shoot(sb["state"], sb["period"])
    values, vectors = np.linalg.eig(shot.monodromy)
    lined = np.abs(vectors.conj().T @ along) / np.linalg.norm(vectors, axis=0)
    assert abs(values[np.argmax(lined)] - 1.0) < 1e-3
    with pytest.raises(ConvergenceError):
        continue_orbit(case, "speed.value", 30.0, orbit=start_orbit, along=along,
                       max_points=3, confirm_periods=0)
