"""Periodic orbits of the non-smooth flow by shooting, and their Floquet multipliers.

The orbit is a fixed point of the flow map over its period T: unknowns are the free
coordinates of a point x0 on it and T; the equations are ``phi_T(x0) - x0 = 0`` and the
phase condition ``f(x0_ref) . (x0 - x0_ref) = 0`` (the correction is orthogonal to the
flow, which removes the freedom to slide x0 along the orbit). Newton's method uses the
monodromy matrix ``M = d phi_T / d x0``, carried exactly across every switch by the
saltation matrices (:mod:`fivdisc.core`, ``tangent.hpp``), and ``d phi_T / dT = f(phi_T(x0))``.

A converged orbit is reduced to its minimal period: an orbit of period T is also a fixed
point of the flow over 2T, 3T, ..., so a first guess near a multiple of the period
converges there. The flow from x0 over T/k is tried for k up to 12, and the largest k
at which the orbit closes is solved again.

The Floquet multipliers are the eigenvalues of ``M``. An autonomous orbit has one equal
to 1 (the flow direction); a direction collapsed by the flow (onto the stick manifold at
slip-to-stick, by a plastic impact) or a coordinate that is not free at x0 (``z``,
``zdot`` of a slider in contact, ``phidot`` of a sticking one) gives a multiplier 0.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from os import PathLike

import numpy as np

from fivdisc.analysis.checks import check_tol
from fivdisc.case import Case
from fivdisc.engine.integration import Integration, LongRunNotice, tangent_step
from fivdisc.errors import ConvergenceError, FivdiscError
from fivdisc.model import layout as lay
from fivdisc.model.build import Model, build_model

__all__ = ["PeriodicOrbit", "Shooting", "periodic_orbit", "saved_start"]

VERDICTS = ("stable", "unstable", "not converged")
# Halvings of a Newton step that does not reduce the residual before giving up.
_HALVINGS = 6
# Largest divisor of a converged period tried when reducing it to the minimal period.
_MAX_DIVISOR = 12
# A return at T/k closer than this (the residual's measure) is solved again at T/k.
_CLOSES = 1e-4
# h omega of the shooting runs' step cap (integration.tangent_step): the monodromy's
# eigenvalues are then right to about 1e-8 at rtol 1e-12. With the default 0.5, where the
# cap sets the steps (a stick phase, a disc mode at rest) the disc mode's multipliers of
# the rigid-disc oscillator were off by up to 4e-6, depending on where the steps fell
# (1e-8 at 0.1, 3e-7 at 0.25).
_SHOOTING_STEP = 0.15
# A converged orbit whose residual is above this fraction of the tolerance gets one more
# Newton step.
_POLISH = 1e-2
@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit found by :func:`periodic_orbit`.

    Attributes
    ----------
    period : float
        T [s].
    state : ndarray
        A point on the orbit (the state layout of :mod:`fivdisc.model.layout`, the
        contact coordinates filled in as a run's output has them).
    phases : ndarray of int
        Each slider's phase at that point (0 slip, 1 stick, 2 separation).
    monodromy : ndarray
        ``d phi_T / d x0`` at that point, ``(2 (n + 2 S),) * 2``.
    multipliers : ndarray of complex
        Its eigenvalues, largest modulus first.
    trivial : int
        Index in ``multipliers`` of the flow direction's multiplier (1).
    residual : float
        ``|phi_T(x0) - x0|`` at the last iterate, in the energy norm
        (:func:`fivdisc.analysis.orbits.energy_scales`) relative to the orbit's size
        ``|f(x0)| T``.
    iterations : int
        Newton iterations taken.
    verdict : str
        ``"stable"`` (every other multiplier inside the unit circle), ``"unstable"`` or
        ``"not converged"``.
    labels : tuple of str
        Names of the state's coordinates.
    start : str
        Where the search started (a transient from the case's initial state, a given
        state, a file): coexisting orbits of nearly the same period are told apart by it.

    See Also
    --------
    periodic_orbit : Makes it.
    fivdisc.continue_orbit : Follows it as a case key changes.

    Examples
    --------
    The stick-slip orbit of a slider with constant kinetic friction on a disc of one
    axisymmetric mode (the textbook mass on a belt, whose orbit has a closed form):

    >>> import fivdisc
    >>> case = fivdisc.Case(
    ...     disc={"modes": [[0, 0]]},
    ...     slider={"rotational_damping": 0.0, "normal_damping": 5.0},
    ...     friction={"kinetic_max": 0.5, "kinetic_min": 0.5},
    ...     speed={"value": 1.0},
    ... )
    >>> orbit = fivdisc.periodic_orbit(case, transient=1.0)
    >>> orbit.labels
    ('q_C00', 'phi_0', 'z_0', 'q_C00_dot', 'phi_0_dot', 'z_0_dot')
    >>> orbit.monodromy.shape, orbit.trivial, orbit.verdict
    ((6, 6), 0, 'stable')

    The Floquet exponents ``ln|multiplier| / T`` [1/s] of the disc mode's pair (the
    first is the flow direction's, 0; the directions that sticking and the contact
    collapse have multipliers 0, to round-off):

    >>> print(orbit.exponents()[1:3].round(3))
    [-4.726 -4.726]

    ``orbit.to_dataset().to_netcdf("orbit.nc")`` keeps it with its monodromy matrix.
    """

    period: float
    state: np.ndarray
    phases: np.ndarray
    monodromy: np.ndarray
    multipliers: np.ndarray
    trivial: int
    residual: float
    iterations: int
    verdict: str
    labels: tuple[str, ...] = field(default=())
    start: str = ""

    @property
    def converged(self) -> bool:
        """Whether Newton shooting converged: only then is this a periodic orbit, and
        its multipliers its Floquet multipliers."""
        return self.verdict != "not converged"

    @property
    def moduli(self) -> np.ndarray:
        """|multiplier| [-]."""
        return np.abs(self.multipliers)

    @property
    def largest(self) -> float:
        """Largest modulus of the multipliers other than the flow direction's."""
        others = np.delete(self.moduli, self.trivial)
        return float(others.max()) if others.size else 0.0

    def exponents(self) -> np.ndarray:
        """Floquet exponents log|multiplier| / T [1/s] (-inf for a zero multiplier)."""
        with np.errstate(divide="ignore"):
            return np.log(self.moduli) / self.period

    def to_dict(self) -> dict:
        """The orbit as plain JSON types: whether it converged, period [s], multipliers
        (real, imag, modulus), verdict, residual, where the search started."""
        return {
            "converged": self.converged,
            "period": self.period,
            "multipliers": [{"real": float(m.real), "imag": float(m.imag),
                             "modulus": float(abs(m))} for m in self.multipliers],
            "verdict": self.verdict,
            "residual": self.residual,
            "iterations": self.iterations,
            "start": self.start,
        }

    def to_json(self) -> str:
        """:meth:`to_dict` as indented JSON (what ``fivdisc orbit --json`` prints)."""
        return json.dumps(self.to_dict(), indent=2)

    def to_dataset(self):
        """The orbit as an :class:`xarray.Dataset` (for netCDF)."""
        import xarray as xr

        n = self.state.size
        coord = np.arange(n)
        ds = xr.Dataset(
            {
                "state": ("coordinate", self.state,
                          {"long_name": "point on the orbit (state layout)"}),
                "monodromy": (("coordinate", "initial_coordinate"), self.monodromy,
                              {"long_name": "monodromy matrix d phi_T / d x0",
                               "units": "1"}),
                "multiplier_real": ("multiplier", self.multipliers.real,
                                    {"long_name": "Floquet multiplier, real part",
                                     "units": "1"}),
                "multiplier_imag": ("multiplier", self.multipliers.imag,
                                    {"long_name": "Floquet multiplier, imaginary part",
                                     "units": "1"}),
                "multiplier_modulus": ("multiplier", self.moduli,
                                       {"long_name": "Floquet multiplier, modulus",
                                        "units": "1"}),
                "phase": ("slider", self.phases,
                          {"long_name": "phase at the point (0 slip, 1 stick, 2 separation)"}),
            },
            coords={"coordinate": coord, "initial_coordinate": coord,
                    "multiplier": np.arange(self.multipliers.size),
                    "slider": np.arange(self.phases.size),
                    "label": ("coordinate", list(self.labels or map(str, coord)))},
            attrs={"period": self.period, "period_units": "s", "verdict": self.verdict,
                   "residual": self.residual, "iterations": self.iterations,
                   "trivial_multiplier": self.trivial, "converged": int(self.converged),
                   "start": self.start, "content": "periodic orbit"},
        )
        return ds

    def __str__(self) -> str:
        if not self.converged:
            return (f"no periodic orbit: Newton shooting did not converge (residual "
                    f"{self.residual:.2e} after {self.iterations} iteration"
                    f"{'' if self.iterations == 1 else 's'}, last period {self.period:.9g} s; "
                    f"started {self.start or 'from the given state'})")
        lines = [f"periodic orbit: T = {self.period:.9g} s ({1 / self.period:.6g} Hz), "
                 f"{self.verdict}, residual {self.residual:.2e} after {self.iterations} "
                 f"Newton iteration{'' if self.iterations == 1 else 's'}",
                 f"started {self.start}" if self.start else "",
                 "Floquet multipliers (modulus, real, imag):"]
        for i, m in enumerate(self.multipliers):
            note = "  flow direction" if i == self.trivial else ""
            lines.append(f"  {abs(m):.9f}  {m.real:+.9f}  {m.imag:+.9f}{note}")
        return "\n".join(line for line in lines if line)


