"""A periodic-orbit search refuses tolerances that make a non-orbit pass, says when its
iterations will be long and stops at its time budget (issue 40, items 4 and 5)."""

from __future__ import annotations

import time
import warnings

import numpy as np
import pytest

from fivdisc import Case
from fivdisc.analysis import orbits
from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.errors import ConvergenceError, FivdiscError, FivdiscWarning


@pytest.mark.parametrize("tol", [1e9, 0.01, 0.0, -1.0, 1e-20])
def test_an_orbit_tolerance_that_passes_an_open_trajectory_is_refused(tol: float) -> None:
    """tol = 1e9 returned a "converged" orbit after 0 Newton iterations, the transient's
    first return, whose residual was 0.005 (0.11 on the probe's case)."""
    start = time.perf_counter()
    with pytest.raises(FivdiscError, match=rf"tol = {tol!r} is invalid: must lie in "
                                           r"\[1e-14, 0.0001\]"):
        periodic_orbit(Case(), tol=tol)
    assert time.perf_counter() - start < 5


def test_continuation_settings_refuse_the_same_tolerances() -> None:
    from fivdisc.continuation.settings import ContinuationSettings

    with pytest.raises(FivdiscError, match=r"tol = 0.1 is invalid: must lie in"):
        ContinuationSettings(tol=0.1)
    with pytest.raises(FivdiscError, match=r"rtol = 1.0 is invalid: must lie in \[1e-14, 0.1\]"):
        ContinuationSettings(rtol=1.0)


def test_an_orbit_search_on_many_pads_warns_and_stops_at_its_budget(monkeypatch) -> None:
    """On many pads a Newton iteration (a run over the period carrying a tangent vector per
    coordinate) takes minutes, and the budget was checked between iterations only: the
    probe's search ran far past it, silently. Now it says what an iteration takes,
    measured, before the first, and a shot stops at the budget. (Ten pads and a threshold
    lowered to a tenth of a second stand in for the probe's many pads and minutes.)"""
    monkeypatch.setattr(orbits, "_LONG_SEARCH", 0.1)
    case = Case(sliders=[{"angle": 2 * np.pi * j / 10} for j in range(10)],
                speed={"value": 22.0}, simulation={"duration": 0.05})
    budget = 2.0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(ConvergenceError) as info:
            periodic_orbit(case, time_budget=budget, tol=1e-14, max_iterations=10**6,
                           window=0.05)
    notes = [str(w.message) for w in caught if issubclass(w.category, FivdiscWarning)]
    assert any(n.startswith("each Newton iteration takes about ") and "carrying 54 tangent "
               "vectors: one per coordinate of 10 sliders and the disc" in n for n in notes), notes
    assert "time budget" in str(info.value)
    assert info.value.reason == "the time budget ran out"


def test_a_shot_stops_at_its_deadline() -> None:
    """The bound itself: a shot whose deadline has passed stops at once, as the budget
    ran out, not as a failed run (which a Newton step would retry at half the step)."""
    from fivdisc.analysis.orbits import OutOfTime, Shooting
    from fivdisc.engine.equilibrium import sliding_equilibrium
    from fivdisc.model.build import build_model

    model = build_model(Case())
    shooting = Shooting(model, np.zeros(1, dtype=np.int64), 1e-12, 1e-19)
    shooting.deadline = time.monotonic() - 1.0
    start = time.perf_counter()
    with pytest.raises(OutOfTime, match="the time budget ran out during a run over the period"):
        shooting.shoot(sliding_equilibrium(model).state, 1.0)
    assert time.perf_counter() - start < 5
    assert not issubclass(OutOfTime, FivdiscError)
