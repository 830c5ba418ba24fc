"""Disc speed profiles Omega(t) as piecewise cubics that the compiled core evaluates.

The paper's three situations (constant, Eq. 3; decelerating, Eq. 1; accelerating,
Eq. 2) and piecewise-linear tables are represented exactly. A pair of Python
callables ``Omega(t)``, ``Omegadot(t)`` is represented by a C1 cubic Hermite
interpolant on adaptively refined nodes, checked inside every piece: by default Omega is
accurate to a relative 1e-10 and Omegadot to 1e-6, and an Omegadot that is not the
derivative of Omega is refused. Kinks (jumps of Omegadot) are integration breakpoints.

The constructors of the built-in profiles validate their arguments with the case
file's ``[speed]`` models, so they accept exactly what a case file accepts.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import pairwise
from typing import Any

import numpy as np

from fivdisc.case import (
    AcceleratingSpeed,
    ConstantSpeed,
    DeceleratingSpeed,
    Speed,
    TableSpeed,
)
from fivdisc.errors import CaseError

# Interior check points of a piece, as fractions of its width: the 3-point Gauss-Legendre
# nodes; the outer two are irrational, so no halving of a piece lands on them.
_CHECK_POINTS = (0.5 - math.sqrt(0.15), 0.5, 0.5 + math.sqrt(0.15))
# Pieces each stretch between breakpoints starts with, and points per stretch at which the
# derivative is checked (offset by the golden ratio's fraction, off every dyadic point).
_START_PIECES = 16
_GOLDEN = 0.5 * (math.sqrt(5.0) - 1.0)
# First finite-difference step of the derivative check, as a fraction of the stretch, and
# how many tenfold smaller steps it may try.
_FD_STEP = 1e-3
_FD_TRIES = 8
# Narrowest piece, as a fraction of t_end: a kink or jump inside one stops refinement.
_MIN_WIDTH = 1e-9
_MAX_RTOL = 1e-3
_SHOWN_CHARS = 60


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
    end : float
        Last time the profile represents [s] (inf: all times); a simulation may not run
        past it.
    source : str
        Where the profile comes from, kept with a run's result: ``"callables"``
        (:meth:`from_callables`) or ``"profile"`` (any other).

    See Also
    --------
    fivdisc.Case : A case's ``[speed]`` table, the usual way to set the speed.
    fivdisc.simulate : Its ``speed`` argument overrides the case's with a profile.

    Examples
    --------
    The paper's deceleration from 2 pi rad/s to rest in 35 s (Eq. 1) [rad/s]:

    >>> import numpy as np
    >>> import fivdisc
    >>> profile = fivdisc.SpeedProfile.decelerating(2 * np.pi, 35.0)
    >>> print(profile.omega([0.0, 17.5, 35.0, 40.0]).round(4))
    [6.2832 3.1416 0.     0.    ]
    >>> print(profile.breakpoints, profile.is_constant())
    [35.] False

    Any smooth speed, from a pair of Python functions ``Omega(t)`` [rad/s] and its
    derivative [rad/s^2], represented on ``[0, t_end]`` to ``rtol``:

    >>> wobble = fivdisc.SpeedProfile.from_callables(
    ...     lambda t: 10.0 + np.sin(50.0 * t), lambda t: 50.0 * np.cos(50.0 * t), t_end=0.05)
    >>> print(f"{float(wobble.omega(0.01)):.7f} {10.0 + np.sin(0.5):.7f} {wobble.source}")
    10.4794255 10.4794255 callables
    >>> case = fivdisc.Case(simulation={"duration": 0.05})
    >>> fivdisc.simulate(case, speed=wobble).status
    'success'
    """

    knots: np.ndarray
    coefficients: np.ndarray
    breakpoints: np.ndarray
    end: float = math.inf
    source: str = "profile"

    @classmethod
    def constant(cls, value: float) -> SpeedProfile:
        """Constant speed ``value`` [rad/s] (paper Eq. 3).

        Raises
        ------
        CaseError
            As a case file's ``[speed]`` table with these values would.
        """
        return cls.from_case(ConstantSpeed(value=value))

    @classmethod
    def decelerating(cls, initial: float, duration: float) -> SpeedProfile:
        """``initial (1 - t / duration)`` [rad/s] until the disc stops at ``duration`` [s],
        then 0 (paper Eq. 1).

        Raises
        ------
        CaseError
            As a case file's ``[speed]`` table with these values would.
        """
        return cls.from_case(DeceleratingSpeed(initial=initial, duration=duration))

    @classmethod
    def accelerating(cls, initial: float, rate: float) -> SpeedProfile:
        """``initial + rate t`` [rad/s], with ``rate`` in rad/s^2 (paper Eq. 2).

        Raises
        ------
        CaseError
            As a case file's ``[speed]`` table with these values would.
        """
        return cls.from_case(AcceleratingSpeed(initial=initial, rate=rate))

    @classmethod
    def table(cls, times: Sequence[float], values: Sequence[float]) -> SpeedProfile:
        """Piecewise-linear through ``(times [s], values [rad/s])``, held at the last value.

        Raises
        ------
        CaseError
            As a case file's ``[speed]`` table with these values would.
        """
        return cls.from_case(TableSpeed(times=times, values=values))

    @classmethod
    def from_case(cls, speed: Speed) -> SpeedProfile:
        """Profile of a case's validated ``[speed]`` table (a ``fivdisc.case`` speed model)."""
        kind = speed.profile
        if kind == "constant":
            return cls(np.array([0.0]), np.array([[speed.value, 0.0, 0.0, 0.0]]), np.empty(0))
        if kind == "decelerating":
            w0, t_stop = speed.initial, speed.duration
            coef = np.array([[w0, -w0 / t_stop, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
            return cls(np.array([0.0, t_stop]), coef, np.array([t_stop]))
        if kind == "accelerating":
            return cls(
                np.array([0.0]), np.array([[speed.initial, speed.rate, 0.0, 0.0]]), np.empty(0)
            )
        t = np.asarray(speed.times, dtype=float)
        v = np.asarray(speed.values, dtype=float)
        coef = np.zeros((t.size, 4))
        coef[:, 0] = v
        coef[:, 1] = np.append(np.diff(v) / np.diff(t), 0.0)
        return cls(t, coef, t[1:].copy())

    @classmethod
    def from_override(
        cls, speed: SpeedProfile | tuple[Callable, Callable] | None, t_end: float
    ) -> SpeedProfile | None:
        """The profile a simulation uses instead of its case's ``[speed]`` table.

        Parameters
        ----------
        speed
            None (keep the case's speed), a profile, or a pair ``(Omega, Omegadot)`` of
            callables of t [s] (see :meth:`from_callables`).
        t_end
            Simulated time [s].

        Raises
        ------
        CaseError
            `speed` is none of these, or the callables cannot be represented.
        """
        if speed is None or isinstance(speed, SpeedProfile):
            return speed
        if isinstance(speed, tuple) and len(speed) == 2 and all(map(callable, speed)):
            return cls.from_callables(*speed, t_end=t_end)
        shown = repr(speed)
        if len(shown) > _SHOWN_CHARS:
            shown = shown[: _SHOWN_CHARS - 3] + "..."
        raise CaseError(
            f"speed = {shown} is invalid: must be a SpeedProfile or a pair (Omega, Omegadot) "
            "of callables of t [s]"
        )

    @classmethod
    def from_callables(
        cls,
        omega: Callable[[float], float],
        omega_dot: Callable[[float], float],
        t_end: float,
        breakpoints: Sequence[float] = (),
        rtol: float = 1e-10,
        rtol_dot: float = 1e-6,
        max_pieces: int = 200_000,
    ) -> SpeedProfile:
        """Cubic Hermite representation of a user profile on ``[0, t_end]``.

        Every piece of the interpolant P matches the callables at three interior check
        points (the Gauss-Legendre nodes of the piece, which no dyadic refinement
        revisits): ``|P - omega| <= rtol (1 + max|omega|)`` and
        ``|P' - omega_dot| <= rtol_dot (1 + max|omega_dot|)``. Pieces are halved until
        they do. First, ``omega_dot`` is compared with a Richardson-extrapolated finite
        difference of ``omega`` at 16 points of every stretch between breakpoints, so
        that a derivative that does not belong to ``omega`` is reported at once.

        Parameters
        ----------
        omega, omega_dot : callable
            Disc speed [rad/s] and its time derivative [rad/s^2] as functions of t [s].
        t_end : float
            Last time needed [s]; beyond it the last piece is extrapolated.
        breakpoints : sequence of float
            Times in (0, t_end) where ``omega_dot`` jumps [s].
        rtol : float
            Relative accuracy of Omega, in (0, 1e-3].
        rtol_dot : float
            Relative accuracy of Omegadot, in (0, 1e-3].
        max_pieces : int
            Refinement limit.

        Raises
        ------
        CaseError
            Bad arguments; Omega negative or not finite; ``omega_dot`` not the derivative
            of ``omega``; a kink not declared as a breakpoint; more than `max_pieces`
            pieces needed. The message names the time and the values.
        """
        if not (np.isfinite(t_end) and t_end > 0):
            raise CaseError(f"t_end = {t_end!r} is invalid: must be a finite time > 0 [s]")
        for name, value in (("rtol", rtol), ("rtol_dot", rtol_dot)):
            if not 0.0 < value <= _MAX_RTOL:
                raise CaseError(f"{name} = {value!r} is invalid: must lie in (0, {_MAX_RTOL}]")
        bps = sorted(float(b) for b in breakpoints)
        for b in bps:
            if not 0.0 < b < t_end:
                raise CaseError(f"breakpoint {b!r} is invalid: must lie in (0, t_end={t_end}) [s]")

        def sample(t: float, left: bool = False) -> tuple[float, float]:
            tt = float(np.nextafter(t, -np.inf)) if left else t
            w, wd = _real(omega, "Omega", tt), _real(omega_dot, "Omegadot", tt)
            if not (math.isfinite(w) and math.isfinite(wd)) or w < 0.0:
                raise CaseError(
                    f"speed profile gives Omega({t}) = {w}, Omegadot = {wd}: "
                    "Omega must be finite and >= 0 [rad/s]"
                )
            return w, wd

        edges = [0.0, *bps, float(t_end)]
        # Derivative probes: (t, stretch length), _START_PIECES per stretch.
        probes = [
            (a + (b - a) * (i + _GOLDEN) / _START_PIECES, b - a)
            for a, b in pairwise(edges)
            for i in range(_START_PIECES)
        ]
        values = [sample(t) for t, _ in probes]
        tol_w = rtol * (1.0 + max(abs(w) for w, _ in values))
        tol_wd = rtol_dot * (1.0 + max(abs(wd) for _, wd in values))
        for (t, stretch), (_, wd) in zip(probes, values, strict=True):
            _check_derivative(omega, t, wd, stretch, tol_wd)

        # Pieces as (lo, hi, (Omega, Omegadot) at lo, left limits at hi), refined depth first
        # from the left so that they come out in order of time.
        stack = []
        for a, b in pairwise(edges):
            nodes = [a + (b - a) * i / _START_PIECES for i in range(_START_PIECES + 1)]
            ends = [sample(t) for t in nodes[:-1]] + [sample(b, left=True)]
            stack += list(zip(nodes[:-1], nodes[1:], ends[:-1], ends[1:], strict=True))
        stack.reverse()
        knots: list[float] = []
        coefs: list[tuple[float, float, float, float]] = []
        min_width = _MIN_WIDTH * t_end
        while stack:
            lo, hi, p_lo, p_hi = stack.pop()
            c = _hermite(lo, hi, p_lo, p_hi)
            worst = (0.0, lo, p_lo)  # largest error in units of the tolerance, where, values
            for fraction in _CHECK_POINTS:
                tau = fraction * (hi - lo)
                point = sample(lo + tau)
                err = max(abs(_cubic(c, tau) - point[0]) / tol_w,
                          abs(_cubic_slope(c, tau) - point[1]) / tol_wd)
                worst = max(worst, (err, lo + tau, point))
            if worst[0] <= 1.0:
                knots.append(lo)
                coefs.append(c)
                continue
            if hi - lo <= min_width:
                _, t, (w, wd) = worst
                raise CaseError(
                    f"speed profile is not smooth near t = {t:.9g} s (Omega = {w:.9g} rad/s, "
                    f"Omegadot = {wd:.9g} rad/s^2): declare its kinks as breakpoints, or "
                    "loosen rtol / rtol_dot"
                )
            mid = 0.5 * (lo + hi)
            p_mid = sample(mid)
            stack += [(mid, hi, p_mid, p_hi), (lo, mid, p_lo, p_mid)]
            if len(knots) + len(stack) > max_pieces:
                raise CaseError(
                    f"speed profile needs more than {max_pieces} pieces for rtol={rtol}, "
                    f"rtol_dot={rtol_dot} (near t = {lo:.9g} s); declare its kinks as "
                    "breakpoints or loosen rtol / rtol_dot"
                )
        return cls(np.array(knots), np.array(coefs), np.array(bps), float(t_end), "callables")

    def _locate(self, t: np.ndarray) -> np.ndarray:
        return np.clip(np.searchsorted(self.knots, t, side="right") - 1, 0, None)

    def omega(self, t) -> np.ndarray:
        """Disc speed [rad/s] at times ``t`` [s] (right limits at knots)."""
        t = np.asarray(t, dtype=float)
        k = self._locate(t)
        return _cubic(np.moveaxis(self.coefficients[k], -1, 0), t - self.knots[k])

    def omega_dot(self, t) -> np.ndarray:
        """Disc angular acceleration [rad/s^2] at times ``t`` [s] (right limits at knots)."""
        t = np.asarray(t, dtype=float)
        k = self._locate(t)
        return _cubic_slope(np.moveaxis(self.coefficients[k], -1, 0), t - self.knots[k])

    def pieces(self) -> np.ndarray:
        """``(len(knots), 5)``: each piece's start [s] and its four coefficients, the form
        the compiled core reads."""
        return np.column_stack([self.knots, self.coefficients])

    def is_constant(self) -> bool:
        """Whether Omega never changes."""
        coef = self.coefficients
        return bool(np.all(coef[:, 1:] == 0.0) and np.ptp(coef[:, 0]) == 0.0)


def _real(f: Callable[[float], float], name: str, t: float) -> float:
    """``f(t)`` as a float, refused in one line unless it is a real number."""
    value = f(t)
    if isinstance(value, np.ndarray) and value.size == 1:
        value = value.reshape(()).item()
    if isinstance(value, (bool, complex, np.complexfloating, np.bool_)) or not isinstance(
            value, (int, float, np.integer, np.floating)):
        shown = repr(value)[:_SHOWN_CHARS]
        raise CaseError(f"speed callable {name}({t!r}) returned {shown} "
                        f"({type(value).__name__}): must return a real number")
    return float(value)


def _check_derivative(omega: Callable[[float], float], t: float, omega_dot: float,
                      stretch: float, tol: float) -> None:
    """Raise CaseError if `omega_dot` [rad/s^2] is not the derivative of `omega` at t [s].

    Central differences with steps h and h / 2 [s], Richardson-extrapolated, estimate the
    derivative; their difference plus the rounding error bounds how far the estimate can
    be off. h shrinks from 1e-3 of the `stretch` [s] until that bound stops improving,
    and only a mismatch beyond 10 times the bound plus `tol` [rad/s^2] is reported.
    """
    eps = float(np.finfo(float).eps)
    best = (math.inf, 0.0)  # (uncertainty, estimate)
    for h in (stretch * _FD_STEP * 0.1**i for i in range(_FD_TRIES)):
        w = [float(omega(t + s)) for s in (-h, -0.5 * h, 0.5 * h, h)]
        coarse = (w[3] - w[0]) / (2.0 * h)
        fine = (w[2] - w[1]) / h
        uncertainty = abs(fine - coarse) + 4.0 * eps * max(map(abs, w)) / h
        if uncertainty >= best[0]:
            break
        best = (uncertainty, (4.0 * fine - coarse) / 3.0)
    uncertainty, estimate = best
    if abs(omega_dot - estimate) > tol + 10.0 * uncertainty:
        raise CaseError(
            f"speed profile gives Omegadot({t:.9g}) = {omega_dot:.9g} rad/s^2, but Omega "
            f"changes at {estimate:.9g} rad/s^2 there: Omegadot must be the derivative of Omega"
        )


def _cubic(c: Sequence[Any], tau: Any) -> Any:
    """``c0 + c1 tau + c2 tau^2 + c3 tau^3`` (floats or arrays)."""
    return c[0] + tau * (c[1] + tau * (c[2] + tau * c[3]))


def _cubic_slope(c: Sequence[Any], tau: Any) -> Any:
    """Derivative of :func:`_cubic` with respect to tau."""
    return c[1] + tau * (2.0 * c[2] + 3.0 * tau * c[3])


def _hermite(
    t0: float, t1: float, p0: tuple[float, float], p1: tuple[float, float]
) -> tuple[float, float, float, float]:
    """Cubic through values and slopes at both ends of [t0, t1], in powers of t - t0."""
    h = t1 - t0
    y0, d0 = p0
    y1, d1 = p1
    delta = (y1 - y0) / h
    return (y0, d0, (3.0 * delta - 2.0 * d0 - d1) / h, (d0 + d1 - 2.0 * delta) / h**2)
