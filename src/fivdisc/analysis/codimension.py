"""Every Hopf curve of the sliding equilibrium in a box of two keys, and the
codimension-two points on them.

:func:`~fivdisc.analysis.boundary.stability_boundary` traces where the largest growth
rate vanishes: the outer boundary of stability. A designer asking where squeal can start
needs more: every eigenvalue pair's own zero-growth curve (a pair may cross the axis
inside the unstable region and matter once a damper removes the first), and the points
where the kind of the instability changes along them:

- **Bautin** (generalised Hopf): the first Lyapunov coefficient ``l1``
  (:mod:`fivdisc.analysis.normalform`) vanishes; on one side the Hopf point is
  supercritical (vibration grows gently from zero), on the other subcritical (a
  threshold around stable sliding: where squeal can start though every eigenvalue is
  stable). A curve of folds of cycles starts there.
- **double Hopf**: two pairs on the imaginary axis at once (two Hopf curves cross).
- **zero-Hopf**: a real eigenvalue passes zero on a Hopf curve (the equilibrium folds).
- **existence**: the curve ends where the sliding equilibrium ceases to exist (a
  slider's normal force reaches zero).

Each pair's curve is traced as the zero set of the real part of that eigenvalue, followed
by continuity: from points where it changes sign on the edges of a grid of seeds, a secant
predictor steps along the curve and Brent's method finds the zero on the normal line
through the predicted point, taking at each trial the eigenvalue nearest to the one
extrapolated along the curve. Codimension-two points are bracketed between neighbouring
points of a curve by a change of sign of their test function (``l1``; another pair's
growth rate; a real eigenvalue; the smallest normal force) and located by Brent's method
along the chord, each trial point corrected onto the curve.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from fivdisc.analysis.boundary import zero_curves
from fivdisc.analysis.normalform import first_lyapunov
from fivdisc.analysis.points import ParameterPoints, box_of
from fivdisc.analysis.stability import mode_labels
from fivdisc.case import Case

__all__ = ["hopf_curve_lines", "hopf_curves"]

# Tolerance of every root in the box scaled to the unit square: the growth rate is known
# to ~1e-13 of the eigenvalues, and the codimension-two points are promised to 1e-6 of
# the keys; 1e-11 of the box leaves room for boxes 1e5 wide.
_XTOL = 1e-11
# Shortest step [unit box] before a curve is given up.
_MIN_STEP = 1e-6
# An eigenvalue found at a corrected point must lie closer to the one predicted along
# the curve than this fraction of its distance to any other eigenvalue.
_SEPARATION = 0.25
# Deepest halving of a seed edge to follow the eigenvalues along it unambiguously.
_EDGE_DEPTH = 6
KINDS = ("bautin", "double_hopf", "zero_hopf", "existence")


@dataclass
class _Solve:
    """The equilibrium and the eigenvalues at one point of the unit box."""

    u: np.ndarray
    model: object
    state: np.ndarray
    jac: np.ndarray
    lam: np.ndarray
    force: float  # smallest normal force [N] (the slip equations' solution, any sign)

    @property
    def upper(self) -> np.ndarray:
        """Indices of the eigenvalues with a positive imaginary part (one per pair)."""
        return np.flatnonzero(self.lam.imag > 0.0)

    def near(self, target: complex) -> int:
        """Index of the eigenvalue of a pair nearest to `target`."""
        up = self.upper
        return int(up[np.argmin(np.abs(self.lam[up] - target))])

    def separated(self, i: int, target: complex) -> bool:
        """Whether eigenvalue i is the clear continuation of `target`."""
        others = np.delete(self.lam, i)
        if others.size == 0:
            return True
        gap = float(np.min(np.abs(others - self.lam[i])))
        return abs(self.lam[i] - target) < _SEPARATION * gap


class _Box:
    """Equilibria and eigenvalues at points of the unit box, counted."""

    def __init__(self, points: ParameterPoints, lo: np.ndarray, span: np.ndarray) -> None:
        self.points, self.lo, self.span = points, lo, span
        self.calls = 0
        self.guess = None

    def values(self, u: np.ndarray) -> tuple[float, float]:
        return tuple(float(v) for v in self.lo + self.span * np.asarray(u))

    def solve(self, u: np.ndarray, fresh: bool = False) -> _Solve | None:
        """The slip equations' solution (with any sign of the normal forces) and its
        eigenvalues at u; None where there is none. ``fresh``: from the rigid-disc guess
        only, not from the last solution."""
        from fivdisc.analysis.points import slip_jacobian
        from fivdisc.engine.equilibrium import sliding_equilibrium
        from fivdisc.errors import SimulationError

        self.calls += 1
        model = self.points.model(self.values(u))
        eq = None
        # From the last solution, else from the rigid-disc guess (a last solution far
        # away, across a critical speed, may lead nowhere).
        guesses = [None] if fresh or self.guess is None else [self.guess, None]
        for guess in guesses:
            try:
                eq = sliding_equilibrium(model, guess=guess, contact=False)
                break
            except SimulationError:
                continue
        if eq is None:
            return None
        if not fresh:
            self.guess = eq
        jac = slip_jacobian(model, eq.state)
        lam = np.linalg.eigvals(jac)
        return _Solve(np.array(u, dtype=float), model, eq.state, jac, lam,
                      float(np.min(eq.normal_force)))

    def growth(self, u: np.ndarray, target: complex) -> tuple[float, _Solve | None, int]:
        """Real part of the eigenvalue nearest `target` at u (nan without a solution)."""
        s = self.solve(u)
        if s is None or s.upper.size == 0:
            return math.nan, s, -1
        i = s.near(target)
        return float(s.lam[i].real), s, i


def _brent(f, a: float, b: float, fa: float, fb: float, xtol: float) -> float:
    from scipy.optimize import brentq

    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    return float(brentq(f, a, b, xtol=xtol, rtol=1e-15))


def _zero_on_segment(box: _Box, a: np.ndarray, b: np.ndarray, lam_a: complex,
                     lam_b: complex) -> tuple[np.ndarray, _Solve, int] | None:
    """The zero of the growth rate of the pair that goes from lam_a at a to lam_b at b
    (their real parts of opposite signs) on the segment a-b."""
    length = float(np.linalg.norm(b - a))

    def g(t: float) -> float:
        value, _, _ = box.growth(a + t * (b - a), lam_a + t * (lam_b - lam_a))
        if math.isnan(value):
            raise _Lost
        return value

    try:
        ga, gb = g(0.0), g(1.0)
        if (ga < 0.0) == (gb < 0.0):
            # Solved again, an end fell on another solution of the slip equations.
            return None
        t = _brent(g, 0.0, 1.0, ga, gb, _XTOL / max(length, 1e-300))
    except _Lost:
        return None
    u = a + t * (b - a)
    _, s, i = box.growth(u, lam_a + t * (lam_b - lam_a))
    if s is None or i < 0:
        return None
    return u, s, i


def _assign(lam_a: np.ndarray, lam_b: np.ndarray) -> tuple[np.ndarray, bool]:
    """Which eigenvalue of lam_b continues each of lam_a (-1: none), and whether every
    match is clear (nearer than a fraction of the distance to the others)."""
    from scipy.optimize import linear_sum_assignment

    out = np.full(lam_a.size, -1)
    if lam_a.size == 0 or lam_b.size == 0:
        return out, lam_a.size == lam_b.size
    cost = np.abs(lam_a[:, None] - lam_b[None, :])
    rows, cols = linear_sum_assignment(cost)
    out[rows] = cols
    clear = lam_a.size == lam_b.size
    for r, c in zip(rows, cols, strict=True):
        others = np.delete(cost[r], c)
        if others.size and cost[r, c] >= _SEPARATION * float(np.min(others)):
            clear = False
    return out, clear


def _chain(box: _Box, sa: _Solve, sb: _Solve, depth: int = 0) -> list[_Solve]:
    """Solves from sa to sb close enough that the pairs' eigenvalues follow clearly
    from one to the next (halving the segment up to _EDGE_DEPTH times)."""
    _, clear = _assign(sa.lam[sa.upper], sb.lam[sb.upper])
    if clear or depth >= _EDGE_DEPTH:
        return [sa, sb]
    mid = box.solve(0.5 * (sa.u + sb.u))
    if mid is None:
        return [sa, sb]
    return _chain(box, sa, mid, depth + 1)[:-1] + _chain(box, mid, sb, depth + 1)


@dataclass
class _Seed:
    u: np.ndarray
    lam: complex
    gap: float = math.inf  # distance from lam to the nearest other eigenvalue there


def _seeds(box: _Box, m: int) -> tuple[list[_Seed], list[list[_Solve | None]]]:
    """Zeros of every pair's growth rate on the edges of an m x m grid."""
    grid = np.linspace(0.0, 1.0, m)
    solves = [[box.solve(np.array([x, y])) for x in grid] for y in grid]
    seeds: list[_Seed] = []
    for iy, ix in itertools.product(range(m), range(m)):
        for dx, dy in ((1, 0), (0, 1)):
            jx, jy = ix + dx, iy + dy
            if jx >= m or jy >= m:
                continue
            sa, sb = solves[iy][ix], solves[jy][jx]
            if sa is None or sb is None or (sa.force <= 0.0 and sb.force <= 0.0):
                continue
            chain = _chain(box, sa, sb)
            for p, q in itertools.pairwise(chain):
                up_p, up_q = p.upper, q.upper
                match, _ = _assign(p.lam[up_p], q.lam[up_q])
                for k, j in enumerate(match):
                    if j < 0:
                        continue
                    la, lb = p.lam[up_p[k]], q.lam[up_q[j]]
                    if (la.real < 0.0) == (lb.real < 0.0):
                        continue
                    found = _zero_on_segment(box, p.u, q.u, la, lb)
                    if found is None:
                        continue
                    u, s, i = found
                    if s.force > 0.0:
                        others = np.delete(s.lam, i)
                        gap = float(np.min(np.abs(others - s.lam[i]))) if others.size \
                            else math.inf
                        seeds.append(_Seed(u, complex(s.lam[i]), gap))
    return seeds, solves