def state_labels(model: Model) -> tuple[str, ...]:
    """Names of the state's coordinates: ``q_C01``, ``phi_0``, ``z_0`` and their rates
    (sliders numbered from 0, as ``sliders.J`` in a case)."""
    ns = model.n_sliders
    pos = ([f"q_{lab}" for lab in model.labels] + [f"phi_{j}" for j in range(ns)]
           + [f"z_{j}" for j in range(ns)])
    return tuple(pos + [f"{p}_dot" for p in pos])


def energy_scales(model: Model) -> np.ndarray:
    """Per coordinate, the size whose energy is 1 J: ``1 / sqrt(K)`` for a displacement
    of stiffness K (modal ``M omega^2``, ``r^2 k_phi``, ``k_z``), ``1 / sqrt(M)`` for a
    rate of inertia M. Dividing by it makes distances between states energy-like and
    free of units."""
    kern = model.kernel
    stiff = np.r_[model.modal_mass * model.omega**2, kern.row("kphi"), kern.row("kz")]
    mass = np.r_[model.modal_mass, kern.row("inertia"), kern.row("mass")]
    return 1.0 / np.sqrt(np.r_[stiff, mass])


@dataclass
class Shot:
    """One run of the flow map: the state reached, the monodromy (None without tangents),
    the vector field at both ends, and the coordinates free at the start."""

    end: np.ndarray
    monodromy: np.ndarray | None
    rate_end: np.ndarray
    rate_start: np.ndarray
    free: np.ndarray


