"""A fold of cycles found by continuation, confirmed by plain forward runs.

The packaged ``damped-disc`` case (the paper's first example with 0.2 % modal damping)
has, near 12.53 rad/s, a stick-slip orbit whose branch folds: stable below the fold, a
saddle orbit after it, the branch turning back in the disc speed. The checks here use
nothing of the continuation but its output: forward simulations without tangents,
whose only observable is the time each stick phase lasts (the kernel locates each
stick and slip switch by root finding, so these durations are a Poincare map of the
flow read to the integration tolerance).
"""

from __future__ import annotations

import numpy as np
import pytest

from fivdisc import examples, load_case, simulate
from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.continuation.walk import continue_orbit

CASE = load_case(examples.path("damped-disc")).replace({"speed.value": 12.3})


@pytest.fixture(scope="module")
def branch():
    orbit = periodic_orbit(CASE, transient=5.0)
    return continue_orbit(CASE, "speed.value", 12.8, orbit=orbit, max_points=16)


@pytest.fixture(scope="module")
def fold(branch):
    folds = [b for b in branch.bifurcations() if b["kind"] == "fold"]
    assert len(folds) == 1
    return folds[0]


def _stick_durations(case, state) -> np.ndarray:
    """The length [s] of each stick phase of a forward run from ``state``."""
    run = simulate(case, initial=state)
    assert run.ok, run.message
    stick, slip = run.events("stick"), run.events("slip")
    slip = slip[slip > stick[0]]
    k = min(stick.size, slip.size)
    return slip[:k] - stick[:k]


def _prony(sequence: np.ndarray, order: int) -> np.ndarray:
    """Roots of the linear recurrence of ``order`` that fits ``sequence`` best (least
    squares): near a periodic orbit the deviations of a Poincare map's observable are
    sums of powers of the orbit's Floquet multipliers, and these roots estimate them."""
    rows = np.column_stack([sequence[j:sequence.size - order + j] for j in range(order)])
    coefficients, *_ = np.linalg.lstsq(rows, sequence[order:], rcond=None)
    return np.roots(np.r_[1.0, -coefficients[::-1]])


def test_the_fold_is_found_once_between_a_stable_and_an_unstable_part(branch, fold):
    # At a fold the critical multiplier passes +1 where the speed turns; that passage
    # is the fold, not a second bifurcation ("branch point") beside it.
    assert [b["kind"] for b in branch.bifurcations()] == ["fold"]
    i = fold["point"]
    assert np.all(branch.stable[: i + 1]) and not np.any(branch.stable[i + 2:])
    # the fold is the largest speed along the branch, which its points approach
    assert fold["parameter"] >= branch.parameter.max()
    assert branch.parameter.max() == pytest.approx(fold["parameter"], rel=1e-4)


@pytest.mark.parametrize("side", [-1.0, 1.0])
def test_forward_runs_stay_below_the_fold_and_leave_above_it(fold, side):
    """From the fold's orbit point, a run just below the fold stays on the orbit that is
    still there; one just above leaves for another motion, as no orbit of the branch
    exists there. The passage past a fold slows as 1/sqrt(distance) (about 5 s at
    1e-4 relative here), so 8 s runs bracket the located fold to 1e-4, not to the
    1e-6 the continuation locates it to."""
    speed = fold["parameter"] * (1.0 + side * 1e-4)
    case = CASE.replace({"speed.value": speed, "simulation.duration": 8.0})
    durations = _stick_durations(case, fold["state"])
    change = np.abs(durations / durations[0] - 1.0)
    if side < 0:
        assert change.max() < 0.01
    else:
        assert change.max() > 0.05
        settled = durations[-100:]
        assert np.ptp(settled) < 1e-3 * settled.mean()  # it settles on another motion


@pytest.mark.parametrize("which", ["stable", "unstable"])
def test_multipliers_equal_the_growth_of_a_perturbation_in_a_forward_run(branch, fold,
                                                                          which):
    """A run started next to a branch point (a relative perturbation of 1e-6 on a stable
    orbit, 1e-10 on an unstable one) is followed until the stick durations' changes
    reach 1e-9 s (still linear: the durations are about 1.5 ms). The dominant roots of
    a sixth-order recurrence fitted to those changes are the orbit's leading
    multipliers; at rtol 1e-10 the changes carry noise of about 1e-13 s, which bounds
    the fit's error to about 1e-4 (seen: 3e-5 to 1.5e-4), hence the tolerance 1e-3."""
    i = fold["point"]
    index = 3 if which == "stable" else i + 5
    assert branch.stable[index] == (which == "stable")
    multipliers = branch.multipliers[index]
    others = np.delete(multipliers, np.argmin(np.abs(multipliers - 1.0)))
    leading = others[np.argmax(np.abs(others))]
    x = branch.dataset["state"].values[index]
    size = 1e-6 if which == "stable" else 1e-10
    start = x * (1.0 + size * np.cos(np.arange(x.size)))
    case = CASE.replace({"speed.value": float(branch.parameter[index]),
                         "simulation.duration": 3.0, "simulation.rtol": 1e-10,
                         "simulation.atol": 1e-13})
    changes = np.diff(_stick_durations(case, start))
    large = np.abs(changes) > 1e-9
    end = int(np.argmax(large)) if large.any() else changes.size
    assert end > 150  # enough returns for the fit
    roots = _prony(changes[10:end], 6)
    dominant = roots[np.argmax(np.abs(roots))]
    assert abs(abs(dominant) - abs(leading)) < 1e-3
    assert np.min(np.abs(others - dominant)) < 1e-3
    assert (abs(dominant) > 1.0) == (which == "unstable")