@dataclass
class _Point:
    u: np.ndarray
    lam: complex
    solve: _Solve


@dataclass
class _Curve:
    points: list[_Point]
    start: str
    end: str
    closed: bool = False
    notes: list[str] = field(default_factory=list)


def _track(box: _Box, sa: _Solve, ia: int, sb: _Solve, depth: int = 0) -> int:
    """Index in sb of the pair that continues sa's eigenvalue ia along the segment
    between them: the nearest, halving the segment while another is almost as near."""
    up = sb.upper
    if up.size == 0:
        return -1
    d = np.abs(sb.lam[up] - sa.lam[ia])
    order = np.argsort(d)
    if up.size == 1 or d[order[0]] < _SEPARATION * d[order[1]] or depth >= _EDGE_DEPTH:
        return int(up[order[0]])
    mid = box.solve(0.5 * (sa.u + sb.u))
    if mid is None or mid.upper.size == 0:
        return int(up[order[0]])
    return _track(box, mid, _track(box, sa, ia, mid, depth + 1), sb, depth + 1)


def _correct(box: _Box, pred: np.ndarray, normal: np.ndarray, width: float,
             target: complex) -> _Point | None:
    """The zero of the growth rate of the pair predicted as `target` at `pred`, on the
    normal line through `pred` within +-width; None if it does not change sign there, is
    lost, or the eigenvalue found is not clearly that pair.

    The pair is followed from `pred` to both ends of the bracket (halving where another
    pair comes near: identical sliders have pairs a fraction of a hertz apart), and at
    each trial of the root finder it is the eigenvalue nearest to its interpolation
    between the bracket's ends and `pred`."""
    sp = box.solve(pred)
    if sp is None or sp.upper.size == 0:
        return None
    ip = sp.near(target)
    if not sp.separated(ip, target):
        return None
    a, b = pred - width * normal, pred + width * normal
    ends = []
    for u in (a, b):
        s = box.solve(u)
        if s is None:
            return None
        i = _track(box, sp, ip, s)
        if i < 0:
            return None
        ends.append(complex(s.lam[i]))
    lam_a, lam_p, lam_b = ends[0], complex(sp.lam[ip]), ends[1]
    if (lam_a.real < 0) == (lam_b.real < 0):
        return None

    def expected(t: float) -> complex:
        return (lam_a + 2 * t * (lam_p - lam_a) if t <= 0.5
                else lam_p + (2 * t - 1) * (lam_b - lam_p))

    def g(t: float) -> float:
        value, _, _ = box.growth(a + t * (b - a), expected(t))
        if math.isnan(value):
            raise _Lost
        return value

    try:
        t = _brent(g, 0.0, 1.0, g(0.0), g(1.0), _XTOL / max(2.0 * width, 1e-300))
    except (_Lost, ValueError):
        return None
    u = a + t * (b - a)
    _, s, i = box.growth(u, expected(t))
    if s is None or i < 0 or not s.separated(i, expected(t)):
        return None
    return _Point(u, complex(s.lam[i]), s)