class Shooting:
    """The flow map of a model over a time from a start whose phases are given, with its
    Jacobian: what Newton shooting (:func:`periodic_orbit`) and continuation
    (:func:`fivdisc.continuation.walk.continue_orbit`) solve.

    Parameters
    ----------
    model : Model
        The model.
    phases : array of int
        Each slider's phase at the start.
    rtol, atol : float
        Integration tolerances.
    scale : ndarray, optional
        Per coordinate, the size distances are measured in (default
        :func:`energy_scales` of `model`; a continuation keeps its first point's).
    """

    def __init__(self, model: Model, phases: np.ndarray, rtol: float, atol: float,
                 scale: np.ndarray | None = None) -> None:
        self.model = model
        self.phases = np.asarray(phases, dtype=np.int64)
        self.rtol, self.atol = rtol, atol
        self.scale = energy_scales(model) if scale is None else scale
        # Steps capped at tangent_step, so that directions the orbit hardly excites are
        # integrated stably and accurately at any rtol.
        cap = tangent_step(model, _SHOOTING_STEP)
        if model.case.simulation.max_step > 0:
            cap = min(cap, model.case.simulation.max_step)
        self.cap = cap
        # A time.monotonic() past which a shot stops (OutOfTime); None: no limit.
        self.deadline: float | None = None

    def at(self, model: Model) -> Shooting:
        """The same shooting (phases, tolerances, scales) on another model."""
        return Shooting(model, self.phases, self.rtol, self.atol, self.scale)

    def shoot(self, x0: np.ndarray, period: float, tangents: bool = True) -> Shot:
        """The flow map over ``period`` [s] from ``x0``, with its Jacobian if asked.

        Raises
        ------
        FivdiscError
            The run did not reach ``period`` (divergence, endless switching, ...).
        """
        nd = self.model.state_size
        run = Integration(self.model, x0, duration=period, output_rate=1.0 / period,
                          rtol=self.rtol, atol=self.atol, max_step=self.cap,
                          phases=self.phases)
        if tangents:
            run.set_tangents(np.eye(nd))
        run.advance(0.0)
        rate_start = run.rhs()
        free = run.free()
        run.run_to(period, self.deadline)
        if run.status_name == "running":
            raise OutOfTime(f"the time budget ran out during a run over the period "
                            f"({period:.6g} s) at t = {run.t:.9g} s")
        if run.status_name != "success":
            raise FivdiscError(f"the run over one period ({period:.6g} s) ended with "
                               f"{run.status_name} at t = {run.t:.9g} s")
        end = run.out_y[1, :nd].copy()
        return Shot(end, run.tangents().T if tangents else None, run.rhs(), rate_start, free)

    def gap(self, shot: Shot, x0: np.ndarray) -> np.ndarray:
        """``(phi_T(x0) - x0) / scale`` on the free coordinates."""
        free = shot.free
        return (shot.end - x0)[free] / self.scale[free]

    def residual(self, shot: Shot, x0: np.ndarray, period: float) -> float:
        """The gap's norm relative to the orbit's size ``|f(x0)| T`` (scaled): the
        measure of convergence."""
        size = np.linalg.norm(shot.rate_start / self.scale) * period
        return float(np.linalg.norm(self.gap(shot, x0)) / size) if size > 0 else np.inf

    def jacobian(self, shot: Shot) -> np.ndarray:
        """``[M - I, f(end); f(x0)^T, 0]`` on the scaled free coordinates and T: the
        Jacobian of the gap and the phase condition."""
        free, sc = shot.free, self.scale
        m = int(free.sum())
        jac = np.zeros((m + 1, m + 1))
        jac[:m, :m] = shot.monodromy[np.ix_(free, free)] * (sc[free][None, :]
                                                            / sc[free][:, None])
        jac[:m, :m] -= np.eye(m)
        jac[:m, m] = shot.rate_end[free] / sc[free]
        jac[m, :m] = shot.rate_start[free] / sc[free]
        return jac

    def stability(self, shot: Shot) -> tuple[np.ndarray, int]:
        r"""The monodromy's eigenvalues, largest modulus first, and the index of the flow
        direction's.

        Notes
        -----
        The flow direction's multiplier is 1. Near a fold of cycles a second one is close
        to 1 too, with an eigenvector nearly parallel to the flow (at the fold the two
        form a Jordan block), so which eigenvalue of :math:`M` is the flow's cannot be
        told from the eigenvectors there. The others are therefore taken as the
        eigenvalues of :math:`Q M` with :math:`Q = I - \hat f \hat f^T` (in the scaled
        state, :math:`\hat f` the unit vector field at the start): the Jacobian of a
        Poincare map on the hyperplane normal to the flow, whose spectrum is the
        non-trivial multipliers and a zero for the flow direction, which is dropped.
        The flow direction's is :math:`\hat f^T M \hat f`, 1 to the orbit's residual.
        """
        sc = self.scale
        f = shot.rate_start / sc
        size = np.linalg.norm(f)
        if not size > 0:
            raise FivdiscError("the orbit's point is an equilibrium: it has no multipliers")
        f /= size
        m = shot.monodromy * (sc[None, :] / sc[:, None])
        others = np.linalg.eigvals(m - np.outer(f, f @ m))
        others = np.delete(others, np.argmin(np.abs(others)))
        mult = np.r_[others, f @ m @ f]
        order = np.argsort(-np.abs(mult), kind="stable")
        return mult[order], int(np.flatnonzero(order == mult.size - 1)[0])


