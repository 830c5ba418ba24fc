"""Lyapunov exponents of the non-smooth flow by the QR (Benettin) method.

``n`` tangent vectors are carried with the state (:mod:`fivdisc.core`, ``tangent.hpp``: the
variational equations inside each phase, saltation matrices at every switch) and
re-orthonormalised every ``interval`` seconds: ``V = Q R``; the logarithms of ``|R_ii|``
summed over the measurement and divided by its length are the exponents, largest first.
For more than one exponent two such sets, from independent random starts, are carried
and the exponents are their mean. The vectors start with the run and are carried through
the transient, so that the measurement starts from aligned directions; the uncertainty
adds the drift of the estimate (and the difference between the two starts) to its
statistical error (Notes of :func:`lyapunov`).

The orthonormalisation uses the energy norm (:func:`fivdisc.analysis.orbits.energy_scales`),
so that the result does not depend on the units of the coordinates over a finite run.
Only coordinates that are free in the current phases carry tangent components: a
direction collapsed by sticking or by a plastic impact has exponent -inf, and at most as
many exponents as free coordinates exist.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from fivdisc.case import Case
from fivdisc.engine.integration import Integration, check_steps, tangent_step
from fivdisc.engine.progress import SIMULATED_TIME, progress_bar
from fivdisc.errors import FivdiscError
from fivdisc.model.build import Model, build_model
from fivdisc.model.layout import EventKind

__all__ = ["LyapunovSpectrum", "lyapunov"]

#: The verdicts of :meth:`LyapunovSpectrum.verdict`.
POSITIVE, ZERO, NEGATIVE, UNDECIDED = "positive", "zero", "negative", "undecided"
# How many uncertainties from zero (or apart) decide a sign (or resolve two exponents):
# the reference tests find the estimates within three of their limits.
SIGNIFICANCE = 3.0

# Blocks of the run whose exponents give the uncertainty (their spread).
_BLOCKS = 10
#: Largest :attr:`LyapunovSpectrum.recurrence` of a motion that stays near a periodic
#: orbit: its sticks recur at intervals equal to 1e-2 or better. An irregular stick-slip
#: motion's intervals differ by a good part of themselves (the paper's Fig. 19a slider at
#: a constant 6 pi rad/s: 0.6); the three-pad case's motion near its unstable orbit, 3e-4.
RECURRENT = 1e-2
# Sets of tangent vectors from independent random starts for more than one exponent: the
# difference of their exponents is what the start still does to the estimate (Notes of
# `lyapunov`). The largest exponent alone keeps one set: sweeps compute it at every point.
_STARTS = 2
# [s]: the default re-orthonormalisation interval.
DEFAULT_INTERVAL = 0.05
#: Most re-orthonormalisations of one run, transient and measurement (each returns to
#: Python, and each of the measurement keeps a row of n logarithms).
MAX_INTERVALS = 1_000_000


@dataclass(frozen=True)
class LyapunovSpectrum:
    """The first ``n`` Lyapunov exponents of a run, from :func:`lyapunov`.

    Attributes
    ----------
    exponents : ndarray
        ``(n,)`` exponents [1/s], largest first.
    uncertainty : ndarray
        ``(n,)`` uncertainty of each [1/s]: the standard error from ten equal blocks of
        the measurement combined with the drift between the whole measurement's
        estimate and its second half's and, for more than one exponent, with the
        difference between two random starts (Notes of :func:`lyapunov`); an estimate of
        how far the finite-time value may be from the limit, not a bound.
    times : ndarray
        ``(m,)`` times of the re-orthonormalisations [s], from the start of the
        measurement (after the transient).
    running : ndarray
        ``(m, n)`` running estimates [1/s] at those times.
    transient, duration, interval : float
        Length of the transient, of the measurement and the re-orthonormalisation
        interval [s].
    recurrence : float
        How regularly the sliders stick over the measurement: the largest, over the
        sliders that stick at least three times, of the standard deviation of the
        intervals between a slider's successive sticks over their mean [-]; nan where
        none does. Below :data:`RECURRENT` the motion stays near a periodic orbit, and a
        positive exponent is that orbit's instability over this window, not chaos: its
        verdict is undecided (:meth:`verdict`).

    See Also
    --------
    lyapunov : Makes it.

    Examples
    --------
    A slider on a rigid disc (no modes) near its stable sliding equilibrium: both
    exponents of its mode tend to the eigenvalues' real part, -61.75 1/s.

    >>> import fivdisc
    >>> case = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5},
    ...                     speed={"value": 12.0}, simulation={"initial_state": "equilibrium"})
    >>> spectrum = fivdisc.lyapunov(case, n=2, transient=0.05, duration=0.2)
    >>> print(spectrum.times.round(2), spectrum.running.shape)  # every 0.05 s
    [0.05 0.1  0.15 0.2 ] (4, 2)
    >>> print(spectrum.exponents.round(0), spectrum.uncertainty.round(2), spectrum.conclusive)
    [-62. -62.] [0.15 0.15] [ True  True]
    >>> spectrum.to_dict()["conclusive"]
    [True, True]
    """

    exponents: np.ndarray
    uncertainty: np.ndarray
    times: np.ndarray
    running: np.ndarray
    transient: float
    duration: float
    interval: float
    recurrence: float = math.nan

    @property
    def largest(self) -> float:
        """The largest exponent [1/s]."""
        return float(self.exponents[0])

    @property
    def conclusive(self) -> np.ndarray:
        """``(n,)`` whether each exponent's sign is known at one uncertainty: its
        uncertainty is finite and smaller than its magnitude (a collapsed direction's
        -inf is known), and it is not a positive estimate of a motion whose sticks recur
        regularly (:attr:`recurrence`: near an unstable periodic orbit, which the motion
        may yet leave for a stable one). What sweeps store as
        ``largest_lyapunov_inconclusive``; the verdict (:meth:`verdict`) asks for more."""
        e, u = self.exponents, self.uncertainty
        with np.errstate(invalid="ignore"):
            known = np.isneginf(e) | (np.isfinite(e) & np.isfinite(u) & (u < np.abs(e)))
            return known & ~((e > 0) & (self.recurrence < RECURRENT))

    @property
    def verdicts(self) -> tuple[str, ...]:
        """Each exponent's :meth:`verdict`."""
        return tuple(self.verdict(i) for i in range(self.exponents.size))

    @property
    def decided(self) -> np.ndarray:
        """``(n,)`` whether each exponent's verdict is decided (not ``"undecided"``)."""
        return np.array([v != UNDECIDED for v in self.verdicts], dtype=bool)

    def bounds(self, i: int, k: float = SIGNIFICANCE) -> tuple[float, float]:
        """Where the i-th largest exponent lies if each estimate lies within ``k`` of its
        uncertainties of its limit: between the i-th largest of the estimates' lower
        ends and the i-th largest of their upper ends (a finite run may measure the
        exponents in another order than their limits'). An unknown uncertainty leaves
        that exponent anywhere; -inf stays -inf."""
        e, u = self.exponents, self.uncertainty
        with np.errstate(invalid="ignore"):
            unknown = ~np.isfinite(u) & ~np.isneginf(e)
            low = np.where(unknown, -np.inf, np.where(np.isneginf(e), -np.inf, e - k * u))
            high = np.where(unknown, np.inf, np.where(np.isneginf(e), -np.inf, e + k * u))
        return float(np.sort(low)[::-1][i]), float(np.sort(high)[::-1][i])

    def verdict(self, i: int) -> str:
        """What exponent ``i`` is at this length of measurement: ``"positive"``,
        ``"negative"``, ``"zero"`` (consistent with zero) or ``"undecided"``.

        With ``u`` the uncertainties, each limit is taken to lie within ``3 u`` of its
        estimate (how far the estimates of the reference tests lie from their limits at
        most), so that the i-th largest exponent lies within :meth:`bounds`: it is
        positive or negative where those exclude zero (a collapsed direction's -inf is
        negative). It is zero where the bounds at one uncertainty hold zero and another
        exponent, decided positive or negative, has bounds apart from its own: the
        interval around zero is then narrow against a rate the motion does have (on a
        periodic orbit, the flow direction's 0 against the slowest attraction).
        Otherwise it is undecided: an uncertainty is unknown, it lies between one and
        three uncertainties from zero (neither near it nor clearly away), or no other
        exponent measures the scale (with one exponent, none: compute two). A longer
        measurement shrinks ``u`` and decides it. A positive exponent of a motion whose
        sticks recur regularly (:attr:`recurrence` below :data:`RECURRENT`) is undecided
        too: the motion stays near an unstable periodic orbit over the measurement, and
        whether it leaves it for chaos or for a stable orbit a longer transient tells.
        """
        low, high = self.bounds(i)
        if low > 0:
            return UNDECIDED if self.recurrence < RECURRENT else POSITIVE
        if high < 0:
            return NEGATIVE
        near_low, near_high = self.bounds(i, 1.0)
        if near_low <= 0 <= near_high and np.isfinite(near_high - near_low) and (
                self._resolved_by(i) is not None):
            return ZERO
        return UNDECIDED

    def _resolved_by(self, i: int) -> int | None:
        """The exponent nearest to exponent ``i`` of those decided positive or negative
        whose :meth:`bounds` are apart from exponent ``i``'s (None if none)."""
        low, high = self.bounds(i)
        best = None
        for j in range(self.exponents.size):
            if j == i:
                continue
            other_low, other_high = self.bounds(j)
            decided = other_low > 0 or other_high < 0
            if decided and np.isfinite(other_high) and (other_high < low or other_low > high):
                if best is None or abs(j - i) < abs(best - i):
                    best = j
        return best

    def explain(self, i: int) -> str:
        """Exponent ``i``, its verdict and what the verdict rests on, in one line."""
        e, u = float(self.exponents[i]), float(self.uncertainty[i])
        name = f"lambda_{i + 1}"
        verdict = self.verdict(i)
        low, high = self.bounds(i)
        if np.isneginf(e) and verdict == NEGATIVE:
            return f"{name} = -inf: negative (a direction collapsed by sticking or impact)"
        head = (f"{name} = {e:+.6g} +- {u:.2g} 1/s" if np.isfinite(u)
                else f"{name} = {e:+.6g} 1/s")
        if verdict in (POSITIVE, NEGATIVE):
            return (f"{head}: {verdict} (between {low:+.3g} and {high:+.3g} 1/s at "
                    f"{SIGNIFICANCE:g} uncertainties)")
        if verdict == ZERO:
            j = self._resolved_by(i)
            return (f"{head}: consistent with zero (within one uncertainty, and resolved "
                    f"from lambda_{j + 1} = {self.exponents[j]:+.6g} 1/s)")
        if low > 0:
            return (f"{head}: undecided at this length: positive over the measurement, "
                    f"but the sliders' sticks recur to {self.recurrence:.1e} of their "
                    "interval, so the motion stays near a periodic orbit that is unstable; "
                    "lengthen the transient to see whether it leaves it")
        few = ("too few re-orthonormalisations: lengthen the measurement or shorten the "
               "interval")
        if not np.isfinite(u):
            return f"{head}: undecided, no uncertainty estimate ({few})"
        if not np.all(np.isfinite(self.uncertainty) | np.isneginf(self.exponents)):
            return (f"{head}: undecided: another exponent has no uncertainty estimate, so "
                    f"that this one's place in their order is unknown ({few})")
        near_low, near_high = self.bounds(i, 1.0)
        if near_low <= 0 <= near_high and self.exponents.size == 1:
            return (f"{head}: undecided: within one uncertainty of zero, and no other "
                    "exponent tells how narrow that is; compute two (n = 2, --n 2)")
        where = (f"it lies between {low:+.3g} and {high:+.3g} 1/s (at {SIGNIFICANCE:g} "
                 "uncertainties, the estimates taken in any order)")
        if not near_low <= 0 <= near_high:
            why = f"{where}, not within one uncertainty of zero"
        else:
            why = (f"{where}, within one uncertainty of zero but not resolved from an "
                   "exponent decided non-zero")
        return (f"{head}: undecided at this length: {why}; lengthen the measurement, or "
                "the transient if the estimate still drifts")

    def _word(self, i: int) -> str:
        """The verdict as the text output shows it."""
        verdict = self.verdict(i)
        if verdict == ZERO:
            return "consistent with zero"
        if verdict != UNDECIDED:
            return verdict
        near_low, near_high = self.bounds(i, 1.0)
        if self.exponents.size == 1 and near_low <= 0 <= near_high < np.inf:
            return "undecided (one exponent: compute two)"
        return "undecided at this length"

    def to_dict(self) -> dict:
        """Exponents [1/s] (largest first), their uncertainty and verdicts as plain JSON
        types (-inf, for a collapsed direction, as ``null``); ``verdict`` is the largest
        exponent's."""
        def plain(values):
            return [float(v) if np.isfinite(v) else None for v in values]

        verdicts = list(self.verdicts)
        return {"exponents": plain(self.exponents), "uncertainty": plain(self.uncertainty),
                "verdicts": verdicts, "verdict": verdicts[0],
                "conclusive": [bool(c) for c in self.conclusive],
                "transient": self.transient, "duration": self.duration,
                "interval": self.interval,
                "recurrence": self.recurrence if np.isfinite(self.recurrence) else None}

    def to_json(self) -> str:
        """:meth:`to_dict` as indented JSON (what ``fivdisc lyapunov --json`` prints)."""
        return json.dumps(self.to_dict(), indent=2)

    def to_dataset(self):
        """The spectrum and its running estimates as an :class:`xarray.Dataset`."""
        import xarray as xr

        return xr.Dataset(
            {
                "exponent": ("index", self.exponents,
                             {"long_name": "Lyapunov exponent", "units": "s-1"}),
                "uncertainty": ("index", self.uncertainty,
                                {"long_name": "uncertainty of the exponent (standard "
                                            "error, drift, difference of starts)",
                                 "units": "s-1"}),
                "running": (("time", "index"), self.running,
                            {"long_name": "running estimate of the exponent",
                             "units": "s-1"}),
            },
            coords={"index": np.arange(self.exponents.size),
                    "time": ("time", self.times, {"long_name": "time after the transient",
                                                  "units": "s"})},
            attrs={"transient": self.transient, "duration": self.duration,
                   "interval": self.interval, "time_units": "s"},
        )

    def __str__(self) -> str:
        lines = [f"Lyapunov exponents over {self.duration:g} s after a {self.transient:g} s "
                 f"transient (QR every {self.interval:g} s) [1/s]:"]
        for i, (e, u) in enumerate(zip(self.exponents, self.uncertainty, strict=True)):
            lines.append(f"  lambda_{i + 1} = {e:+.6g} +- {u:.2g}  {self._word(i)}")
        return "\n".join(lines)


