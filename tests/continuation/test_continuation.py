"""Continuation of periodic orbits: branches against closed forms and independent solves,
the minimal period, failures that are not results, the command line and its files."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.cli import cli
from fivdisc.continuation.branch import open_branch
from fivdisc.continuation.walk import continue_orbit
from fivdisc.errors import CaseError, ConvergenceError, FivdiscError

from support.cases import LIGHT, RIGID, rigid_disc_closed_form
from support.cli import run_cli


@pytest.fixture(scope="module")
def rigid_orbit():
    return periodic_orbit(RIGID, transient=4.0)


@pytest.fixture(scope="module")
def rigid_branch(rigid_orbit):
    return continue_orbit(RIGID, "speed.value", 3.0, orbit=rigid_orbit, max_points=60)


def test_rigid_disc_branch_follows_the_closed_form(rigid_branch):
    """The rigid-disc stick-slip oscillator's period is known in closed form at every belt
    speed (test_orbits): each continued point's period equals it to 1e-9 (the shooting
    residual's tolerance is 1e-8 of the orbit's size; the period converges quadratically
    below it), and its disc-mode multipliers equal exp(lambda T) to 1e-6 (the accuracy of
    the monodromy at rtol 1e-12, test_orbits). The stick phase persists over the whole
    range, as the closed form's stick duration 2 d / Omega > 0 says: no signature change."""
    br = rigid_branch
    assert br.stop_reason.startswith("reached")
    assert br.parameter[0] == pytest.approx(1.0)
    assert br.parameter[-1] == pytest.approx(3.0, rel=1e-12)
    assert np.all(np.diff(br.parameter) > 0)
    for p, period, mult in zip(br.parameter, br.period, br.multipliers, strict=True):
        expected, disc = rigid_disc_closed_form(p)
        assert period == pytest.approx(expected, rel=1e-9)
        big = mult[np.abs(mult) > 0.5]
        big = big[np.abs(big - 1.0) > 1e-6]
        assert np.sort_complex(big) == pytest.approx(np.sort_complex(disc), abs=1e-6)
    assert br.stable.all()
    assert br.bifurcations() == []
    sig = {br.signature(i) for i in range(len(br))}
    assert len(sig) == 1
    phases = next(iter(sig))[0].split(" > ")
    assert phases[0] == phases[-1] and phases.count("stick") == 1


