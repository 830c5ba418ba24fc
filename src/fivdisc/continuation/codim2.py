"""Bifurcations of periodic orbits followed in two case keys.

A bifurcation located on a branch in one key (``key``) is followed as the second key
(``key2``) moves: at each value of ``key2`` the point of the branch in ``key`` where the
bifurcation's *defining condition* ``g = 0`` holds is found again, from the previous one.
The problem is the branch's own (:class:`~fivdisc.continuation.problem.OrbitProblem`:
the shooting equations, the phase condition, the corrector, the anchor away from
switches); only its case moves with ``key2``. On each slice the unknowns are the orbit's
point, its period and ``key``, and ``g`` is zeroed by a secant iteration along the
slice's branch (arclength ``s`` from the slice's first point, each iterate a converged
point of the branch): ``s_{k+1} = s_k - g_k (s_k - s_{k-1}) / (g_k - g_{k-1})``, or on
``g^2`` where ``g`` falls as the square root of the distance to its zero (a one-sided
condition whose three last iterates fit that better, or whose straight-line step
overshot).

The defining conditions (each zero at the bifurcation, of one sign on either side):

* ``fold``: the branch tangent's component along ``key`` (the Jacobian of the
  shooting equations in the orbit and the period is singular there);
* ``period doubling``: ``Re mu + 1`` of the real negative multiplier followed from the
  previous point;
* ``torus``: ``|mu| - 1`` of the complex pair followed;
* ``symmetry breaking``: ``|mu| - 1`` of the eigenvalue of the reduced map
  ``P^-1 d phi_{T/k}`` followed (an orbit whose pads move in turn); on an orbit without
  a spatio-temporal symmetry, of the multiplier followed;
* ``grazing``: on a slipping orbit its smallest slip speed ``|Omega - phidot| /
  Omega`` (the interior minimum, a parabola through the cycle's samples), which reaches
  zero where the orbit touches the stick boundary; on a stick-slip orbit the smallest of
  its stick phases' durations over the period and the rates at which they are reached
  (``d(Omega - phidot)/dt`` just before sticking, times ``T / Omega``): zero where a
  stick phase shrinks to nothing or is reached tangentially, the slider's speed
  touching the disc's without crossing it (both one-sided: past the zero the orbit
  changes its sequence of phases or ceases to exist, and an iterate that lands there is
  pulled back half way);
* ``stick split``: the smallest interior minimum of a stick phase's static margin
  ``(mu_s N - |f|) / (mu_s N)``, zero where the stick phase splits in two (one-sided).

Not followed: the borders where switches of different pads change order and the flow
map jumps (a ``discontinuity`` of a branch): there no test function of the orbit need
reach zero (the in-phase orbit of three identical pads ends with its stick phase at 0.2
% of the period and its cascade margins at 3e-5, neither moving towards zero);
:func:`~fivdisc.continuation.region.bistable_region` locates such an end at each value
of the second key by the one-parameter walk instead.

The curve steps ``key2`` evenly from the start to ``to2``; the first iterate of a slice
is the previous point with ``key`` extrapolated through the last three points and the
orbit through the last two (for a one-sided condition, first moved back along the
previous branch by 1e-3 of the scaled arclength, or twice the extrapolation's error),
corrected onto the slice's branch on the hyperplane normal to the previous tangent (so
that it converges next to a fold, where ``key`` alone is no coordinate of the branch).
A slice that fails halves the step of ``key2`` (up to six times in a row; the curve ends
there), and the step grows back once one goes through.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from fivdisc.analysis.kinds import CURVE_CONDITIONS
from fivdisc.analysis.kinds import BifurcationKind as Kind
from fivdisc.case import Case
from fivdisc.continuation.branch import Branch
from fivdisc.continuation.checks import check_key, full_key
from fivdisc.continuation.detection import multipliers_of_kind
from fivdisc.continuation.problem import OrbitProblem, Point
from fivdisc.continuation.settings import ContinuationSettings
from fivdisc.errors import CaseError, ConvergenceError, FivdiscError
from fivdisc.model.build import model_at

__all__ = ["CONDITIONS", "BifurcationCurve", "bifurcation_curve", "curve_from_branch",
           "open_curve"]

#: The defining conditions a curve can follow.
CONDITIONS = CURVE_CONDITIONS
# Conditions that hold on one side only: past their zero the orbit has another sequence
# of phases.
_ONE_SIDED = (Kind.GRAZING, Kind.STICK_SPLIT)
# A slice's secant stops once its step moves the scaled unknowns by less than this (the
# key by less than this relative to its first value): ten times finer than the
# one-parameter location's 1e-7, so that a curve point is on the bifurcation to 1e-8.
_XTOL = 1e-9
_MAX_SECANT = 16
# ... or once g is within this (scaled arclength, about the key's relative change) of its
# zero at its slope: next to a one-sided condition's border the corrector comes no
# nearer than about 1e-7 (its iterates cross it).
_NEAR = 1e-7
# A one-sided condition's first secant step, on the previous slice's slope, goes this
# fraction of the way (the rest on the slice's own slope): past the border it would fail.
_SHORT = 0.9
# A one-sided condition's slice starts from the previous slice's orbit _Track.back back
# along its branch (scaled arclength): 1e-3 at first, doubled (up to _MAX_BACK) with each
# halving of the step of key2.
_MIN_BACK, _MAX_BACK = 1e-3, 0.1
# Halvings of the step of key2 before a curve ends.
_HALVINGS = 6


class CurveProblem(OrbitProblem):
    """The continuation problem of a branch in ``key`` whose case moves with ``key2``.

    The scales of the unknowns are the first slice's, so that points of different
    slices are in one set of coordinates (their tangents compare); the models at the
    values of ``key`` are made from the slice's (:meth:`move`)."""

    def __init__(self, case: Case, key: str, key2: str, phases: np.ndarray, period: float,
                 settings: ContinuationSettings) -> None:
        super().__init__(case, key, phases, period, settings)
        self.key2 = key2
        self.case0, self.base0 = case, self.base
        self.q = check_key(case, key2, "key2")

    def move(self, q: float) -> None:
        """Put the problem at ``key2 = q``."""
        try:
            self.case = self.case0.replace({self.key2: q})
            self.base = model_at(self.base0, self.case0, {self.key2: q})
        except CaseError as exc:
            raise ConvergenceError(str(exc), reason=str(exc)) from None
        self.q = q
        self._models.clear()

    def layout(self) -> tuple:
        """What a slice changes: the value of ``key2`` and the unknowns' layout."""
        return (self.q, self.case, self.base, self.shooting, self.free, self.m,
                self.template)

    def restore(self, saved: tuple) -> None:
        """Back to a :meth:`layout` (a slice that failed)."""
        (self.q, self.case, self.base, self.shooting, self.free, self.m,
         self.template) = saved
        self._models.clear()


