"""Phase portraits, friction trajectories and separation statistics on a synthetic result."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from fivdisc.analysis.spectra import AnalysisError
from fivdisc.analysis.trajectories import (
    friction_trajectory,
    phase_portrait,
    separation_intervals,
    separation_stats,
)
from fivdisc.engine.result import Result

RATE = 1000.0  # samples per second of the synthetic record
# Exact switch times, deliberately between samples; (start, end, peak gap [m]).
SEPARATIONS = [(0.2003, 0.3004, 1e-4), (0.6002, 0.6507, 5e-5)]

_EVENT_TABLE = [  # time, kind, from, to
    (0.05, "stick", 0, 1),
    (0.1, "slip", 1, 0),
    (0.2003, "separation", 0, 2),
    (0.3004, "recontact", 2, 0),
    (0.6002, "separation", 0, 2),
    (0.6507, "recontact", 2, 0),
    (0.8, "stick", 0, 1),
]


def _events(table) -> dict:
    time, kind, before, after = zip(*table, strict=True) if table else ((), (), (), ())
    flags = {"flag_values": np.array([0, 1, 2], np.int8),
             "flag_meanings": "slip stick separation"}
    return {
        "event_time": ("event", np.array(time, float), {"units": "s"}),
        "event_kind": ("event", np.array(kind, dtype=object), {"units": "1"}),
        "event_from": ("event", np.array(before, np.int8), flags),
        "event_to": ("event", np.array(after, np.int8), flags),
    }


def _result(table=_EVENT_TABLE, separations=SEPARATIONS, impact: int = 1) -> xr.Dataset:
    """One second of a result: phase and gap follow ``separations``, events ``table``."""
    t = np.arange(round(RATE) + 1) / RATE
    phase = np.zeros(t.size, np.int8)
    gap = np.zeros(t.size)
    for start, end, peak in separations:
        inside = (t >= start) & (t < end)
        phase[inside] = 2
        gap[inside] = peak * np.sin(np.pi * (t[inside] - start) / (end - start))
    omega = 2 * np.pi
    data = {
        "phi": ("time", 1e-3 * np.sin(2 * np.pi * 50 * t), {"units": "rad", "long_name": "angle"}),
        "phi_dot": ("time", omega * (1 - np.cos(2 * np.pi * 50 * t)),
                    {"units": "rad/s", "long_name": "angular velocity"}),
        "disc_speed": ("time", np.full(t.size, omega), {"units": "rad/s", "long_name": "speed"}),
        "friction_force": ("time", 100 + 50 * np.sin(2 * np.pi * 50 * t),
                           {"units": "N", "long_name": "friction force"}),
        "phase": ("time", phase, {"units": "1", "long_name": "contact phase"}),
        "gap": ("time", gap, {"units": "m", "long_name": "gap"}),
        **_events(table),
    }
    return xr.Dataset(data, coords={"time": ("time", t, {"units": "s"})},
                      attrs={"impact": impact})


def test_intervals_come_exactly_from_the_event_table():
    assert separation_intervals(_result()) == [(s, e) for s, e, _ in SEPARATIONS]


def test_intervals_fall_back_to_sampled_phase_within_one_sample():
    ds = _result().drop_vars(["event_time", "event_kind", "event_from", "event_to"])
    found = separation_intervals(ds)
    assert len(found) == 2
    # Sampled phase switches at the first sample after the event: off by < 1/RATE.
    for (start, end), (s, e, _) in zip(found, SEPARATIONS, strict=True):
        assert 0 <= start - s < 1 / RATE and 0 <= end - e < 1 / RATE


def test_stats_count_duration_gap_and_impacts():
    stats = separation_stats(Result(_result()))
    assert stats["count"] == 2
    assert stats["first_time"] == 0.2003
    assert stats["fraction"] == pytest.approx((0.3004 - 0.2003) + (0.6507 - 0.6002), rel=1e-12)
    # The sampled bump reaches within (pi / 100)^2 / 8 of its 1e-4 m crest.
    assert stats["largest_gap"] == pytest.approx(1e-4, rel=2e-3)
    assert stats["impacts"] == 2
    assert separation_stats(_result(impact=0))["impacts"] == 0


def test_always_in_contact():
    stats = separation_stats(_result(table=_EVENT_TABLE[:2], separations=[]))
    assert stats == {"count": 0, "first_time": stats["first_time"], "fraction": 0.0,
                     "largest_gap": 0.0, "impacts": 0}
    assert np.isnan(stats["first_time"])


def test_open_ended_and_initially_separated_runs():
    table = [(0.05, "recontact", 2, 0), (0.95, "separation", 0, 2)]
    ds = _result(table=table, separations=[(0.0, 0.05, 1e-5), (0.95, 2.0, 1e-5)])
    assert separation_intervals(ds) == [(0.0, 0.05), (0.95, 1.0)]
    assert separation_stats(ds)["fraction"] == pytest.approx(0.1)


def test_time_slice_clips_intervals_and_impacts():
    ds = _result().sel(time=slice(0.25, 0.62))
    assert separation_intervals(ds) == [(0.25, 0.3004), (0.6002, 0.62)]
    assert separation_stats(ds)["impacts"] == 1


def test_phase_portrait_window():
    portrait = phase_portrait(Result(_result()), 0.1, 0.2)
    assert set(portrait.data_vars) == {"phi", "phi_dot"}
    np.testing.assert_allclose(portrait["time"].values[[0, -1]], [0.1, 0.2])
    assert portrait["phi_dot"].attrs["units"] == "rad/s"


def test_friction_trajectory_relative_velocity():
    ds = _result()
    trajectory = friction_trajectory(ds, 0.0, 0.5)
    t = trajectory["time"].values
    expected = 2 * np.pi * np.cos(2 * np.pi * 50 * t)  # Omega - Omega (1 - cos)
    np.testing.assert_allclose(trajectory["relative_velocity"].values, expected, atol=1e-12)
    assert trajectory["relative_velocity"].attrs["units"] == "rad/s"
    assert trajectory["friction_force"].attrs["units"] == "N"


def test_window_outside_the_data_is_refused():
    with pytest.raises(AnalysisError, match=r"t0 = 2\.0 \[s\] is outside the data: must be in"):
        phase_portrait(_result(), 2.0, 3.0)
    with pytest.raises(AnalysisError, match=r"t1 = 0\.1"):
        friction_trajectory(_result(), 0.2, 0.1)