def _inside(u: np.ndarray) -> bool:
    return bool(np.all(u >= -1e-12) and np.all(u <= 1.0 + 1e-12))


def _trace(box: _Box, start: _Point, direction: np.ndarray, step: float
           ) -> tuple[list[_Point], str]:
    """Points from `start` along its pair's curve, first along `direction`, until it
    leaves the box (``"edge"``), comes back to the start (``"closed"``), reaches the
    limit of the equilibrium's existence (``"existence"``, its last point there) or is
    lost (``"lost: ..."``)."""
    path = [start]
    tangent = direction / np.linalg.norm(direction)
    h = step
    while len(path) < 100000:
        p = path[-1]
        normal = np.array([-tangent[1], tangent[0]])
        pred = p.u + h * tangent
        # The eigenvalue extrapolated along the curve (its real part stays 0).
        if len(path) > 1:
            prev = path[-2]
            ds = max(float(np.linalg.norm(p.u - prev.u)), 1e-300)
            target = p.lam + (p.lam - prev.lam) * (h / ds)
        else:
            target = p.lam
        new = None
        for width in (0.125 * h, h):
            new = _correct(box, pred, normal, width, complex(target))
            if new is not None:
                break
        if new is None:
            h *= 0.5
            if h < _MIN_STEP:
                if box.solve(pred) is None:
                    # The slip equations have no solution just ahead: the equilibrium
                    # ends there (its deflection diverges at a critical speed, or it
                    # folds).
                    return path, "existence"
                return path, "lost: the pair's growth rate no longer changes sign across " \
                             "the predicted point (the pair may have become real)"
            continue
        if not _inside(new.u):
            path.append(_exit(box, p, new, h))
            return path, "edge"
        if new.solve.force <= 0.0:
            path.append(_locate(box, p, new, lambda q: q.solve.force))
            return path, "existence"
        if len(path) > 2 and np.linalg.norm(new.u - start.u) < h:
            path += [new, start]
            return path, "closed"
        tangent = (new.u - p.u) / np.linalg.norm(new.u - p.u)
        path.append(new)
        h = min(1.5 * h, step)
    return path, "lost: too many points"


