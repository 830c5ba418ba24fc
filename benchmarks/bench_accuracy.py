"""Accuracy of the default tolerances, the numbers quoted in docs/model.md.

Run ``python benchmarks/bench_accuracy.py``. It prints:

1. for the default case (paper Table 1, Figs. 8-9 parameters, stick-slip from rest) over
   0.2 s, at ``rtol`` = 1e-6 (the default), 1e-7 and 1e-8 (``atol = 1e-3 rtol``): the
   largest difference of the slider angle from a ``rtol = 1e-12`` run, relative to its
   peak, and the largest difference of the switch times;
2. for the paper's chaotic regime (Fig. 18a: 6 pi rad/s, first example) over 1 s: the
   difference between runs at ``rtol`` = 1e-6 and 1e-7, relative to the peak, at 0.1 s
   and 1 s, and when it first exceeds 1e-3.
"""

from __future__ import annotations

import numpy as np

from fivdisc import Case, simulate
from fivdisc.paper import FIG18


def _run(case: Case, rtol: float):
    return simulate(case.replace({"simulation.rtol": rtol, "simulation.atol": 1e-3 * rtol}))


def tolerance_errors(rtols: tuple[float, ...] = (1e-6, 1e-7, 1e-8)) -> list[tuple[float, float,
                                                                                  float]]:
    """(rtol, max |phi error| / peak, max switch time error [s]) of the default case over
    0.2 s against a ``rtol = 1e-12`` run; the switch error is nan if the switch sequence
    differs. tests/package/test_docs_numbers.py checks the README's numbers with it."""
    case = Case(simulation={"duration": 0.2, "output_rate": 20000.0})
    exact = _run(case, 1e-12).dataset
    peak = np.max(np.abs(exact["phi"].values))
    rows = []
    for rtol in rtols:
        ds = _run(case, rtol).dataset
        error = np.max(np.abs(ds["phi"].values - exact["phi"].values)) / peak
        same = list(ds["event_kind"].values) == list(exact["event_kind"].values)
        switch = (np.max(np.abs(ds["event_time"].values - exact["event_time"].values))
                  if same else np.nan)
        rows.append((rtol, float(error), float(switch)))
    return rows


def tolerance_table() -> None:
    print("default case over 0.2 s, against rtol 1e-12:")
    print(f"{'rtol':>6} {'max |phi error| / peak':>24} {'max switch time error [s]':>27}")
    for rtol, error, switch in tolerance_errors():
        shown = f"{switch:.2g}" if np.isfinite(switch) else "different switch sequence"
        print(f"{rtol:>6.0e} {error:>24.2g} {shown:>27}")


def chaotic_divergence() -> None:
    case = FIG18.case.replace({"simulation.duration": 1.0, "simulation.output_rate": 10000.0})
    a, b = (_run(case, rtol).dataset for rtol in (1e-6, 1e-7))
    phi_a, phi_b = a["phi"].values[:, 0], b["phi"].values[:, 0]
    difference = np.abs(phi_a - phi_b) / np.max(np.abs(phi_b))
    t = a["time"].values
    above = t[difference > 1e-3]
    onset = f"{above[0]:.2f} s" if above.size else "never"
    print("Fig. 18a (6 pi rad/s) over 1 s, rtol 1e-6 against 1e-7, |phi difference| / peak:")
    print(f"  at 0.1 s: {difference[np.searchsorted(t, 0.1)]:.2g}, at 1 s: {difference[-1]:.2g},"
          f" first above 1e-3 at {onset}")


if __name__ == "__main__":
    tolerance_table()
    chaotic_divergence()