def verdict_of(mult: np.ndarray, trivial: int) -> str:
    """``"stable"`` if every multiplier but the flow direction's lies inside the unit
    circle, else ``"unstable"``."""
    others = np.delete(np.abs(mult), trivial)
    return "stable" if (others.size == 0 or others.max() < 1.0) else "unstable"


@dataclass
class _Newton:
    x0: np.ndarray
    period: float
    shot: Shot
    residual: float
    iterations: int
    reason: str


class OutOfTime(Exception):
    """A shot stopped at its :attr:`Shooting.deadline` (not a FivdiscError: a Newton
    step does not try a smaller step after it)."""


def _newton(shooting: Shooting, x0: np.ndarray, period: float, tol: float,
            max_iterations: int, deadline: float, bar=None) -> _Newton:
    """Newton shooting on (x0, T) from a guess, each step halved until it reduces the
    residual; ``reason`` is "" when converged, else what ended the iteration."""
    sc = shooting.scale
    shot = shooting.shoot(x0, period)
    residual = shooting.residual(shot, x0, period)
    iterations = 0
    reason = ""
    polish = True
    while residual >= tol or (polish and residual > _POLISH * tol):
        if residual < tol:
            # Converged: one more step, kept only if it lowers the residual, takes the
            # period from the tolerance's accuracy to the integration's.
            polish = False
        elif iterations >= max_iterations:
            reason = f"the iteration budget ({max_iterations} Newton iterations) ran out"
            break
        if time.monotonic() > deadline:
            if residual >= tol:
                reason = "the time budget ran out"
            break
        iterations += 1
        free = shot.free
        m = int(free.sum())
        step = np.linalg.lstsq(shooting.jacobian(shot), np.r_[-shooting.gap(shot, x0), 0.0],
                               rcond=None)[0]
        # The flow map is smooth only while the switch sequence stays the same: a step
        # that adds or removes a switch may not reduce the residual, so it is halved
        # until it does.
        for halving in range(_HALVINGS):
            frac = 0.5**halving
            trial_t = period + frac * step[m]
            if not trial_t > 0:
                continue
            trial_x = x0.copy()
            trial_x[free] += frac * step[:m] * sc[free]
            try:
                trial = shooting.shoot(trial_x, trial_t)
            except OutOfTime:
                return _Newton(x0, period, shot, residual, iterations,
                               "the time budget ran out")
            except FivdiscError:
                continue
            trial_res = shooting.residual(trial, trial_x, trial_t)
            if trial_res < residual:
                x0, period, shot, residual = trial_x, float(trial_t), trial, trial_res
                break
        else:
            if residual >= tol:
                reason = "no Newton step reduces the residual (the guess is too far)"
            break
        if bar is not None:
            bar.update()
            bar.set_postfix_str(f"residual {residual:.2e}")
    return _Newton(x0, period, shot, residual, iterations, reason)


