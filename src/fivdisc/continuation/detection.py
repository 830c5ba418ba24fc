"""Bifurcations between consecutive points of a branch: their test functions, their
location along the arclength, and their records."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from fivdisc.analysis.cycle import Cycle, one_period
from fivdisc.continuation.problem import OrbitProblem, Point
from fivdisc.continuation.settings import LOCATE, REAL
from fivdisc.errors import ConvergenceError, FivdiscError


@dataclass
class Bifurcation:
    """A bifurcation located on a branch.

    Attributes
    ----------
    kind : str
        ``"fold"``, ``"period doubling"``, ``"torus"``, ``"branch point"`` (a real
        multiplier through +1 without a fold), ``"signature change"``
        (discontinuity-induced) or ``"grazing"`` (the branch ends where its slip speed
        touches zero, at its last point).
    parameter : float
        The key's value there [its unit].
    period : float
        The orbit's period there [s].
    state : ndarray
        The orbit's point there.
    before, after : ndarray of complex
        Floquet multipliers on either side: of the branch's points either side for a
        smooth bifurcation (the passing multiplier is inside the circle on one side and
        outside on the other), of the two sides of the bracket for a signature change.
    signature_before, signature_after : tuple of str
        Event signatures on either side.
    rotation : float
        For a torus: the critical pair's angle / 2 pi [-]; else nan.
    point : int
        Index of the branch point before it.
    note : str
        What happens there in words.
    """

    kind: str
    parameter: float
    period: float
    state: np.ndarray
    before: np.ndarray
    after: np.ndarray
    signature_before: tuple[str, ...]
    signature_after: tuple[str, ...]
    rotation: float = math.nan
    point: int = 0
    note: str = ""


def outside_counts(mult: np.ndarray, trivial: int) -> tuple[int, int, int]:
    """Numbers of multipliers (flow direction left out) outside the unit circle: real
    positive, real negative, complex."""
    others = np.delete(mult, trivial)
    out = others[np.abs(others) > 1.0]
    real = np.abs(out.imag) <= REAL * np.abs(out)
    return (int(np.sum(real & (out.real > 0))), int(np.sum(real & (out.real < 0))),
            int(np.sum(~real)))


def nearest_multiplier(mult: np.ndarray, trivial: int, kind: str) -> complex:
    others = np.delete(mult, trivial)
    if kind == "period doubling":
        return complex(others[np.argmin(np.abs(others + 1.0))])
    cplx = others[np.abs(others.imag) > REAL * np.abs(others)]
    return complex(cplx[np.argmin(np.abs(np.abs(cplx) - 1.0))]) if cplx.size else 0j


def test_value(pt: Point, kind: str) -> float:
    if kind == "fold":
        return float(pt.tangent[-1])
    if kind == "period doubling":
        return float(nearest_multiplier(pt.multipliers, pt.trivial, kind).real + 1.0)
    if kind == "branch point":
        others = np.delete(pt.multipliers, pt.trivial)
        real = others[np.abs(others.imag) <= REAL * np.abs(others)]
        return float(real.real[np.argmin(np.abs(real.real - 1.0))] - 1.0) if real.size else 1.0
    return float(abs(nearest_multiplier(pt.multipliers, pt.trivial, kind)) - 1.0)


def multipliers_of_kind(pt: Point, kind: str) -> np.ndarray:
    """``pt``'s multipliers (flow direction left out) of the class whose passage makes
    ``kind``: real negative (period doubling), complex with a positive imaginary part
    (torus; one of each pair), real positive (branch point)."""
    others = np.delete(pt.multipliers, pt.trivial)
    real = np.abs(others.imag) <= REAL * np.abs(others)
    if kind == "period doubling":
        return others[real & (others.real < 0)]
    if kind == "torus":
        return others[~real & (others.imag > 0)]
    return others[real & (others.real > 0)]


def passage(mu: complex, kind: str) -> float:
    """One multiplier's test function: zero where it passes -1, the unit circle or +1."""
    if kind == "period doubling":
        return mu.real + 1.0
    if kind == "torus":
        return abs(mu) - 1.0
    return mu.real - 1.0