def lyapunov(
    case: Case,
    n: int = 1,
    *,
    transient: float | None = None,
    duration: float | None = None,
    interval: float | None = None,
    initial=None,
    rtol: float | None = None,
    atol: float | None = None,
    seed: int = 0,
    progress: bool = False,
) -> LyapunovSpectrum:
    r"""The first ``n`` Lyapunov exponents of a case's trajectory.

    Parameters
    ----------
    case : Case
        The case; any speed profile (for a varying speed the exponents are those of
        the finite run).
    n : int
        How many exponents, at most the number of coordinates free at the start.
    transient : float, optional
        Simulated time before the measurement starts [s]; default a fifth of the case's
        ``simulation.duration``. The tangent vectors align with the most expanding
        directions over it (Notes): it should last several times ``1 / (lambda_n -
        lambda_(n+1))``.
    duration : float, optional
        Length of the measurement [s]; default the case's ``simulation.duration``.
    interval : float, optional
        Re-orthonormalisation interval [s]; default 0.05 s, or the whole measurement
        when that is shorter. Shorter keeps the vectors well apart when
        the exponents differ widely (the n-th loses about ``(lambda_1 - lambda_n)
        interval / ln 10`` digits against the first); the exponents do not depend on it
        otherwise. Each re-orthonormalisation returns to Python (about 0.1 ms), so the
        default (a few stick-slip cycles of brake squeal) keeps that a small part of the
        run.
    initial : optional
        Initial state, as for :func:`fivdisc.simulate`.
    rtol, atol : float, optional
        Integration tolerances (default the case's). The step is also capped at
        :func:`fivdisc.engine.integration.tangent_step`, so that the tangent dynamics is
        resolved where the state alone would allow long steps.
    seed : int
        Seed of the random tangent vectors at the start of the transient.
    progress : bool
        Show a progress bar in simulated time over the transient and the measurement (on
        a terminal).

    Returns
    -------
    LyapunovSpectrum
        The exponents, largest first, with their uncertainties and running estimates.

    See Also
    --------
    fivdisc.periodic_orbit : A periodic orbit and its Floquet multipliers, whose
        ``ln|multiplier| / T`` are the Lyapunov exponents of the orbit.
    fivdisc.linear_stability : At a stable sliding equilibrium, the eigenvalues'
        real parts are the exponents.

    Notes
    -----
    **Method.** ``n`` tangent vectors, the columns of ``V``, are carried with the state
    by the linearised equations and across every switch by its saltation matrix. Every
    ``interval`` they are orthonormalised, ``V = Q R``, ``V <- Q``; with ``R^(k)`` the
    factor at the k-th time ``t_k`` of the measurement (``k = 1 ... m``, ``t_m = T``),

    .. math::

        \lambda_i = \frac{1}{T} \sum_{k=1}^{m} l_i^{(k)}, \qquad
        l_i^{(k)} = \ln \lvert R_{ii}^{(k)} \rvert.

    **Alignment.** From random vectors, the QR method measures the exponents only once
    the vectors have turned into the most expanding directions. Until then the k-th
    vector grows more slowly than ``lambda_k``, and the deficit decays like
    ``exp(-(lambda_k - lambda_(k+1)) t)``: with gaps of a few tenths of 1/s, as between
    the lightly damped modes of a disc, that takes seconds, and a measurement started
    from random vectors is biased by the deficit divided by its length. The vectors
    therefore start at random with the run and are carried through the transient,
    re-orthonormalised every ``interval`` as in the measurement, their stretching
    discarded. The transient serves both purposes: the trajectory forgets its start on
    it, and so do the vectors.

    **Uncertainty.** For ``n > 1`` two sets of vectors from independent random starts
    give ``lambda_i^a`` and ``lambda_i^b``, and the reported exponent and the terms below
    are those of their mean; for ``n = 1`` the last term is 0. Split into
    ``B = min(10, m)`` equal blocks of rates ``lambda_i^(b)``, the standard error is
    ``s_i = std_b(lambda_i^(b)) / sqrt(B)`` (sample standard deviation); the estimate
    over the second half is ``lambda_i'' = sum_(k > m/2) l_i^(k) / (T - t_(m/2))``, and

    .. math::

        u_i = \sqrt{s_i^2 + (\lambda_i - \lambda_i'')^2 + (\lambda_i^a - \lambda_i^b)^2}.

    The drift term measures a finite-time bias the block spread does not: a deficit
    ``C`` accumulated early in the measurement (the last of the alignment, or the
    ``ln(kappa)`` of a non-normal linearisation) biases ``lambda_i`` by ``C / T`` and
    the second half by little, so their difference is about the bias of the whole.
    Where the estimate only fluctuates the drift is of the size of ``s_i``. The last
    term is what the random start still does to the estimate: once both sets have
    aligned they are the same vectors and it vanishes, chaotic or not; while they align
    their deficits differ. The largest exponent alone is computed from one start: it is
    what sweeps compute at every point, and a second set of vectors would add to the
    cost of each, for a direction that the first vector, the fastest to align, finds
    soonest.

    **Limits.** A vector whose start had almost nothing along its direction measures the
    next exponent until it turns, steadily, after about ``ln(1/p) / (lambda_k -
    lambda_(k+1))`` for a start's component ``p``; if every start is like that (a
    direction that random vectors in the energy norm barely touch) no estimate from the
    run sees it. Doubling the transient and comparing is the check.

    **Cost.** The transient runs with the tangent vectors instead of a plain run, and
    for ``n > 1`` with twice the vectors; each vector carried adds to the cost of a step
    (``benchmarks/bench_tangent.py`` measures it). The documentation's tutorial
    "Periodic orbits, Floquet multipliers and Lyapunov exponents" gives the measured
    costs and the checks of the uncertainty against known exponents.

    Examples
    --------
    At a stable sliding equilibrium the exponents are the real parts of the
    linearisation's eigenvalues. A slider on a rigid disc (no modes), started near its
    equilibrium at 12 rad/s, where its rotational damping exceeds the friction's
    negative damping:

    >>> import fivdisc
    >>> case = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5},
    ...                     speed={"value": 12.0}, simulation={"initial_state": "equilibrium"})
    >>> spectrum = fivdisc.lyapunov(case, transient=0.05, duration=0.2)
    >>> print(f"{spectrum.largest:.0f} +- {spectrum.uncertainty[0]:.1f} 1/s, "
    ...       f"{spectrum.verdict(0)}")
    -62 +- 0.3 1/s, negative
    >>> print(f"{fivdisc.linear_stability(case).max_growth_rate:.2f} 1/s")
    -61.75 1/s

    On a periodic orbit they are its Floquet exponents: here the stick-slip orbit of a
    slider with constant kinetic friction on a disc of one axisymmetric mode, whose
    first exponent (the flow direction's) is 0 and whose next two (the disc mode's
    pair) are -4.726 1/s. Over 2 s the first is undecided, its range (2.4 1/s either
    way) reaching the next; over 5 s it is resolved from them (its verdict,
    :meth:`LyapunovSpectrum.verdict`):

    >>> orbit_case = fivdisc.Case(
    ...     disc={"modes": [[0, 0]]},
    ...     slider={"rotational_damping": 0.0, "normal_damping": 5.0},
    ...     friction={"kinetic_max": 0.5, "kinetic_min": 0.5},
    ...     speed={"value": 1.0},
    ... )
    >>> print(fivdisc.lyapunov(orbit_case, n=3, transient=1.0, duration=2.0))
    Lyapunov exponents over 2 s after a 1 s transient (QR every 0.05 s) [1/s]:
      lambda_1 = ... +- 2...  undecided at this length
      lambda_2 = -4.7... +- 0.06...  negative
      lambda_3 = -4.7... +- 0.06...  negative
    >>> fivdisc.lyapunov(orbit_case, n=3, transient=1.0, duration=5.0).verdicts
    ('zero', 'negative', 'negative')
    """
    sim = case.simulation
    transient = 0.2 * sim.duration if transient is None else transient
    duration = sim.duration if duration is None else duration
    if interval is None:
        interval = min(DEFAULT_INTERVAL, duration) if duration > 0 else DEFAULT_INTERVAL
    from fivdisc.analysis.checks import check_time

    check_time("transient", transient, zero=True)
    check_time("duration", duration)
    check_time("interval", interval)
    if not interval <= duration:
        raise FivdiscError(f"interval = {interval!r} is invalid: must be <= duration [s]")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise FivdiscError(f"n = {n!r} is invalid: must be an integer >= 1")
    from fivdisc.engine.simulation import Deflection, initial_state

    model = build_model(case)
    check_steps(model, transient + duration, "transient + duration")
    # After check_steps, which names a transient or duration too long to run at all.
    if (transient + duration) / interval > MAX_INTERVALS:
        raise FivdiscError(
            f"interval = {interval!r} is invalid: (transient + duration) / interval = "
            f"{(transient + duration) / interval:.3g} re-orthonormalisations, more than "
            f"{MAX_INTERVALS:g}; must be >= (transient + duration) / 1e6 [s]")
    cap = tangent_step(model)
    if sim.max_step > 0:
        cap = min(cap, sim.max_step)
    run = Integration(model, initial_state(model, initial), duration=transient + duration,
                      rtol=rtol, atol=atol, max_step=cap)
    run.advance(0.0)
    # The phases at the start are chosen by the first advance.
    free = run.free()
    if n > free.sum():
        raise FivdiscError(f"n = {n} is invalid: must be at most {int(free.sum())}, the "
                           "number of coordinates free at the start (where the tangent "
                           "vectors start)")
    limit = Deflection(model)
    # One bar in simulated time over the transient and the measurement: a long transient
    # is the first minutes of a run.
    bar = progress_bar(transient + duration, "Lyapunov exponents", "s", show=progress,
                       bar_format=SIMULATED_TIME)
    try:
        spectrum = _measure(run, model, limit, free, n, seed, transient, duration, interval,
                            progress, bar)
    finally:
        bar.close()
    return spectrum