@dataclass
class _Track:
    """What a condition follows from one point to the next: the critical multiplier (or
    reduced eigenvalue) and the slope of ``g`` along the tangent."""

    mu: complex = 0j
    slope: float = math.nan
    back: float = _MIN_BACK


def _stick_phases(pt: Point) -> list[float]:
    """The length of each stick phase of ``pt``'s orbit over the period."""
    out = []
    for j in range(len(pt.cycle.signature)):
        ev = [(t, kind) for t, kind, i in pt.cycle.events if i == j
              and kind in ("stick", "slip")]
        for (t1, k1), (t2, k2) in zip(ev, ev[1:] + ev[:1], strict=True):
            if k1 == "stick" and k2 == "slip":
                out.append(((t2 - t1) % pt.period) / pt.period)
    return out


def _approaches(problem: OrbitProblem, pt: Point) -> list[float]:
    """The rate at which each stick phase of ``pt``'s orbit is reached: the slider's
    relative acceleration ``d(Omega - phidot)/dt`` just before it sticks, times the period
    over the disc speed. A backward difference over ``d`` and ``d/2`` before the switch
    (``d`` = 2e-6 of the period), extrapolated to zero (Richardson): its error is that
    of the rates over ``d``, about 1e-6."""
    from fivdisc.engine.integration import Integration

    shooting = problem.shooter(pt.value)
    model = shooting.model
    omega = float(model.speed.omega(0.0))
    start = shooting.held(pt.x)
    out = []
    for t, kind, j in pt.cycle.events:
        if kind != "stick":
            continue
        values = []
        for d in (2e-6 * pt.period, 1e-6 * pt.period):
            before = t - d
            if not before > 0:
                break
            run = Integration(model, start, duration=before, output_rate=1.0 / before,
                              rtol=problem.rtol, atol=problem.atol, phases=pt.phases,
                              max_step=shooting.cap)
            run.run_to(before)
            values.append((omega - run.out_y[1, model.index("phi_dot", j)]) / d)
        if len(values) == 2:
            out.append(abs(2.0 * values[1] - values[0]) * pt.period / max(abs(omega), 1e-300))
    return out