def crossings(a: Point, b: Point, kind: str) -> list[tuple[complex, complex]]:
    """The multipliers of ``kind``'s class that pass between ``a`` and ``b``, each as its
    values at ``a`` and at ``b`` (matched by nearness)."""
    from scipy.optimize import linear_sum_assignment

    at_a, at_b = multipliers_of_kind(a, kind), multipliers_of_kind(b, kind)
    rows, cols = linear_sum_assignment(np.abs(at_a[:, None] - at_b[None, :]))
    return [(complex(at_a[i]), complex(at_b[j])) for i, j in zip(rows, cols, strict=True)
            if passage(at_a[i], kind) * passage(at_b[j], kind) < 0]


def smooth_kinds(a: Point, b: Point) -> list[str]:
    kinds = []
    if a.tangent[-1] * b.tangent[-1] < 0:
        kinds.append("fold")
    oa, ob = outside_counts(a.multipliers, a.trivial), outside_counts(b.multipliers, b.trivial)
    if oa[1] != ob[1]:
        kinds.append("period doubling")
    if oa[2] != ob[2]:
        kinds.append("torus")
    if oa[0] != ob[0] and "fold" not in kinds:
        kinds.append("branch point")
    return kinds


def located(problem: OrbitProblem, a: Point, b: Point, s_ab: float, kind: str,
             deadline: float, depth: int = 0) -> list[tuple[Point, Point]]:
    """Each bifurcation of smooth ``kind`` between ``a`` and ``b``, located. Where several
    multipliers pass in one interval (two pairs leaving the unit circle close together)
    the interval is halved until each holds one, and each passage is followed by its own
    multiplier: the multiplier nearest the circle jumps from one pair to the other
    between them, and a root search on it would find the jump."""
    if kind == "fold":
        return [locate(problem, a, b, s_ab, kind, deadline)]
    passing = crossings(a, b, kind)
    if not passing:
        # No multiplier of the class passes: the count changed because a pair outside
        # the circle became two real ones (next to a fold) or the reverse, which is no
        # bifurcation of this kind.
        return []
    if len(passing) == 1 or depth == 6:
        # each followed by its own multiplier (still together after six halvings: the
        # straight-line guesses tell them apart)
        return [locate(problem, a, b, s_ab, kind, deadline, track) for track in passing]
    mid = problem.step_from(a, 0.5 * s_ab, deadline)
    return [found for lo, hi in ((a, mid), (mid, b))
            for found in located(problem, lo, hi, float(np.linalg.norm(hi.z - lo.z)), kind,
                                  deadline, depth + 1)]


def locate(problem: OrbitProblem, a: Point, b: Point, s_ab: float, kind: str,
            deadline: float, track: tuple[complex, complex] | None = None
            ) -> tuple[Point, Point]:
    """The bifurcation of ``kind`` between ``a`` and ``b`` (arclength ``s_ab`` apart):
    the located point, or for a signature change the two points bracketing it. With
    ``track`` (the passing multiplier at ``a`` and at ``b``), the test function is that
    multiplier's, followed from its straight-line guess."""
    from scipy.optimize import brentq

    p_tol = LOCATE * max(abs(problem.unpack(a.z)[2]), 1e-12) / problem.ps
    if kind == "signature change":
        lo, hi, s_lo, s_hi = a, b, 0.0, s_ab
        key = a.cycle.cyclic()
        while abs(hi.z[-1] - lo.z[-1]) > p_tol and s_hi - s_lo > 1e-12:
            s = 0.5 * (s_lo + s_hi)
            mid = problem.step_from(a, s, deadline)
            if mid.cycle.cyclic() == key:
                lo, s_lo = mid, s
            else:
                hi, s_hi = mid, s
        return lo, hi
    memo: dict[float, Point] = {0.0: a, s_ab: b}

    def value(s: float) -> float:
        if s not in memo:
            memo[s] = problem.step_from(a, s, deadline)
        near = multipliers_of_kind(memo[s], kind) if track is not None else np.zeros(0)
        if near.size == 0:
            return test_value(memo[s], kind)
        guess = track[0] + (track[1] - track[0]) * s / s_ab
        return passage(complex(near[np.argmin(np.abs(near - guess))]), kind)

    # |dp/ds| <= 1 in the scaled unknowns, so s to p_tol gives p to p_tol.
    s = brentq(value, 0.0, s_ab, xtol=p_tol, rtol=4 * np.finfo(float).eps)
    value(s)
    return memo[s], memo[s]