def _measure(run: Integration, model: Model, limit: Any, free: np.ndarray, n: int,
             seed: int | None, transient: float, duration: float, interval: float,
             progress: bool, bar: Any) -> LyapunovSpectrum:
    """Align random tangent vectors over the transient, then measure the exponents over
    `duration`, with `bar` counting both."""
    from fivdisc.analysis.orbits import energy_scales

    sc = energy_scales(model)
    rng = np.random.default_rng(seed)
    starts = _STARTS if n > 1 else 1
    q = np.hstack([np.linalg.qr(rng.standard_normal((model.state_size, n)) * free[:, None])[0]
                   for _ in range(starts)])
    aligning = transient > 0
    t0 = run.t
    run.set_tangents((q * sc[:, None]).T)
    first = _interval(run, limit, min(interval, transient if aligning else duration), sc,
                      starts, "the transient" if aligning else "the measurement")
    bar.update(run.t - bar.n)
    # Alignment: the vectors are carried through the transient and re-orthonormalised as
    # in the measurement, their stretching discarded, so that the measurement starts from
    # directions that have forgotten their random start (Notes of `lyapunov`).
    k = 2
    while aligning and run.t < transient:
        _interval(run, limit, min(k * interval, transient), sc, starts, "the transient")
        bar.update(run.t - bar.n)
        k += 1
    if aligning:
        t0 = run.t
    steps = int(np.ceil(duration / interval - 1e-9))
    logs = np.zeros((steps, starts * n))
    times = np.zeros(steps)
    for k in range(steps):
        if k or aligning:
            logs[k] = _interval(run, limit, min(t0 + (k + 1) * interval, transient + duration),
                                sc, starts, "the measurement")
        else:
            logs[k] = first
        times[k] = run.t - t0
        bar.update(run.t - bar.n)
    # Over a finite run the QR order need not be the order of the values: sort each start's.
    sets = [part[:, np.argsort(-part.sum(axis=0), kind="stable")]
            for part in np.split(logs, starts, axis=1)]
    logs = np.mean(sets, axis=0)
    exponents = logs.sum(axis=0) / times[-1]
    running = np.cumsum(logs, axis=0) / times[:, None]
    with np.errstate(invalid="ignore"):
        spread = np.ptp([part.sum(axis=0) / times[-1] for part in sets], axis=0)
    return LyapunovSpectrum(exponents, _uncertainty(logs, times, exponents, spread), times,
                            running, float(transient), float(duration), float(interval),
                            _recurrence(run, t0))