def _followed(values: np.ndarray, track: _Track) -> complex:
    """The value of ``values`` nearest the one followed (the first time: nearest the unit
    circle)."""
    if values.size == 0:
        raise ConvergenceError("no multiplier of the condition's kind",
                               reason="the critical multiplier is gone")
    if track.mu == 0j:
        return complex(values[np.argmin(np.abs(np.abs(values) - 1.0))])
    return complex(values[np.argmin(np.abs(values - track.mu))])


def condition_value(problem: OrbitProblem, pt: Point, condition: str,
                    track: _Track | None = None) -> tuple[float, complex]:
    """The defining condition ``g`` of ``condition`` at ``pt`` (module docstring) and the
    multiplier it follows (0 if none).

    Raises
    ------
    ConvergenceError
        The point has no quantity of the condition's kind (no slipping slider for a
        grazing, no stick phase for a stick split, no multiplier of the class).
    """
    track = track or _Track()
    if condition == Kind.FOLD:
        return float(pt.tangent[-1]), 0j
    if condition in (Kind.PERIOD_DOUBLING, Kind.TORUS):
        mu = _followed(multipliers_of_kind(pt, condition), track)
        return (mu.real + 1.0 if condition == Kind.PERIOD_DOUBLING else abs(mu) - 1.0), mu
    if condition == Kind.SYMMETRY_BREAKING:
        if pt.reduced is not None:
            red = np.delete(pt.reduced, np.argmin(np.abs(pt.reduced - 1.0)))
            mu = _followed(red, track)
        else:
            others = np.delete(pt.multipliers, pt.trivial)
            mu = _followed(others, track)
        return abs(mu) - 1.0, mu
    sig = " ".join(pt.cycle.signature)
    if condition == Kind.GRAZING:
        if "stick" in sig:
            # a stick phase that shrinks to nothing, or one reached tangentially
            near = _stick_phases(pt) + _approaches(problem, pt)
            if near:
                return float(min(near)), 0j
        slips = [v for j, kind, v, _ in pt.cycle.dips
                 if kind == "slip" and "stick" not in pt.cycle.signature[j]]
        if slips:
            return float(min(slips)), 0j
        raise ConvergenceError("no slip speed minimum on the orbit",
                               reason="the orbit has no interior slip-speed minimum")
    dips = [v for _, kind, v, _ in pt.cycle.dips if kind == "stick"]
    if not dips:
        raise ConvergenceError("no static margin minimum inside a stick phase",
                               reason="no stick phase with an interior margin minimum")
    return float(min(dips)), 0j