def bifurcation_record(problem: OrbitProblem, kind: str, lo: Point, hi: Point, index: int,
                 sides: tuple[Point, Point] | None = None) -> Bifurcation:
    """The record of a bifurcation located at ``lo`` (a smooth one, ``hi`` the same) or
    between ``lo`` and ``hi`` (a signature change). Its multipliers before and after are
    those of ``sides`` if given (the branch's points either side of a smooth one, where
    the passing multiplier shows), else of ``lo`` and ``hi``."""
    before, after = sides if sides is not None else (lo, hi)
    _, t_lo, p_lo = problem.unpack(lo.z)
    _, t_hi, p_hi = problem.unpack(hi.z)
    at = hi if kind == "signature change" else lo
    rotation = math.nan
    note = ""
    if kind == "torus":
        pair = nearest_multiplier(at.multipliers, at.trivial, kind)
        rotation = abs(math.atan2(pair.imag, pair.real)) / (2 * math.pi)
        note = f"a complex pair crosses the unit circle, rotation number {rotation:.6f}"
    elif kind == "period doubling":
        note = "a real multiplier crosses -1: an orbit of twice the period branches off"
    elif kind == "fold":
        note = "the branch turns back in the parameter (fold of cycles)"
    elif kind == "branch point":
        note = "a real multiplier crosses +1 without a fold"
    else:
        sides = [f"slider {j}: {u} -> {v}" for j, (u, v) in
                 enumerate(zip(lo.cycle.signature, hi.cycle.signature, strict=True)) if u != v]
        note = "the event signature changes (" + "; ".join(sides) + ")"
    return Bifurcation(kind=kind, parameter=0.5 * (p_lo + p_hi), period=0.5 * (t_lo + t_hi),
                       state=at.x.copy(), before=before.multipliers, after=after.multipliers,
                       signature_before=lo.cycle.signature, signature_after=hi.cycle.signature,
                       rotation=rotation, point=index, note=note)


def without_fold_echoes(found: list[Bifurcation]) -> list[Bifurcation]:
    """``found`` without the branch points next to a fold.

    At a fold the critical multiplier passes +1 where the parameter turns; the two test
    functions (the multiplier, the tangent's parameter component) are different
    quantities, so where the fold lies within their errors of a point of the branch the
    passage may be counted in the interval beside the turn. A fold is that passage; it
    is not reported twice."""
    folds = [b.point for b in found if b.kind == "fold"]
    return [b for b in found
            if not (b.kind == "branch point" and any(abs(b.point - f) <= 1 for f in folds))]


def closed_on(found: list[Bifurcation], new: int) -> Bifurcation | None:
    """An earlier fold that one of ``found[new:]`` repeats (the same parameter and period
    to 1e-5, ten times the location's accuracy), else None: the branch is a closed curve
    and has come round."""
    for b in found[new:]:
        if b.kind != "fold":
            continue
        for earlier in found[:new]:
            if (earlier.kind == "fold"
                    and abs(earlier.parameter - b.parameter) <= 1e-5 * abs(b.parameter)
                    and abs(earlier.period - b.period) <= 1e-5 * b.period):
                return earlier
    return None


def slip_margin(problem: OrbitProblem, a: Point) -> float:
    """The smallest slip speed ``|Omega - phidot|`` over ``a``'s orbit, relative to the
    disc speed, over the sliders that slip throughout (infinite if none does: a lost
    stick-slip orbit has not grazed)."""
    _, _, p = problem.unpack(a.z)
    speed = p if problem.key == "speed.value" else problem.case.speed.value
    speed = abs(speed)
    margins = []
    for j, sig in enumerate(a.cycle.signature):
        if sig.startswith("slip") and "stick" not in sig:
            hi = a.cycle.measures["phi_dot_max"][j]
            lo = a.cycle.measures["phi_dot_min"][j]
            margins.append(min(abs(speed - hi), abs(speed - lo)))
    return min(margins) / speed if margins and speed > 0 else np.inf