def _exit(box: _Box, p: _Point, new: _Point, h: float) -> _Point:
    """Where the curve leaves the box between p (inside) and new (outside): its zero on
    the crossed edge, the pair followed as in :func:`_correct`."""
    d = new.u - p.u
    t = min(((1.0 if d[k] > 0 else 0.0) - p.u[k]) / d[k] for k in range(2)
            if d[k] != 0 and not 0.0 <= new.u[k] <= 1.0)
    end = np.clip(p.u + t * d, 0.0, 1.0)
    # Along the edge: the coordinate that is not at 0 or 1.
    k = 1 if 0.0 < end[1] < 1.0 else 0
    along = np.zeros(2)
    along[k] = 1.0
    width = min(h, end[k], 1.0 - end[k])
    target = p.lam + t * (new.lam - p.lam)
    if width > 0.0:
        for w in (0.125 * width, width):
            point = _correct(box, end, along, w, complex(target))
            if point is not None:
                return point
    return p


def _on_chord(box: _Box, a: _Point, b: _Point, s: float) -> _Point | None:
    """The point of the curve on the normal through ``a + s (b - a)``."""
    chord = b.u - a.u
    length = float(np.linalg.norm(chord))
    normal = np.array([-chord[1], chord[0]]) / max(length, 1e-300)
    target = a.lam + s * (b.lam - a.lam)
    for width in (0.25 * length, length):
        point = _correct(box, a.u + s * chord, normal, max(width, 1e-9), complex(target))
        if point is not None:
            return point
    return None


def _locate(box: _Box, a: _Point, b: _Point, test) -> _Point:
    """The point of the curve between a and b where ``test(point)`` (of opposite signs
    at a and b) vanishes, by Brent's method along the chord."""
    cache: dict[float, _Point] = {0.0: a, 1.0: b}

    def f(s: float) -> float:
        point = cache.get(s) or _on_chord(box, a, b, s)
        if point is None:
            raise _Lost
        cache[s] = point
        return float(test(point))

    length = float(np.linalg.norm(b.u - a.u))
    try:
        s = _brent(f, 0.0, 1.0, f(0.0), f(1.0), _XTOL / max(length, 1e-300))
    except (_Lost, ValueError):
        return a
    return cache.get(s) or _on_chord(box, a, b, s) or a


class _Lost(Exception):
    """A trial point of a location could not be corrected onto the curve."""


def _trace_seed(box: _Box, seed: _Seed, step: float) -> _Curve | None:
    s = box.solve(seed.u)
    if s is None:
        return None
    start = _Point(seed.u, seed.lam, s)
    e = 1e-6
    grad = []
    for d in (np.array([1.0, 0.0]), np.array([0.0, 1.0])):
        gp, _, _ = box.growth(seed.u + e * d, seed.lam)
        gm, _, _ = box.growth(seed.u - e * d, seed.lam)
        grad.append((gp - gm) / (2 * e))
    grad = np.array(grad)
    if not np.all(np.isfinite(grad)) or not np.any(grad):
        return None
    along = np.array([-grad[1], grad[0]])
    path, end = _trace(box, start, along, step)
    if end == "closed":
        return _Curve(path, "closed", "closed", closed=True)
    backward, begin = _trace(box, start, -along, step)
    return _Curve(backward[::-1] + path[1:], begin, end)


def _covers(curve: _Curve, seed: _Seed, tol: float = 1e-3) -> bool:
    """Whether the seed lies on the traced curve: within `tol` of the box from it, its
    eigenvalue nearer to the curve's (interpolated there) than a quarter of its distance
    to the other eigenvalues at the seed."""
    u = np.array([p.u for p in curve.points])
    lam = np.array([p.lam for p in curve.points])
    for k in range(len(u) - 1):
        d = u[k + 1] - u[k]
        length2 = float(d @ d)
        t = 0.0 if length2 == 0 else min(max(float((seed.u - u[k]) @ d) / length2, 0.0), 1.0)
        if np.linalg.norm(seed.u - (u[k] + t * d)) < tol:
            here = lam[k] + t * (lam[k + 1] - lam[k])
            if abs(here - seed.lam) < _SEPARATION * min(seed.gap, 1e300):
                return True
    return False


def _follows_to(box: _Box, curve: _Curve, seed: _Seed, step: float) -> bool:
    """Whether the seed lies on the traced curve where the chords miss it: a seed lies on
    the exact curve, the chords off it by up to their sagitta, which near a sharp bend
    exceeds :func:`_covers`' tolerance (a Hopf curve of C02 was traced twice). Within a
    step of the curve's nearest point, the curve's eigenvalue is followed along the line
    to the seed in steps of 1e-3 of the box (each time the eigenvalue nearest the last:
    the pad modes' eigenvalues, 0.1 Hz apart, move far less per step) and must arrive at
    the seed's own."""
    u = np.array([p.u for p in curve.points])
    dist = np.linalg.norm(u - seed.u, axis=1)
    k = int(np.argmin(dist))
    if dist[k] >= step:
        return False
    lam = curve.points[k].lam
    n = max(2, math.ceil(dist[k] / 1e-3))
    for t in np.linspace(0.0, 1.0, n + 1)[1:]:
        s = box.solve(u[k] + t * (seed.u - u[k]))
        if s is None:
            return False
        lam = complex(s.lam[int(np.argmin(np.abs(s.lam - lam)))])
    return abs(lam - seed.lam) <= 1e-9 * abs(seed.lam)