def _on_slice(problem: CurveProblem, start: Point, condition: str, track: _Track,
              deadline: float) -> tuple[Point, float]:
    """The point of the slice's branch where ``condition`` holds, from ``start`` (a point
    of the slice's branch): secant along the arclength (module docstring), with the
    slope ``track`` carries from the previous slice for the first step (without one, a
    probe step). For a one-sided condition an iterate past the border is pulled back
    half way to the last one on the orbit's side. Returns the point and ``g`` there."""
    one_sided = condition in _ONE_SIDED
    g0, mu0 = condition_value(problem, start, condition, track)
    sign = float(np.sign(g0)) or 1.0

    def at(s: float, mu: complex, near: tuple | None = None
           ) -> tuple[float, float, Point, complex]:
        # from the last iterate: next to a border a long step's corrector crosses it
        s_from, from_pt = (near[0], near[2]) if near is not None else (0.0, start)
        pt = problem.step_from(from_pt, s - s_from, deadline)
        if one_sided and pt.cycle.cyclic() != start.cycle.cyclic():
            raise ConvergenceError("past the border", reason="past the border")
        g, mu_s = condition_value(problem, pt, condition, _Track(mu))
        if one_sided and g * sign < 0:
            raise ConvergenceError("past the border", reason="past the border")
        return s, g, pt, mu_s

    good = [(0.0, g0, start, mu0)]
    if not (np.isfinite(track.slope) and track.slope != 0.0):
        for probe in (1e-3, -1e-3):
            try:
                good.append(at(probe, mu0))
                break
            except ConvergenceError:
                if not one_sided or probe < 0:
                    raise
    power = 1.0  # g ~ (s* - s)^power near the zero: 1, or 1/2 at a square-root end
    bad = math.nan
    for _ in range(_MAX_SECANT):
        if time.monotonic() > deadline:
            raise ConvergenceError("the time budget ran out", reason="the time budget ran out")
        if one_sided and len(good) > 2:
            power = min((1.0, 0.5), key=lambda a: _spread(good[-3:], a, sign))
        sb, mub = good[-1][0], good[-1][3]
        dist = _to_zero(good[-2:], power, sign, track.slope)
        if one_sided:
            # short of the border by half the stopping distance (iterates nearer than
            # about 1e-7 fall across it in the corrector); the first step, on the
            # previous slice's slope, only _SHORT of the way
            dist = (dist * _SHORT if len(good) == 1 else dist) - 0.5 * _NEAR * np.sign(dist)
        s = sb + dist
        if np.isfinite(bad) and (s - bad) * (sb - bad) <= 0:
            s = 0.5 * (sb + bad)
        try:
            found = at(s, mub, good[-1])
        except ConvergenceError:
            if not one_sided:
                raise
            bad = s
            if len(good) < 3:
                power = 0.5  # overshot on a straight line: a square-root end
            continue
        good.append(found)
        left = abs(_to_zero(good[-2:], power, sign, track.slope))
        if abs(s - sb) < _XTOL or left < (_NEAR if one_sided else _XTOL):
            break
    else:
        reason = f"the condition's secant did not settle in {_MAX_SECANT} steps"
        raise ConvergenceError(reason, reason=reason)
    newer = good[-1]
    s, g, pt, mu = newer
    # the slope over the widest pair of iterates (the last steps are too short to give
    # one): the first step of the next slice
    wide = max(good[:-1], key=lambda other: abs(other[0] - s))
    if wide[0] != s and wide[1] != g:
        track.slope = (g - wide[1]) / (s - wide[0])
    track.mu = mu
    return pt, g


def _to_zero(pair: list[tuple], power: float, sign: float, slope: float) -> float:
    """The step from the last of ``pair`` ((s, g, ...) points) to where ``g`` vanishes,
    on the straight line through ``(s, g)``, or through ``(s, (sign g)^(1/power))``
    (with one point, on ``slope``)."""
    h = [p[1] if power == 1.0 else max(sign * p[1], 0.0) ** (1.0 / power) for p in pair]
    if len(pair) == 1 or h[-1] == h[-2] or pair[-1][0] == pair[-2][0]:
        return -pair[-1][1] / slope
    return -h[-1] * (pair[-1][0] - pair[-2][0]) / (h[-1] - h[-2])


def _spread(three: list[tuple], power: float, sign: float) -> float:
    """How far apart the zeros predicted by the first two and the last two of ``three``
    points lie, with ``g`` taken to the ``1/power``: the smaller, the better the power
    fits."""
    a = three[1][0] + _to_zero(three[:2], power, sign, math.nan)
    b = three[2][0] + _to_zero(three[1:], power, sign, math.nan)
    return abs(a - b) if np.isfinite(a - b) else math.inf


@dataclass
class _Row:
    point: Point
    q: float
    g: float
    # the problem's count of anchor moves when the point was made: points with the same
    # count have their unknowns in one layout
    anchor: int = 0


def _predicted(rows: list[_Row], q: float) -> tuple[float, float]:
    """``key`` at ``key2 = q`` extrapolated from the last points: through the last three
    (or fewer), and the difference between that and the straight line through the last
    two (a measure of the extrapolation's error)."""
    qs = np.array([r.q for r in rows[-3:]])
    ps = np.array([r.point.value for r in rows[-3:]])
    if qs.size == 1:
        return float(ps[0]), 0.0
    line = ps[-1] + (ps[-1] - ps[-2]) / (qs[-1] - qs[-2]) * (q - qs[-1])
    if qs.size == 2:
        return float(line), float(abs(line - ps[-1]))
    # the parabola through three points, in divided differences
    d1 = (ps[2] - ps[1]) / (qs[2] - qs[1])
    d2 = ((ps[2] - ps[1]) / (qs[2] - qs[1]) - (ps[1] - ps[0]) / (qs[1] - qs[0])) / (
        qs[2] - qs[0])
    quad = ps[2] + d1 * (q - qs[2]) + d2 * (q - qs[2]) * (q - qs[1])
    return float(quad), float(abs(quad - line))