# A search whose Newton iterations are estimated to take longer than this in all [s]
# says so before the first (a FivdiscWarning): with many sliders one takes minutes.
_LONG_SEARCH = 60.0
# Iterations a search usually takes, for that estimate.
_TYPICAL_ITERATIONS = 5
# Fraction of the period a shot is timed over, for that estimate.
_TIMED_SHOT = 0.05


def _announce_shots(shooting: Shooting, x0: np.ndarray, period: float,
                    time_budget: float) -> None:
    """Warn when a Newton iteration (a run over the period carrying a tangent vector per
    coordinate) is long, with its time measured on a part of the period."""
    import warnings

    from fivdisc.errors import FivdiscWarning
    from fivdisc.limits import duration_words

    start = time.perf_counter()
    try:
        shooting.shoot(x0, _TIMED_SHOT * period)
    except FivdiscError:
        return
    shot = (time.perf_counter() - start) / _TIMED_SHOT
    if shot * _TYPICAL_ITERATIONS > _LONG_SEARCH:
        warnings.warn(
            f"each Newton iteration takes about {duration_words(shot)} (a run over the "
            f"period, {period:.3g} s, carrying {shooting.model.state_size} tangent vectors: "
            f"one per coordinate of {shooting.model.n_sliders} sliders and the disc), "
            f"measured; the search stops at its time budget, {duration_words(time_budget)}",
            FivdiscWarning, stacklevel=3)


def _returns_at(shooting: Shooting, x0: np.ndarray, period: float) -> int:
    """The largest k <= 12 at which the orbit through ``x0`` closes after T/k (1 if none):
    T is then k times the minimal period."""
    for k in range(_MAX_DIVISOR, 1, -1):
        try:
            shot = shooting.shoot(x0, period / k, tangents=False)
        except FivdiscError:
            continue
        if shooting.residual(shot, x0, period / k) < _CLOSES:
            return k
    return 1