@dataclass
class _Special:
    kind: str
    point: _Point
    curve: int
    other: complex = complex(math.nan, math.nan)
    note: str = ""


def _l1(point: _Point) -> tuple[float, float]:
    s = point.solve
    res = first_lyapunov(s.model, s.state, point.lam.imag, s.jac)
    return res.value, res.error


def _specials(box: _Box, curve: _Curve, index: int, l1s: list[tuple[float, float]]
              ) -> list[_Special]:
    """The codimension-two points between neighbouring points of one curve."""
    found = []
    pts = curve.points
    for k in range(len(pts) - 1):
        a, b = pts[k], pts[k + 1]
        if np.array_equal(a.u, b.u):
            continue
        (la, ea), (lb, eb) = l1s[k], l1s[k + 1]
        if (np.isfinite(la) and np.isfinite(lb) and abs(la) > ea and abs(lb) > eb
                and (la < 0) != (lb < 0)):
            point = _locate(box, a, b, lambda q: _l1(q)[0])
            l1, err = _l1(point)
            # A change of sign through a pole of l1 (where the slip speed's share of
            # the critical mode vanishes, as a normal force reaches zero) is no zero.
            if abs(l1) <= max(10.0 * err, 1e-6 * max(abs(la), abs(lb))):
                found.append(_Special("bautin", point, index,
                                      note=f"l1 = {l1:.3g} +- {err:.2g} s^2 there"))
        sa, sb = a.solve, b.solve
        ia, ib = sa.near(a.lam), sb.near(b.lam)
        # The other pairs, followed from a to b.
        oa = np.array([i for i in sa.upper if i != ia])
        ob = np.array([i for i in sb.upper if i != ib])
        match, _ = _assign(sa.lam[oa] if oa.size else np.array([]),
                           sb.lam[ob] if ob.size else np.array([]))
        for j, m in enumerate(match):
            if m < 0:
                continue
            pa, pb = complex(sa.lam[oa[j]]), complex(sb.lam[ob[m]])
            if (pa.real < 0.0) == (pb.real < 0.0):
                continue

            def other_growth(q: _Point, pa=pa, pb=pb, a=a, b=b) -> float:
                t = _fraction(a, b, q)
                return float(q.solve.lam[q.solve.near(pa + t * (pb - pa))].real)

            point = _locate(box, a, b, other_growth)
            t = _fraction(a, b, point)
            other = complex(point.solve.lam[point.solve.near(pa + t * (pb - pa))])
            found.append(_Special("double_hopf", point, index, other=other))
        ra, rb = np.sort(sa.lam[sa.lam.imag == 0.0].real), np.sort(sb.lam[sb.lam.imag == 0.0].real)
        if ra.size == rb.size and np.any((ra < 0.0) != (rb < 0.0)):
            j = int(np.flatnonzero((ra < 0.0) != (rb < 0.0))[0])

            def real_growth(q: _Point, ra=ra, rb=rb, j=j, a=a, b=b) -> float:
                t = _fraction(a, b, q)
                real = q.solve.lam[q.solve.lam.imag == 0.0].real
                if real.size == 0:
                    return math.nan
                return float(real[np.argmin(np.abs(real - (ra[j] + t * (rb[j] - ra[j]))))])

            point = _locate(box, a, b, real_growth)
            found.append(_Special("zero_hopf", point, index, other=complex(0.0, 0.0)))
    for end, point in ((curve.start, pts[0]), (curve.end, pts[-1])):
        if end == "existence":
            why = ("a slider's normal force reaches zero" if abs(point.solve.force) < 1e-6
                   * max(abs(pts[0].solve.force), 1.0) else "the slip equations' solution "
                   "is lost just beyond (within 1e-6 of the box; its deflection diverges "
                   "at a critical speed, or it folds)")
            found.append(_Special("existence", point, index, note=why))
    return found


def _fraction(a: _Point, b: _Point, q: _Point) -> float:
    d = b.u - a.u
    length2 = float(d @ d)
    return 0.0 if length2 == 0 else float((q.u - a.u) @ d) / length2