def _first_on(problem: CurveProblem, rows: list[_Row], q: float, condition: str,
              track: _Track, deadline: float) -> Point:
    """The first point of the slice at ``key2 = q``: the last point's orbit with ``key``
    extrapolated (:func:`_predicted`), corrected on the hyperplane normal to the last
    point's tangent. For a one-sided condition the orbit is first moved back along the
    last point's branch by ``track.back`` (scaled arclength), or by twice the
    extrapolation's error estimate if that is more (an orbit predicted past the border
    has no orbit near it to correct to)."""
    last = rows[-1]
    a = last.point
    p, error = _predicted(rows, q)
    if condition in _ONE_SIDED and np.isfinite(track.slope) and track.slope != 0.0:
        # back along the arclength, towards larger g: by track.back, or by twice the
        # extrapolation's error if that is more
        dp_ds = abs(a.tangent[-1]) * problem.ps
        back = min(max(track.back, 2.0 * error / dp_ds if dp_ds > 0 else 0.0), _MAX_BACK)
        a = problem.step_from(a, back * np.sign(track.slope) * (np.sign(last.g) or 1.0),
                              deadline)
        p += a.value - last.point.value
    z = a.z.copy()
    if (len(rows) > 1 and rows[-2].anchor == last.anchor == problem.reanchors
            and rows[-2].point.z.shape == z.shape):
        # the orbit extrapolated too, where the last two points share the layout
        z += (last.point.z - rows[-2].point.z) * (q - last.q) / (last.q - rows[-2].q)
    z[-1] = p / problem.ps
    x, period, _ = problem.unpack(z)
    problem.move(q)
    guess = problem.point_at(x, period, p, a.phases, float(np.sign(a.tangent[-1]) or 1.0),
                             along=a.tangent)
    pt = problem.correct(guess.z, a.tangent, float(a.tangent @ guess.z), guess, math.inf,
                         deadline)
    return problem.reanchored(problem.finish(pt, a.tangent, 1.0))