def _probe(model: Model, x0: np.ndarray, phases: np.ndarray | None, window: float,
           rtol: float, atol: float) -> tuple[np.ndarray, float]:
    """Samples of the trajectory from ``x0`` over ``window`` (about 200 per period of the
    fastest mode kept; the output fills in the contact coordinates), and their spacing."""
    rate = max(200.0 * float(np.max(model.omega)) / (2 * np.pi), 1e4)
    probe = Integration(model, x0, duration=window, output_rate=rate, rtol=rtol, atol=atol,
                        phases=phases)
    probe.run_to(window)
    return probe.out_y[: probe.n_samples, : model.state_size], 1.0 / rate


def _first_return(model: Model, samples: np.ndarray, dt: float) -> float:
    """Time of the first close return of the sampled trajectory to its first point: the
    earliest local minimum of the distance (energy norm) that is close."""
    dist = np.linalg.norm((samples - samples[0]) / energy_scales(model), axis=1)
    # Skip the start: the distance rises from 0 first.
    rising = np.argmax(dist > 0.5 * dist.max())
    interior = np.arange(max(rising, 1), dist.size - 1)
    low = (dist[interior] <= dist[interior - 1]) & (dist[interior] <= dist[interior + 1])
    minima = interior[low]
    if minima.size == 0:
        raise FivdiscError("periodic_orbit: the trajectory does not return near its start "
                           "within the search window; give period= or a longer window")
    # A return closer than 1 % of the excursion counts (the orbit may not be reached yet,
    # Newton refines it); a multiple of the period would only be closer still.
    close = max(2.0 * dist[minima].min(), 1e-2 * dist.max())
    first = minima[dist[minima] <= close][0]
    return float(first * dt)


def _positive(name: str, value: float, unit: str = "") -> None:
    if not (np.isfinite(value) and value > 0):
        raise FivdiscError(f"{name} = {value!r} is invalid: must be a finite number > 0"
                           + (f" [{unit}]" if unit else ""))


