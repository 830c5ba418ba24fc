"""Bifurcations of periodic orbits followed in two keys, against one-parameter branches.

Each curve is checked against something it does not use: the one-parameter branch in
the first key, computed afresh at three values of the second key (the curve's own points,
so that no interpolation between them enters), must locate its bifurcation where the
curve says, to 1e-6 relative. The branch locates a fold by a root of its tangent's
component along the key (Brent, 1e-7), a grazing of the slipping orbits and the end of
the stick-slip orbits by halving its step where the corrector fails (to a step of 1e-6
of the scaled unknowns); the curve zeroes another quantity by a secant (the tangent
component for the fold, but the slip speed's minimum and the stick phase's approach rate
for the ends), each to 1e-7 (``_NEAR``) or better. So 1e-6 holds the two methods to the
coarser one's accuracy with a margin of ten.
"""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

import fivdisc
from fivdisc import examples, load_case
from fivdisc.cli import cli
from fivdisc.continuation.codim2 import bifurcation_curve, curve_from_branch, open_curve
from fivdisc.errors import CaseError, FivdiscError

RIGID = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
DAMPING = "slider.rotational_damping"
SPEED = "speed.value"


def _slipping_orbits(damping: float) -> fivdisc.Branch:
    """The unstable orbits born at the rigid disc's subcritical Hopf point, followed to
    where they graze the stick boundary."""
    case = RIGID.replace({DAMPING: damping})
    (hopf,) = fivdisc.hopf_points(case, SPEED, np.linspace(1.0, 19.0, 7))
    return fivdisc.hopf_cycles(hopf, 30.0, confirm_periods=0)


def _stick_slip(damping: float) -> fivdisc.Branch:
    """The stable stick-slip orbit of the rigid disc at 10.6 rad/s, from a start stuck to
    the disc, followed up in speed to its end."""
    case = RIGID.replace({DAMPING: damping, SPEED: 10.6,
                          "simulation.initial_state": "equilibrium",
                          "simulation.perturbation.phi_dot": 10.6})
    orbit = fivdisc.periodic_orbit(case)
    return fivdisc.continue_orbit(case, SPEED, 14.0, orbit=orbit, confirm_periods=0)


@pytest.fixture(scope="module")
def grazing():
    return curve_from_branch(_slipping_orbits(0.5), 0, DAMPING, 0.56, points=7)


@pytest.fixture(scope="module")
def stick_slip_end():
    branch = _stick_slip(0.5)
    (end,) = [i for i, b in enumerate(branch.bifurcations()) if b["kind"] == "end"]
    return curve_from_branch(branch, end, DAMPING, 0.53, condition="grazing", points=4)


@pytest.fixture(scope="module")
def fold():
    case = load_case(examples.path("damped-disc")).replace({SPEED: 12.3})
    orbit = fivdisc.periodic_orbit(case, transient=5.0)
    branch = fivdisc.continue_orbit(case, SPEED, 12.8, orbit=orbit, max_points=16)
    (k,) = [i for i, b in enumerate(branch.bifurcations()) if b["kind"] == "fold"]
    return curve_from_branch(branch, k, "disc.damping_ratio", 0.0025, points=6)