def bifurcation_curve(
    case: Case,
    key: str,
    condition: str,
    key2: str,
    to2: float,
    *,
    state: np.ndarray,
    period: float,
    phases: np.ndarray,
    points: int = 50,
    settings: ContinuationSettings | None = None,
    start: str = "",
    progress: bool = False,
    **options: Any,
) -> BifurcationCurve:
    """Follow a bifurcation of periodic orbits in two keys.

    Parameters
    ----------
    case : Case
        A constant-speed case, at the bifurcation's values of ``key`` and ``key2`` (or
        near them: the first point is located on the branch through ``state``).
    key : str
        The key of the branch the bifurcation lies on (solved for at each point).
    condition : str
        One of :data:`CONDITIONS` (module docstring).
    key2 : str
        The second key, stepped evenly from its value in ``case`` to ``to2``.
    to2 : float
        Where the curve ends [``key2``'s unit].
    state, period, phases : ndarray, float, ndarray
        A point of an orbit of the branch at or near the bifurcation, its period [s] and
        its sliders' phases there (a :class:`~fivdisc.continuation.branch.Branch`'s
        bifurcation record has them).
    points : int
        Points on the curve, the first included (>= 2), evenly spaced in ``key2``; where
        a slice fails the step is halved (up to six times in a row) and the points in
        between come in addition, up to four times ``points`` in all.
    settings : ContinuationSettings, optional
        Tolerances and time budget (``tol``, ``rtol``, ``atol``, ``time_budget``).
    start : str
        Where the start comes from, kept in the curve.
    progress : bool
        Show the points on a terminal (stderr).
    **options
        Fields of :class:`~fivdisc.continuation.settings.ContinuationSettings`.

    Returns
    -------
    BifurcationCurve
        The points, each a converged orbit with its multipliers, its residual and the
        defining condition's value there.

    Raises
    ------
    CaseError
        A key that is not numeric, ``key2`` equal to ``key``, ``to2`` not an allowed
        value of ``key2`` or equal to its value, ``points`` below 2.
    FivdiscError
        An unknown condition.
    ConvergenceError
        The bifurcation is not found near the start.

    See Also
    --------
    curve_from_branch : The same from a bifurcation of a branch.
    fivdisc.continue_orbit : The one-parameter branch.

    Notes
    -----
    Each point solves the shooting equations ``phi_T(x; p, q) - x = 0`` with the phase
    condition and the defining condition ``g(x, T, p; q) = 0`` at its ``q``: the
    shooting residual is below ``tol``, and the secant on ``g`` along the branch stops
    once its last step moved the unknowns by less than 1e-9 (scaled), or, for a
    one-sided condition, once the zero it predicts lies within 1e-7 (scaled arclength,
    about the key's relative change): ``|g|`` is below its slope times that, or at a
    square-root end (``g ~ sqrt(s* - s)``, a stick phase reached tangentially) about
    the square root of it. Both are stored per point (``residual``, ``condition``).

    Examples
    --------
    The grazing of the orbits born at a rigid disc's Hopf point, from the branch's
    record of it, followed in the slider's damping:

    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> (hopf,) = fivdisc.hopf_points(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> b = fivdisc.hopf_cycles(hopf, 30.0, confirm_periods=0).bifurcations()[0]
    >>> curve = fivdisc.bifurcation_curve(
    ...     rigid.replace({"speed.value": b["parameter"]}), "speed.value", "grazing",
    ...     "slider.rotational_damping", 0.52, state=b["state"], period=b["period"],
    ...     phases=b["phases"], points=3)
    >>> for i in (0, -1):
    ...     print(f"{curve.second_parameter[i]:.3f} N m s/rad: grazing at "
    ...           f"{curve.parameter[i]:.5f} rad/s")
    0.500 N m s/rad: grazing at 10.49852 rad/s
    0.520 N m s/rad: grazing at 9.98023 rad/s
    """
    settings = ContinuationSettings.of(settings, options)
    key, key2 = full_key(key, "key"), full_key(key2, "key2")
    if condition not in CONDITIONS:
        raise FivdiscError(f"condition = {condition!r} is invalid: must be one of "
                           f"{', '.join(CONDITIONS)}")
    if key2 == key:
        raise CaseError(f"key2 = {key2!r} is invalid: it is the branch's key; give another")
    check_key(case, key)
    q0 = check_key(case, key2, "key2")
    if not np.isfinite(to2) or to2 == q0:
        raise CaseError(f"to2 = {to2!r} is invalid: must be a finite value of {key2} other "
                        f"than its value {q0:g}")
    case.replace({key2: float(to2)})
    if isinstance(points, bool) or not isinstance(points, int) or points < 2:
        raise CaseError(f"points = {points!r} is invalid: must be an integer >= 2")
    from fivdisc.engine.progress import progress_bar

    deadline = time.monotonic() + settings.time_budget
    problem = CurveProblem(case, key, key2, phases, period, settings)
    p0 = problem.p0
    x, ph = problem.anchored(np.asarray(state, dtype=float), period, p0, phases)
    first = problem.point_at(x, period, p0, ph, 1.0)
    track = _Track()
    rows: list[_Row] = []
    stop = f"reached {key2} = {to2:g}"
    with progress_bar(points, f"following the {condition} in {key2}", "point",
                      show=progress) as bar:
        pt, g = _on_slice(problem, first, condition, track, deadline)
        rows.append(_Row(pt, q0, g, problem.reanchors))
        bar.update()
        h = h0 = (to2 - q0) / (points - 1)
        halvings = 0
        # slices that had to halve the step take points of their own
        max_points = 4 * points
        while len(rows) < max_points:
            last = rows[-1]
            q = last.q + h
            if (q - to2) * np.sign(h) > -1e-9 * abs(h0):
                q = to2
            saved = _Track(track.mu, track.slope, track.back)
            layout = problem.layout()
            try:
                guess = _first_on(problem, rows, q, condition, track, deadline)
                pt, g = _on_slice(problem, guess, condition, track, deadline)
            except (ConvergenceError, FivdiscError) as exc:
                track = saved
                problem.restore(layout)
                if time.monotonic() > deadline:
                    stop = "the time budget ran out"
                    break
                if halvings == _HALVINGS:
                    stop = (f"the {condition} was not found past {key2} = {last.q:.9g} "
                            f"({getattr(exc, 'reason', None) or exc})")
                    break
                halvings += 1
                h *= 0.5
                track.back = min(2.0 * track.back, _MAX_BACK)
                continue
            rows.append(_Row(pt, q, g, problem.reanchors))
            bar.update()
            if q == to2:
                break
            # back to the even step once a slice has gone through
            h = h0 if abs(2.0 * h) > abs(h0) else 2.0 * h
            track.back = max(0.5 * track.back, _MIN_BACK)
            halvings = 0
        else:
            stop = f"the largest number of points ({max_points}) is reached"
    problem.move(q0)
    return BifurcationCurve.from_rows(problem, rows, condition, stop, start)


