"""Hopf points of the sliding equilibrium along one key.

A Hopf point is where a complex pair of eigenvalues of the linearised slip equations
crosses the imaginary axis: there the equilibrium gains or loses stability and a family
of small periodic orbits is born, with the pair's angular frequency and along its
eigenvector. The crossings are bracketed on the eigenvalue branches of
:func:`~fivdisc.analysis.eigenbranches.eigen_branches` and located with Brent's method on
the real part of the eigenvalue that continues the branch. Each point carries its first
Lyapunov coefficient (:mod:`fivdisc.analysis.normalform`), whose sign says whether the
orbits born there are stable (supercritical) or a threshold around stable sliding
(subcritical).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import xarray as xr

from fivdisc.analysis.normalform import first_lyapunov
from fivdisc.analysis.points import (
    ParameterPoints,
    check_jacobian,
    reduced_indices,
    slip_jacobian,
)
from fivdisc.case import Case
from fivdisc.engine.equilibrium import (
    Equilibrium,
    sliding_equilibrium,
    slip_evaluation,
    slip_phases,
)
from fivdisc.engine.evaluation import unslaved
from fivdisc.errors import AnalysisError, SimulationError
from fivdisc.model.build import Model

# Relative tolerance of the located value of the key (Brent's method; the growth rate is
# smooth in the key, so the root is found to about this, far inside the 1e-8 promised).
KEY_TOLERANCE = 1e-12
# Growth rates within this fraction of the largest eigenvalue's modulus are round-off: no
# sign, no crossing (the eigenvalues are computed to about 2.2e-16 times it; an undamped
# mode's growth rate of exactly 0 comes out as +-5e-13 beside a 3600 1/s slider rate).
ROUND_OFF = 1e-12


@dataclass(frozen=True)
class HopfPoint:
    """A complex pair of eigenvalues of the sliding equilibrium on the imaginary axis.

    Attributes
    ----------
    key : str
        The varied case key.
    value : float
        Its value at the Hopf point.
    omega : float
        Critical angular frequency Im(lambda) [rad/s]; the orbits born here start with
        the period ``2 pi / omega``.
    direction : int
        +1 if the pair's growth rate rises through zero as the key increases (the mode
        becomes unstable), -1 if it falls.
    rate : float
        d Re(lambda) / d key at the point [1/s per unit of the key] (transversality:
        not zero).
    eigenvalue : complex
        The eigenvalue (real part zero to round-off) [1/s].
    state : ndarray
        The sliding equilibrium in the kernel's full dynamic state layout
        ``[q, phi, z, qdot, phidot, zdot]`` (``2 (n + 2 S)`` values; the z, zdot of
        sliders in contact hold the disc's surface under them, as a run's output does).
    eigenvector : ndarray
        Complex right eigenvector in the same layout, of unit 2-norm, phased so that its
        largest component is real and positive. A small orbit starts at
        ``state + eps * Re(eigenvector)``.
    mode : str
        The label of the pair's eigenvalue branch (the ``mode`` of
        :func:`~fivdisc.analysis.eigenbranches.eigen_branches` along the same values:
        :func:`~fivdisc.analysis.stability.mode_labels` where the values come nearest
        the case's own value of the key).
    on_boundary : bool
        Whether every other eigenvalue has a negative real part there: the equilibrium
        changes stability at this point (else it stays unstable on both sides).
    equilibrium : Equilibrium
        The sliding equilibrium at the point.
    case : Case
        The base case with the key set to `value`.
    unstable_modes : tuple of str
        The labels of the other modes that are unstable there (empty where
        `on_boundary`): while one is, every small orbit born here is unstable too.
    l1 : float
        First Lyapunov coefficient [s^2] per (rad/s)^2 of the slip-speed amplitude of
        the slider that moves most (:func:`~fivdisc.analysis.normalform.first_lyapunov`):
        negative supercritical, positive subcritical.
    l1_error : float
        Its estimated absolute error [s^2].

    See Also
    --------
    hopf_points : Makes them.
    fivdisc.hopf_cycles : The periodic orbits born at one.

    Examples
    --------
    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> (point,) = fivdisc.hopf_points(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> point.key, point.mode, point.direction, point.on_boundary
    ('speed.value', 'phi', -1, True)
    >>> print(f"{point.value:.6f} rad/s, {point.omega:.4f} rad/s, "
    ...       f"period {2 * np.pi / point.omega * 1e3:.4f} ms")
    9.162907 rad/s, 1414.2136 rad/s, period 4.4429 ms
    >>> point.case.speed.value == point.value
    True
    >>> print(f"l1 = {point.l1:.6e} s^2: {point.criticality}")
    l1 = 2.209709e-04 s^2: subcritical
    """

    key: str
    value: float
    omega: float
    direction: int
    rate: float
    eigenvalue: complex
    state: np.ndarray
    eigenvector: np.ndarray
    mode: str
    on_boundary: bool
    equilibrium: Equilibrium
    case: Case
    l1: float = math.nan
    l1_error: float = math.nan
    unstable_modes: tuple[str, ...] = ()

    @property
    def frequency(self) -> float:
        """Critical frequency ``omega / 2 pi`` [Hz]."""
        return self.omega / (2.0 * np.pi)

    @property
    def period(self) -> float:
        """``2 pi / omega`` [s], the period of the orbits born here."""
        return 2.0 * np.pi / self.omega

    @property
    def criticality(self) -> str:
        """By the sign of :attr:`l1`: ``"subcritical"`` (positive: small unstable orbits
        on the side where the equilibrium is stable), ``"supercritical"`` (negative:
        small stable orbits where it is unstable), or ``"degenerate"`` (zero within its
        error, or not computed)."""
        if not math.isfinite(self.l1) or abs(self.l1) <= self.l1_error:
            return "degenerate"
        return "subcritical" if self.l1 > 0.0 else "supercritical"

    @property
    def orbit_offset(self) -> float:
        """``d p / d rho^2`` [unit of the key per (rad/s)^2]: a small orbit of slip-speed
        amplitude ``rho`` lies at ``p = value + orbit_offset rho^2`` (from the normal
        form, ``rate (p - value) + omega l1 rho^2 = 0``)."""
        return -self.omega * self.l1 / self.rate

    def __str__(self) -> str:
        turn = "loses" if self.direction > 0 else "gains"
        others = ", ".join(self.unstable_modes) or "another mode"
        verb = "stay" if len(self.unstable_modes) > 1 else "stays"
        where = "" if self.on_boundary else f" ({others} {verb} unstable)"
        kind = (f"; first Lyapunov coefficient l1 = {self.l1:.4g} s^2: {self.criticality}"
                if math.isfinite(self.l1) else "")
        return (f"Hopf point at {self.key} = {self.value:.10g}: {self.mode} at "
                f"{self.frequency:.6g} Hz ({self.omega:.6g} rad/s) {turn} stability as "
                f"{self.key} increases{where}{kind}")


def _full_layout(model: Model, eq: Equilibrium, vector: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Equilibrium and eigenvector (reduced variables) in the kernel's full layout, the
    sliders' z, zdot filled in from the disc under them."""
    ph, sg = slip_phases(model)
    idx = reduced_indices(model)
    full = np.zeros((2, model.state_size))
    full[0, idx], full[1, idx] = vector.real, vector.imag
    full = unslaved(model, eq.state, ph, sg, full)
    state = eq.state.copy()
    # The slaved rows of the equilibrium itself: z = w under the slider (zdot = 0).
    _, aux = slip_evaluation(model, state)
    state[model.slices.z] = aux["w"]
    vec = full[0] + 1j * full[1]
    vec /= np.linalg.norm(vec)
    big = np.argmax(np.abs(vec))
    vec *= np.exp(-1j * np.angle(vec[big]))
    return state, vec


def _locate(points: ParameterPoints, key: str, lo: float, hi: float, row_lo: np.ndarray,
            row_hi: np.ndarray, b: int, labels: Sequence[str],
            guesses: Sequence[Equilibrium], option: str) -> HopfPoint | None:
    """The Hopf point of branch `b` between `lo` and `hi` (its followed rows of
    eigenvalues there `row_lo`, `row_hi`), its other modes named by `labels`; None if
    the growth rates recomputed at the ends do not change sign (a crossing at round-off
    level). `guesses` are the equilibria at the ends (those found)."""
    from scipy.optimize import brentq, linear_sum_assignment

    lam_lo, lam_hi = row_lo[b], row_hi[b]

    def linearise(value: float) -> tuple:
        near = list(guesses if abs(value - lo) <= abs(value - hi) else guesses[::-1])
        point = points.linearise((value,), near[0] if near else None)
        if point is not None:
            return point
        # From the other end's equilibrium, or the rigid-disc guess: in a bracket spanning
        # decades of the key the nearest end's may not converge.
        model = points.model((value,))
        failure: Exception | None = None
        for guess in [*near[1:], None]:
            try:
                eq = sliding_equilibrium(model, guess=guess)
            except SimulationError as err:
                failure = err
                continue
            jac = slip_jacobian(model, eq.state)
            check_jacobian(model, eq.state, jac, f"at {key} = {value:g}: ")
            return model, eq, jac
        raise AnalysisError(
            f"{option} {key}: a complex pair crosses the imaginary axis between {lo:g} and "
            f"{hi:g}, but the sliding equilibrium is not found at {value:g} in between "
            f"({failure}); give values closer together there"
        )

    def eig_near(value: float) -> tuple:
        """The eigen-solution at `value` and which eigenvalue continues branch `b`: all
        of them matched to the branches interpolated there (so that near-equal
        eigenvalues, as identical pads have, each keep their own branch)."""
        model, eq, jac = linearise(value)
        lam, vec = np.linalg.eig(jac)
        t = (value - lo) / (hi - lo)
        _, column = linear_sum_assignment(
            np.abs((row_lo + t * (row_hi - row_lo))[:, None] - lam[None, :]))
        return model, eq, jac, lam, vec, int(column[b])

    def growth(value: float) -> float:
        _, _, _, lam, _, i = eig_near(value)
        return float(lam[i].real)

    if (growth(lo) < 0.0) == (growth(hi) < 0.0):
        return None
    scale = max(abs(lo), abs(hi), abs(hi - lo))
    root = float(brentq(growth, lo, hi, xtol=KEY_TOLERANCE * scale, rtol=1e-15))
    model, eq, jac, lam, vec, i = eig_near(root)
    # The slope by a central difference, kept inside the bracket (a root at its end, such
    # as a key's lowest allowed value, has no values beyond it).
    step = 1e-6 * abs(hi - lo)
    a, c = max(min(lo, hi), root - step), min(max(lo, hi), root + step)
    rate = (growth(c) - growth(a)) / (c - a)
    pick = i if lam[i].imag > 0 else int(np.argmin(np.abs(lam - np.conj(lam[i]))))
    pair = [i, int(np.argmin(np.abs(lam - np.conj(lam[i]))))]
    others = np.delete(lam.real, pair)
    # Each eigenvalue at the point is matched to the branch it continues (the branches
    # interpolated to the point), which names it.
    t = (root - lo) / (hi - lo)
    _, branch_of = linear_sum_assignment(
        np.abs(lam[:, None] - (row_lo + t * (row_hi - row_lo))[None, :]))
    branch_of[i] = b
    unstable = [labels[branch_of[j]] for j in np.argsort(-lam.real)
                if j not in pair and lam[j].real >= 0.0 and lam[j].imag >= 0.0]
    state, vector = _full_layout(model, eq, vec[:, pick])
    l1 = first_lyapunov(model, eq.state, float(lam[pick].imag), jac)
    return HopfPoint(
        key=key, value=root, omega=float(lam[pick].imag),
        direction=1 if (lam_hi.real - lam_lo.real) / (hi - lo) > 0.0 else -1,
        rate=float(rate),
        eigenvalue=complex(lam[pick]), state=state, eigenvector=vector,
        mode=str(labels[b]), on_boundary=bool(np.all(others < 0.0)), equilibrium=eq,
        case=points.case.replace({key: root}),
        unstable_modes=tuple(dict.fromkeys(unstable)),
        l1=l1.value, l1_error=l1.error,
    )


def hopf_points(case: Case, key: str, values: Sequence[float], option: str = "key",
                branches: xr.Dataset | None = None) -> list[HopfPoint]:
    """Hopf points of the sliding equilibrium along one numeric key.

    Parameters
    ----------
    case : Case
        Base case at constant speed.
    key : str
        Dotted case key, e.g. ``"speed.value"``.
    values : sequence of float
        Values on which the eigenvalue branches are followed; every crossing of a
        complex pair between two neighbours is located. Crossings closer together than
        the spacing of `values` can cancel out unseen: refine the values to find them.
    option : str
        What names `key` in error messages.
    branches : xarray.Dataset, optional
        The branches of :func:`~fivdisc.analysis.eigenbranches.eigen_branches` over the
        same key and values, if already computed.

    Returns
    -------
    list of HopfPoint
        In order of the key's value (of `values`' direction), each located to
        ``KEY_TOLERANCE`` relative.

    Raises
    ------
    CaseError
        As :func:`~fivdisc.analysis.eigenbranches.eigen_branches`.

    See Also
    --------
    fivdisc.eigen_branches : The eigenvalues along the key, from which the points are
        located.
    fivdisc.hopf_cycles : The periodic orbits born at a Hopf point.

    Notes
    -----
    At the point the growth rate ``g(p) = Re lambda(p)`` of the branch is zero; it is
    bracketed by a change of sign between neighbouring values, the branches are followed
    again between them in steps over which every eigenvalue moves less than a quarter
    of the least distance between two (near-equal eigenvalues, as identical pads have,
    each keep their own branch: up to 64 steps), and each crossing is found with
    :func:`scipy.optimize.brentq` on its step, the eigenvalues at each trial value being
    matched to the branches' linear interpolation. A real eigenvalue crossing zero (a
    fold of the equilibrium, not a Hopf point) is not reported.

    Examples
    --------
    A slider on a rigid disc (no modes), with rotational damping ``c`` = 0.5 N m s/rad
    and the falling exponential friction law: sliding turns stable where the friction's
    negative damping ``r^2 N0 alpha (mu_0 - mu_1) exp(-alpha r Omega)`` drops below
    ``c``, at ``Omega = 10 ln 2.5`` rad/s, and the pair crosses at
    ``sqrt(k_phi / I)`` [rad/s]:

    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> points = fivdisc.hopf_points(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> [(round(p.value, 6), round(p.omega, 3), p.direction) for p in points]
    [(9.162907, 1414.214, -1)]
    >>> print(f"{10 * np.log(2.5):.6f} {np.sqrt(2000 / (0.1 * 0.1**2)):.3f}")
    9.162907 1414.214
    """
    from fivdisc.analysis.eigenbranches import eigen_branches

    if branches is None:
        branches = eigen_branches(case, key, values, option=option)
    values = branches[key].values
    lam = branches["growth_rate"].values + 2j * np.pi * branches["frequency"].values
    labels = [str(m) for m in branches["mode"].values]
    points = ParameterPoints(case, [key])
    found = []
    for i in range(values.size - 1):
        if not _crossed(lam[i], lam[i + 1]):
            continue
        ends = [points.equilibrium(points.model((v,))) for v in values[i : i + 2]]
        guess = ends[0]
        # Between the two values the branches are followed again in steps short enough
        # to keep near-equal eigenvalues apart (identical pads), from the first value's
        # order, and each crossing is located on its own sub-step.
        sub, rows = _refine(points, values[i], values[i + 1], lam[i], lam[i + 1], guess)
        for k in range(sub.size - 1):
            for b in _crossed(rows[k], rows[k + 1]):
                hopf = _locate(points, key, sub[k], sub[k + 1], rows[k], rows[k + 1], b,
                               labels, [e for e in ends if e is not None], option)
                if hopf is not None:
                    found.append(hopf)
    ascending = values[-1] > values[0]
    return sorted(found, key=lambda h: h.value, reverse=not ascending)


# Most sub-steps between two values of a scan in which hopf_points follows the branches
# again (doubled from 2 until each eigenvalue moves less than _STEP_SHARE of the least
# distance between two of them).
_MAX_SUBSTEPS = 64
_STEP_SHARE = 0.25


def _crossed(row: np.ndarray, after: np.ndarray) -> list[int]:
    """The branches whose complex eigenvalue (positive imaginary part) crosses the
    imaginary axis from `row` to `after`. Growth rates within round-off of zero
    (:data:`ROUND_OFF` of the largest eigenvalue's modulus) have no sign: an undamped
    mode's come out as +-5e-13 at random, and are no crossing."""
    if not (np.isfinite(row).all() and np.isfinite(after).all()):
        return []
    noise = ROUND_OFF * max(float(np.max(np.abs(row))), float(np.max(np.abs(after))))
    return [b for b in range(row.size)
            if (row[b].real < 0.0) != (after[b].real < 0.0)
            and min(row[b].imag, after[b].imag) > 0
            and min(abs(row[b].real), abs(after[b].real)) > noise]


def _refine(points: ParameterPoints, lo: float, hi: float, row_lo: np.ndarray,
            row_hi: np.ndarray, guess: Equilibrium) -> tuple[np.ndarray, list[np.ndarray]]:
    """Values from `lo` to `hi` and the eigenvalues there in the order of `row_lo`'s
    branches, followed in steps over which each moves less than a quarter of the least
    distance between two of them."""
    from scipy.optimize import linear_sum_assignment

    def spread(row: np.ndarray) -> float:
        d = np.abs(row[:, None] - row[None, :])
        return float(np.min(d[~np.eye(row.size, dtype=bool)], initial=np.inf))

    m = 2
    while True:
        sub = np.linspace(lo, hi, m + 1)
        raw = [row_lo]
        for value in sub[1:-1]:
            point = points.linearise((value,), guess)
            if point is None:  # no equilibrium inside: the coarse step it is
                return np.array([lo, hi]), [row_lo, row_hi]
            raw.append(np.linalg.eigvals(point[2]))
        raw.append(row_hi)
        rows = [row_lo]
        for row in raw[1:]:
            ahead = rows[-1] if len(rows) < 2 else 2.0 * rows[-1] - rows[-2]
            _, order = linear_sum_assignment(np.abs(ahead[:, None] - row[None, :]))
            rows.append(row[order])
        moves = max(float(np.max(np.abs(b - a))) for a, b in itertools.pairwise(rows))
        if moves < _STEP_SHARE * min(spread(r) for r in rows) or m >= _MAX_SUBSTEPS:
            return sub, rows
        m *= 2


def with_hopf_points(branches: xr.Dataset, hopf: Sequence[HopfPoint]) -> xr.Dataset:
    """The branches of :func:`~fivdisc.analysis.eigenbranches.eigen_branches` with their
    Hopf points (what ``fivdisc stability --x`` writes).

    Parameters
    ----------
    branches : xarray.Dataset
        The branches.
    hopf : sequence of HopfPoint
        Their Hopf points (:func:`hopf_points` over the same key and values).

    Returns
    -------
    xarray.Dataset
        `branches` with, along a dimension ``hopf``: ``hopf`` (the key's value),
        ``hopf_frequency`` [Hz], ``hopf_direction`` (+1: the mode loses stability as the
        key increases), ``hopf_mode`` (the branch's label, as ``mode``),
        ``hopf_on_boundary`` (1: the equilibrium changes stability there),
        ``hopf_unstable_modes`` (the other modes unstable there, comma-separated) and
        ``hopf_l1``, ``hopf_l1_error`` (the first Lyapunov coefficient and its error).
    """
    key = branches.attrs["x_key"]
    return branches.assign(
        hopf=(("hopf",), np.array([hp.value for hp in hopf], dtype=float),
              {**branches[key].attrs, "long_name": "Hopf points: where a complex pair "
                                                    "crosses the imaginary axis"}),
        hopf_frequency=(("hopf",), np.array([hp.frequency for hp in hopf], dtype=float),
                        {"units": "Hz", "long_name": "critical frequency"}),
        hopf_direction=(("hopf",), np.array([hp.direction for hp in hopf], dtype=np.int8),
                        {"long_name": "+1: the mode loses stability as the key increases"}),
        hopf_mode=(("hopf",), np.array([hp.mode for hp in hopf], dtype=str),
                   {"long_name": "label of the critical mode's branch (as mode)"}),
        hopf_on_boundary=(("hopf",), np.array([hp.on_boundary for hp in hopf], dtype=np.int8),
                          {"long_name": "1: the equilibrium changes stability here; 0: "
                                        "another mode stays unstable on both sides"}),
        hopf_unstable_modes=(("hopf",), np.array([", ".join(hp.unstable_modes)
                                                  for hp in hopf], dtype=str),
                             {"long_name": "the other modes unstable here"}),
        hopf_l1=(("hopf",), np.array([hp.l1 for hp in hopf], dtype=float),
                 {"units": "s2", "long_name": "first Lyapunov coefficient per (rad/s)^2 of "
                                              "slip-speed amplitude (> 0: subcritical, < 0: "
                                              "supercritical)"}),
        hopf_l1_error=(("hopf",), np.array([hp.l1_error for hp in hopf], dtype=float),
                       {"units": "s2", "long_name": "estimated error of hopf_l1"}),
    )