def test_branch_points_agree_with_independent_orbit_solves(rigid_branch):
    """At three points of the branch, periodic_orbit started afresh (a transient from rest
    at that speed, nothing taken from the branch) converges to the same period to 1e-9:
    the orbit is the global attractor of the damped oscillator, so the transient finds it."""
    br = rigid_branch
    for i in (1, len(br) // 2, len(br) - 1):
        case = RIGID.replace({"speed.value": float(br.parameter[i])})
        alone = periodic_orbit(case, transient=4.0)
        assert alone.period == pytest.approx(br.period[i], rel=1e-9)


def test_branch_is_continuous_in_both_directions(rigid_orbit):
    """Down in the speed from the same orbit: the parameter decreases monotonically and
    the periods follow the closed form, so no point jumped to another orbit."""
    br = continue_orbit(RIGID, "speed.value", 0.5, orbit=rigid_orbit, max_points=120)
    assert br.parameter[-1] == pytest.approx(0.5, rel=1e-12)
    assert np.all(np.diff(br.parameter) < 0)
    for p, period in zip(br.parameter, br.period, strict=True):
        assert period == pytest.approx(rigid_disc_closed_form(p)[0], rel=1e-9)


def test_continuation_in_a_slider_key_matches_independent_solves():
    """A branch in the slider's normal damping of the light-disc case: at its last point
    an independent periodic_orbit (transient from rest at that value) gives the same
    period to 1e-9, and the branch's measures bracket that orbit's phi_dot."""
    start = periodic_orbit(LIGHT, transient=2.0)
    br = continue_orbit(LIGHT, "slider.normal_damping", 40.0, orbit=start, max_points=15)
    assert br.parameter[-1] == pytest.approx(40.0, rel=1e-12)
    alone = periodic_orbit(LIGHT.replace({"slider.normal_damping": 40.0}), transient=2.0)
    assert alone.period == pytest.approx(br.period[-1], rel=1e-9)
    # The stored point is the orbit's in every coordinate, those the contact holds (the
    # slider's z, zdot) included: one period of a plain run returns to it.
    from fivdisc.analysis.orbits import Shooting, energy_scales
    from fivdisc.model.build import build_model

    model = build_model(LIGHT.replace({"slider.normal_damping": 40.0}))
    x = br.dataset["state"].values[-1]
    shot = Shooting(model, br.phases(len(br) - 1), 1e-12, 1e-19).shoot(
        x, float(br.period[-1]), tangents=False)
    scale = energy_scales(model)
    size = np.linalg.norm(shot.rate_start / scale) * br.period[-1]
    assert np.linalg.norm((shot.end - x) / scale) < 1e-7 * size
    ds = br.dataset
    assert np.all(ds["phi_dot_max"].values >= ds["phi_dot_min"].values)
    # A sticking slider moves with the disc: the largest angular velocity is the speed.
    assert ds["phi_dot_max"].values[:, 0] == pytest.approx(LIGHT.speed.value, rel=1e-6)


def test_a_branch_lands_on_a_bound_of_the_key_range():
    """Continued to zero disc damping (the lowest value allowed): the predictor and the
    parameter derivative never step outside the range, the branch ends exactly at zero,
    and the period is the closed form's all along (the disc mode is at rest on the
    rigid-disc orbit, so its damping does not change the period)."""
    case = RIGID.replace({"disc.damping_ratio": 0.05})
    start = periodic_orbit(case, transient=4.0)
    br = continue_orbit(case, "disc.damping_ratio", 0.0, orbit=start, max_points=40)
    assert br.stop_reason.startswith("reached")
    assert br.parameter[-1] == 0.0
    expected = rigid_disc_closed_form()[0]
    assert br.period == pytest.approx(np.full(len(br), expected), rel=1e-9)
    assert br.bifurcations() == []


def test_torus_points_lie_where_independent_solves_cross_the_unit_circle():
    """The Fig. 13 orbit continued in the disc's damping ratio from 1e-5 down to zero
    loses stability through two complex pairs (rotation numbers near 0.16 and 0.41)
    within a factor 1.5 of each other. At 2 % either side of each located torus point,
    periodic_orbit started from the branch's state gives that pair's modulus on the
    far side of 1 on each side: |mu| - 1 is there about 3e-7, thirty times the
    monodromy's error at rtol 1e-12 (1e-8, test_orbits), so the sign is certain."""
    from fivdisc import paper

    case = paper.FIG13.case.replace({"disc.damping_ratio": 1e-5})
    start = periodic_orbit(case, transient=5.0)
    br = continue_orbit(case, "disc.damping_ratio", 0.0, orbit=start, max_points=60)
    tori = [b for b in br.bifurcations() if b["kind"] == "torus"]
    assert len(tori) == 2
    assert abs(tori[0]["rotation"] - tori[1]["rotation"]) > 0.1
    # Upwards from the undamped disc both pairs pass within the first step: each is
    # found, at the same place.
    undamped = paper.FIG13.case
    up = continue_orbit(undamped, "disc.damping_ratio", 1e-5,
                        orbit=periodic_orbit(undamped, transient=5.0), max_points=3)
    found = sorted((b for b in up.bifurcations() if b["kind"] == "torus"),
                   key=lambda b: -b["parameter"])
    assert [b["parameter"] for b in found] == pytest.approx(
        [b["parameter"] for b in tori], rel=1e-6)
    for torus in tori:
        for factor, outside in ((0.98, True), (1.02, False)):
            alone = periodic_orbit(
                case.replace({"disc.damping_ratio": torus["parameter"] * factor}),
                guess=torus["state"], period=torus["period"])
            mu = alone.multipliers
            pair = mu[np.abs(mu.imag) > 1e-9]
            rotation = np.abs(np.angle(pair)) / (2 * np.pi)
            closest = pair[np.argmin(np.abs(rotation - torus["rotation"]))]
            assert (abs(closest) > 1.0) == outside
            assert abs(abs(closest) - 1.0) > 1e-7


def test_an_interrupted_continuation_keeps_its_branch(rigid_orbit, tmp_path, monkeypatch):
    """Ctrl-C during the walk ends it as a time budget does: the points so far are the
    branch (the API returns it, the command writes it and exits 130)."""
    from fivdisc.continuation.problem import OrbitProblem
    from fivdisc.continuation.settings import INTERRUPTED

    step_from = OrbitProblem.step_from
    calls = {"n": 0}

    def interrupted_later(self, a, s, deadline):
        calls["n"] += 1
        if calls["n"] == 4:
            raise KeyboardInterrupt
        return step_from(self, a, s, deadline)

    monkeypatch.setattr(OrbitProblem, "step_from", interrupted_later)
    br = continue_orbit(RIGID, "speed.value", 3.0, orbit=rigid_orbit, max_points=20)
    assert br.stop_reason == INTERRUPTED
    assert len(br) == 4
    for p, period in zip(br.parameter, br.period, strict=True):
        assert period == pytest.approx(rigid_disc_closed_form(p)[0], rel=1e-9)

    case, orbit_file, out = tmp_path / "rigid.toml", tmp_path / "orbit.nc", tmp_path / "b.nc"
    case.write_text(RIGID.replace({"simulation.duration": 4.0}).to_toml())
    runner = CliRunner()
    result = runner.invoke(cli, ["orbit", str(case), "--no-progress", "-o", str(orbit_file)])
    assert result.exit_code == 0, result.output
    calls["n"] = 0
    result = runner.invoke(cli, ["continue", "--from", str(orbit_file), "--key",
                                 "speed.value", "--to", "3", "--no-progress", "-o", str(out)])
    assert result.exit_code == 130, result.output
    assert len(open_branch(out)) == 4


def test_the_doubled_orbits_are_born_at_the_period_doubling():
    """The damped-disc orbit at 2.59 rad/s, continued in the disc damping towards zero,
    has a real multiplier pass -1 at about 3.59e-6. From that point the branch of
    doubled orbits: each of its points closes after 2 T (the branch's residual) but not
    after T, by a distance a that vanishes at the period doubling as a pitchfork's does
    (a^2 proportional to the distance in the key, the same constant to 5 % over the
    branch's first points), on one side of it only."""
    from fivdisc import examples, load_case
    from fivdisc.analysis.orbits import Shooting, energy_scales
    from fivdisc.continuation.starts import doubled_start
    from fivdisc.model.build import build_model

    case = load_case(examples.path("damped-disc")).replace({"speed.value": 2.5911321532805127})
    start = periodic_orbit(case, transient=6.0)
    primary = continue_orbit(case, "disc.damping_ratio", 2e-6, orbit=start, max_points=120)
    (pd,) = [b for b in primary.bifurcations() if b["kind"] == "period doubling"]
    at = case.replace({"disc.damping_ratio": pd["parameter"]})
    orbit, along = doubled_start(at, pd["state"], pd["period"], pd["phases"])
    doubled = continue_orbit(at, "disc.damping_ratio", 0.0, orbit=orbit, along=along,
                             max_points=8)
    assert len(doubled) == 8
    assert np.all(doubled.period == pytest.approx(2 * pd["period"], rel=1e-6))
    distance = pd["parameter"] - doubled.parameter
    assert np.all(distance > 0)
    ratios = []
    for i in range(len(doubled)):
        model = build_model(at.replace({"disc.damping_ratio": float(doubled.parameter[i])}))
        scale = energy_scales(model)
        x = doubled.dataset["state"].values[i]
        half = Shooting(model, doubled.phases(i), 1e-12, 1e-19, scale).shoot(
            x, 0.5 * float(doubled.period[i]), tangents=False)
        size = np.linalg.norm(half.rate_start / scale) * doubled.period[i]
        gap = np.linalg.norm(((half.end - x) / scale)[half.free]) / size
        ratios.append(gap**2 / distance[i])
    assert np.ptp(ratios) < 0.05 * np.mean(ratios)


def test_a_multiple_of_the_period_is_reduced_to_the_minimal_period():
    """Started with three times the closed-form period as its guess, Newton converges on
    the orbit traversed three times; it is reported at its minimal period, with the
    multipliers of that period (the disc mode's exp(lambda T), not their cubes)."""
    period, disc = rigid_disc_closed_form()
    first = periodic_orbit(RIGID, transient=4.0)
    orbit = periodic_orbit(RIGID, first.state, period=3.0 * period, phases=first.phases)
    assert orbit.period == pytest.approx(period, rel=1e-9)
    others = np.delete(orbit.multipliers, orbit.trivial)
    big = others[np.abs(others) > 0.5]
    assert np.sort_complex(big) == pytest.approx(np.sort_complex(disc), abs=1e-6)


def test_an_orbit_that_does_not_converge_is_no_result():
    """No Newton iteration allowed from a guess off the orbit: ConvergenceError, whose
    result is marked not converged and whose text labels no multiplier."""
    period, _ = rigid_disc_closed_form()
    first = periodic_orbit(RIGID, transient=4.0)
    guess = first.state.copy()
    guess[RIGID_PHI] += 0.05
    with pytest.raises(ConvergenceError, match="iteration budget") as info:
        periodic_orbit(RIGID, guess, period=period, phases=first.phases, max_iterations=0)
    orbit = info.value.result
    assert not orbit.converged
    assert orbit.verdict == "not converged"
    assert "flow direction" not in str(orbit)
    assert orbit.to_dict()["converged"] is False


RIGID_PHI_DOT = 4  # q, phi, z, qdot, phidot, zdot for one mode and one slider
RIGID_PHI = 1  # free in every phase (a stuck slider's rate is held at the disc speed)


def test_orbit_command_exits_1_when_not_converged(tmp_path):
    path = tmp_path / "rigid.toml"
    path.write_text(RIGID.replace({"simulation.duration": 4.0}).to_toml())
    res = run_cli(["orbit", str(path), "--json", "--no-progress",
                                   "--period", "0.005", "--window", "0.01"])
    assert res.exit_code == 1
    data = json.loads(res.stdout)
    assert data["converged"] is False
    assert "not converged" in res.stderr and "residual" in res.stderr


def test_orbit_and_branch_files_round_trip(tmp_path):
    """fivdisc orbit -o, then --from that file; fivdisc continue -o, plot and --from."""
    case = tmp_path / "rigid.toml"
    case.write_text(RIGID.replace({"simulation.duration": 4.0}).to_toml())
    orbit_nc = tmp_path / "orbit.nc"
    runner = CliRunner()
    res = runner.invoke(cli, ["orbit", str(case), "--no-progress", "-o", str(orbit_nc)])
    assert res.exit_code == 0, res.output
    res = runner.invoke(cli, ["orbit", "--from", str(orbit_nc), "--json", "--no-progress"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert data["period"] == pytest.approx(rigid_disc_closed_form()[0], rel=1e-9)
    assert str(orbit_nc) in data["start"]
    branch_nc = tmp_path / "branch.nc"
    res = runner.invoke(cli, ["continue", "--from", str(orbit_nc), "--key", "speed.value",
                              "--to", "1.5", "--no-progress", "-o", str(branch_nc)])
    assert res.exit_code == 0, res.output
    br = open_branch(branch_nc)
    assert br.key == "speed.value"
    assert br.parameter[-1] == pytest.approx(1.5)
    assert br.period[-1] == pytest.approx(rigid_disc_closed_form(1.5)[0], rel=1e-9)
    res = runner.invoke(cli, ["continue", "--from", str(branch_nc), "--key", "speed.value",
                              "--to", "2.0", "--json", "--no-progress"])
    assert res.exit_code == 0, res.output
    again = json.loads(res.stdout)
    assert again["points"][0]["parameter"] == pytest.approx(1.5)
    assert again["points"][-1]["parameter"] == pytest.approx(2.0)
    # each point's multipliers: the disc mode's, by hand (as in the rigid-disc branch test)
    for point in again["points"]:
        mult = np.array([m["real"] + 1j * m["imag"] for m in point["multipliers"]])
        assert [m["modulus"] for m in point["multipliers"]] == pytest.approx(np.abs(mult))
        big = mult[np.abs(mult) > 0.5]
        big = big[np.abs(big - 1.0) > 1e-6]
        disc = rigid_disc_closed_form(point["parameter"])[1]
        assert np.sort_complex(big) == pytest.approx(np.sort_complex(disc), abs=1e-6)
    png = tmp_path / "branch.png"
    res = runner.invoke(cli, ["plot", str(branch_nc), "--var", "phi_dot", "-o", str(png)])
    assert res.exit_code == 0, res.output
    assert png.stat().st_size > 0
    # options that do not apply to a branch are refused, not ignored
    for extra in (["--kind", "spectrogram"], ["--slider", "0"]):
        res = runner.invoke(cli, ["plot", str(branch_nc), *extra, "-o", str(png)])
        assert res.exit_code == 2 and "is not used" in res.output, res.output
    res = runner.invoke(cli, ["plot", str(branch_nc)])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "branch-period.png").exists()


def test_a_branch_rewritten_through_xarray_keeps_its_checksum(rigid_branch, tmp_path):
    # The rigid disc's branch has no bifurcation: its text tables (kind, note, the
    # signatures) are empty, which once made xarray's rewrite change the file's checksum.
    from fivdisc.files import check_netcdf

    from support.files import through_xarray

    assert not rigid_branch.bifurcations()
    path = tmp_path / "branch.nc"
    rigid_branch.to_netcdf(path)
    copy = through_xarray(path, tmp_path / "copy.nc")
    assert check_netcdf(copy)
    again = open_branch(copy)
    assert again.to_dict() == open_branch(path).to_dict()


@pytest.mark.parametrize(("args", "message"), [
    (["--key", "speed.profile", "--to", "1"], "is not a number"),
    (["--key", "disc.modes", "--to", "1"], "is not a number"),
    (["--key", "simulation.impact", "--to", "1"], "simulation settings"),
    (["--key", "simulation.duration", "--to", "2"], "simulation settings"),
    (["--key", "simulation.perturbation.phi", "--to", "0.1"], "simulation settings"),
    (["--key", "speed.valeu", "--to", "1"], "did you mean 'speed.value'"),
    (["--key", "speed.value", "--to", "-1"], "must be >= 0"),
    (["--key", "speed.value", "--to", "inf"], "finite"),
    (["--key", "slider.mass", "--to", "0"], "slider.mass"),
    (["--key", "speed.value", "--to", "0.5", "--back-to", "0.8"], "--back-to = 0.8 is invalid"),
    (["--key", "speed.value", "--to", "3", "--back-to", "nan"], "--back-to = nan is invalid"),
])
def test_continue_refuses_bad_input_before_any_work(tmp_path, args, message):
    case = tmp_path / "rigid.toml"
    case.write_text(RIGID.to_toml())
    res = run_cli(["continue", str(case), "--no-progress", *args])
    assert res.exit_code == 2
    assert message in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1


def test_continue_needs_an_autonomous_case_and_a_periodic_start(rigid_orbit):
    moving = RIGID.replace({"speed.profile": "decelerating", "speed.initial": 1.0,
                            "speed.duration": 10.0})
    with pytest.raises(FivdiscError, match="constant disc speed"):
        continue_orbit(moving, "speed.initial", 2.0)
    with pytest.raises(CaseError, match="own value"):
        continue_orbit(RIGID, "speed.value", 1.0, orbit=rigid_orbit)
    period, _ = rigid_disc_closed_form()
    try:
        periodic_orbit(RIGID, rigid_orbit.state + 0.01, period=period,
                       phases=rigid_orbit.phases, max_iterations=0)
    except ConvergenceError as exc:
        unconverged = exc.result
    with pytest.raises(ConvergenceError, match="not a converged periodic orbit"):
        continue_orbit(RIGID, "speed.value", 2.0, orbit=unconverged)


# --- switches inside one step, and a branch that ends at a stick split ----------------------

# The rigid-disc oscillator, undamped in the normal direction, at a crawling disc speed:
# started sticking with the disc mode ringing, the friction needed to stick is nearly
# constant while the normal force oscillates at the disc mode's 237 Hz; the first trough
# of mu_s N that falls below the needed friction starts a slip.
_GRAZE = RIGID.replace({"slider.normal_damping": 0.0, "speed.value": 0.01})
_GRAZE_SPAN = 0.004  # [s]: one period of the disc mode, 4.2 ms


def _graze_run(phi0: float, max_step: float = 0.0):
    from fivdisc.engine.integration import Integration
    from fivdisc.model.build import build_model
    from fivdisc.model.layout import Phase

    model = build_model(_GRAZE)
    y = np.zeros(model.state_size)
    y[model.n + 2] = -0.1  # the disc mode's velocity [m/s]: it rings
    y[model.index("phi")] = phi0
    y[model.index("phi_dot")] = 0.01
    run = Integration(model, y, duration=_GRAZE_SPAN, output_rate=1.0 / _GRAZE_SPAN,
                      rtol=1e-6, atol=1e-12, max_step=max_step,
                      phases=np.array([Phase.STICK]))
    run.run_to(_GRAZE_SPAN)
    times, _ = run.events()
    return times, run.out_y[1, : model.state_size], run.stats["steps"]


def test_a_switch_inside_one_step_is_found():
    """The slider is started sticking at the angle phi0* where the trough of the static
    limit just touches the needed friction (found by bisection with steps capped at
    0.1 us, so that every trough is resolved), plus 1e-7 of it: the event function dips
    below zero for a few microseconds only (its depth is 1e-7 of the needed friction, so
    the dip's width is of order sqrt(1e-7) of the disc mode's period), while the steps of
    the free run at rtol 1e-6 are of order 100 us. The free run finds the slip at the
    same time as the capped run, to 1 ns (the slip's time at a shallow trough is sensitive
    to the dense output's error at rtol 1e-6), and ends in the same state to 1e-4
    (the state's error at rtol 1e-6 over 4 ms, relative)."""
    cap = 1e-7
    lo, hi = 0.0, 0.06
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        if _graze_run(mid, cap)[0].size:
            hi = mid
        else:
            lo = mid
    phi0 = hi * (1.0 + 1e-7)
    capped, end_capped, _ = _graze_run(phi0, cap)
    free, end_free, steps = _graze_run(phi0)
    assert capped.size == 1 and 0.2 * _GRAZE_SPAN < capped[0] < 0.8 * _GRAZE_SPAN
    assert _GRAZE_SPAN / steps > 50e-6  # the free run's mean step: far wider than the dip
    assert free.size == 1
    assert free[0] == pytest.approx(capped[0], abs=1e-9)
    assert end_free == pytest.approx(end_capped, rel=1e-4, abs=1e-10)
    # Below the threshold no trough reaches the needed friction: no switch at all.
    assert _graze_run(lo * (1.0 - 1e-7))[0].size == 0


@pytest.mark.slow
def test_fig13_branch_ends_where_its_stick_phase_splits():
    """The Fig. 13 orbit continued up in the disc speed: near 6.576 rad/s the friction
    needed to stick touches mu_s N at an interior maximum of the stick phase, the slider
    slips there and the flow map jumps, so the orbit ends. The continuation locates the
    stick split to 1e-6; plain runs from the last orbit's point with steps capped at
    0.1 us (independent of the continuation and of the kernel's dip search) show one
    stick phase 2e-6 below the located speed and a split one 2e-6 above it.

    Beside it, at 6.58 rad/s, lies an orbit of six cycles whose period is 3e-5 from six
    times the one-cycle orbit's (a transient of 3 s finds it): the branch does not jump
    onto it. Its points move continuously (each within a tenth of the state's size of
    the previous), every period stays a one-cycle period, and it ends at the split."""
    from fivdisc.analysis.cycle import one_period
    from fivdisc.model.build import build_model
    from fivdisc.paper.cases import FIGURES

    case = FIGURES[13].case
    orbit = periodic_orbit(case, transient=5.0, window=0.05)
    br = continue_orbit(case, "speed.value", 8.0, orbit=orbit, max_points=40)
    assert "does not persist past the stick split" in br.stop_reason
    six = periodic_orbit(case.replace({"speed.value": 6.58}), transient=3.0, window=0.05)
    assert six.period == pytest.approx(6 * br.period[-1], rel=1e-4)
    assert np.all(np.abs(6 * br.period / six.period - 1) > 1e-5)
    states = br.dataset["state"].values
    steps = np.linalg.norm(np.diff(states, axis=0), axis=1)
    assert np.all(steps < 0.1 * np.linalg.norm(states[1:], axis=1))
    (end,) = [b for b in br.bifurcations() if b["kind"] == "stick split"]
    assert end["signature_before"] == ("slip+ > stick > slip+",)
    assert end["signature_after"][0].count("stick") == 2
    x, period = end["state"], end["period"]
    phases = end["phases"]
    for factor, sticks in ((1 - 2e-6, 1), (1 + 2e-6, 2)):
        model = build_model(case.replace({"speed.value": end["parameter"] * factor}))
        cyc = one_period(_capped(model), x, phases, period, 1e-12, 1e-19)
        assert cyc.signature[0].count("stick") == sticks


def _capped(model):
    """The model with its case's largest step set to 0.1 us."""
    from dataclasses import replace

    return replace(model, case=model.case.replace({"simulation.max_step": 1e-7}))


def test_a_branch_is_laid_over_a_brute_force_diagram(tmp_path, rigid_branch):
    """fivdisc bifurcation --branch: the sweep's section values (phi_dot at its maxima,
    which on the stick-slip orbit is the disc speed) and the branch's largest phi_dot
    share the axes; a branch in another key is refused in one line before the sweep."""
    branch_nc = tmp_path / "branch.nc"
    rigid_branch.to_netcdf(branch_nc)
    sweep = tmp_path / "speed.toml"
    sweep.write_text("""
mode = "grid"
[base.disc]
modes = [[0, 0]]
[base.slider]
rotational_damping = 0.0
normal_damping = 5.0
[base.friction]
static = 0.8
kinetic_max = 0.5
kinetic_min = 0.5
decay = 0.0
[base.simulation]
duration = 0.5
output_rate = 5000.0
[axes]
"speed.value" = "1.0:2.0:2"
[[reduce.section]]
variable = "phi_dot"
at = "maxima"
after = 0.3
max_points = 50
""")
    png = tmp_path / "diagram.png"
    runner = CliRunner()
    res = runner.invoke(cli, ["bifurcation", str(sweep), "--branch", str(branch_nc),
                              "--workers", "1", "--no-progress", "-o", str(png)])
    assert res.exit_code == 0, res.output
    assert png.stat().st_size > 0
    other = tmp_path / "other.nc"
    br = open_branch(branch_nc)
    br.dataset.attrs["key"] = "slider.mass"
    br.to_netcdf(other)
    res = runner.invoke(cli, ["bifurcation", str(sweep), "--branch", str(other),
                              "--workers", "1", "--no-progress", "-o", str(png)])
    assert res.exit_code == 2
    assert "cannot share an axis" in res.stderr
