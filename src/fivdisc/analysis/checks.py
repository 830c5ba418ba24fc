"""Checks of an analysis request before any work starts, and of its answer after.

:func:`check_orbit_request` refuses what would make a periodic-orbit search run without
bound or answer nonsense (an infinite transient or window, an absurd period guess or
tolerance, a disc without modes); :func:`check_period` refuses a period that no orbit of
the model can have. Both name the option, its value and what is allowed, in one line.
"""

from __future__ import annotations

import math

from fivdisc.case import Case
from fivdisc.errors import FivdiscError
from fivdisc.limits import (
    MAX_SHOOTING_RTOL,
    MAX_SHOOTING_TOL,
    MIN_SHOOTING_RTOL,
    MIN_SHOOTING_TOL,
)

__all__ = ["MAX_RTOL", "MAX_TOL", "MIN_RTOL", "MIN_TOL", "check_orbit_request",
           "check_period", "check_time", "check_tol", "shortest_period"]

# Below this preload [N] a normal force has no physical meaning (a millionth of a gram's
# weight; fivdisc.engine.simulation._NO_FORCE, which calls such a run degenerate).
_NO_FORCE = 1e-9
#: Tolerances the shooting runs accept (:data:`fivdisc.limits.MIN_SHOOTING_RTOL`).
MIN_RTOL = MIN_SHOOTING_RTOL
MAX_RTOL = MAX_SHOOTING_RTOL
#: Shooting residuals an orbit may be converged to (:data:`fivdisc.limits.MAX_SHOOTING_TOL`).
MIN_TOL = MIN_SHOOTING_TOL
MAX_TOL = MAX_SHOOTING_TOL


def check_tol(name: str, value: float) -> None:
    """Refuse a tolerance of the shooting residual outside [:data:`MIN_TOL`,
    :data:`MAX_TOL`]: above it a trajectory that does not close passes for an orbit."""
    if isinstance(value, bool) or not (isinstance(value, int | float)
                                       and MIN_TOL <= value <= MAX_TOL):
        raise FivdiscError(f"{name} = {value!r} is invalid: must lie in [{MIN_TOL:g}, "
                           f"{MAX_TOL:g}] (the shooting residual relative to the orbit's "
                           "size: above it a trajectory that does not close passes for an "
                           "orbit)")


def check_time(name: str, value: float | None, *, zero: bool = False) -> None:
    """Refuse a time option [s] that is not finite and positive (or zero with `zero`)."""
    if value is None:
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise FivdiscError(f"{name} = {value!r} is invalid: must be a number [s]")
    ok = math.isfinite(value) and (value >= 0 if zero else value > 0)
    if not ok:
        raise FivdiscError(f"{name} = {value!r} is invalid: must be finite and "
                           f"{'>= 0' if zero else '> 0'} [s]")


def shortest_period(case: Case) -> float:
    """The shortest period [s] an orbit of `case` may have: half the period of the
    model's fastest time scale (:func:`fivdisc.engine.integration.fastest_time_scale`). No
    motion of the model is faster; the half leaves room for the coupling of the disc and
    the sliders, which raises the fastest frequency above each part's own."""
    from fivdisc.engine.integration import fastest_time_scale
    from fivdisc.model.build import build_model

    return math.pi / fastest_time_scale(build_model(case))[1]


def check_period(case: Case, period: float, what: str = "--period") -> None:
    """Refuse a period [s] shorter than :func:`shortest_period`."""
    shortest = shortest_period(case)
    if not period >= shortest:
        raise FivdiscError(
            f"{what} = {period!r} s is invalid: must be >= {shortest:.3g} s, half the period "
            "of the model's fastest motion (no orbit is shorter)"
        )


def check_orbit_request(case: Case, *, period: float | None = None,
                        transient: float | None = None, window: float = 1.0,
                        rtol: float = 1e-12, names: tuple[str, ...] = (
                            "--period", "--transient", "--window", "--rtol")) -> None:
    """Refuse a periodic-orbit request that cannot give an answer in bounded time.

    Parameters
    ----------
    case
        The case.
    period, transient, window
        The guess of the period, the transient run and the window searched for a return [s].
    rtol
        Tolerance of the shooting runs.
    names
        How the four are named in messages (the command line's options by default).

    Raises
    ------
    FivdiscError
        One line naming the option, its value and what is allowed; also for a disc
        without modes (nothing to shoot on), a window (without a period) shorter than
        any period, and runs (transient, window, one period) whose work estimate exceeds
        ``simulation.max_steps`` (:func:`fivdisc.engine.integration.check_steps`).
    """
    p_name, t_name, w_name, r_name = names
    check_time(p_name, period)
    check_time(t_name, transient)
    check_time(w_name, window)
    if isinstance(rtol, bool) or not (isinstance(rtol, (int, float))
                                      and MIN_RTOL <= rtol <= MAX_RTOL):
        raise FivdiscError(f"{r_name} = {rtol!r} is invalid: must lie in "
                           f"[{MIN_RTOL:g}, {MAX_RTOL:g}]")
    if not case.disc.modes:
        raise FivdiscError("disc.modes = [] is invalid for a periodic orbit: a rigid disc "
                           "has no disc coordinates to shoot on; give at least one mode")
    # As a run's degeneracy test (fivdisc.engine.simulation.degenerate) counts it: below
    # a nanonewton a normal force has no physical meaning (2.2e-308 N drove the shooting
    # to subnormal states, a ZeroDivisionError in the kernel).
    strongest = max(range(len(case.sliders)), key=lambda j: case.sliders[j].preload)
    preload = case.sliders[strongest].preload
    if not preload > _NO_FORCE:
        raise FivdiscError(f"{case.slider_key(strongest)}.preload = {preload:g} is invalid "
                           f"for a periodic orbit: must be > {_NO_FORCE:g} N for some slider "
                           "(without a normal force nothing drives the disc, which stays at "
                           "rest)")
    if period is not None:
        check_period(case, period, p_name)
    else:
        check_period(case, window, w_name)  # no return comes sooner
    from fivdisc.engine.integration import check_steps
    from fivdisc.model.build import build_model

    model = build_model(case)
    run = case.simulation.duration if transient is None else transient
    # The transient, the window searched, and at least one shot over the period.
    span = " + ".join([t_name if transient is not None else "simulation.duration", w_name]
                      + ([p_name] if period else []))
    check_steps(model, run + window + (period or 0.0), span)