def _three(curve) -> list[int]:
    """Three points of the curve away from its start: near its first third, middle and
    end."""
    n = len(curve)
    return sorted({max(1, n // 3), n // 2, n - 1})


def test_grazing_curve_crosses_the_branches_of_slipping_orbits(grazing):
    assert grazing.stop_reason == f"reached {DAMPING} = 0.56"
    for i in _three(grazing):
        branch = _slipping_orbits(float(grazing.second_parameter[i]))
        (found,) = [b["parameter"] for b in branch.bifurcations() if b["kind"] == "grazing"]
        assert found == pytest.approx(grazing.parameter[i], rel=1e-6)


def test_end_of_the_stick_slip_orbit_crosses_its_branches(stick_slip_end):
    # the rigid disc's stable stick-slip orbit ends where its slider reaches the disc's
    # speed tangentially (not where its stick phase vanishes: 9 % of the period is left)
    assert stick_slip_end.stop_reason == f"reached {DAMPING} = 0.53"
    for i in _three(stick_slip_end):
        branch = _stick_slip(float(stick_slip_end.second_parameter[i]))
        (found,) = [b["parameter"] for b in branch.bifurcations() if b["kind"] == "end"]
        assert found == pytest.approx(stick_slip_end.parameter[i], rel=1e-6)
        assert branch.stable.all()


def test_fold_curve_crosses_the_branches_of_the_paper_case(fold):
    """The damped-disc case's fold of stick-slip orbits (tests/continuation/
    test_fold_against_forward_runs.py checks the fold itself by forward runs)."""
    assert fold.stop_reason == "reached disc.damping_ratio = 0.0025"
    for i in _three(fold):
        case = load_case(examples.path("damped-disc")).replace(
            {SPEED: 12.2, "disc.damping_ratio": float(fold.second_parameter[i])})
        orbit = fivdisc.periodic_orbit(case, transient=5.0)
        branch = fivdisc.continue_orbit(case, SPEED, 12.8, orbit=orbit, max_points=30)
        (found,) = [b["parameter"] for b in branch.bifurcations() if b["kind"] == "fold"]
        assert found == pytest.approx(fold.parameter[i], rel=1e-6)


def test_every_point_keeps_and_prints_its_residuals(grazing, fold, tmp_path):
    # The shooting residual below the tolerance; the slip speed's minimum within 1e-7
    # (scaled arclength) of zero at its slope, about 2.5: below 1e-6; the fold's tangent
    # component at the noise of the tangent (its d/dp column is a difference).
    for curve, bound in ((grazing, 1e-6), (fold, 1e-6)):
        ds = curve.dataset
        assert (ds["residual"].values < 1e-8).all()
        assert (np.abs(ds["condition"].values) < bound).all()
        text = str(curve)
        assert "largest shooting residual" in text
        assert len(curve.lines()) == len(curve) + 1
        for i, line in enumerate(curve.lines()[1:]):
            assert f"{ds['residual'].values[i]:.1e}" in line
    grazing.to_netcdf(tmp_path / "curve.nc")
    again = open_curve(tmp_path / "curve.nc")
    assert again.dataset.equals(grazing.dataset) and str(again) == str(grazing)
    assert again.at(float(grazing.second_parameter[2])) == grazing.parameter[2]


def test_command_line_follows_writes_prints_and_draws(tmp_path):
    branch = _slipping_orbits(0.5)
    branch.to_netcdf(tmp_path / "branch.nc")
    runner = CliRunner()
    out = tmp_path / "curve.nc"
    res = runner.invoke(cli, ["continue", "--from", str(tmp_path / "branch.nc"), "--key", SPEED,
                              "--bifurcation", "0", "--key2", DAMPING, "--to2", "0.52",
                              "--curve-points", "3", "-o", str(out), "--no-progress"])
    assert res.exit_code == 0, res.output
    assert "grazing curve in (speed.value, slider.rotational_damping)" in res.output
    assert "residual" in res.output and "condition" in res.output
    curve = open_curve(out)
    assert curve.second_parameter[-1] == 0.52
    res = runner.invoke(cli, ["plot", str(out), "-o", str(tmp_path / "curve.png")])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "curve.png").stat().st_size > 0
    # refusals, one line each, before any work
    for args, words in (
            (["--to2", "0.6"], "--key2 KEY and --to2 VALUE"),
            (["--key2", DAMPING, "--to2", "0.6", "--bifurcation", "5"], "bifurcation = 5"),
            (["--key2", SPEED, "--to2", "0.6", "--bifurcation", "0"], "key2 = 'speed.value'"),
            (["--key2", DAMPING, "--to2", "0.5", "--bifurcation", "0"], "to2 = 0.5"),
            (["--key2", DAMPING, "--to2", "0.6", "--bifurcation", "0",
              "--curve-points", "1"], "--curve-points = 1")):
        res = runner.invoke(cli, ["continue", "--from", str(tmp_path / "branch.nc"),
                                  "--key", SPEED, *args, "--no-progress"])
        assert res.exit_code == 2, res.output
        (line,) = res.output.strip().splitlines()
        assert line.startswith("error: ") and words in line, line


def test_bad_conditions_and_keys_are_refused():
    branch_args = {"state": np.zeros(4), "period": 1e-3, "phases": np.zeros(1, dtype=int)}
    with pytest.raises(FivdiscError, match="condition = 'hopf' is invalid"):
        bifurcation_curve(RIGID, SPEED, "hopf", DAMPING, 0.6, **branch_args)
    with pytest.raises(CaseError, match="points = 1 is invalid"):
        bifurcation_curve(RIGID, SPEED, "fold", DAMPING, 0.6, points=1, **branch_args)
    with pytest.raises(CaseError, match=r"to2 = -1\.0 is invalid|must be >= 0"):
        bifurcation_curve(RIGID, SPEED, "fold", DAMPING, -1.0, **branch_args)


@pytest.mark.slow
def test_period_doubling_and_torus_curves_cross_the_branches():
    """The damped-disc orbit near 2.59 rad/s continued in the disc's damping ratio
    towards zero meets tori and a period doubling near 3.59e-6
    (test_continuation.py's doubled orbits start there). The period doubling and the
    last torus before it followed in the speed; at three of the curves' speeds the branch
    in the damping, computed afresh, locates each where its curve says (Brent on the
    passing multiplier, 1e-7, against the curve's secant on Re mu + 1 or |mu| - 1, 1e-9:
    1e-6 relative)."""
    speed = 2.5911321532805127
    case = load_case(examples.path("damped-disc"))
    key = "disc.damping_ratio"

    def primary(value: float) -> fivdisc.Branch:
        at = case.replace({SPEED: value})
        start = fivdisc.periodic_orbit(at, transient=6.0)
        return fivdisc.continue_orbit(at, key, 2e-6, orbit=start, max_points=120)

    branch = primary(speed)
    kinds = [b["kind"] for b in branch.bifurcations()]
    pd = kinds.index("period doubling")
    torus = max(i for i, k in enumerate(kinds) if k == "torus" and i < pd)
    curves = {kind: curve_from_branch(branch, i, SPEED, 2.6, points=4)
              for kind, i in (("period doubling", pd), ("torus", torus))}
    for curve in curves.values():
        assert curve.stop_reason == f"reached {SPEED} = 2.6"
        assert (np.abs(curve.condition) < 1e-8).all()
    nodes = curves["period doubling"].second_parameter
    for i in (1, 2, 3):
        found = primary(float(nodes[i])).bifurcations()
        for kind, curve in curves.items():
            j = int(np.argmin(np.abs(curve.second_parameter - nodes[i])))
            assert curve.second_parameter[j] == nodes[i]
            near = [b["parameter"] for b in found if b["kind"] == kind]
            value = min(near, key=lambda p: abs(p - curve.parameter[j]))
            assert value == pytest.approx(curve.parameter[j], rel=1e-6)


@pytest.mark.slow
def test_symmetry_breaking_curve_crosses_the_branches_of_three_pads():
    """Issue 36's three pads: the orbits born at the subcritical Hopf point (pads in
    turn, T/3 apart) lose their symmetry near 19.7231 rad/s, where a pair of the T/3
    map crosses the unit circle near the 1:3 resonance. Followed in the disc's damping
    ratio (|mu| - 1 of the reduced map's eigenvalue); at three of its values the branch
    from the Hopf point, computed afresh, locates it where the curve says (1e-6)."""
    from pathlib import Path

    case = load_case(Path(__file__).parents[1] / "data" / "three_pads_issue36.toml")
    key = "disc.damping_ratio"

    def cycles(damping: float) -> fivdisc.Branch:
        at = case.replace({key: damping})
        hopf = next(h for h in fivdisc.hopf_points(at, SPEED, np.linspace(19.4, 19.8, 5))
                    if h.on_boundary)
        return fivdisc.hopf_cycles(hopf, 20.0, confirm_periods=0)

    branch = cycles(0.003)
    (k,) = [i for i, b in enumerate(branch.bifurcations()) if b["kind"] == "symmetry breaking"]
    curve = curve_from_branch(branch, k, key, 0.0033, points=4)
    assert curve.stop_reason == f"reached {key} = 0.0033"
    assert (np.abs(curve.condition) < 1e-9).all()
    for i in (1, 2, 3):
        found = [b["parameter"] for b in cycles(float(curve.second_parameter[i])).bifurcations()
                 if b["kind"] == "symmetry breaking"]
        assert len(found) == 1
        assert found[0] == pytest.approx(curve.parameter[i], rel=1e-6)


def test_a_curve_point_is_a_start_at_both_keys(grazing, tmp_path):
    """An orbit started from a point of a curve (``--from curve.nc --point K``) is at the
    point's values of both keys: Newton from the stored state converges at once to it."""
    from fivdisc.analysis.orbits import saved_start

    grazing.to_netcdf(tmp_path / "curve.nc")
    saved = saved_start(tmp_path / "curve.nc", 3)
    assert saved.case.get(DAMPING) == grazing.second_parameter[3]
    assert saved.case.get(SPEED) == grazing.parameter[3]
    orbit = fivdisc.periodic_orbit(saved.case, saved.state, period=saved.period,
                                   phases=saved.phases)
    assert orbit.period == pytest.approx(grazing.period[3], rel=1e-9)


def _fig13_branch(static: float) -> fivdisc.Branch:
    """The paper's Fig. 13 stick-slip orbit, continued up in the disc speed to where its
    stick phase splits (near 6.5758 rad/s at mu_s = 0.8)."""
    from fivdisc.paper.cases import FIGURES

    case = FIGURES[13].case.replace({"friction.static": static})
    orbit = fivdisc.periodic_orbit(case, transient=5.0, window=0.05)
    return fivdisc.continue_orbit(case, SPEED, 8.0, orbit=orbit, max_points=40,
                                  confirm_periods=0)


def test_stick_split_curve_crosses_the_branches_of_the_paper_case():
    """The Fig. 13 branch ends at a stick split; followed in the static friction
    coefficient, the split moves up in speed. Each fresh branch locates its end by
    bisection on converged orbits to 1e-7, and where it meets a shallow dip the last
    orbit found depends on how shallow an excursion the event search still sees: 2e-6
    across starts and steps (docs/continuation.md). So the curve (condition zeroed to
    1e-7) agrees with the branches to 3e-6."""
    branch = _fig13_branch(0.8)
    (k,) = [i for i, b in enumerate(branch.bifurcations()) if b["kind"] == "stick split"]
    curve = curve_from_branch(branch, k, "friction.static", 0.808, points=4)
    assert curve.stop_reason == "reached friction.static = 0.808"
    assert np.all(np.abs(curve.condition) < 1e-6)
    assert np.all(np.diff(curve.parameter) > 0)
    for i in _three(curve):
        again = _fig13_branch(float(curve.second_parameter[i]))
        (found,) = [b["parameter"] for b in again.bifurcations()
                    if b["kind"] == "stick split"]
        assert found == pytest.approx(curve.parameter[i], rel=1e-6)
