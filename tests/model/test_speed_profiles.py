"""Disc speed profiles: callables represented to the stated accuracy or refused, and the
Python constructors validating as case files do (issue 14, item 3)."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
import pytest

from fivdisc import Case, simulate
from fivdisc.errors import CaseError
from fivdisc.model.speed import SpeedProfile

TWO_PI = 2.0 * math.pi


def _periodic(amplitude: float = 2.0, cycles: float = 64.0):
    """Omega = 3 + A sin(2 pi f t) and its derivative: f t_end = 64 puts every dyadic node
    and every midpoint of [0, 1] on a zero of the sine."""
    w = 2.0 * math.pi * cycles
    return (lambda t: 3.0 + amplitude * math.sin(w * t),
            lambda t: amplitude * w * math.cos(w * t))


def _errors(profile: SpeedProfile, omega, omega_dot, t_end: float) -> tuple[float, float]:
    t = np.linspace(0.0, t_end, 400_001)
    return (float(np.max(np.abs(profile.omega(t) - np.vectorize(omega)(t)))),
            float(np.max(np.abs(profile.omega_dot(t) - np.vectorize(omega_dot)(t)))))


@pytest.mark.parametrize(
    ("pair", "t_end"),
    [
        (_periodic(), 1.0),
        ((lambda t: 10.0 * math.exp(-t), lambda t: -10.0 * math.exp(-t)), 3.0),
        ((lambda t: 5.0 + math.tanh(50.0 * (t - 0.3)),
          lambda t: 50.0 / math.cosh(50.0 * (t - 0.3)) ** 2), 1.0),
    ],
    ids=["periodic", "exponential", "steep-step"],
)
def test_callables_are_represented_to_the_stated_accuracy(pair, t_end: float) -> None:
    omega, omega_dot = pair
    profile = SpeedProfile.from_callables(omega, omega_dot, t_end=t_end)
    t = np.linspace(0.0, t_end, 4001)
    scale_w = 1.0 + np.max(np.abs(np.vectorize(omega)(t)))
    scale_wd = 1.0 + np.max(np.abs(np.vectorize(omega_dot)(t)))
    err_w, err_wd = _errors(profile, omega, omega_dot, t_end)
    # Stated: 1e-10 of the scale for Omega and 1e-6 for Omegadot, at the check points of
    # every piece; between them the cubic's error is smaller still (2 % slack for the
    # maximum of the scale falling between samples).
    assert err_w <= 1.02e-10 * scale_w
    assert err_wd <= 1.02e-6 * scale_wd


def test_periodic_profile_that_fooled_the_midpoint_check() -> None:
    """Checked at midpoints only, one cubic through (0, 3) and (1, 3) with the slopes of the
    sine matched the sine at t = 0.5 and was kept: wrong by up to ~1e3 rad/s."""
    omega, omega_dot = _periodic()
    profile = SpeedProfile.from_callables(omega, omega_dot, t_end=1.0)
    assert profile.knots.size > 1000
    assert _errors(profile, omega, omega_dot, 1.0)[0] < 1e-9


@pytest.mark.parametrize(
    ("pair", "words"),
    [
        ((lambda t: 6.0, lambda t: 1000.0),
         ["Omegadot(", "= 1000 rad/s^2", "changes at 0 rad/s^2"]),
        # a derivative off by 1e-5 of its size, 10 times the stated accuracy
        ((_periodic()[0], lambda t: 1.00001 * _periodic()[1](t)), ["must be the derivative"]),
        ((lambda t: 6.0 * math.exp(-t), lambda t: 6.0 * math.exp(-t)), ["must be the derivative"]),
    ],
    ids=["constant-with-slope", "slightly-off", "wrong-sign"],
)
def test_a_derivative_that_is_not_one_is_refused_at_once(pair, words) -> None:
    start = time.perf_counter()
    with pytest.raises(CaseError) as info:
        SpeedProfile.from_callables(*pair, t_end=5.0)
    assert time.perf_counter() - start < 2.0
    message = str(info.value)
    assert "\n" not in message and "must be the derivative of Omega" in message
    for word in words:
        assert word in message


def test_a_derivative_right_to_the_stated_accuracy_is_accepted() -> None:
    omega, omega_dot = _periodic()
    SpeedProfile.from_callables(omega, lambda t: (1.0 + 1e-8) * omega_dot(t), t_end=1.0)


def test_kinks_must_be_declared() -> None:
    kink = 0.3
    omega = lambda t: 6.0 + abs(t - kink)  # noqa: E731
    omega_dot = lambda t: 1.0 if t >= kink else -1.0  # noqa: E731
    with pytest.raises(CaseError, match=r"not smooth near t = 0\.3 s .*declare its kinks as "
                                        r"breakpoints"):
        SpeedProfile.from_callables(omega, omega_dot, t_end=1.0)
    profile = SpeedProfile.from_callables(omega, omega_dot, t_end=1.0, breakpoints=[kink])
    assert kink in profile.knots and list(profile.breakpoints) == [kink]
    assert _errors(profile, omega, omega_dot, 1.0)[0] < 1e-9


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"t_end": 0.0}, ["t_end = 0.0 is invalid"]),
        ({"t_end": 1.0, "breakpoints": [1.5]}, ["breakpoint 1.5 is invalid"]),
        ({"t_end": 1.0, "rtol": 0.0}, ["rtol = 0.0 is invalid: must lie in (0, 0.001]"]),
        ({"t_end": 1.0, "rtol_dot": 1.0}, ["rtol_dot = 1.0 is invalid"]),
        ({"t_end": 1.0, "max_pieces": 10}, ["needs more than 10 pieces"]),
    ],
)
def test_bad_arguments(kwargs: dict[str, Any], words) -> None:
    with pytest.raises(CaseError) as info:
        SpeedProfile.from_callables(*_periodic(), **kwargs)
    for word in words:
        assert word in str(info.value)


def test_negative_speed_is_refused() -> None:
    with pytest.raises(CaseError, match=r"Omega must be finite and >= 0"):
        SpeedProfile.from_callables(lambda t: 1.0 - 2.0 * t, lambda t: -2.0, t_end=1.0)


@pytest.mark.parametrize("speed", ["fast", 6.0, (lambda t: 1.0,), (1.0, 2.0)],
                         ids=["text", "number", "one-callable", "numbers"])
def test_simulate_refuses_a_speed_that_is_not_a_profile(speed) -> None:
    with pytest.raises(CaseError, match=r"^speed = .* is invalid: must be a SpeedProfile or a "
                                        r"pair \(Omega, Omegadot\) of callables of t \[s\]$"):
        simulate(Case(simulation={"duration": 0.01}), speed=speed)


def test_simulate_with_callables_uses_the_checked_profile() -> None:
    case = Case(simulation={"duration": 0.01, "output_rate": 1000.0})
    with pytest.raises(CaseError, match="must be the derivative"):
        simulate(case, speed=(lambda t: 6.0, lambda t: 1000.0))
    result = simulate(case, speed=(lambda t: 6.0 + t, lambda t: 1.0))
    np.testing.assert_allclose(result.dataset["disc_speed"].values,
                               6.0 + result.dataset["time"].values, rtol=1e-12)


# --- the constructors validate as case files do ----------------------------------------------


@pytest.mark.parametrize(
    ("build", "table"),
    [
        (lambda: SpeedProfile.constant(-3), {"profile": "constant", "value": -3}),
        (lambda: SpeedProfile.constant(math.inf), {"profile": "constant", "value": math.inf}),
        (lambda: SpeedProfile.constant("6"), {"profile": "constant", "value": "6"}),
        (lambda: SpeedProfile.decelerating(6, 0), {"profile": "decelerating", "initial": 6,
                                                    "duration": 0}),
        (lambda: SpeedProfile.decelerating(-1, 5), {"profile": "decelerating", "initial": -1,
                                                     "duration": 5}),
        (lambda: SpeedProfile.accelerating(1, -0.5), {"profile": "accelerating", "initial": 1,
                                                       "rate": -0.5}),
        (lambda: SpeedProfile.table([0.5, 1.5], [1, 2]), {"profile": "table",
                                                          "times": [0.5, 1.5], "values": [1, 2]}),
        (lambda: SpeedProfile.table([0, 1, 1], [1, 2, 3]), {"profile": "table",
                                                            "times": [0, 1, 1],
                                                            "values": [1, 2, 3]}),
        (lambda: SpeedProfile.table([0, 1], [1, 2, 3]), {"profile": "table", "times": [0, 1],
                                                         "values": [1, 2, 3]}),
        (lambda: SpeedProfile.table([0, 1], [1, -2]), {"profile": "table", "times": [0, 1],
                                                       "values": [1, -2]}),
    ],
)
def test_constructors_refuse_what_case_files_refuse(build, table) -> None:
    with pytest.raises(CaseError) as from_python:
        build()
    with pytest.raises(CaseError) as from_case:
        Case(speed=table)
    assert str(from_python.value) == str(from_case.value)


@pytest.mark.parametrize(
    ("profile", "table"),
    [
        (SpeedProfile.constant(3), {"profile": "constant", "value": 3.0}),
        (SpeedProfile.decelerating(TWO_PI, 35), {"profile": "decelerating"}),
        (SpeedProfile.accelerating(1, 0.2), {"profile": "accelerating", "initial": 1.0}),
        (SpeedProfile.table(np.array([0.0, 1.0, 2.0]), [1, 4, 4]),
         {"profile": "table", "times": [0, 1, 2], "values": [1.0, 4.0, 4.0]}),
    ],
)
def test_constructors_equal_the_case_profiles(profile: SpeedProfile, table) -> None:
    expected = SpeedProfile.from_case(Case(speed=table).speed)
    np.testing.assert_array_equal(profile.knots, expected.knots)
    np.testing.assert_array_equal(profile.coefficients, expected.coefficients)
    np.testing.assert_array_equal(profile.breakpoints, expected.breakpoints)


def test_model_validate_raises_case_error() -> None:
    with pytest.raises(CaseError, match=r"^slider.mass = -1 is invalid: must be > 0 \[kg\]$"):
        Case.model_validate({"slider": {"mass": -1}})
    with pytest.raises(CaseError, match=r"^case = 5 is invalid: must be a table$"):
        Case.model_validate(5)
    assert Case.model_validate({"speed": {"value": 3}}) == Case(speed={"value": 3.0})