def grazing(problem: OrbitProblem, a: Point, index: int) -> Bifurcation:
    """The end of a branch of slipping orbits lost where its slip speed touches zero."""
    _, period, p = problem.unpack(a.z)
    return Bifurcation(kind="grazing", parameter=p, period=period, state=a.x.copy(),
                       before=a.multipliers, after=a.multipliers,
                       signature_before=a.cycle.signature, signature_after=a.cycle.signature,
                       point=index,
                       note=f"the slip speed touches zero (smallest {slip_margin(problem, a):.1e}"
                       " of the disc speed): a stick phase appears and the slipping orbits "
                       "end (the stick-slip orbits leave from here)")


def vanishing(problem: OrbitProblem, a: Point, index: int) -> Bifurcation | None:
    """Where the branch is lost just after ``a``: if the flow from ``a``'s point changes
    its event signature within a relative change of the key of 1e-3 ahead, the orbit
    ends at that change (the flow map jumps there, as where a stick phase splits). It is
    bracketed with ``a``'s point held, then located to 1e-6 by bisection on the orbits
    themselves: the last value at which the corrector finds the orbit with ``a``'s
    signature. None if the signature does not change."""
    x, period, p = problem.unpack(a.z)
    ahead = np.sign(a.tangent[-1]) or 1.0
    key = a.cycle.cyclic()
    scale = max(abs(p), problem.ps * 1e-3)

    def cycle(q: float) -> Cycle:
        return one_period(problem.model(q), x, problem.shooting.phases, period, problem.rtol,
                          problem.atol)

    lo, hi, far = p, None, None
    for k in range(11):
        q = p + ahead * scale * 1e-6 * 2.0**k
        try:
            c = cycle(q)
        except FivdiscError:
            continue
        if c.cyclic() != key:
            hi, far = q, c
            break
        lo = q
    if hi is None:
        return None
    # Refined on the orbits themselves: the last value at which the corrector still finds
    # the orbit with its signature, the flow from that orbit's point changing its
    # signature at the upper end of the bracket (where the corrector fails short of the
    # change, the held point decides).
    deadline = time.monotonic() + 600.0
    last, lo = a, p

    def beyond(q: float) -> Cycle | None:
        x_last, period_last, _ = problem.unpack(last.z)
        c = one_period(problem.model(q), x_last, problem.shooting.phases, period_last,
                       problem.rtol, problem.atol)
        return c if c.cyclic() != key else None

    far = beyond(hi)
    if far is None:
        return None
    while abs(hi - lo) > LOCATE * scale:
        mid = 0.5 * (lo + hi)
        try:
            pt = problem.at_value(last, mid, deadline)
        except ConvergenceError:
            pt = None
        if pt is not None and pt.cycle.cyclic() == key:
            last, lo = pt, mid
            far = beyond(hi) or far
            continue
        changed = beyond(mid)
        if changed is not None:
            hi, far = mid, changed
        else:
            lo = mid
    x, period, _ = problem.unpack(last.z)
    shot = problem.shooter(hi).shoot(x, period)
    after, _ = problem.shooting.stability(shot)
    sides = [f"slider {j}: {u} -> {v}" for j, (u, v) in
             enumerate(zip(last.cycle.signature, far.signature, strict=True)) if u != v]
    return Bifurcation(kind="signature change", parameter=0.5 * (lo + hi), period=period,
                       state=x.copy(), before=last.multipliers, after=after,
                       signature_before=last.cycle.signature, signature_after=far.signature,
                       point=index,
                       note="the event signature changes (" + "; ".join(sides) + ") and the "
                       "orbit does not persist past it (multipliers after: of the flow map "
                       "from the last orbit's point)")
