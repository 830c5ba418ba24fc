"""Bifurcations between consecutive points of a branch: their test functions, their
location along the arclength, and their records."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fivdisc.analysis.cycle import Cycle
from fivdisc.analysis.kinds import BifurcationKind as Kind
from fivdisc.analysis.symmetry import RESONANT, classify_reduced, isotypic
from fivdisc.continuation.problem import OrbitProblem, Point
from fivdisc.continuation.settings import LOCATE, REAL


@dataclass
class Bifurcation:
    """A bifurcation located on a branch.

    Attributes
    ----------
    kind : str
        ``"fold"``, ``"period doubling"``, ``"torus"``, ``"branch point"`` (a real
        multiplier through +1 without a fold), ``"symmetry breaking"`` (a multiplier
        crossing whose eigenvector breaks the orbit's symmetry: see
        :mod:`fivdisc.analysis.symmetry`), the discontinuity-induced ones:
        ``"signature change"`` (a phase of a slider appears or vanishes),
        ``"switching order"`` (switches of different sliders change order, the flow map
        continuous), ``"discontinuity"`` (they change order and the flow map jumps: the
        branch jumps with it to the orbit of the other side), and the ends:
        ``"discontinuity end"`` and ``"cascade end"`` (the flow map jumps and no orbit
        lies past the border), ``"grazing"`` (the branch ends where its slip speed
        touches zero, at its last point), ``"end"`` (the branch is lost there, no border
        found), and ``"gap"`` (the corrector could not follow, a forward run found the
        orbit again past it).
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
    period_after : float
        Where the branch jumps: the period on the other side [s]; else nan.
    phases : ndarray of int
        Each slider's phase at ``state``.
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
    period_after: float = math.nan
    phases: np.ndarray | None = None


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
    if kind == Kind.PERIOD_DOUBLING:
        return complex(others[np.argmin(np.abs(others + 1.0))])
    cplx = others[np.abs(others.imag) > REAL * np.abs(others)]
    return complex(cplx[np.argmin(np.abs(np.abs(cplx) - 1.0))]) if cplx.size else 0j


def test_value(pt: Point, kind: str) -> float:
    if kind == Kind.FOLD:
        return float(pt.tangent[-1])
    if kind == Kind.PERIOD_DOUBLING:
        return float(nearest_multiplier(pt.multipliers, pt.trivial, kind).real + 1.0)
    if kind == Kind.BRANCH_POINT:
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
    if kind == Kind.PERIOD_DOUBLING:
        return others[real & (others.real < 0)]
    if kind == Kind.TORUS:
        return others[~real & (others.imag > 0)]
    return others[real & (others.real > 0)]


def passage(mu: complex, kind: str) -> float:
    """One multiplier's test function: zero where it passes -1, the unit circle or +1."""
    if kind == Kind.PERIOD_DOUBLING:
        return mu.real + 1.0
    if kind == Kind.TORUS:
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
        kinds.append(Kind.FOLD)
    oa, ob = outside_counts(a.multipliers, a.trivial), outside_counts(b.multipliers, b.trivial)
    if oa[1] != ob[1]:
        kinds.append(Kind.PERIOD_DOUBLING)
    if oa[2] != ob[2]:
        kinds.append(Kind.TORUS)
    if oa[0] != ob[0] and Kind.FOLD not in kinds:
        kinds.append(Kind.BRANCH_POINT)
    return kinds


