"""The speed baseline of the benchmarks: the slow reference model of tests/reference/model.py.

The reference (plain numpy right-hand side with a dense solve at every evaluation,
scipy ``solve_ivp`` with Python event functions) is run with ``method="RK45"`` and the
tolerances the fast simulator uses (``case.simulation.rtol`` / ``atol``), so that a
benchmark compares like with like: same model, same error control, different machinery.

Usage::

    from baseline import baseline_simulate
    result = baseline_simulate(case)             # RK45, case.simulation.rtol / atol
    result.evaluate(times)["phi"]
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

_TESTS = str(Path(__file__).resolve().parents[1] / "tests")
if _TESTS not in sys.path:
    sys.path.insert(0, _TESTS)

from reference.model import (  # noqa: E402
    ModeData,
    ReferenceResult,
    jacobi_integral,
    kinetic_energy_t2,
    mode_data_from_case,
    reference_simulate,
    sliding_equilibrium,
)

__all__ = [
    "ModeData",
    "ReferenceResult",
    "baseline_simulate",
    "jacobi_integral",
    "kinetic_energy_t2",
    "mode_data_from_case",
    "reference_simulate",
    "sliding_equilibrium",
]


def baseline_simulate(
    case: Any,
    t_end: float | None = None,
    *,
    rtol: float | None = None,
    atol: float | None = None,
    mode_data: ModeData | None = None,
) -> ReferenceResult:
    """Reference model with RK45 at the fast code's tolerances (default: the case's).

    Parameters
    ----------
    case : fivdisc.case.Case
    t_end : float, optional
        End time [s]; default ``case.simulation.duration``.
    rtol, atol : float, optional
        Default ``case.simulation.rtol`` and ``case.simulation.atol``.
    mode_data : ModeData, optional
        Precomputed modal data (keeps the plate's root finding out of a timing).
    """
    sim = case.simulation
    return reference_simulate(
        case,
        t_end,
        rtol=float(sim.rtol if rtol is None else rtol),
        atol=float(sim.atol if atol is None else atol),
        method="RK45",
        mode_data=mode_data,
    )