def hopf_curves(
    case: Case,
    x: tuple[str, tuple[float, float]],
    y: tuple[str, tuple[float, float]],
    seeds: int = 12,
    step: float = 0.02,
) -> xr.Dataset:
    """Every Hopf curve of the sliding equilibrium in a box of two keys, with the
    codimension-two points on them.

    Parameters
    ----------
    case : Case
        Base case at constant speed.
    x, y : (str, (float, float))
        Dotted case key and (start, stop) of each side of the box.
    seeds : int
        Seed lines per side (at least 2): a curve is started where a pair's growth rate
        changes sign between neighbouring seed points (the eigenvalues followed along
        each edge by continuity, halving it where that is ambiguous).
    step : float
        Largest step along a curve, as a fraction of the box's sides.

    Returns
    -------
    xarray.Dataset
        Dimension ``point`` (the curves' points, in order along each), with variables
        named after the two keys (their values), ``hopf_curve`` (which curve),
        ``frequency`` [Hz] and ``mode`` of the pair on the axis, ``l1`` and
        ``l1_error`` [s^2] (first Lyapunov coefficient: > 0 subcritical, < 0
        supercritical), ``on_boundary`` (1 where every other eigenvalue is stable: the
        outer stability boundary), ``normal_force`` [N] (the smallest); dimension
        ``curve_index`` with ``curve_mode`` (the mode most of its points have),
        ``curve_start``, ``curve_end`` (``"edge"``, ``"closed"``, ``"existence"``,
        ``"lost: ..."``); dimension ``codim2`` with ``codim2_kind`` (``"bautin"``,
        ``"double_hopf"``, ``"zero_hopf"``, ``"existence"``), ``codim2_x``,
        ``codim2_y`` (the keys' values), ``codim2_curve``, ``codim2_other_curve`` (the
        other pair's curve at a double Hopf point, -1 if not traced),
        ``codim2_frequency``, ``codim2_other_frequency`` [Hz], ``codim2_mode`` and
        ``codim2_note``; dimension ``existence_point`` with ``existence_x``,
        ``existence_y`` and ``existence_branch``: the curves where the smallest normal
        force of the slip equations' solution is zero, the limit of the equilibrium's
        existence. Attributes ``x_key``, ``y_key``, ``x_range``, ``y_range``,
        ``evaluations`` (equilibria solved) and the case.

    Raises
    ------
    CaseError
        Non-numeric or repeated keys, an empty range, an end outside a key's allowed
        values, too few seeds, or no sliding equilibrium at the box's first corner.

    See Also
    --------
    fivdisc.stability_boundary : The outer boundary only, the zero of the largest growth
        rate.
    fivdisc.hopf_points : Hopf points along one key, with their ``l1``.
    hopf_curve_lines : The curves and points as text, as the command line prints them.

    Notes
    -----
    A curve point solves ``Re lambda(x, y) = 0`` for its pair to ``1e-11`` of the box;
    a codimension-two point is the root of its test function along the curve to the same
    tolerance: ``l1`` (Bautin), the growth rate of another pair followed along the curve
    (double Hopf), a real eigenvalue (zero-Hopf), the smallest normal force
    (existence). The Bautin point's accuracy is that of ``l1`` divided by its rate of
    change along the curve. Two crossings of one seed edge by the same pair, a closed
    curve between two seed lines, or a pair whose eigenvalues cannot be told apart from
    another's within ``_EDGE_DEPTH`` halvings of a seed edge, are missed: more seeds find
    them. Where the curve's pair becomes two real eigenvalues (a Bogdanov-Takens point)
    the curve ends as ``lost``.

    Examples
    --------
    A slider on a rigid disc with the Stribeck law ``mu = mu_1 + dmu exp(-(u / v_s)^2)``
    loses stability where its rotational damping falls below ``-r^2 N0 mu'(r Omega)``;
    ``l1`` is proportional to ``-mu'''(r Omega)``, which changes sign at
    ``r Omega = v_s sqrt(3/2)``: a Bautin point at ``Omega = 12.2474487`` rad/s, damping
    ``2 r^2 N0 dmu sqrt(3/2) exp(-3/2) = 0.6831938`` N m s/rad, supercritical below it
    in speed and subcritical above:

    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []},
    ...                      friction={"law": "stribeck", "stribeck_velocity": 1.0,
    ...                                "stribeck_exponent": 2.0})
    >>> curves = fivdisc.hopf_curves(rigid, ("speed.value", (5.0, 20.0)),
    ...                              ("slider.rotational_damping", (0.3, 1.2)),
    ...                              seeds=4, step=0.05)
    >>> print(curves.sizes["curve_index"], str(curves["curve_mode"].values[0]))
    1 phi
    >>> kind, x, y = (str(curves["codim2_kind"].values[0]), curves["codim2_x"].values[0],
    ...               curves["codim2_y"].values[0])
    >>> print(f"{kind} at {x:.7f} rad/s, {y:.7f} N m s/rad")
    bautin at 12.2474487 rad/s, 0.6831938 N m s/rad
    >>> print(curves["l1"].values[0] < 0 < curves["l1"].values[-1])
    True
    """
    checked = box_of(case, x, y, seeds, step, "--hopf-curves")
    box = _Box(checked.points, checked.lo, checked.span)
    found, grid = _seeds(box, seeds)
    curves: list[_Curve] = []
    for seed in found:
        if any(_covers(c, seed) or _follows_to(box, c, seed, step) for c in curves):
            continue
        curve = _trace_seed(box, seed, step)
        if curve is not None and len(curve.points) > 1:
            curves.append(curve)
    l1s = [[_l1(p) for p in c.points] for c in curves]
    specials = [sp for i, c in enumerate(curves) for sp in _specials(box, c, i, l1s[i])]
    specials = _merge(specials, curves)
    existence = _existence_curves(box, grid, seeds, step)
    return _dataset(case, box, curves, l1s, specials, existence, checked.x, checked.y)


def _merge(specials: list[_Special], curves: list[_Curve]) -> list[_Special]:
    """A double Hopf point is found from both its curves: keep one, naming the other."""
    out: list[_Special] = []
    for sp in specials:
        if sp.kind == "double_hopf":
            twin = next((o for o in out if o.kind == "double_hopf"
                         and np.linalg.norm(o.point.u - sp.point.u) < 1e-7), None)
            if twin is not None:
                continue
        out.append(sp)
    return out