def periodic_orbit(
    case: Case,
    guess: np.ndarray | None = None,
    *,
    period: float | None = None,
    phases: np.ndarray | None = None,
    transient: float | None = None,
    window: float = 1.0,
    rtol: float = 1e-12,
    atol: float | None = None,
    tol: float = 1e-8,
    max_iterations: int = 30,
    time_budget: float = 900.0,
    start: str = "",
    progress: bool = False,
) -> PeriodicOrbit:
    r"""Find a periodic orbit of a constant-speed case by shooting.

    Parameters
    ----------
    case : Case
        A case with ``speed.profile = "constant"`` (an autonomous system).
    guess : ndarray, optional
        A state near the orbit. Default: the state after a transient run from the
        case's initial state.
    period : float, optional
        A guess of the period [s]. Default: the first close return of the trajectory
        from the guess within `window`. Either way the converged orbit is reduced to
        its minimal period.
    phases : array of int, optional
        Phases of the sliders at `guess` (default: in contact).
    transient : float, optional
        Length of the transient run [s] when no guess is given (default: the case's
        ``simulation.duration``).
    window : float
        How long to follow the trajectory to find its first return [s].
    rtol, atol : float
        Integration tolerances of the shooting runs. The step size follows the state
        alone, so a tangent direction the orbit hardly excites (a disc mode at rest on
        the orbit) is integrated less accurately than the state, and its steps are capped
        at 0.15 of the model's shortest time scale. The default 1e-12 makes the
        multipliers' moduli right to better than 1e-6, enough to tell whether a
        multiplier 1e-4 from the unit circle lies inside or outside it (the tutorial
        "Periodic orbits, Floquet multipliers and Lyapunov exponents" measures the error
        against a closed form at 1e-10 to 1e-12). ``atol`` defaults to ``1e-7 rtol``.
    tol : float
        Convergence: scaled residual ``|phi_T(x0) - x0|`` below this.
    max_iterations : int
        Budget of Newton iterations.
    time_budget : float
        Budget of wall time for the Newton iterations [s].
    start : str
        Where `guess` comes from, kept in the orbit's ``start`` (default: "from the
        given state", or the transient run's description).
    progress : bool
        Show the Newton iterations and their residual on a terminal (stderr).

    Returns
    -------
    PeriodicOrbit
        A converged orbit at its minimal period.

    Raises
    ------
    ConvergenceError
        Newton shooting did not converge within its budgets; its ``result`` is the
        last iterate, a :class:`PeriodicOrbit` whose ``converged`` is False and whose
        ``verdict`` is ``"not converged"``, and its ``reason`` says which budget ran out.
    FivdiscError
        A case that is not autonomous, or an invalid argument.

    See Also
    --------
    fivdisc.continue_orbit : Follows an orbit, from this one, as a case key changes.
    fivdisc.hopf_cycles : The small orbits born where sliding loses stability.
    fivdisc.lyapunov : Lyapunov exponents of any motion, periodic or not.

    Notes
    -----
    The unknowns are the free coordinates of a point ``x0`` on the orbit and the period
    ``T``; Newton's method solves

    .. math::

        \varphi_T(x_0) - x_0 = 0, \qquad f(x_{ref}) \cdot (x_0 - x_{ref}) = 0,

    the second (the phase condition) keeping the correction normal to the flow ``f``.
    Its Jacobian holds the monodromy matrix ``M = d phi_T / d x0``, carried across every
    switch by the saltation matrices, and ``d phi_T / dT = f(phi_T(x0))``. The Floquet
    multipliers are the eigenvalues of ``M`` (the module :mod:`fivdisc.analysis.orbits`
    says more).

    Examples
    --------
    The stick-slip orbit of a slider with constant kinetic friction on a disc of one
    axisymmetric mode: stick, then a free oscillation of the slider in slip, 59 times a
    second. Its multipliers are the flow direction's 1, the disc mode's pair and zeros
    (directions collapsed by sticking and by the contact):

    >>> import fivdisc
    >>> case = fivdisc.Case(
    ...     disc={"modes": [[0, 0]]},
    ...     slider={"rotational_damping": 0.0, "normal_damping": 5.0},
    ...     friction={"kinetic_max": 0.5, "kinetic_min": 0.5},
    ...     speed={"value": 1.0},
    ... )
    >>> orbit = fivdisc.periodic_orbit(case, transient=1.0)
    >>> print(f"T = {orbit.period * 1e3:.6f} ms, {orbit.verdict}, "
    ...       f"residual below 1e-8: {orbit.residual < 1e-8}")
    T = 16.901572 ms, stable, residual below 1e-8: True
    >>> print(orbit.moduli.round(6))
    [1.       0.923224 0.923224 0.       0.       0.      ]
    """
    if case.speed.profile != "constant":
        raise FivdiscError(f"periodic_orbit needs a constant disc speed (speed.profile = "
                           f"'constant'), not {case.speed.profile!r}: with a varying speed "
                           "the system is not autonomous and has no free period")
    check_tol("tol", tol)
    for name, value in (("window", window), ("time_budget", time_budget)):
        _positive(name, value)
    if not (np.isfinite(rtol) and 0 < rtol < 1e-2):
        raise FivdiscError(f"rtol = {rtol!r} is invalid: must be in (0, 1e-2)")
    if period is not None:
        _positive("period", period, "s")
    if not (isinstance(max_iterations, int) and max_iterations >= 0):
        raise FivdiscError(f"max_iterations = {max_iterations!r} is invalid: must be an "
                           "integer >= 0")
    model = build_model(case)
    if model.n_sliders == 0 or model.state_size == 0:
        raise FivdiscError("periodic_orbit needs a case with a slider")
    from fivdisc.engine.simulation import initial_state

    atol_run = atol if atol is not None else rtol * 1e-7
    if guess is None:
        y0 = initial_state(model)
        duration = case.simulation.duration if transient is None else transient
        _positive("transient", duration, "s")
        run = Integration(model, y0, duration=duration, rtol=rtol, atol=atol_run)
        run.run_to(duration, notice=LongRunNotice(model, duration, "the transient run",
                                                  "a shorter transient takes less"))
        if run.status_name != "success":
            raise FivdiscError(f"periodic_orbit: the transient run ended with "
                               f"{run.status_name} at t = {run.t:.9g} s")
        from fivdisc.engine.simulation import Deflection

        # A run that left the model's range (fivdisc.simulate calls it diverged) has no
        # orbit to find: its samples would overflow the search.
        limit = Deflection(model)
        if limit.beyond(run.state):
            raise FivdiscError(f"periodic_orbit: the transient run {limit.message(run.t)}")
        phases = run.ph.copy()
        samples, dt = _probe(model, run.state, phases, window, rtol, atol_run)
        if limit.beyond(samples[-1]):
            raise FivdiscError(f"periodic_orbit: the run after the transient "
                               f"{limit.message(duration + window)}")
        x0 = samples[0].copy()
        start = start or (f"after a {duration:g} s transient from the case's initial state "
                          f"({case.simulation.initial_state})")
        if period is None:
            period = _first_return(model, samples, dt)
    else:
        x0 = np.array(guess, dtype=float)
        if x0.shape != (model.state_size,) or not np.all(np.isfinite(x0)):
            raise FivdiscError(f"guess has shape {x0.shape}: must be ({model.state_size},), "
                               "a finite state")
        start = start or "from the given state"
        if period is None:
            period = _first_return(model, *_probe(model, x0, phases, window, rtol, atol_run))
    phases = (np.full(model.n_sliders, lay.SLIP) if phases is None
              else np.asarray(phases, dtype=np.int64))
    shooting = Shooting(model, phases, rtol, atol_run)
    deadline = time.monotonic() + time_budget

    from fivdisc.engine.progress import progress_bar

    shooting.shoot(x0, min(period, 1e-6), tangents=True)  # the tangents' set-up
    _announce_shots(shooting, x0, period, time_budget)
    # A shot stops at the budget (with many sliders one takes minutes), with some room
    # left for the minimal period's and the multipliers' work after the iteration.
    shooting.deadline = deadline
    try:
        with progress_bar(max_iterations, "Newton shooting", "iteration",
                          show=progress) as bar:
            sol = _newton(shooting, x0, period, tol, max_iterations, deadline, bar)
    except OutOfTime as exc:  # in the first shot: no iterate to report
        raise ConvergenceError(f"periodic_orbit: not converged: time_budget = "
                               f"{time_budget:g} s ran out ({exc})", result=None,
                               reason="the time budget ran out") from None
    if not sol.reason:
        # The minimal period, if the budget leaves time for it (else the orbit converged
        # at a period that may be a multiple).
        try:
            k = _returns_at(shooting, sol.x0, sol.period)
            if k > 1:
                again = _newton(shooting, sol.x0, sol.period / k, tol, max_iterations,
                                deadline)
                if not again.reason and abs(again.period * k / sol.period - 1.0) < 1e-6:
                    again.iterations += sol.iterations
                    sol = again
        except OutOfTime:
            pass
    mult, trivial = shooting.stability(sol.shot)
    orbit = PeriodicOrbit(period=float(sol.period), state=sol.x0, phases=phases.copy(),
                          monodromy=sol.shot.monodromy, multipliers=mult, trivial=trivial,
                          residual=sol.residual, iterations=sol.iterations,
                          verdict="not converged" if sol.reason else verdict_of(mult, trivial),
                          labels=state_labels(model), start=start)
    if sol.reason:
        raise ConvergenceError(
            f"periodic_orbit: not converged: {sol.reason}; residual {sol.residual:.2e} "
            f"(tolerance {tol:g}) with period {sol.period:.6g} s; try a longer transient, "
            "a period guess, or a start nearer the orbit", result=orbit, reason=sol.reason)
    return orbit


