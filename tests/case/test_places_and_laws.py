"""Case values that gave wrong answers, now refused with the rule a researcher expects
(issue 40, item 4): where sliders and probes may be, what a friction table may hold, when
a perturbation applies, what output rate samples a run. One test per reproduction."""

from __future__ import annotations

import math

import pytest

from fivdisc import Case, simulate
from fivdisc.errors import CaseError


def _refused(words: list[str], **tables) -> str:
    with pytest.raises(CaseError) as info:
        Case(**tables)
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message, message
    return message


def test_sliders_closer_than_a_micrometre_are_refused() -> None:
    """0 and 1e-9 rad on a 0.1 m track are 1e-10 m apart: one contact spot given twice
    (the former test, angles equal to 1e-12 rad, let them through)."""
    _refused(["sliders.1.angle = 1e-09 is invalid: puts sliders.1 1e-10 m from sliders.0",
              "sliders on one face must be at least 1e-06 m apart",
              "give one slider with their stiffnesses, dampers and preloads added"],
             sliders=[{"angle": 0.0}, {"angle": 1e-9}])
    # Different radii at one angle count by their distance too.
    _refused(["puts sliders.1 5e-07 m from sliders.0"],
             sliders=[{"angle": 1.0}, {"angle": 1.0, "track_radius": 0.1 + 5e-7}])
    # A micrometre and more apart, or on the other face, they are two sliders.
    Case(sliders=[{"angle": 0.0}, {"angle": 1e-4}])
    Case(sliders=[{"angle": 0.0}, {"angle": 0.0, "face": "bottom"}])


def test_a_probe_angle_beyond_the_resolution_of_a_double_is_refused() -> None:
    """A probe at theta = 1e300 recorded the deflection at an angle a double cannot place
    (cos(l 1e300) of round-off); slider angles likewise."""
    _refused(["simulation.probes[0] = [0.08, 1e+300] is invalid: theta must lie within "
              "+-1e+06 rad"], simulation={"probes": [[0.08, 1e300]]})
    _refused(["sliders.0.angle = 1e+300 is invalid: must lie within +-1e+06 rad"],
             sliders=[{"angle": 1e300}, {"angle": 1.0}])
    Case(simulation={"probes": [[0.08, -1e6]]})


def test_a_friction_table_above_static_is_refused() -> None:
    """The table's first value was checked against the static coefficient, not the others:
    a curve rising above static friction while sliding."""
    _refused(["friction.static = 0.8 is invalid: must be >= every value of friction.values: "
              "friction.values[1] = 0.9 at friction.speeds[1] = 1.0 m/s is above it"],
             friction={"law": "table", "static": 0.8, "speeds": [0.0, 1.0, 2.0],
                       "values": [0.6, 0.9, 0.3]})
    Case(friction={"law": "table", "static": 0.9, "speeds": [0.0, 1.0, 2.0],
                   "values": [0.6, 0.9, 0.3]})


def test_a_perturbation_of_a_run_from_rest_is_refused() -> None:
    """[simulation.perturbation] was silently ignored without initial_state =
    "equilibrium"."""
    _refused(["simulation.perturbation = {phi = 0.01, phi_dot = 0.0} is invalid: must keep "
              'its defaults unless simulation.initial_state = "equilibrium"'],
             simulation={"perturbation": {"phi": 0.01}})
    start = Case(simulation={"initial_state": "equilibrium", "perturbation": {"phi": 0.01}})
    # A case written out (every key, the default perturbation) reads back from rest.
    assert Case.from_toml(Case().to_toml()) == Case()
    assert start.simulation.perturbation.phi == 0.01


def test_an_output_rate_without_a_finite_sample_interval_is_refused() -> None:
    """5e-324 Hz: the sample interval 1 / rate is infinite, the first sample's time
    0 * inf a NaN, and the run "succeeded" with a NaN normal force."""
    _refused(["simulation.output_rate = 5e-324 is invalid: must be >= 1e-300"],
             simulation={"output_rate": 5e-324})
    # The slowest rate allowed records the start of a run, as any rate below 1 / duration.
    run = simulate(Case(simulation={"output_rate": 1e-300, "duration": 0.01}))
    assert run.ok and run.dataset.sizes["time"] == 1
    assert math.isfinite(float(run.dataset["normal_force"].values.ravel()[0]))