def _other_curve(sp: _Special, curves: list[_Curve]) -> int:
    """The traced curve of the other pair of a double Hopf point (-1: not traced)."""
    if sp.kind != "double_hopf":
        return -1
    gap = abs(sp.other - sp.point.lam)
    for i, c in enumerate(curves):
        if i != sp.curve and _covers(c, _Seed(sp.point.u, sp.other, gap)):
            return i
    return -1


def _existence_curves(box: _Box, grid, seeds: int, step: float) -> list[list[np.ndarray]]:
    """Where the smallest normal force is zero, if it changes sign on the seed grid."""
    forces = np.array([[s.force if s is not None else -1.0 for s in row] for row in grid])
    if forces.min() > 0.0 or forces.max() <= 0.0:
        return []

    def force(u: np.ndarray) -> float:
        # No solution of the slip equations at all counts as no equilibrium: the curve
        # then follows the edge of the solutions, as eigen_branches' limit does. Each
        # solve starts from the rigid-disc guess, so that the function is the same
        # wherever the tracer comes from.
        s = box.solve(u, fresh=True)
        return -1.0 if s is None else s.force

    return [path for path, _ in zero_curves(force, seeds, step)]


def _dataset(case: Case, box: _Box, curves: list[_Curve], l1s, specials: list[_Special],
             existence: list[list[np.ndarray]], x, y) -> xr.Dataset:
    from fivdisc.engine.conventions import global_attrs, key_attrs

    (xkey, xr_), (ykey, yr_) = x, y
    rows = []
    curve_modes = []
    for c, (curve, l1) in enumerate(zip(curves, l1s, strict=True)):
        modes = []
        for p, (value, error) in zip(curve.points, l1, strict=True):
            s = p.solve
            lam, vec = np.linalg.eig(s.jac)
            i = int(np.argmin(np.abs(lam - p.lam)))
            mode = mode_labels(s.model, lam, vec)[i]
            modes.append(mode)
            others = np.delete(lam.real, [i, int(np.argmin(np.abs(lam - np.conj(lam[i]))))])
            rows.append((*box.values(p.u), c, p.lam.imag / (2 * np.pi), mode, value, error,
                         int(np.all(others < 0.0)), s.force))
        curve_modes.append(max(set(modes), key=modes.count))
    cols = list(zip(*rows, strict=True)) if rows else [[]] * 9
    sx, sy = zip(*[box.values(sp.point.u) for sp in specials], strict=True) if specials \
        else ((), ())
    ex = [(*box.values(u), b) for b, path in enumerate(existence) for u in path]
    ecols = list(zip(*ex, strict=True)) if ex else [[]] * 3
    xa, ya = key_attrs(xkey), key_attrs(ykey)

    def special_mode(sp: _Special) -> str:
        s = sp.point.solve
        lam, vec = np.linalg.eig(s.jac)
        i = int(np.argmin(np.abs(lam - sp.point.lam)))
        return mode_labels(s.model, lam, vec)[i]

    return xr.Dataset(
        {
            xkey: (("point",), np.array(cols[0], dtype=float), xa),
            ykey: (("point",), np.array(cols[1], dtype=float), ya),
            "hopf_curve": (("point",), np.array(cols[2], dtype=np.int64),
                           {"units": "1", "long_name": "which Hopf curve"}),
            "frequency": (("point",), np.array(cols[3], dtype=float), {
                "units": "Hz", "long_name": "frequency of the pair on the imaginary axis"}),
            "mode": (("point",), np.array(cols[4], dtype=str), {
                "long_name": "coordinate with most of the critical mode's kinetic energy"}),
            "l1": (("point",), np.array(cols[5], dtype=float), {
                "units": "s2", "long_name": "first Lyapunov coefficient per (rad/s)^2 of "
                                            "slip-speed amplitude (> 0: subcritical, < 0: "
                                            "supercritical)"}),
            "l1_error": (("point",), np.array(cols[6], dtype=float), {
                "units": "s2", "long_name": "estimated error of l1"}),
            "on_boundary": (("point",), np.array(cols[7], dtype=np.int8), {
                "units": "1", "long_name": "every other eigenvalue stable: the outer "
                                           "stability boundary",
                "flag_values": np.array([0, 1], dtype=np.int8),
                "flag_meanings": "inside_unstable_region on_stability_boundary"}),
            "normal_force": (("point",), np.array(cols[8], dtype=float), {
                "units": "N", "long_name": "smallest normal force at the equilibrium"}),
            "curve_mode": (("curve_index",), np.array(curve_modes, dtype=str), {
                "long_name": "mode of most of the curve's points"}),
            "curve_start": (("curve_index",), np.array([c.start for c in curves], dtype=str),
                            {"long_name": "how the curve starts (edge, closed, existence, "
                                          "lost)"}),
            "curve_end": (("curve_index",), np.array([c.end for c in curves], dtype=str),
                          {"long_name": "how the curve ends (edge, closed, existence, "
                                        "lost)"}),
            "codim2_kind": (("codim2",), np.array([sp.kind for sp in specials], dtype=str), {
                "long_name": "codimension-two point: bautin (l1 = 0), double_hopf (two pairs "
                             "on the axis), zero_hopf (a real eigenvalue zero), existence "
                             "(the equilibrium ceases to exist)"}),
            "codim2_x": (("codim2",), np.array(sx, dtype=float),
                         {**xa, "long_name": f"{xa['long_name']} at the point"}),
            "codim2_y": (("codim2",), np.array(sy, dtype=float),
                         {**ya, "long_name": f"{ya['long_name']} at the point"}),
            "codim2_curve": (("codim2",), np.array([sp.curve for sp in specials],
                                                   dtype=np.int64),
                             {"units": "1", "long_name": "the Hopf curve it lies on"}),
            "codim2_other_curve": (("codim2",), np.array(
                [_other_curve(sp, curves) for sp in specials], dtype=np.int64), {
                "units": "1", "long_name": "the other pair's Hopf curve at a double Hopf "
                                           "point (-1: none or not traced)"}),
            "codim2_frequency": (("codim2",), np.array(
                [sp.point.lam.imag / (2 * np.pi) for sp in specials], dtype=float),
                {"units": "Hz", "long_name": "frequency of the curve's pair"}),
            "codim2_other_frequency": (("codim2",), np.array(
                [sp.other.imag / (2 * np.pi) for sp in specials], dtype=float),
                {"units": "Hz", "long_name": "frequency of the other critical eigenvalue "
                                             "(double Hopf: the other pair; zero-Hopf: 0)"}),
            "codim2_mode": (("codim2",), np.array([special_mode(sp) for sp in specials],
                                                  dtype=str),
                            {"long_name": "mode of the curve's pair there"}),
            "codim2_note": (("codim2",), np.array([sp.note for sp in specials], dtype=str),
                            {"long_name": "what else is known there"}),
            "existence_x": (("existence_point",), np.array(ecols[0], dtype=float),
                            {**xa, "long_name": f"{xa['long_name']} where the smallest "
                                                "normal force is zero"}),
            "existence_y": (("existence_point",), np.array(ecols[1], dtype=float),
                            {**ya, "long_name": f"{ya['long_name']} where the smallest "
                                                "normal force is zero"}),
            "existence_branch": (("existence_point",), np.array(ecols[2], dtype=np.int64),
                                 {"units": "1", "long_name": "which existence curve"}),
        },
        attrs={**global_attrs(f"fivdisc Hopf curves over {xkey} and {ykey}",
                              "fivdisc.analysis.hopf_curves"),
               "fivdisc_kind": "hopf_curves", "x_key": xkey, "y_key": ykey,
               "x_range": np.asarray(xr_, dtype=float), "y_range": np.asarray(yr_, dtype=float),
               "evaluations": box.calls, "case": case.to_toml()},
    )


