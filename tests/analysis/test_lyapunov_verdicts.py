"""The verdict on each Lyapunov exponent (positive, consistent with zero, negative,
undecided at this length), each checked by a second route: the Floquet exponents of the
periodic orbit that shooting finds, and the eigenvalues of the linearisation at an
equilibrium, stable or unstable (issue 40, item 1: ``fivdisc lyapunov`` on a periodic
orbit exited 1 because the uncertainty exceeded the estimate)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fivdisc.analysis.exponents import RECURRENT, LyapunovSpectrum, lyapunov
from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.analysis.stability import linear_stability
from fivdisc.case import Case

from support.cli import messages, run_cli

# The rigid-disc stick-slip oscillator (tests/support/cases.py): a stable periodic orbit
# whose exponents are 0 (the flow direction) and the disc mode's log|mu| / T.
RIGID = Case(
    disc={"modes": [[0, 0]]},
    slider={"rotational_damping": 0.0, "normal_damping": 5.0},
    friction={"static": 0.8, "kinetic_max": 0.5, "kinetic_min": 0.5, "decay": 0.0},
    speed={"value": 1.0},
)
# A light disc whose sliding equilibrium is stable (rates -9.6 and -171 1/s).
STABLE = Case(disc={"density": 720.0, "modes": [[0, 0]]},
              slider={"mass": 1.0, "normal_damping": 20.0, "rotational_damping": 4.0},
              friction={"decay": 0.5}, speed={"value": 1.0},
              simulation={"initial_state": "equilibrium"})
# A sliding equilibrium just below its Hopf point (growth 3.87 1/s): from a perturbation
# of 1e-12 rad the motion grows by e^(3.87 x 4) ~ 5e6 over the run, linear throughout.
UNSTABLE = Case(disc={"modes": [[0, 0]]}, slider={"rotational_damping": 0.5},
                friction={"decay": 1.0}, speed={"value": 8.7},
                simulation={"initial_state": "equilibrium", "perturbation": {"phi": 1e-12}})


def _spectrum(exponents, uncertainty) -> LyapunovSpectrum:
    e = np.asarray(exponents, dtype=float)
    return LyapunovSpectrum(e, np.asarray(uncertainty, dtype=float), np.arange(1.0, 11.0),
                            np.zeros((10, e.size)), 1.0, 10.0, 1.0)


def test_a_periodic_orbit_s_largest_exponent_is_consistent_with_zero():
    """Second route: shooting finds the orbit, whose Floquet exponents are 0 and the
    disc mode's decay; the measured spectrum agrees and says so in its verdicts."""
    orbit = periodic_orbit(RIGID, transient=4.0)
    floquet = np.sort(orbit.exponents())[::-1][:2]
    assert floquet[0] == pytest.approx(0.0, abs=1e-6) and floquet[1] < -1.0
    spec = lyapunov(RIGID, n=2, transient=4.0, duration=5.0)
    assert np.all(np.abs(spec.exponents - floquet) <= 3 * spec.uncertainty + 0.02)
    assert spec.verdicts == ("zero", "negative")
    assert spec.decided.all()
    assert "consistent with zero" in str(spec)
    assert "resolved from lambda_2" in spec.explain(0)


def test_a_stable_equilibrium_s_exponents_are_negative():
    """Second route: every eigenvalue of the linearisation has a negative real part, and
    the largest exponent is the largest real part."""
    lin = linear_stability(STABLE)
    assert lin.stable
    spec = lyapunov(STABLE, n=1, transient=1.0, duration=5.0)
    assert spec.verdict(0) == "negative"
    assert spec.largest == pytest.approx(lin.max_growth_rate, abs=3 * spec.uncertainty[0])


def test_an_unstable_equilibrium_s_largest_exponent_is_positive():
    """Second route: the growth rate of the linearisation, 3.87 1/s, which the small
    perturbation follows over the whole run."""
    lin = linear_stability(UNSTABLE)
    assert 3.0 < lin.max_growth_rate < 5.0
    spec = lyapunov(UNSTABLE, n=1, transient=0.5, duration=3.0)
    assert spec.verdict(0) == "positive"
    assert spec.largest == pytest.approx(lin.max_growth_rate, rel=0.02)


