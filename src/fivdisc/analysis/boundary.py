"""Exact stability boundaries in two keys: the Hopf curves of the sliding equilibrium,
traced by continuation instead of read off a grid.

The boundary is the zero set of the largest growth rate ``g(x, y) = max Re lambda`` of
the linearised slip equations: pieces of Hopf curves (a complex pair on the imaginary
axis), meeting at corners where another mode takes over. It is traced in the box scaled
to the unit square, by a secant predictor along the curve and a corrector that finds the
zero of g on the normal line through the predicted point (:func:`scipy.optimize.brentq`),
so every point lies on the boundary to the root finder's tolerance.

Every branch is started from a change of sign of g along the edges of a coarse grid of
seeds over the box (its outer edges included): curves through the box, curves that
leave and re-enter it (one branch per visit), and closed curves, with either side
stable. A closed curve that fits between two seed lines, or two crossings of one seed
edge, are not seen: more seeds find them.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import xarray as xr

from fivdisc.analysis.points import ParameterPoints, box_of
from fivdisc.analysis.stability import mode_labels
from fivdisc.case import Case

# Root-finder tolerance in the box scaled to the unit square: the growth rate is known to
# ~1e-13 of the eigenvalues, so a tighter tolerance only chases round-off.
_XTOL = 1e-10
# Shortest step [unit box] before a branch is given up as lost.
_MIN_STEP = 1e-5


class _Growth:
    """g at points of the unit box, counted, reusing the nearest equilibrium."""

    def __init__(self, points: ParameterPoints, lo: np.ndarray, span: np.ndarray) -> None:
        self.points, self.lo, self.span = points, lo, span
        self.calls = 0
        self.guess = None
        # The growth rates on the seed grid (rows along y), once computed.
        self.seed_values = np.empty((0, 0))

    def values(self, u: np.ndarray) -> tuple[float, float]:
        return tuple(self.lo + self.span * np.asarray(u))

    def __call__(self, u: np.ndarray) -> float:
        self.calls += 1
        point = self.points.linearise(self.values(u), self.guess)
        if point is None:
            return math.nan
        self.guess = point[1]
        return float(np.max(np.linalg.eigvals(point[2]).real))

    def critical(self, u: np.ndarray) -> tuple[complex, str]:
        """The eigenvalue with the largest real part (positive imaginary part of a pair)
        and its mode's label (:func:`~fivdisc.analysis.stability.mode_labels`)."""
        model, _, jac = self.points.linearise(self.values(u), self.guess)
        lam, vec = np.linalg.eig(jac)
        top = lam.real >= lam.real.max() - 1e-9 * np.abs(lam).max()
        i = int(np.argmax(np.where(top, lam.imag, -np.inf)))
        return complex(lam[i]), mode_labels(model, lam, vec)[i]


def _zero_between(g: _Growth, a: np.ndarray, b: np.ndarray, ga: float, gb: float
                  ) -> np.ndarray:
    from scipy.optimize import brentq

    if ga == 0.0:
        return a
    s = brentq(lambda t: g(a + t * (b - a)), 0.0, 1.0,
               xtol=_XTOL / max(np.linalg.norm(b - a), 1e-300), rtol=1e-15)
    return a + s * (b - a)


def _seeds(g: _Growth, m: int) -> dict[tuple, np.ndarray]:
    """Boundary points on the edges of an m x m grid over the unit box, by edge."""
    grid = np.linspace(0.0, 1.0, m)
    values = np.array([[g(np.array([x, y])) for x in grid] for y in grid])
    if isinstance(g, _Growth):
        g.seed_values = values
    seeds = {}
    for iy in range(m):
        for ix in range(m):
            for dx, dy, kind in ((1, 0, "h"), (0, 1, "v")):
                jx, jy = ix + dx, iy + dy
                if jx >= m or jy >= m:
                    continue
                ga, gb = values[iy, ix], values[jy, jx]
                if not (np.isfinite(ga) and np.isfinite(gb)) or (ga < 0) == (gb < 0):
                    continue
                a, b = np.array([grid[ix], grid[iy]]), np.array([grid[jx], grid[jy]])
                # A horizontal edge lies on grid row iy between columns ix and ix + 1.
                edge = (kind, iy, ix) if kind == "h" else (kind, ix, iy)
                seeds[edge] = _zero_between(g, a, b, ga, gb)
    return seeds


def _edges_crossed(p: np.ndarray, q: np.ndarray, m: int) -> set[tuple]:
    """Seed edges that the segment p-q crosses (or touches)."""
    found = set()
    cells = m - 1
    for axis, kind in ((1, "h"), (0, "v")):
        # Horizontal edges lie on lines of constant y (axis 1), vertical on constant x.
        lo, hi = sorted((p[axis] * cells, q[axis] * cells))
        for line in range(math.ceil(lo - 1e-9), math.floor(hi + 1e-9) + 1):
            if not 0 <= line < m:
                continue
            t = 0.0 if q[axis] == p[axis] else (line / cells - p[axis]) / (q[axis] - p[axis])
            other = (p + t * (q - p))[1 - axis] * cells
            cell = min(max(math.floor(other), 0), cells - 1)
            found.add((kind, line, cell))
            if abs(other - round(other)) < 1e-9 and 0 < round(other) <= cells:
                found.add((kind, line, round(other) - 1))
    return found


