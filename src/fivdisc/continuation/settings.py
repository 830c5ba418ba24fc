"""The settings of a continuation: step control, tolerances and budgets, their defaults in
one place (light to import, for the command line's defaults)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from fivdisc.errors import FivdiscError
from fivdisc.limits import (
    MAX_SHOOTING_RTOL,
    MAX_SHOOTING_TOL,
    MIN_SHOOTING_RTOL,
    MIN_SHOOTING_TOL,
)

# A corrector may move the point at most this many step lengths from the predictor.
MAX_CORRECTION = 0.5
# Cosine of the largest turn of the tangent between consecutive points (60 degrees).
MIN_COSINE = 0.5
MAX_NEWTON = 10
# Relative step of the central difference d phi_T / dp.
DP_STEP = 1e-6
# The two one-sided differences of d phi_T / dp agree to this (relative) on a smooth
# piece; where they do not, the held flow map jumps within DP_STEP of the point (two pads'
# switches change order there) and the difference is taken on one side.
DP_CONSISTENT = 1e-2
# A point is moved along its orbit when a switch has come within this fraction of the
# switch-free interval it lies in, or that interval is this fraction of the longest.
REANCHOR = 0.25
# The point lies in an interval where no slider sticks if there is one at least this
# fraction as long as the longest interval without a switch.
PREFER_FREE = 0.05
# A point that did not polish is refused when switches of different pads lie within this
# fraction of the period of each other (next to a border where they change order).
NEAR_SWITCHES = 1e-5
# The orbit found past a border where the flow map jumps is the branch's continuation if
# its point lies within this (scaled, relative to the orbit's size) of the border orbit's.
OTHER_PIECE = 1e-3
# Where no test function extrapolates to zero at a branch's end, one whose value at the
# last orbit is below this (a margin of mu_s N, a gap over the period) names it.
NEAR_ZERO = 1e-5
# Where the forward run that confirms an end starts: this fraction past the end.
PAST = 2e-3
# A forward run has settled on a periodic orbit when its returns to the section come
# back within this (scaled, relative to the orbit's size).
SETTLES = 1e-6
# Relative accuracy in the parameter to which bifurcations are located.
LOCATE = 1e-7
# A converged point is refined while its residual falls, to below this fraction of the
# tolerance (OrbitProblem.correct) ...
POLISH = 1e-2
# ... and until the last correction moved the period by less than this (relative): where a
# multiplier is near 1 the period's error is many times the residual (30 to 100 times on
# a stick-slip orbit whose multipliers are 0.98 to 0.99), so the residual alone does not
# hold it to 1e-9.
SETTLED = 1e-11
# A multiplier whose imaginary part is below this (relative) is taken as real.
REAL = 1e-6
# A lost branch of slipping orbits whose smallest slip speed is below this fraction of
# the disc speed ends grazing the stick boundary.
GRAZING = 1e-3
INTERRUPTED = "interrupted (Ctrl-C)"
DOUBLED_AMPLITUDE = 1e-4  # first doubled orbit's distance from the period doubling


@dataclass(frozen=True)
class ContinuationSettings:
    """How a branch is followed: its length, step control, tolerances and time budget.

    One set of defaults for :func:`~fivdisc.continuation.walk.continue_orbit`,
    :func:`~fivdisc.continuation.from_hopf.hopf_cycles` and ``fivdisc continue``; checked
    when made, so a bad value is refused before any work.

    Attributes
    ----------
    max_points : int
        Most points on the branch (the first included).
    step, max_step, min_step : float
        First, largest and smallest arclength step, in the scaled unknowns (the orbit's
        point over its size, the period over the first period, the parameter over its
        first value): a step of 0.02 changes them by about 2 %.
    rtol : float
        Relative tolerance of the integration.
    atol : float or None
        Absolute tolerance of the integration; None: ``rtol * 1e-7``.
    tol : float
        Tolerance of the shooting residual, as for
        :func:`~fivdisc.analysis.orbits.periodic_orbit`.
    time_budget : float
        Wall time after which the continuation stops [s].
    confirm_periods : int
        Length of the forward run that confirms each end of the branch, in periods
        (from the last orbit's point, :data:`PAST` past the end); 0: none.

    See Also
    --------
    fivdisc.continue_orbit, fivdisc.hopf_cycles : Take it as ``settings``, or its fields
        as keyword arguments.

    Examples
    --------
    >>> import fivdisc
    >>> fivdisc.ContinuationSettings()
    ContinuationSettings(max_points=200, step=0.02, max_step=0.1, min_step=1e-06, rtol=1e-12,
                         atol=None, tol=1e-08, time_budget=3600.0, confirm_periods=400)
    >>> fivdisc.ContinuationSettings(max_points=50).replace(step=0.01).step
    0.01
    >>> fivdisc.ContinuationSettings(step=-1.0)
    Traceback (most recent call last):
        ...
    fivdisc.errors.FivdiscError: step = -1.0 is invalid: must be a finite number > 0
    """

    max_points: int = 200
    step: float = 0.02
    max_step: float = 0.1
    min_step: float = 1e-6
    rtol: float = 1e-12
    atol: float | None = None
    tol: float = 1e-8
    time_budget: float = 3600.0
    confirm_periods: int = 400

    def __post_init__(self) -> None:
        for name in ("step", "max_step", "min_step", "time_budget", "tol", "rtol"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or not (
                    math.isfinite(value) and value > 0):
                raise FivdiscError(f"{name} = {value!r} is invalid: must be a finite number > 0")
        if not MIN_SHOOTING_RTOL <= self.rtol <= MAX_SHOOTING_RTOL:
            raise FivdiscError(f"rtol = {self.rtol!r} is invalid: must lie in "
                               f"[{MIN_SHOOTING_RTOL:g}, {MAX_SHOOTING_RTOL:g}]")
        if not MIN_SHOOTING_TOL <= self.tol <= MAX_SHOOTING_TOL:
            raise FivdiscError(f"tol = {self.tol!r} is invalid: must lie in "
                               f"[{MIN_SHOOTING_TOL:g}, {MAX_SHOOTING_TOL:g}] (the shooting "
                               "residual relative to the orbit's size: above it a trajectory "
                               "that does not close passes for an orbit)")
        if self.atol is not None and not (isinstance(self.atol, int | float)
                                          and math.isfinite(self.atol) and self.atol > 0):
            raise FivdiscError(f"atol = {self.atol!r} is invalid: must be a finite number > 0 "
                               "or None (rtol * 1e-7)")
        if not self.min_step <= self.step <= self.max_step:
            raise FivdiscError(f"step = {self.step!r} is invalid: must lie between min_step = "
                               f"{self.min_step!r} and max_step = {self.max_step!r}")
        if isinstance(self.max_points, bool) or not (isinstance(self.max_points, int)
                                                     and self.max_points >= 1):
            raise FivdiscError(f"max_points = {self.max_points!r} is invalid: must be an "
                               "integer >= 1")
        if isinstance(self.confirm_periods, bool) or not (
                isinstance(self.confirm_periods, int) and 0 <= self.confirm_periods <= 10**6):
            raise FivdiscError(f"confirm_periods = {self.confirm_periods!r} is invalid: must "
                               "be an integer in [0, 1000000]")

    @property
    def atol_run(self) -> float:
        """The absolute tolerance the integration uses."""
        return self.atol if self.atol is not None else self.rtol * 1e-7

    def replace(self, **changes: Any) -> ContinuationSettings:
        """A copy with ``changes`` (field names), checked."""
        return dataclasses.replace(self, **changes)

    @classmethod
    def of(cls, settings: ContinuationSettings | None, options: dict[str, Any]
           ) -> ContinuationSettings:
        """``settings`` (default: the defaults) with the fields among ``options`` taken out
        of it and applied; the other options are left in ``options``."""
        names = {f.name for f in dataclasses.fields(cls)}
        changes = {name: options.pop(name) for name in list(options) if name in names}
        base = settings if settings is not None else cls()
        return base.replace(**changes) if changes else base
