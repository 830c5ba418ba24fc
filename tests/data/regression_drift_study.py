"""How far the saved regression runs move under round-off, and under real model changes.

Run ``python tests/data/regression_drift_study.py`` from the repository root. For each
``regression_*.nc`` it prints the largest difference of the event times [s] and of the
variables (over their peak) between:

1. the current code and the saved file (on another CPU than the one that wrote it, a
   last-bit difference of libm or numpy amplified by the switching);
2. the current code and the same case with the slider's mass changed by 1 and by 4 ulps
   (what ``tests/engine/test_single_slider_unchanged.py`` measures to set its bounds);

then the same for two real model changes: the accelerating and decelerating runs without
the dOmega/dt terms, and the stick-slip run with its normal damping changed by 1e-6.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import xarray as xr

from fivdisc.case import Case
from fivdisc.engine.simulation import simulate

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE.parent / "engine"))
from test_single_slider_unchanged import _drift  # noqa: E402


def _run(case: Case, initial: np.ndarray) -> xr.Dataset:
    return simulate(case, initial=initial if initial.size else None).dataset.isel(slider=0)


def _show(label: str, a: xr.Dataset, b: xr.Dataset) -> str:
    if list(a["event_kind"].values) != list(b["event_kind"].values):
        return f"{label}: other events"
    times, variables = _drift(a, b)
    return f"{label}: events {times:.1e} s, variables {max(variables.values()):.1e}"


def main() -> None:
    for path in sorted(HERE.glob("regression_*.nc")):
        saved = xr.load_dataset(path)
        case = Case.from_toml(saved.attrs["case"])
        initial = np.atleast_1d(saved.attrs["regression_initial"])
        new = _run(case, initial)
        parts = [_show("saved", new, saved)]
        for ulps in (1, 4):
            mass = case.sliders[0].mass * (1.0 + ulps * np.finfo(float).eps)
            parts.append(_show(f"{ulps} ulp", _run(case.replace({"slider.mass": mass}), initial),
                               new))
        print(f"{path.stem.removeprefix('regression_'):28s} " + "; ".join(parts))
    changes = {
        "accelerating": lambda case: {"simulation.omega_dot_terms": False},
        "decelerating": lambda case: {"simulation.omega_dot_terms": False},
        "stick_slip": lambda case: {
            "slider.normal_damping": case.sliders[0].normal_damping * (1.0 + 1e-6)},
    }
    for stem, change in changes.items():
        saved = xr.load_dataset(HERE / f"regression_{stem}.nc")
        case = Case.from_toml(saved.attrs["case"])
        initial = np.atleast_1d(saved.attrs["regression_initial"])
        edit = change(case)
        print(f"{stem:28s} " + _show(f"with {edit}", _run(case.replace(edit), initial),
                                     _run(case, initial)))

if __name__ == "__main__":
    main()