def _recurrence(run: Integration, since: float) -> float:
    """:attr:`LyapunovSpectrum.recurrence` of the run's sticks after ``since`` [s]."""
    times, rows = run.events()
    keep = (rows[:, 0] == EventKind.STICK) & (times >= since)
    spreads = []
    for j in np.unique(rows[keep, 3]):
        gaps = np.diff(times[keep & (rows[:, 3] == j)])
        if gaps.size >= 2:
            spreads.append(gaps.std() / gaps.mean())
    return float(max(spreads)) if spreads else math.nan


def _uncertainty(logs: np.ndarray, times: np.ndarray, exponents: np.ndarray,
                 spread: np.ndarray) -> np.ndarray:
    """Standard error of ten blocks combined with the drift from the second half's
    estimate and the spread between the starts (formula in Notes of `lyapunov`); NaN with
    fewer than two intervals."""
    steps = len(times)
    if steps < 2:
        return np.full(logs.shape[1], np.nan)
    blocks = np.array_split(np.arange(steps), min(_BLOCKS, steps))
    edges = np.r_[0.0, times]
    half = steps // 2
    with np.errstate(invalid="ignore"):
        rates = np.array([logs[b].sum(axis=0) / (edges[b[-1] + 1] - edges[b[0]])
                          for b in blocks])
        error = rates.std(axis=0, ddof=1) / np.sqrt(len(blocks))
        later = logs[half:].sum(axis=0) / (times[-1] - times[half - 1])
        return np.sqrt(error**2 + (exponents - later) ** 2 + spread**2)