def hopf_curve_lines(ds: xr.Dataset) -> list[str]:
    """What a dataset of :func:`hopf_curves` holds, as lines of text: per curve its mode,
    frequencies, ends and sub- and supercritical parts; per codimension-two point its
    kind and where (``fivdisc stability --hopf-curves`` prints them).

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`hopf_curves` (or its file).

    Returns
    -------
    list of str
    """
    xkey, ykey = ds.attrs["x_key"], ds.attrs["y_key"]
    lines = []
    if ds.sizes["curve_index"] == 0:
        lines.append("no Hopf curve in the box: no eigenvalue pair crosses the imaginary "
                     "axis there")
    for c in range(ds.sizes["curve_index"]):
        sel = ds["hopf_curve"].values == c
        freq = ds["frequency"].values[sel]
        l1 = ds["l1"].values[sel]
        err = ds["l1_error"].values[sel]
        sub = int(np.sum(l1 > err))
        sup = int(np.sum(l1 < -err))
        outer = int(ds["on_boundary"].values[sel].sum())
        ends = ("closed" if str(ds["curve_start"].values[c]) == "closed" else
                f"from {ds['curve_start'].values[c]} to {ds['curve_end'].values[c]}")
        lines.append(f"Hopf curve {c} ({ds['curve_mode'].values[c]}, {freq.min():.6g}-"
                     f"{freq.max():.6g} Hz, {int(sel.sum())} points, {ends}): "
                     f"{sub} subcritical, {sup} supercritical points; {outer} on the "
                     "stability boundary")
    names = {"bautin": "Bautin point (l1 = 0)", "double_hopf": "double Hopf point",
             "zero_hopf": "zero-Hopf point", "existence": "end of existence"}
    for i in range(ds.sizes["codim2"]):
        kind = str(ds["codim2_kind"].values[i])
        note = str(ds["codim2_note"].values[i])
        other = int(ds["codim2_other_curve"].values[i])
        with_other = ""
        if kind == "double_hopf":
            with_other = (f" with {ds['codim2_other_frequency'].values[i]:.6g} Hz"
                          + (f" (curve {other})" if other >= 0 else ""))
        lines.append(f"{names[kind]} on curve {int(ds['codim2_curve'].values[i])} at "
                     f"{xkey} = {ds['codim2_x'].values[i]:.10g}, {ykey} = "
                     f"{ds['codim2_y'].values[i]:.10g}: "
                     f"{ds['codim2_frequency'].values[i]:.6g} Hz "
                     f"({ds['codim2_mode'].values[i]}){with_other}"
                     + (f"; {note}" if note else ""))
    return lines