@pytest.mark.slow
def test_the_fold_is_the_same_from_a_distant_start(fold):
    """From the orbit at 2 pi rad/s, 6.2 rad/s below, the branch reaches the same fold
    after about 120 points of other step sizes: its location agrees with the one found
    from 12.3 rad/s to 1e-6 (the location's accuracy), and, as there, the fold's own
    multiplier passing +1 is not reported as a branch point beside it."""
    case = CASE.replace({"speed.value": 2.0 * np.pi})
    start = periodic_orbit(case, transient=5.0)
    far = continue_orbit(case, "speed.value", 20.0, orbit=start, max_points=125)
    found = [b for b in far.bifurcations() if abs(b["parameter"] - 12.5) < 0.1]
    assert [b["kind"] for b in found] == ["fold"]
    assert found[0]["parameter"] == pytest.approx(fold["parameter"], rel=1e-6)


def test_a_pair_turning_real_at_a_fold_is_not_a_torus():
    """Near 2.647 rad/s the damped-disc orbit's branch folds just after a complex pair of
    small rotation (0.002) leaves the unit circle: past the circle the pair meets the
    real axis and splits, one of the two real multipliers being the fold's. The pair's
    passage is a torus point; its turning real is no second torus (rotation 0) at the
    fold, and the fold is reported once."""
    case = CASE.replace({"speed.value": 3.0})
    start = periodic_orbit(case, transient=6.0)
    br = continue_orbit(case, "speed.value", 0.5, orbit=start, max_points=50)
    near = [b for b in br.bifurcations() if abs(b["parameter"] - 2.647) < 0.01]
    assert [b["kind"] for b in near] == ["torus", "fold"]
    torus, fold = near
    assert torus["rotation"] > 1e-3
    # the pair leaves the circle on the way to the fold: stable before, not after
    assert torus["parameter"] > fold["parameter"]
    assert np.all(br.stable[: torus["point"] + 1])
    assert not br.stable[torus["point"] + 1]


@pytest.mark.slow
def test_stability_changes_only_at_the_folds():
    """At 11 rad/s, continued in the disc's damping ratio, the orbit's branch folds twice
    within 3 % of the damping (8.304e-4 and 8.515e-4): between the folds one multiplier
    lies outside the unit circle by at most 1e-3, nearly parallel in its eigenvector to
    the flow's own multiplier 1. The verdict is unstable exactly between the folds and
    stable elsewhere, the flow's multiplier is 1 to the orbits' residual at every point,
    and nothing but the two folds is reported."""
    case = CASE.replace({"speed.value": 11.0})
    start = periodic_orbit(case, transient=6.0)
    br = continue_orbit(case, "disc.damping_ratio", 0.0, orbit=start, max_points=60)
    folds = [b for b in br.bifurcations()]
    assert [b["kind"] for b in folds] == ["fold", "fold"]
    first, second = folds[0]["point"], folds[1]["point"]
    expected = np.ones(len(br), bool)
    expected[first + 1: second + 1] = False
    assert np.array_equal(br.stable, expected)
    for mult in br.multipliers:
        assert np.min(np.abs(mult - 1.0)) < 1e-6


def test_a_closed_branch_stops_where_it_came_round():
    """In the friction law's decay the 12.3 rad/s orbit lies on a closed curve of orbits
    (an isola between folds at 0.8343 and 2.3194 s/m). In a window that holds it
    (``back_to`` beyond its far fold) the walk goes round once and
    stops at the first fold met a second time, instead of drawing the curve again; the
    verdict changes only at the folds (one multiplier passes +1 at each)."""
    start = periodic_orbit(CASE, transient=5.0)
    br = continue_orbit(CASE, "friction.decay", 0.0, orbit=start, back_to=3.0,
                        max_points=400)
    assert "closed on itself" in br.stop_reason
    kinds = [b["kind"] for b in br.bifurcations()]
    assert kinds == ["fold", "fold", "fold"]
    first, last = br.bifurcations()[0], br.bifurcations()[-1]
    assert last["parameter"] == pytest.approx(first["parameter"], rel=1e-6)
    # one change at each fold passed, the first one twice
    assert np.count_nonzero(np.diff(br.stable.astype(int))) == len(kinds)


def test_a_branch_that_turns_at_a_fold_stops_where_it_began():
    # Continued towards 12.8 rad/s from just below the fold, the branch turns there and
    # comes back; it stops at its starting speed (AUTO's window from the start to the
    # target), on the saddle orbit beside the stable one it began on, instead of
    # walking away from the target until its points run out.
    case = CASE.replace({"speed.value": 12.45})
    branch = continue_orbit(case, "speed.value", 12.8,
                            orbit=periodic_orbit(case, transient=5.0), max_points=60)
    assert "came back to speed.value = 12.45" in branch.stop_reason
    assert [b["kind"] for b in branch.bifurcations()] == ["fold"]
    assert len(branch) < 60
    assert branch.parameter[-1] == pytest.approx(12.45, abs=1e-12)
    assert np.all(branch.parameter[1:-1] > 12.45)
    # two orbits at one speed: the first stable, the last a saddle of another period
    assert branch.stable[0] and not branch.stable[-1]
    assert f"(over 12.45 to {branch.parameter.max():.9g} rad/s)" in str(branch)
    assert abs(branch.period[-1] / branch.period[0] - 1.0) > 1e-4