def _inside(u: np.ndarray) -> bool:
    return bool(np.all(u >= -1e-12) and np.all(u <= 1.0 + 1e-12))


def _trace(g: _Growth, start: np.ndarray, direction: np.ndarray, step: float
           ) -> tuple[list[np.ndarray], bool]:
    """Points from `start` along the boundary, first along `direction`, until it leaves
    the box, comes back to `start` (closed: True) or is lost."""
    path = [start]
    tangent = direction / np.linalg.norm(direction)
    h = step
    while len(path) < 100000:
        p = path[-1]
        normal = np.array([-tangent[1], tangent[0]])
        pred = p + h * tangent
        # The secant predictor misses the curve by O(h^2 curvature): a narrow bracket
        # on the normal line first, a wide one before the step is halved.
        for width in (0.125 * h, h):
            a, b = pred - width * normal, pred + width * normal
            ga, gb = g(a), g(b)
            if np.isfinite(ga) and np.isfinite(gb) and (ga < 0) != (gb < 0):
                break
        else:
            h *= 0.5
            if h < _MIN_STEP:
                return path, False
            continue
        new = _zero_between(g, a, b, ga, gb)
        if not _inside(new):
            # Where the last step crosses the box's edge.
            d = new - p
            t = min(((1.0 if d[k] > 0 else 0.0) - p[k]) / d[k] for k in range(2) if d[k] != 0
                    and not 0.0 <= new[k] <= 1.0)
            end = np.clip(p + t * d, 0.0, 1.0)
            # On the crossed edge, the curve's exact end lies within the step.
            k = 1 if 0.0 < end[1] < 1.0 else 0
            a, b = end.copy(), end.copy()
            a[k], b[k] = max(end[k] - h, 0.0), min(end[k] + h, 1.0)
            ga, gb = g(a), g(b)
            if np.isfinite(ga) and np.isfinite(gb) and (ga < 0) != (gb < 0):
                end = _zero_between(g, a, b, ga, gb)
            path.append(end)
            return path, False
        if len(path) > 2 and np.linalg.norm(new - start) < h:
            path += [new, start]
            return path, True
        tangent = (new - p) / np.linalg.norm(new - p)
        path.append(new)
        h = min(1.5 * h, step)
    return path, False


def stability_boundary(
    case: Case,
    x: tuple[str, tuple[float, float]],
    y: tuple[str, tuple[float, float]],
    seeds: int = 12,
    step: float = 0.02,
) -> xr.Dataset:
    """The stability boundary of the sliding equilibrium in a box of two keys, traced.

    Parameters
    ----------
    case : Case
        Base case at constant speed.
    x, y : (str, (float, float))
        Dotted case key and (start, stop) of each side of the box.
    seeds : int
        Seed lines per side (at least 2): branches are started where the growth rate
        changes sign between neighbouring seed points.
    step : float
        Largest step along a curve, as a fraction of the box's sides.

    Returns
    -------
    xarray.Dataset
        Dimension ``point``, in order along each branch. Variables named after the two
        keys (their values), ``branch`` (which curve), ``frequency`` [Hz] and ``mode`` of
        the critical eigenvalue (the pair on the imaginary axis; frequency 0 where a
        real eigenvalue crosses), ``growth_rate`` [1/s] (the largest real part there,
        zero to the root finder's tolerance); ``closed`` (per branch); attributes
        ``x_key``, ``y_key``, ``x_range``, ``y_range``, ``evaluations`` (eigen-solves
        made), ``seeds`` (seed lines a side) with ``seeds_stable``, ``seeds_unstable``
        and ``seeds_without_equilibrium`` (how the seed grid's points came out: without
        a curve, a boundary can still enclose a region between them) and the case.

    Raises
    ------
    CaseError
        Non-numeric or repeated keys, an empty range, an end outside a key's allowed
        values, too few seeds, or no sliding equilibrium at the box's first corner.

    See Also
    --------
    fivdisc.stability_map : The growth rate sampled on a grid of the two keys (with a
        boundary interpolated in each column).
    fivdisc.plots.plot_stability_boundary : Draws the curves.

    Examples
    --------
    A slider on a rigid disc (no modes) with the falling exponential friction law loses
    stability where its rotational damping ``c`` falls below
    ``r^2 N0 alpha (mu_0 - mu_1) exp(-alpha r Omega) = 1.25 exp(-0.1 Omega)``
    [N m s/rad]. The traced curve runs from the box's left side (Omega = 1 rad/s) to
    its bottom (c = 0.2 N m s/rad), on that closed form:

    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []})
    >>> curve = fivdisc.stability_boundary(rigid, ("speed.value", (1.0, 20.0)),
    ...                                    ("slider.rotational_damping", (0.2, 1.5)))
    >>> speed, damping = curve["speed.value"].values, curve["slider.rotational_damping"].values
    >>> print(f"{speed.min():.4f} to {speed.max():.4f} rad/s, "
    ...       f"{damping.max():.4f} to {damping.min():.4f} N m s/rad")
    1.0000 to 18.3258 rad/s, 1.1310 to 0.2000 N m s/rad
    >>> bool(np.abs(damping - 1.25 * np.exp(-0.1 * speed)).max() < 1e-8)
    True
    >>> print(f"{curve['frequency'].values[0]:.2f} Hz")  # sqrt(k_phi / I) / 2 pi
    225.08 Hz
    """
    box = box_of(case, x, y, seeds, step, "--boundary", "a boundary box")
    g = _Growth(box.points, box.lo, box.span)
    return _dataset(case, g, zero_curves(g, seeds, step), box.x, box.y)