def curve_from_branch(branch: Branch, which: int, key2: str, to2: float, *,
                      condition: str | None = None, **options: Any) -> BifurcationCurve:
    """Follow bifurcation ``which`` of ``branch`` in ``key2`` (:func:`bifurcation_curve`).

    Parameters
    ----------
    branch : Branch
        From :func:`~fivdisc.continuation.walk.continue_orbit` or
        :func:`~fivdisc.continuation.open_branch`.
    which : int
        Index of the bifurcation in ``branch.bifurcations()``.
    key2, to2 : str, float
        The second key and where the curve ends.
    condition : str, optional
        The defining condition (:data:`CONDITIONS`); default: the bifurcation's kind
        (a fold, a period doubling, a torus, a symmetry breaking, a grazing). Needed
        for the other kinds, such as the end of a branch of stick-slip orbits where its
        stick phase vanishes (``"grazing"``).
    **options
        Keyword arguments of :func:`bifurcation_curve`.

    Examples
    --------
    The unstable orbits born at the subcritical Hopf point of a slider on a rigid disc
    graze the stick boundary; the grazing followed in the slider's damping:

    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> (hopf,) = fivdisc.hopf_points(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> branch = fivdisc.hopf_cycles(hopf, 30.0, confirm_periods=0)
    >>> [b["kind"] for b in branch.bifurcations()]
    ['grazing']
    >>> curve = fivdisc.curve_from_branch(branch, 0, "slider.rotational_damping", 0.55,
    ...                                   points=3)
    >>> print(curve.stop_reason, bool(abs(curve.condition).max() < 1e-6))
    reached slider.rotational_damping = 0.55 True
    """
    bifs = branch.bifurcations()
    if isinstance(which, bool) or not isinstance(which, int) or not 0 <= which < len(bifs):
        raise FivdiscError(f"bifurcation = {which!r} is invalid: the branch has {len(bifs)} "
                           "bifurcation(s), numbered from 0")
    b = bifs[which]
    if condition is None:
        # A kind with a defining condition of its own is followed by it.
        if b["kind"] not in CONDITIONS:
            raise FivdiscError(f"bifurcation {which} is a {b['kind']}: say which condition to "
                               f"follow there (one of {', '.join(CONDITIONS)})")
        condition = Kind(b["kind"])
    value, state, period, phases = (float(b["parameter"]), b["state"], float(b["period"]),
                                    b["phases"])
    if condition in _ONE_SIDED and 0 <= b["point"] < len(branch):
        # from the branch's last orbit before it: the record of a border's orbit lies on
        # the border, where the orbit's phases are about to change
        i = int(b["point"])
        value, state, period, phases = (float(branch.parameter[i]),
                                        branch.dataset["state"].values[i],
                                        float(branch.period[i]), branch.phases(i))
    case = branch.case.replace({branch.key: value})
    return bifurcation_curve(case, branch.key, condition, key2, to2, state=state,
                             period=period, phases=phases,
                             start=f"{b['kind']} {which} of a branch in {branch.key} at "
                                   f"{b['parameter']:.10g}", **options)


