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
* discontinuity-induced: the event signature (:mod:`fivdisc.analysis.cycle`) changes;
  the multipliers on either side are reported, since they may jump there.
* grazing: a branch of slipping orbits lost where its slip speed touches zero ends
  there (the stick-slip orbits turn back from it).

A branch may also start at a Hopf point of the equilibrium
(:func:`fivdisc.continuation.from_hopf.hopf_cycles`): the first point is corrected with its
amplitude along the critical eigenvector held and the parameter free.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fivdisc.analysis.orbits import (
    PeriodicOrbit,
    periodic_orbit,
)
from fivdisc.case import Case
from fivdisc.continuation.branch import Branch
from fivdisc.continuation.checks import check_search, check_target, check_window, full_key
from fivdisc.continuation.detection import (
    Bifurcation,
    bifurcation_record,
    closed_on,
    grazing,
    locate,
    located,
    slip_margin,
    smooth_kinds,
    vanishing,
    without_fold_echoes,
)
from fivdisc.continuation.problem import OrbitProblem, Point
from fivdisc.continuation.settings import GRAZING, INTERRUPTED, MIN_COSINE, ContinuationSettings
from fivdisc.continuation.starts import start_point
from fivdisc.errors import ConvergenceError

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
    grows by 1.5, after 7 or more it halves; a refused or failed step is halved, and a
    step below ``min_step`` ends the branch as lost.

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
    began = problem.unpack(walk.points[0].z)[2] if back_to is None else back_to
    lo_period, hi_period = problem.period0 / 100.0, problem.period0 * 100.0
    while len(walk.points) < max_points:
        a = walk.points[-1]
        if time.monotonic() > deadline:
            walk.stop = Stop("the time budget ran out")
            return
        # A predictor past the target goes to the target itself: beyond it the key may
        # leave its allowed range (a damping continued to zero).
        landing = np.sign(target - (a.z[-1] + ds * a.tangent[-1])) != side
        try:
            b = problem.at_value(a, to, deadline) if landing else problem.step_from(a, ds,
                                                                                 deadline)
            if float(b.tangent @ a.tangent) < MIN_COSINE:
                reason = "the tangent turned by more than 60 degrees"
                raise ConvergenceError(reason, reason=reason)
        except ConvergenceError as exc:
            ds *= 0.5
            if ds < min_step:
                _, _, p = problem.unpack(a.z)
                end = vanishing(problem, a, len(walk.points) - 1)
                if end is None and slip_margin(problem, a) < GRAZING:
                    walk.bifurcations.append(grazing(problem, a, len(walk.points) - 1))
                    walk.stop = Stop(f"the orbit grazes the stick boundary at {problem.key} "
                                      f"= {p:.9g} and does not persist past it")
                elif end is None:
                    walk.stop = Stop(f"the orbit is lost at {problem.key} = {p:.9g}: "
                                      f"{exc.reason}", lost=True)
                else:
                    walk.bifurcations.append(end)
                    walk.stop = Stop(f"the orbit does not persist past the signature change "
                                      f"at {problem.key} = {end.parameter:.9g}")
                return
            continue
        _, period, _ = problem.unpack(b.z)
        if not lo_period < period < hi_period:
            walk.stop = Stop(f"the period left [{lo_period:.3g}, {hi_period:.3g}] s "
                              "(a period growing without bound: a homoclinic orbit?)")
            return
        passed = landing or np.sign(target - b.z[-1]) != side
        turned = any(f.kind == "fold" for f in walk.bifurcations)
        back = turned and away(problem, b, began, to) and not away(problem, a, began, to)
        if (passed and not landing) or back:
            try:
                b = problem.at_value(a, began if back else to, deadline)
            except ConvergenceError:
                ds *= 0.5
                continue
        found = len(walk.bifurcations)
        record_between(problem, walk, a, b, float(np.linalg.norm(b.z - a.z)), deadline)
        walk.points.append(b)
        folds = [f for f in walk.bifurcations if f.kind == "fold"]
        if back or (not turned and folds and away(problem, b, began, to)):
            walk.stop = Stop(f"the branch turned at the fold at {problem.key} = "
                              f"{folds[-1].parameter:.9g} and came back to {problem.key} = "
                              f"{began:.9g}, the other end of its window")
            bar.update()
            return
        again = closed_on(walk.bifurcations, found)
        if again is not None:
            walk.stop = Stop(f"the branch closed on itself (an isola): it passed the fold at "
                              f"{problem.key} = {again.parameter:.9g} a second time")
            return
        bar.update()
        _, _, p = problem.unpack(b.z)
        bar.set_postfix_str(f"{problem.key} = {p:.6g}, T = {period:.6g} s")
        if passed:
            walk.stop = Stop(f"reached {problem.key} = {to:.9g}")
            return
        if b.iterations <= 3:
            ds = min(ds * 1.5, max_step)
        elif b.iterations >= 7:
            ds = max(ds * 0.5, min_step)
    walk.stop = Stop(f"the largest number of points ({max_points}) is reached")


def away(problem: OrbitProblem, point: Point, began: float, to: float) -> bool:
    """Whether ``point``'s key lies past ``began`` on the side away from ``to``."""
    return (problem.unpack(point.z)[2] - began) * (to - began) < 0


def record_between(problem: OrbitProblem, walk: Walk, a: Point, b: Point, s_ab: float,
            deadline: float) -> None:
    """Locate and record the bifurcations between consecutive points ``a`` and ``b``."""
    index = len(walk.points) - 1
    if a.cycle.cyclic() != b.cycle.cyclic():
        try:
            lo, hi = locate(problem, a, b, s_ab, "signature change", deadline)
        except ConvergenceError:
            lo, hi = a, b
        walk.bifurcations.append(bifurcation_record(problem, "signature change", lo, hi, index))
        return
    for kind in smooth_kinds(a, b):
        try:
            found = located(problem, a, b, s_ab, kind, deadline)
        except (ConvergenceError, ValueError):
            found = [(a, b)]
        walk.bifurcations.extend(bifurcation_record(problem, kind, lo, hi, index, sides=(a, b))
                                 for lo, hi in found)