def zero_curves(g, seeds: int = 12, step: float = 0.02
                ) -> list[tuple[list[np.ndarray], bool]]:
    """Every curve where the continuous function `g` of the unit square changes sign.

    Parameters
    ----------
    g : callable
        ``g(u)`` of a point ``u`` (2 values in [0, 1]); NaN where undefined.
    seeds, step
        As for :func:`stability_boundary`.

    Returns
    -------
    list of (list of ndarray, bool)
        Per curve, its points in order and whether it is closed.
    """
    found = _seeds(g, seeds)
    covered: set[tuple] = set()
    curves: list[tuple[list[np.ndarray], bool]] = []
    for edge, seed in sorted(found.items()):
        if edge in covered:
            continue
        e = 1e-7
        grad = np.array([(g(seed + e * d) - g(seed - e * d)) / (2 * e)
                         for d in (np.array([1.0, 0.0]), np.array([0.0, 1.0]))])
        if np.all(np.isfinite(grad)) and np.any(grad):
            along = np.array([-grad[1], grad[0]])
        else:
            # g is undefined or flat beside the seed (a jump, where g is defined on one
            # side only): start across the seed's edge.
            along = np.array([0.0, 1.0]) if edge[0] == "h" else np.array([1.0, 0.0])
        path, closed = _trace(g, seed, along, step)
        if not closed:
            backward, _ = _trace(g, seed, -along, step)
            path = backward[::-1] + path[1:]
        for p, q in itertools.pairwise(path):
            covered |= _edges_crossed(p, q, seeds)
        covered.add(edge)
        curves.append((path, closed))
    return curves


def _dataset(case: Case, g: _Growth, branches, x, y) -> xr.Dataset:
    from fivdisc.engine.conventions import global_attrs, key_attrs

    (xkey, xr_), (ykey, yr_) = x, y
    rows = []
    for b, (path, _) in enumerate(branches):
        for u in path:
            lam, mode = g.critical(u)
            rows.append((*g.values(u), b, lam.real, abs(lam.imag) / (2 * np.pi), mode))
    evaluations = g.calls
    seeds = g.seed_values
    cols = list(zip(*rows, strict=True)) if rows else [[]] * 6
    return xr.Dataset(
        {
            xkey: (("point",), np.array(cols[0], dtype=float), key_attrs(xkey)),
            ykey: (("point",), np.array(cols[1], dtype=float), key_attrs(ykey)),
            "branch": (("point",), np.array(cols[2], dtype=np.int64),
                       {"long_name": "which boundary curve"}),
            "growth_rate": (("point",), np.array(cols[3], dtype=float), {
                "units": "1/s", "long_name": "largest real part of the eigenvalues (zero on "
                                             "the boundary)"}),
            "frequency": (("point",), np.array(cols[4], dtype=float), {
                "units": "Hz", "long_name": "frequency of the critical eigenvalue"}),
            "mode": (("point",), np.array(cols[5], dtype=str), {
                "long_name": "label of the critical mode (mode_labels at the point)"}),
            "closed": (("curve",), np.array([c for _, c in branches], dtype=np.int8),
                       {"long_name": "the curve closes on itself inside the box"}),
        },
        attrs={**global_attrs(f"fivdisc stability boundary over {xkey} and {ykey}",
                              "fivdisc.stability_boundary"),
               "fivdisc_kind": "stability_boundary", "x_key": xkey, "y_key": ykey,
               "x_range": np.asarray(xr_, dtype=float), "y_range": np.asarray(yr_, dtype=float),
               "evaluations": evaluations, "seeds": seeds.shape[0],
               "seeds_stable": int(np.sum(seeds < 0.0)),
               "seeds_unstable": int(np.sum(seeds >= 0.0)),
               "seeds_without_equilibrium": int(np.sum(np.isnan(seeds))),
               "case": case.to_toml()},
    )