def _interval(run: Integration, limit: Any, target: float, sc: np.ndarray, starts: int,
              what: str) -> np.ndarray:
    """Integrate to `target`, re-orthonormalise each start's tangent vectors (energy norm)
    and return the logarithms of their stretching factors, start after start."""
    run.run_to(target)
    _check(run, limit, what)
    vectors = run.tangents(slaved=False).T / sc[:, None]
    stretch = np.empty(vectors.shape[1])
    for cols in np.split(np.arange(vectors.shape[1]), starts):
        q, r = np.linalg.qr(vectors[:, cols])
        diag = np.diag(r)
        vectors[:, cols] = q * np.where(diag < 0, -1.0, 1.0)
        stretch[cols] = np.abs(diag)
    run.set_tangents((vectors * sc[:, None]).T)
    with np.errstate(divide="ignore"):
        return np.log(stretch)


def _check(run: Integration, limit, what: str) -> None:
    """Refuse to go on from a run that failed or left the model's range (as
    :func:`fivdisc.simulate` would call it diverged): its exponents would describe a
    blow-up, not the case."""
    if limit.beyond(run.y):
        raise FivdiscError(f"lyapunov: the run diverged during {what}: "
                           f"{limit.message(run.t)}")
    if run.status_name not in ("running", "success"):
        raise FivdiscError(f"lyapunov: the run ended with {run.status_name} at "
                           f"t = {run.t:.9g} s during {what}")

