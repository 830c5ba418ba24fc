"""The paper's model is unchanged by the model family: single-slider runs against saved
outputs of the kernel before sliders, damping and friction laws were added.

``tests/data/regression_*.nc`` were written by ``tests/data/make_regression.py`` from the
commit stored in each file (``regression_commit``). Each file's case is rerun with the
current code; every variable must agree to 1e-12 of its peak (the outputs of two builds
doing the same arithmetic are identical; a reordered sum would differ by round-off,
which a chaotic stick-slip run can amplify, so the bound is kept that tight on purpose)
and the event table must be the same.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from fivdisc.case import Case
from fivdisc.simulate import simulate

FILES = sorted((Path(__file__).parent / "data").glob("regression_*.nc"))
PER_SLIDER = ("phi", "phi_dot", "normal_force", "friction_force", "phase", "z", "z_dot", "gap")


@pytest.mark.parametrize("path", FILES, ids=[p.stem.removeprefix("regression_") for p in FILES])
def test_single_slider_runs_are_unchanged(path: Path) -> None:
    saved = xr.load_dataset(path)
    case = Case.from_toml(saved.attrs["case"])
    initial = np.atleast_1d(saved.attrs["regression_initial"])
    new = simulate(case, initial=initial if initial.size else None).dataset
    assert new.attrs["status"] == saved.attrs["status"]
    assert list(new["event_kind"].values) == list(saved["event_kind"].values)
    np.testing.assert_array_equal(new["event_slider"].values, 0)
    for name in ("event_time", "event_from", "event_to"):
        np.testing.assert_array_equal(new[name].values, saved[name].values, err_msg=name)
    for name in (*PER_SLIDER, "disc_speed", "w", "q", "q_dot"):
        old = saved[name].values
        now = new[name].values
        if name in PER_SLIDER:
            assert new[name].dims == ("time", "slider")
            now = now[:, 0]
        peak = np.max(np.abs(old))
        assert np.max(np.abs(now - old), initial=0.0) <= 1e-12 * peak, name