class BifurcationCurve(Branch):
    """A bifurcation of periodic orbits followed in two keys: a
    :class:`~fivdisc.continuation.branch.Branch` (one orbit per point, ``parameter`` the
    first key's value) with, per point, ``second_parameter`` (the second key's value) and
    ``condition`` (the defining condition's value there); attributes ``curve_kind`` (the
    condition), ``key2``.

    See Also
    --------
    bifurcation_curve, curve_from_branch : Make one.
    open_curve : Read one written by :meth:`~fivdisc.continuation.branch.Branch.to_netcdf`.

    Examples
    --------
    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> (hopf,) = fivdisc.hopf_points(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> branch = fivdisc.hopf_cycles(hopf, 30.0, confirm_periods=0)
    >>> curve = fivdisc.curve_from_branch(branch, 0, "slider.rotational_damping", 0.52,
    ...                                   points=2)
    >>> curve.kind, curve.key, curve.key2, float(curve.second_parameter[-1])
    ('grazing', 'speed.value', 'slider.rotational_damping', 0.52)
    >>> print(f"{curve.at(0.51):.4f} rad/s")
    10.2359 rad/s
    """

    @classmethod
    def from_rows(cls, problem: CurveProblem, rows: list[_Row], condition: str, stop: str,
                  start: str) -> BifurcationCurve:
        from types import SimpleNamespace

        from fivdisc.case import describe_key

        walk = SimpleNamespace(points=[r.point for r in rows], bifurcations=[],
                               stop=SimpleNamespace(reason=stop, lost=False), checks=[])
        ds = Branch.from_walk(problem, walk, start).dataset
        info = describe_key(problem.key2)
        ds["second_parameter"] = ("point", np.array([r.q for r in rows]),
                                  {"long_name": info.long_name, "units": info.unit,
                                   "key": problem.key2})
        ds["condition"] = ("point", np.array([r.g for r in rows]),
                           {"long_name": f"defining condition of the {condition} (zero on "
                                         "the curve)", "units": "1"})
        ds.attrs.update({"curve_kind": condition, "key2": problem.key2})
        return cls(ds)

    @property
    def key2(self) -> str:
        """The second key."""
        return str(self.dataset.attrs["key2"])

    @property
    def kind(self) -> str:
        """The defining condition followed."""
        return str(self.dataset.attrs["curve_kind"])

    @property
    def second_parameter(self) -> np.ndarray:
        """The second key's value at each point."""
        return self.dataset["second_parameter"].values

    @property
    def condition(self) -> np.ndarray:
        """The defining condition's value at each point (zero on the curve)."""
        return self.dataset["condition"].values

    def at(self, value2: float) -> float:
        """The first key's value on the curve at ``key2 = value2``, interpolated linearly
        between its points [the first key's unit]."""
        q, p = self.second_parameter, self.parameter
        order = np.argsort(q)
        return float(np.interp(value2, q[order], p[order]))

    def lines(self) -> list[str]:
        """Each point as a line: both keys, the period, the residuals."""
        out = [f"{'':>4} {self.key2:>16} {self.key:>16} {'period [s]':>14} "
               f"{'residual':>9} {'condition':>10} stable"]
        for i, (q, p, t, r, g, s) in enumerate(zip(
                self.second_parameter, self.parameter, self.period,
                self.dataset["residual"].values, self.condition, self.stable, strict=True)):
            out.append(f"{i:>4} {q:>16.10g} {p:>16.10g} {t:>14.9g} {r:>9.1e} {g:>10.1e} "
                       f"{'yes' if s else 'no'}")
        return out

    def __str__(self) -> str:
        q, p = self.second_parameter, self.parameter
        head = (f"{self.kind} curve in ({self.key}, {self.key2}): {len(self)} points from "
                f"{self.key2} = {q[0]:.10g} ({self.key} = {p[0]:.10g}) to {q[-1]:.10g} "
                f"({self.key} = {p[-1]:.10g})")
        worst = (f"largest shooting residual {self.dataset['residual'].values.max():.1e}, "
                 f"largest |condition| {np.abs(self.condition).max():.1e}")
        return "\n".join([head, f"stopped: {self.stop_reason}", worst, *self.lines()])


def open_curve(path) -> BifurcationCurve:
    """Read a curve written by :meth:`BifurcationCurve.to_netcdf`.

    Raises
    ------
    FivdiscError
        The file is not a bifurcation curve.

    Examples
    --------
    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> (hopf,) = fivdisc.hopf_points(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> branch = fivdisc.hopf_cycles(hopf, 30.0, confirm_periods=0)
    >>> curve = fivdisc.curve_from_branch(branch, 0, "slider.rotational_damping", 0.52,
    ...                                   points=2)
    >>> curve.to_netcdf("grazing.nc")
    >>> fivdisc.open_curve("grazing.nc").dataset.equals(curve.dataset)
    True
    """
    from fivdisc.continuation.branch import open_branch

    ds = open_branch(path).dataset
    if "curve_kind" not in ds.attrs:
        raise FivdiscError(f"{path} is a branch, not a bifurcation curve (fivdisc continue "
                           "--key2 -o)")
    return BifurcationCurve(ds)
