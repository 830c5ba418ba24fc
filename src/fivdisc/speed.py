"""Disc speed profiles Omega(t) as piecewise cubics that the compiled kernel evaluates.

The paper's three situations (constant, Eq. 3; decelerating, Eq. 1; accelerating,
Eq. 2) and piecewise-linear tables are represented exactly. A pair of Python
callables ``Omega(t)``, ``Omegadot(t)`` is represented by a C1 cubic Hermite
interpolant on adaptively refined nodes, accurate to a relative 1e-10 by default.
Kinks (jumps of Omegadot) are integration breakpoints.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from fivdisc.errors import CaseError


@dataclass(frozen=True, eq=False)
class SpeedProfile:
    """Piecewise-cubic disc speed.

    On ``[knots[i], knots[i+1])`` (the last piece extends to infinity),
    ``Omega(t) = c0 + c1 tau + c2 tau^2 + c3 tau^3`` with ``tau = t - knots[i]``.

    Attributes
    ----------
    knots : ndarray
        Start times of the pieces [s], increasing, ``knots[0] == 0``.
    coefficients : ndarray
        ``(len(knots), 4)`` polynomial coefficients [rad/s, rad/s^2, rad/s^3, rad/s^4].
    breakpoints : ndarray
        Times where Omegadot jumps [s]; the integrator stops and restarts there.
    """

    knots: np.ndarray
    coefficients: np.ndarray
    breakpoints: np.ndarray

    @classmethod
    def constant(cls, value: float) -> SpeedProfile:
        """Constant speed ``value`` [rad/s] (paper Eq. 3)."""
        return cls(np.array([0.0]), np.array([[value, 0.0, 0.0, 0.0]]), np.empty(0))

    @classmethod
    def decelerating(cls, initial: float, duration: float) -> SpeedProfile:
        """``initial (1 - t / duration)`` until the disc stops at ``duration`` [s], then 0
        (paper Eq. 1)."""
        coef = np.array([[initial, -initial / duration, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
        return cls(np.array([0.0, duration]), coef, np.array([duration]))

    @classmethod
    def accelerating(cls, initial: float, rate: float) -> SpeedProfile:
        """``initial + rate t`` [rad/s] (paper Eq. 2)."""
        return cls(np.array([0.0]), np.array([[initial, rate, 0.0, 0.0]]), np.empty(0))

    @classmethod
    def table(cls, times: Sequence[float], values: Sequence[float]) -> SpeedProfile:
        """Piecewise-linear through ``(times, values)``, held at the last value."""
        t = np.asarray(times, dtype=float)
        v = np.asarray(values, dtype=float)
        slopes = np.append(np.diff(v) / np.diff(t), 0.0)
        coef = np.zeros((t.size, 4))
        coef[:, 0] = v
        coef[:, 1] = slopes
        return cls(t, coef, t[1:].copy())

    @classmethod
    def from_case(cls, speed) -> SpeedProfile:
        """Profile of a case's ``[speed]`` table (a ``fivdisc.case`` speed model)."""
        kind = speed.profile
        if kind == "constant":
            return cls.constant(speed.value)
        if kind == "decelerating":
            return cls.decelerating(speed.initial, speed.duration)
        if kind == "accelerating":
            return cls.accelerating(speed.initial, speed.rate)
        return cls.table(speed.times, speed.values)

    @classmethod
    def from_callables(
        cls,
        omega: Callable[[float], float],
        omega_dot: Callable[[float], float],
        t_end: float,
        breakpoints: Sequence[float] = (),
        rtol: float = 1e-10,
        max_pieces: int = 200_000,
    ) -> SpeedProfile:
        """Cubic Hermite representation of a user profile on ``[0, t_end]``.

        Parameters
        ----------
        omega, omega_dot : callable
            Disc speed [rad/s] and its time derivative [rad/s^2] as functions of t [s].
        t_end : float
            Last time needed [s]; beyond it the last piece is extrapolated.
        breakpoints : sequence of float
            Times in (0, t_end) where ``omega_dot`` jumps [s].
        rtol : float
            Nodes are refined until the interpolant matches ``omega`` at interval
            midpoints to ``rtol * (1 + max|omega|)``.
        max_pieces : int
            Refinement limit; exceeding it raises :class:`~fivdisc.errors.CaseError`.
        """
        if not (np.isfinite(t_end) and t_end > 0):
            raise CaseError(f"t_end = {t_end!r} is invalid: must be a finite time > 0 [s]")
        bps = sorted(float(b) for b in breakpoints)
        for b in bps:
            if not 0.0 < b < t_end:
                raise CaseError(f"breakpoint {b!r} is invalid: must lie in (0, t_end={t_end}) [s]")

        def sample(t: float, left: bool) -> tuple[float, float]:
            tt = np.nextafter(t, -np.inf) if left else t
            w, wd = float(omega(tt)), float(omega_dot(tt))
            if not (np.isfinite(w) and np.isfinite(wd)) or w < 0.0:
                raise CaseError(
                    f"speed profile gives Omega({t}) = {w}, Omegadot = {wd}: "
                    "Omega must be finite and >= 0 [rad/s]"
                )
            return w, wd

        edges = [0.0, *bps, float(t_end)]
        knots: list[float] = []
        coefs: list[np.ndarray] = []
        scale = 1.0 + max(abs(sample(e, False)[0]) for e in edges)
        for a, b in pairwise(edges):
            stack = [(a, b)]
            pieces: list[tuple[float, np.ndarray]] = []
            while stack:
                lo, hi = stack.pop()
                c = _hermite(lo, hi, sample(lo, False), sample(hi, True))
                mid = 0.5 * (lo + hi)
                tau = mid - lo
                err = abs(c[0] + tau * (c[1] + tau * (c[2] + tau * c[3])) - sample(mid, False)[0])
                if err > rtol * scale and hi - lo > 1e-9 * t_end:
                    stack.extend([(mid, hi), (lo, mid)])
                    if len(pieces) + len(stack) > max_pieces:
                        raise CaseError(
                            f"speed profile needs more than {max_pieces} pieces for rtol={rtol}; "
                            "declare its kinks as breakpoints or loosen rtol"
                        )
                else:
                    pieces.append((lo, c))
            for lo, c in pieces:
                knots.append(lo)
                coefs.append(c)
        return cls(np.array(knots), np.array(coefs), np.array(bps))

    def _locate(self, t: np.ndarray) -> np.ndarray:
        return np.clip(np.searchsorted(self.knots, t, side="right") - 1, 0, None)

    def omega(self, t) -> np.ndarray:
        """Disc speed [rad/s] at times ``t`` [s] (right limits at knots)."""
        t = np.asarray(t, dtype=float)
        k = self._locate(t)
        tau = t - self.knots[k]
        c = self.coefficients[k]
        return c[..., 0] + tau * (c[..., 1] + tau * (c[..., 2] + tau * c[..., 3]))

    def omega_dot(self, t) -> np.ndarray:
        """Disc angular acceleration [rad/s^2] at times ``t`` [s] (right limits at knots)."""
        t = np.asarray(t, dtype=float)
        k = self._locate(t)
        tau = t - self.knots[k]
        c = self.coefficients[k]
        return c[..., 1] + tau * (2.0 * c[..., 2] + 3.0 * tau * c[..., 3])

    def is_constant(self) -> bool:
        """Whether Omega never changes."""
        coef = self.coefficients
        return bool(np.all(coef[:, 1:] == 0.0) and np.ptp(coef[:, 0]) == 0.0)


def _hermite(t0: float, t1: float, p0: tuple[float, float], p1: tuple[float, float]) -> np.ndarray:
    """Cubic through values and slopes at both ends of [t0, t1], in powers of t - t0."""
    h = t1 - t0
    y0, d0 = p0
    y1, d1 = p1
    delta = (y1 - y0) / h
    return np.array([y0, d0, (3.0 * delta - 2.0 * d0 - d1) / h, (d0 + d1 - 2.0 * delta) / h**2])