def located(problem: OrbitProblem, a: Point, b: Point, s_ab: float, kind: str,
             deadline: float, depth: int = 0) -> list[tuple[Point, Point]]:
    """Each bifurcation of smooth ``kind`` between ``a`` and ``b``, located. Where several
    multipliers pass in one interval (two pairs leaving the unit circle close together)
    the interval is halved until each holds one, and each passage is followed by its own
    multiplier: the multiplier nearest the circle jumps from one pair to the other
    between them, and a root search on it would find the jump."""
    if kind == Kind.FOLD:
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

    p_tol = LOCATE * max(abs(a.value), 1e-12) / problem.ps
    if kind == Kind.SIGNATURE_CHANGE:
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
    the passing multiplier shows), else of ``lo`` and ``hi``. A smooth one on a symmetric
    orbit is classified by its critical eigenvector's symmetry (:func:`symmetric_kind`)."""
    before, after = sides if sides is not None else (lo, hi)
    at = hi if kind == Kind.SIGNATURE_CHANGE else lo
    rotation = math.nan
    note = ""
    if kind == Kind.TORUS:
        pair = nearest_multiplier(at.multipliers, at.trivial, kind)
        rotation = abs(math.atan2(pair.imag, pair.real)) / (2 * math.pi)
        note = f"a complex pair crosses the unit circle, rotation number {rotation:.6f}"
    elif kind == Kind.PERIOD_DOUBLING:
        note = "a real multiplier crosses -1: an orbit of twice the period branches off"
    elif kind == Kind.FOLD:
        note = "the branch turns back in the parameter (fold of cycles)"
    elif kind == Kind.BRANCH_POINT:
        note = "a real multiplier crosses +1 without a fold"
    else:
        sides_ = [f"slider {j}: {u} -> {v}" for j, (u, v) in
                  enumerate(zip(lo.cycle.signature, hi.cycle.signature, strict=True)) if u != v]
        note = "the event signature changes (" + "; ".join(sides_) + ")"
        kind, what = discontinuity_kind(lo.cycle, hi.cycle)
        if what:
            note = f"{what}: {note}"
    if kind in (Kind.TORUS, Kind.PERIOD_DOUBLING, Kind.BRANCH_POINT):
        found = symmetric_kind(kind, at, before, after)
        if found is not None:
            new_kind, extra = found
            if new_kind != kind:
                kind, note = new_kind, extra
            else:
                note = f"{note}; {extra}"
    return Bifurcation(kind=kind, parameter=0.5 * (lo.value + hi.value),
                       period=0.5 * (lo.period + hi.period), state=at.x.copy(),
                       before=before.multipliers, after=after.multipliers,
                       signature_before=lo.cycle.signature, signature_after=hi.cycle.signature,
                       rotation=rotation, point=index, note=note, phases=at.phases.copy())


# What each discontinuity-induced kind means, in words.
TOUCHES = {Kind.GRAZING: "grazing of the stick boundary (the slip speed touches zero: a "
                         "stick phase appears or vanishes)",
           "flight": "grazing of the separation boundary (the normal force touches zero: a "
                     "flight appears or vanishes)",
           Kind.STICK_SPLIT: "a stick phase splits (the friction needed to stick touches "
                             "mu_s N inside it: a short slip appears or vanishes)"}
# The phase that begins at an event of each kind.
_BEGINS = {"stick": "stick", "slip": "slip", "reversal": "reversal", "separation": "flight",
           "recontact": "slip"}


def _shortest(cycle: Cycle, j: int) -> tuple[str, str]:
    """The phase of slider ``j`` shortest over ``cycle``'s period, and the phase after
    it."""
    ev = sorted((t, kind) for t, kind, slider in cycle.events if slider == j)
    if len(ev) < 2:
        return "", ""
    times = np.array([t for t, _ in ev])
    i = int(np.argmin(np.diff(np.r_[times, times[0] + cycle.period])))
    return _BEGINS[ev[i][1]], _BEGINS[ev[(i + 1) % len(ev)][1]]


def discontinuity_kind(before: Cycle, after: Cycle) -> tuple[Kind, str]:
    """The name of a change of the event signature between two orbits of a branch, and
    what it is in words: a phase appearing or vanishing in each slider that changes is
    the shortest phase of the side that has it; a stick phase or a flight is a grazing
    (of the stick or of the separation boundary), a slip between two sticks a stick
    split; any other change (a slip reversal, phases exchanged) a signature change."""
    found = set()
    for j, (u, v) in enumerate(zip(before.cyclic(), after.cyclic(), strict=True)):
        if u == v:
            continue
        nu, nv = len(u.split(" > ")), len(v.split(" > "))
        if nu == nv:
            return Kind.SIGNATURE_CHANGE, ""
        phase, following = _shortest(after if nv > nu else before, j)
        if phase == "slip" and following == "stick":
            found.add(Kind.STICK_SPLIT)
        elif phase in ("stick", "flight"):
            found.add(Kind.GRAZING if phase == "stick" else "flight")
        else:
            return Kind.SIGNATURE_CHANGE, ""
    if len(found) != 1:
        return Kind.SIGNATURE_CHANGE, ""
    what = found.pop()
    return (Kind.GRAZING if what == "flight" else what), TOUCHES[what]


def _reduced_crossings(a: Point, b: Point) -> list[tuple[complex, complex]]:
    """The eigenvalues of the reduced map R (flow direction's left out) that cross the
    unit circle between ``a`` and ``b``, as their values at each (matched by nearness)."""
    from scipy.optimize import linear_sum_assignment

    def others(mu: np.ndarray) -> np.ndarray:
        return np.delete(mu, np.argmin(np.abs(mu - 1.0)))

    ra, rb = others(a.reduced), others(b.reduced)
    rows, cols = linear_sum_assignment(np.abs(ra[:, None] - rb[None, :]))
    return [(complex(ra[i]), complex(rb[j])) for i, j in zip(rows, cols, strict=True)
            if (abs(ra[i]) - 1.0) * (abs(rb[j]) - 1.0) < 0 and ra[i].imag >= -1e-12]


