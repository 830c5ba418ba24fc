"""Continuation of periodic orbits in one case key, through their bifurcations.

A branch is followed by pseudo-arclength continuation of the shooting equations of
:mod:`fivdisc.analysis.orbits` with the parameter ``p`` as one more unknown. With ``x``
the free coordinates of the orbit's point, scaled (energy scales, divided by the first
orbit's size), ``T`` the period and ``p`` the key's value, each divided by its value at
the start, the unknowns are ``z = (x, T, p)`` and the equations

* ``phi_T(x; p) - x = 0``: the orbit closes;
* ``f(x_prev) . (x - x_prev) = 0``: the point moves orthogonally to the flow from the
  previous point's (which fixes it on the orbit);
* ``t_prev . (z - z_prev) = ds``: a step ``ds`` along the previous tangent.

The predictor is ``z_prev + ds t_prev``; a chord Newton corrector takes the previous
point's Jacobian: the monodromy (exact across every switch) for ``d phi_T / dx``, the
vector field for ``d phi_T / dT`` and a central difference for ``d phi_T / dp``; each
converged point gets its own, for its multipliers and tangent. A corrector that needs more than
:data:`MAX_CORRECTION` of ``ds`` to converge, or whose tangent turns by more than 60
degrees, is refused and the step halved: so the branch moves continuously and never
jumps to a nearby orbit (orbits of nearly the same period coexist in the paper's cases).

Bifurcations are detected between consecutive points and located by a root of a test
function along the arclength (:func:`scipy.optimize.brentq`) or, for a change of the
event signature, by bisection, each to a relative accuracy of 1e-6 in the parameter:

* fold: the tangent's parameter component changes sign;
* period doubling: a real multiplier crosses -1;
* torus (Neimark-Sacker): a complex pair crosses the unit circle;
* symmetry breaking: on a symmetric orbit of identical pads, a multiplier crossing
  whose eigenvector breaks the symmetry (:mod:`fivdisc.analysis.symmetry`: classified on
  the reduced map ``P^-1 d phi_{T/k}``, with the resonance it lies near);
* discontinuity-induced: the event signature (:mod:`fivdisc.analysis.cycle`) changes
  (a phase of a slider appears or vanishes), or the switches of different sliders
  change order (:mod:`fivdisc.continuation.borders`): where the flow map is continuous
  there the branch goes on (``switching order``); where it jumps, the branch jumps to
  the orbit of the other side (``discontinuity``, both periods recorded) or, if there
  is none, ends (``discontinuity end``, ``cascade end``). The multipliers on either side
  are reported, since they may jump there.
* grazing: a branch of slipping orbits lost where its slip speed touches zero ends
  there (the stick-slip orbits turn back from it).

Between two converged points the per-slider cyclic signatures and the order of all
switches are compared; a change is bisected on converged orbits to 1e-7 of the key. No
held point is ever tested. Where the corrector fails, the step is halved down to
``min_step`` (which is tried itself), the last orbit's border is located and named by
its test functions, and every end is confirmed by a forward run 0.2 % past it
(:func:`fivdisc.continuation.borders.forward_run`).

A branch may also start at a Hopf point of the equilibrium
(:func:`fivdisc.continuation.from_hopf.hopf_cycles`): the first point is corrected with its
amplitude along the critical eigenvector held and the parameter free.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fivdisc.analysis.cycle import order_changes
from fivdisc.analysis.kinds import BifurcationKind as Kind
from fivdisc.analysis.orbits import (
    PeriodicOrbit,
    periodic_orbit,
)
from fivdisc.case import Case
from fivdisc.continuation.borders import (
    Ahead,
    Test,
    border_ahead,
    forward_run,
    order_key,
    other_piece,
    pad_classes,
    same_piece,
    switch_tests,
)
from fivdisc.continuation.branch import Branch
from fivdisc.continuation.checks import check_search, check_target, check_window, full_key
from fivdisc.continuation.detection import (
    TOUCHES,
    Bifurcation,
    bifurcation_record,
    closed_on,
    grazing,
    locate,
    located,
    slip_margin,
    smooth_kinds,
    without_fold_echoes,
)
from fivdisc.continuation.problem import OrbitProblem, Point, close_switches
from fivdisc.continuation.settings import (
    GRAZING,
    INTERRUPTED,
    LOCATE,
    MIN_COSINE,
    NEAR_ZERO,
    OTHER_PIECE,
    PAST,
    POLISH,
    ContinuationSettings,
)
from fivdisc.continuation.starts import start_point
from fivdisc.errors import ConvergenceError, FivdiscError

__all__ = ["continue_orbit"]


@dataclass
class Stop:
    reason: str = ""
    lost: bool = False


@dataclass
class Walk:
    points: list[Point] = field(default_factory=list)
    bifurcations: list[Bifurcation] = field(default_factory=list)
    stop: Stop = field(default_factory=Stop)
    # The forward runs that confirmed the branch's ends, in words.
    checks: list[str] = field(default_factory=list)


def continue_orbit(
    case: Case,
    key: str,
    to: float,
    *,
    orbit: PeriodicOrbit | None = None,
    along: np.ndarray | None = None,
    back_to: float | None = None,
    settings: ContinuationSettings | None = None,
    progress: bool = False,
    **options: Any,
) -> Branch:
    """Follow a periodic orbit of ``case`` as ``key`` goes to ``to``, and locate the
    bifurcations on the way.

    Parameters
    ----------
    case : Case
        A constant-speed case.
    key : str
        A numeric case key (``speed.value``, ``slider.normal_damping``,
        ``sliders.1.preload``, ``friction.decay``, ``disc.damping_ratio``, ...).
    to : float
        Where the continuation stops [the key's unit]; its side of the case's value sets
        the direction. A branch that turns at a fold stops where the key comes back past
        ``back_to`` (the walk's window runs from there to ``to``).
    orbit : PeriodicOrbit, optional
        The orbit to start from (at the case's value of ``key``). Default: found as
        :func:`~fivdisc.analysis.orbits.periodic_orbit` finds it, with the ``options``
        that are not settings as its keyword arguments (``transient``, ``period``,
        ``guess``, ``phases``, ...).
    along : ndarray, optional
        Branch switching: the first step leaves ``orbit``'s point in this state
        direction instead of along the branch through it (see :func:`doubled_start`).
    back_to : float, optional
        The window's other end [the key's unit]: once the branch has turned at a fold, it
        stops where the key comes back past this value, on a point corrected to it.
        Default: the case's value. On the case's value or on its side away from ``to``;
        give a value beyond the range the orbits span to follow a closed branch (an
        isola) round.
    settings : ContinuationSettings, optional
        Length, step control, tolerances and time budget (default: its defaults).
    progress : bool
        Show the points on a terminal (stderr).
    **options
        Fields of :class:`~fivdisc.continuation.settings.ContinuationSettings`
        (``max_points``, ``step``, ``max_step``, ``min_step``, ``rtol``, ``atol``,
        ``tol``, ``time_budget``) that change ``settings``; the others go to the search
        of the first orbit.

    Returns
    -------
    Branch
        The points, their measures and multipliers, the bifurcations and why the
        continuation stopped (:class:`fivdisc.continuation.branch.Branch`).

    Raises
    ------
    CaseError
        ``key`` is not a numeric key, or ``to`` is not an allowed value of it.
    ConvergenceError
        No periodic orbit to start from.

    See Also
    --------
    fivdisc.periodic_orbit : One orbit, at one value of the key.
    fivdisc.hopf_cycles : A branch that starts at a Hopf point of the sliding
        equilibrium instead of at an orbit.
    fivdisc.plots.plot_branch : Draws a branch.

    Notes
    -----
    The method is in the module's docstring and on the documentation's continuation
    page. Step control: after a point that took at most 3 corrector iterations the step
    grows by 1.5 (not right after a failed step), after 7 or more it halves; a refused or
    failed step is halved down to ``min_step``, which is tried itself; a failure there
    ends the branch where the last orbit's border is (located and named, a jump to the
    other side's orbit taken where there is one) or, if none is found, as lost. Each end
    is confirmed by a forward run 0.2 % past it (``confirm_periods``).

    Examples
    --------
    The stick-slip orbit of a slider with constant kinetic friction on a disc of one
    axisymmetric mode, followed from 1 to 1.1 rad/s: its period shortens, it stays
    stable and keeps its sequence of phases (one stick and one slip), so no bifurcation
    is met.

    >>> import fivdisc
    >>> case = fivdisc.Case(
    ...     disc={"modes": [[0, 0]]},
    ...     slider={"rotational_damping": 0.0, "normal_damping": 5.0},
    ...     friction={"kinetic_max": 0.5, "kinetic_min": 0.5},
    ...     speed={"value": 1.0},
    ... )
    >>> orbit = fivdisc.periodic_orbit(case, transient=1.0)
    >>> branch = fivdisc.continue_orbit(case, "speed.value", 1.1, orbit=orbit, max_points=30)
    >>> branch.stop_reason
    'reached speed.value = 1.1'
    >>> print(f"{branch.parameter[0]:.2f} -> {branch.parameter[-1]:.2f} rad/s: "
    ...       f"T = {branch.period[0] * 1e3:.4f} -> {branch.period[-1] * 1e3:.4f} ms")
    1.00 -> 1.10 rad/s: T = 16.9016 -> 15.5931 ms
    >>> bool(branch.stable.all()), branch.signature(0), branch.bifurcations()
    (True, ('slip+ > stick > slip+',), [])
    """
    settings = ContinuationSettings.of(settings, options)
    key = full_key(key)
    p0 = check_target(case, key, to)
    if back_to is None:
        back_to = p0
    check_window(key, p0, to, back_to)
    if orbit is None:
        check_search(case, options, settings.rtol)
        orbit = periodic_orbit(case, rtol=settings.rtol, atol=settings.atol_run,
                               tol=settings.tol, progress=progress, **options)
    elif not orbit.converged:
        raise ConvergenceError("the start is not a converged periodic orbit", result=orbit,
                               reason="not converged")
    direction = 1.0 if to > p0 else -1.0
    problem = OrbitProblem(case, key, orbit.phases, orbit.period, settings)
    return run_walk(problem, lambda deadline: start_point(problem, orbit, direction, along,
                                                          deadline),
                    to, settings, progress, orbit.start, back_to)


def run_walk(problem: OrbitProblem, first: Callable[[float], Point], to: float,
             settings: ContinuationSettings, progress: bool, start: str,
             back_to: float | None = None) -> Branch:
    """The first point (``first(deadline)``), then the walk to ``to`` (and, after a fold,
    back to ``back_to``, default the first point's value): the branch."""
    from fivdisc.engine.progress import progress_bar

    deadline = time.monotonic() + settings.time_budget
    walk = Walk()
    with progress_bar(settings.max_points, f"continuing in {problem.key}", "point",
                      show=progress) as bar:
        walk.points.append(first(deadline))
        bar.update()
        try:
            walk_on(problem, walk, to, back_to, settings, deadline, bar)
        except KeyboardInterrupt:
            # The points and bifurcations so far are a branch: kept, as a time budget
            # running out keeps them.
            walk.stop = Stop(INTERRUPTED)
    walk.bifurcations = without_fold_echoes(walk.bifurcations)
    return Branch.from_walk(problem, walk, start)


def walk_on(problem: OrbitProblem, walk: Walk, to: float, back_to: float | None,
            settings: ContinuationSettings, deadline: float, bar: Any) -> None:
    """Add points to ``walk`` until ``to``, the window's far end, the settings' limits or
    the branch's end; say why it stopped in ``walk.stop``."""
    max_points, ds = settings.max_points, settings.step
    max_step, min_step = settings.max_step, settings.min_step
    target = to / problem.ps
    side = np.sign(target - walk.points[0].z[-1])
    # Once the branch has turned at a fold, it stops where the key comes back past
    # `began` away from `to`, as AUTO stops at the far end of its window; the walk
    # covers the range from there to `to` and no more.
    began = walk.points[0].value if back_to is None else back_to
    lo_period, hi_period = problem.period0 / 100.0, problem.period0 * 100.0
    failed = False
    while len(walk.points) < max_points:
        if time.monotonic() > deadline:
            walk.stop = Stop("the time budget ran out")
            return
        # The point away from its switches, which drift along the branch.
        a = walk.points[-1] = problem.reanchored(walk.points[-1])
        # A predictor past the target goes to the target itself: beyond it the key may
        # leave its allowed range (a damping continued to zero).
        landing = np.sign(target - (a.z[-1] + ds * a.tangent[-1])) != side
        try:
            b = problem.at_value(a, to, deadline) if landing else problem.step_from(a, ds,
                                                                                 deadline)
            classes = pad_classes(a) or pad_classes(b)
            if (float(b.tangent @ a.tangent) < MIN_COSINE
                    and _piece(b, classes) == _piece(a, classes)):
                reason = "the tangent turned by more than 60 degrees"
                raise ConvergenceError(reason, reason=reason)
        except ConvergenceError as exc:
            failed = True
            if ds > min_step:
                # halved down to min_step, which is tried itself
                ds = max(0.5 * ds, min_step)
                continue
            restart = end_of_branch(problem, walk, a, exc.reason, ds, settings, deadline)
            if restart is None:
                return
            walk.points.append(restart)
            bar.update()
            ds = max(min_step, min(settings.step, 0.1 * max_step))
            continue
        if not lo_period < b.period < hi_period:
            walk.stop = Stop(f"the period left [{lo_period:.3g}, {hi_period:.3g}] s "
                              "(a period growing without bound: a homoclinic orbit?)")
            return
        passed = landing or np.sign(target - b.z[-1]) != side
        turned = any(f.kind == Kind.FOLD for f in walk.bifurcations)
        back = turned and away(b, began, to) and not away(a, began, to)
        if (passed and not landing) or back:
            try:
                b = problem.at_value(a, began if back else to, deadline)
            except ConvergenceError:
                ds *= 0.5
                continue
        found = len(walk.bifurcations)
        nxt = record_between(problem, walk, a, b, float(np.linalg.norm(b.z - a.z)),
                             settings, deadline)
        if nxt is None:
            return
        walk.points.append(nxt)
        bar.update()
        if nxt is not b:
            # the branch jumped at a border: go on from the other side's orbit
            ds = max(min_step, min(ds, settings.step))
            failed = False
            continue
        folds = [f for f in walk.bifurcations if f.kind == Kind.FOLD]
        if back or (not turned and folds and away(b, began, to)):
            walk.stop = Stop(f"the branch turned at the fold at {problem.key} = "
                              f"{folds[-1].parameter:.9g} and came back to {problem.key} = "
                              f"{began:.9g}, the other end of its window")
            return
        again = closed_on(walk.bifurcations, found)
        if again is not None:
            walk.stop = Stop(f"the branch closed on itself (an isola): it passed the fold at "
                              f"{problem.key} = {again.parameter:.9g} a second time")
            return
        bar.set_postfix_str(f"{problem.key} = {b.value:.6g}, T = {b.period:.6g} s")
        if passed:
            walk.stop = Stop(f"reached {problem.key} = {to:.9g}")
            return
        if b.iterations <= 3 and not failed:
            ds = min(ds * 1.5, max_step)
        elif b.iterations >= 7:
            ds = max(ds * 0.5, min_step)
        failed = False
    walk.stop = Stop(f"the largest number of points ({max_points}) is reached")


def away(point: Point, began: float, to: float) -> bool:
    """Whether ``point``'s key lies past ``began`` on the side away from ``to``."""
    return (point.value - began) * (to - began) < 0


def _piece(pt: Point, classes: dict[int, int] | None = None) -> tuple:
    """What one smooth piece of the flow map shares: the per-slider cyclic signatures and
    the order of all switches (of an in-phase orbit, those of the sliders its symmetry
    relates taken as one: :func:`~fivdisc.continuation.borders.order_key`; ``classes``
    default: ``pt``'s own)."""
    if classes is None:
        classes = pad_classes(pt)
    return pt.cycle.cyclic(), order_key(pt.cycle, classes)


@dataclass
class Bracket:
    """A border located by bisection on converged orbits: ``lo`` the last orbit of the
    piece, ``p_hi`` the first value of the key past it (the predictor's, along the
    tangent), ``hi`` an orbit found there if one was, ``earlier`` the orbit of the piece
    found before ``lo`` (or None)."""

    lo: Point
    p_hi: float
    hi: Point | None
    earlier: Point | None


def _bisect(problem: OrbitProblem, a: Point, s_hi: float, deadline: float,
            same: Any, hi: Point | None = None) -> Bracket:
    """Bisection on converged orbits, to :data:`LOCATE` of the key: the last orbit for
    which ``same(point)`` holds and the first value past it. Each try is a step from the
    last orbit found (``a`` at first) along its tangent, at half the arclength left to the
    first failure (``s_hi`` from ``a``)."""
    lo, earlier = a, None
    left = s_hi
    p_tol = LOCATE * max(abs(a.value), 1e-12)

    def past(base: Point, s: float) -> float:
        return base.value + s * base.tangent[-1] * problem.ps

    for _ in range(80):
        if abs(past(lo, left) - lo.value) <= p_tol or left <= 1e-14:
            break
        s = 0.5 * left
        try:
            mid = problem.step_from(lo, s, deadline)
        except (ConvergenceError, FivdiscError):
            mid = None
        if mid is not None and same(mid):
            # the arclength left, from the new point: what is left beyond it
            left = max(left - float(np.linalg.norm(mid.z - lo.z)), 0.5 * s)
            lo, earlier = mid, lo
        else:
            left, hi = s, mid
    return Bracket(lo, past(lo, left), hi, earlier)


def _jump_note(problem: OrbitProblem, lo: Point, other: Point) -> str:
    """What happens at a border where the branch jumps: the switches that change order,
    the margins involved (and their jumps), the period's jump."""
    flips = order_changes(lo.cycle, other.cycle)
    pads = set()
    for line in flips:
        pads.update(int(w) for w in line.replace("'s", " ").split() if w.isdigit())
    tests = []
    for pt in (lo, other):
        try:
            for t in switch_tests(problem, pt):
                if ((t.kind == "margin" and t.key[2] in pads and t.key[1][1] in pads)
                        or t.kind == "cascade"):
                    tests.append(t.text)
        except FivdiscError:
            pass
    text = "switches of different pads change order: " + ("; ".join(flips) or "(none seen)")
    if tests:
        text += " [" + "; ".join(dict.fromkeys(tests)) + "]"
    return (f"{text}; the flow map jumps there: the period jumps from {lo.period:.10g} to "
            f"{other.period:.10g} s ({other.period - lo.period:+.3e} s), and the branch goes "
            f"on from the other side's orbit ({other.verdict}, {other.symmetry or 'no symmetry'})")


def record_between(problem: OrbitProblem, walk: Walk, a: Point, b: Point, s_ab: float,
                   settings: ContinuationSettings, deadline: float) -> Point | None:
    """Locate and record the bifurcations between consecutive points ``a`` and ``b``; the
    point the branch goes on from (``b``, or where it jumps at a border the other side's
    orbit), or None where it ends at a border between them (``walk.stop`` says so)."""
    index = len(walk.points) - 1
    if a.cycle.cyclic() != b.cycle.cyclic():
        try:
            lo, hi = locate(problem, a, b, s_ab, Kind.SIGNATURE_CHANGE, deadline)
        except ConvergenceError:
            lo, hi = a, b
        walk.bifurcations.append(bifurcation_record(problem, Kind.SIGNATURE_CHANGE, lo, hi, index))
        return b
    classes = pad_classes(a) or pad_classes(b)
    if _piece(a, classes) != _piece(b, classes):
        piece = _piece(a, classes)
        br = _bisect(problem, a, s_ab, deadline, lambda pt: _piece(pt, classes) == piece, b)
        lo, hi, p_hi = br.lo, br.hi, br.p_hi
        width = abs(p_hi - lo.value) / problem.ps
        if hi is not None and float(np.linalg.norm(hi.z - lo.z)) <= 10.0 * width + 1e-9:
            bif = bifurcation_record(problem, Kind.SWITCHING_ORDER, lo, hi, index)
            bif.note = ("switches of different pads change order, the flow map continuous "
                        "there (its derivative jumps): " + "; ".join(order_changes(lo.cycle,
                                                                                   hi.cycle)))
            walk.bifurcations.append(bif)
            return b
        return _across(problem, walk, br, index, settings, deadline, "the corrector")
    for kind in smooth_kinds(a, b):
        try:
            found = located(problem, a, b, s_ab, kind, deadline)
        except (ConvergenceError, ValueError):
            found = [(a, b)]
        walk.bifurcations.extend(bifurcation_record(problem, kind, lo, hi, index, sides=(a, b))
                                 for lo, hi in found)
    return b


def _across(problem: OrbitProblem, walk: Walk, br: Bracket, index: int,
            settings: ContinuationSettings, deadline: float, found_by: str) -> Point | None:
    """At a border where the flow map jumps (``br``): the other side's orbit near the last
    orbit's, recorded as a discontinuity and returned, or the end of the branch (recorded
    and confirmed; None). The last orbit of the piece joins the branch."""
    lo, hi, p_hi = br.lo, br.hi, br.p_hi
    if lo is not walk.points[-1]:
        walk.points.append(lo)
        index = len(walk.points) - 1
    other = None
    if hi is not None and _near(problem, lo, hi):
        other = hi
    else:
        for cand in other_piece(problem, lo, p_hi):
            if not _near_state(problem, lo, cand[0], cand[1]):
                continue
            x, period, phases, residual = cand
            try:
                x, phases = problem.anchored(x, period, p_hi, phases)
                pt = problem.point_at(x, period, p_hi, phases, float(np.sign(lo.tangent[-1])),
                                      along=lo.tangent, residual=residual)
            except (ConvergenceError, FivdiscError):
                continue
            if (_piece(pt, pad_classes(lo)) != _piece(lo)
                    and not (pt.residual > POLISH * problem.tol and close_switches(pt.cycle))):
                other = pt
                break
    if other is not None:
        bif = Bifurcation(kind=Kind.DISCONTINUITY, parameter=0.5 * (lo.value + p_hi),
                          period=lo.period, state=lo.x.copy(), before=lo.multipliers,
                          after=other.multipliers, signature_before=lo.cycle.signature,
                          signature_after=other.cycle.signature, point=index,
                          note=_jump_note(problem, lo, other), period_after=other.period,
                          phases=lo.phases.copy())
        walk.bifurcations.append(bif)
        if other is hi:
            # re-made in the current layout as a first point, oriented as lo
            x, phases = problem.anchored(hi.x, hi.period, hi.value, hi.phases, hi.cycle)
            other = problem.point_at(x, hi.period, hi.value, phases,
                                     float(np.sign(lo.tangent[-1])), along=lo.tangent,
                                     residual=hi.residual)
        return other
    return _end(problem, walk, br, index, settings, deadline,
                f"{found_by} found no orbit of the branch past it")


def _near(problem: OrbitProblem, lo: Point, other: Point) -> bool:
    """Whether ``other`` (an orbit past a border, its point found from ``lo``'s with the
    phase condition) lies within :data:`OTHER_PIECE` of ``lo``'s orbit."""
    return _near_state(problem, lo, other.x, other.period)


def _near_state(problem: OrbitProblem, lo: Point, x: np.ndarray, period: float) -> bool:
    if abs(period / lo.period - 1.0) > OTHER_PIECE:
        return False
    sc = problem.scale
    size = float(np.linalg.norm(lo.shot.rate_start / sc) * lo.period)
    return float(np.linalg.norm((x - lo.x) / sc)) / size < OTHER_PIECE


def end_of_branch(problem: OrbitProblem, walk: Walk, a: Point, reason: str, ds: float,
                  settings: ContinuationSettings, deadline: float) -> Point | None:
    """The corrector failed at the smallest step from ``a``: locate where the branch ends
    (bisection on converged orbits of ``a``'s piece), and there either jump to the other
    side's orbit (returned) or end the branch (None, ``walk.stop`` set)."""
    index = len(walk.points) - 1
    classes = pad_classes(a)
    piece = _piece(a, classes)
    br = _bisect(problem, a, ds, deadline, lambda pt: _piece(pt, classes) == piece)
    if br.earlier is None and len(walk.points) > 1:
        br.earlier = walk.points[-2]
    lo, hi = br.lo, br.hi
    if hi is not None and hi.cycle.cyclic() != lo.cycle.cyclic() and _near(problem, lo, hi):
        # past the border the corrector finds the orbit with another signature: the
        # branch goes on through the signature change
        if lo is not walk.points[-1]:
            walk.points.append(lo)
            index += 1
        walk.bifurcations.append(bifurcation_record(problem, Kind.SIGNATURE_CHANGE, lo, hi,
                                                    index))
        x, phases = problem.anchored(hi.x, hi.period, hi.value, hi.phases, hi.cycle)
        return problem.point_at(x, hi.period, hi.value, phases,
                                float(np.sign(lo.tangent[-1])), along=lo.tangent)
    return _across(problem, walk, br, index, settings, deadline,
                   f"the corrector ({reason}, the step halved to {ds:.1e})")


def _predicted(signature: tuple[str, ...], test) -> tuple[str, ...]:
    """The per-slider signature past a border named by a dip or a phase test."""
    out = list(signature)
    kind = test.key[0]
    if kind == "dip":
        j, phase = test.key[1], test.key[2]
        if phase == "stick":
            out[j] = out[j].replace("stick", "stick > slip+ > stick", 1)
        else:
            out[j] = out[j].replace("slip+", "slip+ > stick > slip+", 1)
    return tuple(out)


def _end(problem: OrbitProblem, walk: Walk, br: Bracket, index: int,
         settings: ContinuationSettings, deadline: float, why: str) -> Point | None:
    """The branch ends at ``br.lo`` (the first value past it ``br.p_hi``): the border
    named by the test function that vanishes there, confirmed by a forward run past it;
    a forward run that finds the branch's own orbit again goes on from it (returned)."""
    lo, p_hi = br.lo, br.p_hi
    earlier = br.earlier
    classes = pad_classes(lo)
    if (earlier is None or _piece(earlier, classes) != _piece(lo)
            or earlier.value == lo.value):
        earlier = None
        for pt in reversed(walk.points):
            if pt is not lo and _piece(pt, classes) == _piece(lo) and pt.value != lo.value:
                earlier = pt
                break
    ahead = None
    if earlier is not None:
        try:
            ahead = border_ahead(problem, lo, earlier, p_hi)
        except FivdiscError:
            ahead = None
    if ahead is None:
        # No test function extrapolates to zero there: the one nearest zero at the last
        # orbit, if it is (the orbit sits next to a border it has partly crossed).
        try:
            near = [t for t in switch_tests(problem, lo)
                    if t.kind in ("gap", "margin", "cascade") and 0 <= t.gone < NEAR_ZERO]
        except FivdiscError:
            near = []
        if near:
            test = min(near, key=lambda t: t.gone)
            releases = ((test.kind == "margin" and test.key[1][0] == "slip")
                        or (test.kind == "gap" and test.key[1][0] == test.key[2][0] == "slip"))
            if releases:
                # a stuck pad just short of releasing with another, or just after it:
                # their cascade
                test = Test("cascade", test.key, -test.value, test.jump, test.text)
            ahead = Ahead(test, lo.value, test)
    at = 0.5 * (lo.value + p_hi)
    key = problem.key
    fwd = None
    if settings.confirm_periods > 0:
        direction = np.sign(p_hi - lo.value) or np.sign(lo.tangent[-1]) or 1.0
        past = at + direction * PAST * max(abs(at), problem.ps * 1e-3)
        try:
            fwd = forward_run(problem, lo, past, settings.confirm_periods)
        except (ConvergenceError, FivdiscError) as exc:
            walk.checks.append(f"no forward run past {key} = {at:.9g}: {exc}")
        if fwd is not None:
            walk.checks.append(fwd.text)
            if same_piece(problem, lo, fwd):
                restart = other_piece_at(problem, lo, fwd)
                if restart is not None:
                    walk.bifurcations.append(Bifurcation(
                        kind=Kind.GAP, parameter=at, period=lo.period, state=lo.x.copy(),
                        before=lo.multipliers, after=restart.multipliers,
                        signature_before=lo.cycle.signature,
                        signature_after=restart.cycle.signature, point=index,
                        note=f"{why}, but {fwd.text}: the same orbit; the branch goes on "
                        "from it", period_after=restart.period, phases=lo.phases.copy()))
                    return restart
    confirm = f"; {fwd.text}" if fwd is not None else ""
    sig_after = lo.cycle.signature
    if ahead is not None and ahead.test.kind in ("margin", "gap"):
        kind = Kind.DISCONTINUITY_END
        jump = ahead.test.jump
        what = (f"{ahead.test.text}: it reaches zero at {key} = {ahead.at:.9g}, where the "
                "switches of different pads change order"
                + (f" and the flow map jumps (a relief of {jump:.3g} at the switch)"
                   if np.isfinite(jump) and jump > 0 else ""))
        stop = f"the orbit does not persist past the discontinuity at {key} = {at:.9g}"
    elif slip_margin(problem, lo) < GRAZING:
        walk.bifurcations.append(grazing(problem, lo, index))
        walk.bifurcations[-1].note += confirm
        walk.stop = Stop(f"the orbit grazes the stick boundary at {key} = {lo.value:.9g} and "
                         f"does not persist past it{confirm}")
        return None
    elif ahead is not None and ahead.test.kind == "cascade":
        kind = Kind.CASCADE_END
        what = (f"{ahead.test.text}: it reaches zero at {key} = {ahead.at:.9g}, where the "
                "load turns into a relief and the pads no longer switch together"
                if ahead.at != lo.value else
                f"{ahead.test.text}: next to zero at the last orbit, where the pads cease to "
                "switch together")
        stop = (f"the orbit does not persist past the end of its release cascade at {key} = "
                f"{at:.9g}")
    elif ahead is not None:
        sig_after = _predicted(lo.cycle.signature, ahead.test)
        # A dip reaching zero: inside a stick phase a split, inside a slip a grazing.
        kind = {"stick": Kind.STICK_SPLIT, "slip": Kind.GRAZING}.get(
            ahead.test.key[2] if ahead.test.key[0] == "dip" else "", Kind.SIGNATURE_CHANGE)
        what = (f"{ahead.test.text}: it reaches zero at {key} = {ahead.at:.9g}, where a phase "
                "appears or vanishes" + (f" ({TOUCHES[kind]})" if kind in TOUCHES else ""))
        stop = f"the orbit does not persist past the {kind} at {key} = {at:.9g}"
    else:
        walk.bifurcations.append(Bifurcation(
            kind=Kind.END, parameter=at, period=lo.period, state=lo.x.copy(),
            before=lo.multipliers, after=lo.multipliers, signature_before=lo.cycle.signature,
            signature_after=lo.cycle.signature, point=index,
            note=f"{why}; no test function of the orbit vanishes there{confirm}",
            phases=lo.phases.copy()))
        walk.stop = Stop(f"the orbit is lost at {key} = {lo.value:.9g}: {why}{confirm}",
                         lost=True)
        return None
    walk.bifurcations.append(Bifurcation(
        kind=kind, parameter=at, period=lo.period, state=lo.x.copy(), before=lo.multipliers,
        after=lo.multipliers, signature_before=lo.cycle.signature, signature_after=sig_after,
        point=index, note=f"{what}; {why}{confirm}", phases=lo.phases.copy()))
    walk.stop = Stop(f"{stop}{confirm}")
    return None


def other_piece_at(problem: OrbitProblem, lo: Point, fwd) -> Point | None:
    """The orbit a settled forward run found, as a branch point (Newton at its value)."""
    from fivdisc.analysis.orbits import Shooting, newton_shooting

    shooting = Shooting(problem.model(fwd.value), fwd.phases, problem.rtol, problem.atol,
                        problem.scale)
    try:
        sol = newton_shooting(shooting, fwd.state, fwd.period, problem.tol, 20, math.inf)
        if sol.reason:
            return None
        x, phases = problem.anchored(shooting.held(sol.x0), sol.period, fwd.value,
                                     fwd.phases)
        return problem.point_at(x, sol.period, fwd.value, phases,
                                float(np.sign(lo.tangent[-1])), along=lo.tangent,
                                residual=sol.residual)
    except (ConvergenceError, FivdiscError):
        return None
