"""One point of a sweep, as a worker computes it: what a worker process imports.

Kept apart from :mod:`fivdisc.sweep.run` and the store, so that a spawned worker loads
the simulator only, not Zarr (the coordinator alone writes the store).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from fivdisc.case import Case
from fivdisc.errors import FivdiscError
from fivdisc.sweep.reductions import LyapunovSettings, evaluate
from fivdisc.sweep.sections import Section

__all__ = ["PointOutcome", "run_point"]


@dataclass(frozen=True)
class PointOutcome:
    """What one point produced.

    Attributes
    ----------
    index
        The point's index.
    values
        Stored name -> value of every kept reduction, and per section its values
        (``(max_points,)``, NaN padded) and their count; None if the point failed.
    error
        "" for success, else why the point failed.
    """

    index: int
    values: dict[str, Any] | None
    error: str = ""


def run_point(
    index: int,
    case: Case,
    keep: tuple[str, ...],
    sections: Sequence[Section] = (),
    lyapunov: LyapunovSettings | None = None,
) -> PointOutcome:
    """Compute one point (see :func:`~fivdisc.sweep.reductions.evaluate`); a failure is
    returned as the outcome's error, not raised."""
    try:
        return PointOutcome(index, evaluate(case, keep, sections, lyapunov))
    except FivdiscError as exc:
        return PointOutcome(index, None, str(exc))
    except Exception as exc:  # a user reduction or the solver may raise anything
        return PointOutcome(index, None, f"{type(exc).__name__}: {exc}")
