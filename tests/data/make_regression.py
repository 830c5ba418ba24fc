"""Write the single-slider regression outputs that guard the paper's model.

Run once, from a checkout of the commit recorded in each file, before the kernel is
changed: ``python tests/data/make_regression.py``. Each file holds a whole simulation
dataset, the case text (``attrs["case"]``), the initial state given to ``simulate``
(``attrs["regression_initial"]``, empty for the case's own) and the commit
(``attrs["regression_commit"]``). ``tests/engine/test_single_slider_unchanged.py``
reruns every file's case with the current code and compares.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np

from fivdisc.case import Case, load_case
from fivdisc.engine.simulation import simulate
from fivdisc.examples import DIRECTORY as EXAMPLES

HERE = Path(__file__).parent


def _kick(case: Case) -> np.ndarray:
    """Rest, with a strong transverse velocity of the first disc mode: the slider separates
    and lands again (with the plastic impact) within 0.2 s."""
    n = sum(1 if l == 0 else 2 for _, l in case.disc.modes)
    y = np.zeros(2 * n + 4)
    y[n + 2] = 5.0
    return y


def cases() -> dict[str, tuple[Case, np.ndarray | None]]:
    """Name -> (case, initial state or None)."""
    out: dict[str, tuple[Case, np.ndarray | None]] = {}
    # Paper Figs. 8-9: stick-slip from rest.
    out["stick_slip"] = (load_case(EXAMPLES / "default.toml").replace(
        {"simulation.duration": 1.0, "simulation.output_rate": 5000.0}), None)
    # Separation and re-contact with and without the plastic impact.
    kick = Case(simulation={"duration": 0.2, "output_rate": 20000.0})
    out["separation_impact"] = (kick, _kick(kick))
    out["separation_no_impact"] = (kick.replace({"simulation.impact": False}), _kick(kick))
    # Paper Fig. 18a: separation from the system's own dynamics at 6 pi rad/s.
    out["separation_fig18a"] = (load_case(EXAMPLES / "fig18a.toml").replace(
        {"simulation.duration": 3.2}), None)
    # Decelerating disc that stops inside the span (speed kink at t_max).
    out["decelerating"] = (load_case(EXAMPLES / "fig10.toml").replace(
        {"speed.duration": 0.5, "simulation.duration": 0.8,
         "simulation.output_rate": 5000.0}), None)
    # Paper Fig. 24a: accelerating disc.
    out["accelerating"] = (load_case(EXAMPLES / "fig24a.toml").replace(
        {"simulation.duration": 1.0, "simulation.output_rate": 5000.0}), None)
    # Paper Fig. 4: perturbed sliding equilibrium decaying.
    out["equilibrium_perturbed"] = (load_case(EXAMPLES / "fig04.toml").replace(
        {"simulation.duration": 1.0}), None)
    return out


def main() -> None:
    commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                            check=True, cwd=HERE).stdout.strip()
    for name, (case, initial) in cases().items():
        ds = simulate(case, initial=initial).dataset
        ds.attrs["regression_commit"] = commit
        ds.attrs["regression_initial"] = np.empty(0) if initial is None else initial
        for key in ("wall_time", "final_state"):
            ds.attrs.pop(key, None)
        encoding = {v: {"zlib": True, "complevel": 6} for v in ds.data_vars
                    if ds[v].dtype.kind == "f"}
        ds.to_netcdf(HERE / f"regression_{name}.nc", encoding=encoding)
        print(name, ds.attrs["status"], ds.attrs["n_steps"], int(ds.sizes["event"]))


if __name__ == "__main__":
    main()