def saved_start(path: str | PathLike[str]) -> tuple[Case | None, np.ndarray, np.ndarray,
                                                     float | None, str]:
    """A start for :func:`periodic_orbit` from a file fivdisc wrote: an orbit
    (``fivdisc orbit -o``; its state, phases and period) or a simulation result (its
    final state and phases).

    Returns
    -------
    case : Case or None
        The case stored in the file.
    state : ndarray
    phases : ndarray of int
    period : float or None
        The orbit's period [s] (None for a simulation result).
    start : str
        Where it came from, for the orbit's ``start``.
    """
    from fivdisc.files import read_dataset

    ds = read_dataset(path, "--from")
    text = ds.attrs.get("case")
    case = Case.from_toml(text) if text else None
    if ds.attrs.get("content") == "periodic orbit" and "state" in ds:
        return (case, ds["state"].values.astype(float), ds["phase"].values.astype(np.int64),
                float(ds.attrs["period"]), f"from the orbit in {path}")
    if "final_state" in ds.attrs and "final_phase" in ds.attrs:
        state = np.atleast_1d(np.asarray(ds.attrs["final_state"], dtype=float))
        phases = np.atleast_1d(np.asarray(ds.attrs["final_phase"], dtype=np.int64))
        return case, state, phases, None, f"from the final state of the run in {path}"
    raise FivdiscError(f"--from {path}: holds neither a periodic orbit (fivdisc orbit -o) "
                       "nor a simulation result (fivdisc simulate -o)")