def symmetric_kind(kind: str, at: Point, before: Point, after: Point
                   ) -> tuple[str, str] | None:
    """What a smooth bifurcation of a symmetric orbit is: ``(Kind.SYMMETRY_BREAKING,
    note)`` when its critical eigenvector breaks the orbit's symmetry (on the reduced map
    of a spatio-temporal symmetry, a crossing at the angle ``2 pi m / k``, ``m != 0``, or
    near it: :func:`fivdisc.analysis.symmetry.classify_reduced`; on an in-phase orbit, an
    eigenvector in a non-trivial eigenspace of ``P``), ``(kind, note)`` with what the
    symmetry says of it otherwise, None for an orbit without symmetry."""
    if (before.reduced is not None and after.reduced is not None
            and before.k == after.k > 1):
        k = before.k
        passing = _reduced_crossings(before, after)
        for mu_a, mu_b in passing:
            mu = 0.5 * (mu_a + mu_b)
            found = classify_reduced(mu, k)
            if found is not None:
                return found.kind, f"{found.note} ({at.symmetry} on both sides)"
        if passing:
            mu = 0.5 * (passing[0][0] + passing[0][1])
            theta = abs(math.atan2(mu.imag, mu.real)) / (2 * math.pi)
            m = round(theta * k)
            where = (f" ({m}/{k} {'+' if theta >= m / k else '-'} {abs(theta - m / k):.3g}: "
                     f"outside the {RESONANT:g}-turn window of the {m}:{k} resonance)"
                     if m % k else "")
            return kind, (f"the orbit keeps its symmetry ({at.symmetry}): the T/{k} map's "
                          f"multiplier crosses at the angle 2 pi x {theta:.6f}{where}")
    if at.sym is not None and at.sym.spatial:
        mult, vecs = np.linalg.eig(at.shot.monodromy)
        crit = nearest_multiplier(at.multipliers, at.trivial, kind) if kind != Kind.BRANCH_POINT \
            else 1.0 + 0j
        i = int(np.argmin(np.abs(mult - crit)))
        for el in at.sym.spatial:
            m = isotypic(vecs[:, i], el)
            if m != 0:
                forced = " (the symmetry makes it a double multiplier)" if el.order > 2 else ""
                return (Kind.SYMMETRY_BREAKING,
                        f"the critical multiplier {mult[i]:.6f}{forced} has an eigenvector "
                        f"that the {el.label} does not map to itself (the orbit is "
                        f"{at.symmetry}): orbits without that symmetry branch off")
        return kind, f"the orbit keeps its symmetry ({at.symmetry})"
    return None


def without_fold_echoes(found: list[Bifurcation]) -> list[Bifurcation]:
    """``found`` without the branch points next to a fold.

    At a fold the critical multiplier passes +1 where the parameter turns; the two test
    functions (the multiplier, the tangent's parameter component) are different
    quantities, so where the fold lies within their errors of a point of the branch the
    passage may be counted in the interval beside the turn. A fold is that passage; it
    is not reported twice."""
    folds = [b.point for b in found if b.kind == Kind.FOLD]
    return [b for b in found
            if not (b.kind == Kind.BRANCH_POINT and any(abs(b.point - f) <= 1 for f in folds))]


def closed_on(found: list[Bifurcation], new: int) -> Bifurcation | None:
    """An earlier fold that one of ``found[new:]`` repeats (the same parameter and period
    to 1e-5, ten times the location's accuracy), else None: the branch is a closed curve
    and has come round."""
    for b in found[new:]:
        if b.kind != Kind.FOLD:
            continue
        for earlier in found[:new]:
            if (earlier.kind == Kind.FOLD
                    and abs(earlier.parameter - b.parameter) <= 1e-5 * abs(b.parameter)
                    and abs(earlier.period - b.period) <= 1e-5 * b.period):
                return earlier
    return None


def slip_margin(problem: OrbitProblem, a: Point) -> float:
    """The smallest slip speed ``|Omega - phidot|`` over ``a``'s orbit, relative to the
    disc speed, over the sliders that slip throughout (infinite if none does: a lost
    stick-slip orbit has not grazed)."""
    p = a.value
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
    period, p = a.period, a.value
    return Bifurcation(kind=Kind.GRAZING, parameter=p, period=period, state=a.x.copy(),
                       before=a.multipliers, after=a.multipliers,
                       signature_before=a.cycle.signature, signature_after=a.cycle.signature,
                       point=index,
                       note=f"the slip speed touches zero (smallest {slip_margin(problem, a):.1e}"
                       " of the disc speed): a stick phase appears and the slipping orbits "
                       "end (the stick-slip orbits leave from here)")