def test_a_short_measurement_of_a_periodic_orbit_is_undecided_and_says_what_decides_it():
    """Over 2 s the flow direction's estimate (+1.2 +- 2.4 1/s) is too wide to be told
    from the disc mode's decay; 5 s decide it (above)."""
    spec = lyapunov(RIGID, n=2, transient=4.0, duration=2.0)
    assert spec.verdict(0) == "undecided" and spec.verdict(1) == "negative"
    assert "undecided at this length" in str(spec)
    assert "lengthen the measurement" in spec.explain(0)


def test_one_exponent_near_zero_has_no_scale_and_asks_for_two():
    spec = lyapunov(RIGID, n=1, transient=4.0, duration=5.0)
    assert spec.verdict(0) == "undecided"
    assert "compute two" in spec.explain(0) and "compute two" in str(spec)


@pytest.mark.parametrize(("exponents", "uncertainty", "verdicts"), [
    # Clear of zero by more than three uncertainties, either way; -inf is negative.
    ([2.0, -1.0, -np.inf], [0.1, 0.1, np.nan], ("positive", "negative", "negative")),
    # Between one and three uncertainties from zero: neither.
    ([0.25, -3.0], [0.1, 0.1], ("undecided", "negative")),
    # No uncertainty: nothing is decided.
    ([0.5, -3.0], [np.nan, np.nan], ("undecided", "undecided")),
    # Within one uncertainty of zero and resolved from a negative one: zero. Two zeros
    # (a torus) are each resolved from the third.
    ([0.01, -0.02, -2.0], [0.05, 0.05, 0.1], ("zero", "zero", "negative")),
    # Not resolved: the negative exponent's range reaches the zero's.
    ([0.01, -0.5], [0.1, 0.1], ("undecided", "negative")),
    # Measured in the wrong order: a precise -0.108 above an imprecise zero. The largest
    # is not known to be negative, since the other may be the larger one.
    ([-0.108, -0.17], [0.009, 0.26], ("undecided", "negative")),
])
def test_verdicts_follow_the_bounds_of_each_exponent(exponents, uncertainty, verdicts):
    assert _spectrum(exponents, uncertainty).verdicts == verdicts


def test_the_command_exits_0_with_a_verdict_on_a_periodic_orbit(tmp_path):
    path = tmp_path / "rigid.toml"
    path.write_text(RIGID.to_toml())
    common = ["lyapunov", path, "--transient", "4", "--duration", "5", "--no-progress"]
    res = run_cli([*common, "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert data["verdict"] == "zero" and data["verdicts"] == ["zero", "negative"]
    res = run_cli(common)
    assert res.exit_code == 0 and "consistent with zero" in res.stdout
    # One exponent cannot decide a zero: exit 1, one line saying what would.
    res = run_cli([*common, "--n", "1"])
    assert res.exit_code == 1
    (line,) = messages(res.stderr)
    assert line.startswith("error: lambda_1 = ") and "--n 2" in line


def test_a_positive_exponent_of_a_recurrent_motion_is_undecided():
    """Three identical pads from their equilibrium, with the default transient (0.6 s):
    over the measurement the motion stays near an unstable periodic orbit (the pads'
    sticks recur to 3e-4 of their interval), where the finite-time exponent is positive
    at three uncertainties. It is not chaos: with a 6 s transient the motion has left for
    the stable orbit of the pads sticking in turn, whose largest exponent (the flow
    direction's) is consistent with zero. So the verdict of the first is undecided, and
    says why."""
    from support.cases import THREE_PADS

    short = lyapunov(THREE_PADS, n=2)
    assert short.bounds(0)[0] > 0  # positive over the window, at three uncertainties
    assert short.recurrence < RECURRENT
    assert short.verdict(0) == "undecided"
    assert "stays near a periodic orbit" in short.explain(0)
    long = lyapunov(THREE_PADS, n=2, transient=6.0)
    assert long.verdict(0) == "zero"


@pytest.mark.parametrize(("recurrence", "verdict"), [
    (np.nan, "positive"),  # no sticks to judge the motion by
    (0.6, "positive"),  # irregular sticks
    (1e-3, "undecided"),  # sticks that recur: near a periodic orbit
])
def test_the_recurrence_of_sticks_decides_a_positive_verdict(recurrence, verdict):
    spec = LyapunovSpectrum(np.array([2.0, -1.0]), np.array([0.1, 0.1]), np.ones(1),
                            np.zeros((1, 2)), 0.0, 1.0, 1.0, recurrence)
    assert spec.verdict(0) == verdict
    assert spec.verdict(1) == "negative"
    # what sweeps store as largest_lyapunov_inconclusive follows it
    assert spec.conclusive.tolist() == [verdict == "positive", True]
