"""Periodic orbits of the non-smooth flow by shooting, and their Floquet multipliers.

The orbit is a fixed point of the flow map over its period T: unknowns are the free
coordinates of a point x0 on it and T; the equations are ``phi_T(x0) - x0 = 0`` and the
phase condition ``f(x0_ref) . (x0 - x0_ref) = 0`` (the correction is orthogonal to the
flow, which removes the freedom to slide x0 along the orbit). Newton's method uses the
monodromy matrix ``M = d phi_T / d x0``, carried exactly across every switch by the
saltation matrices (:mod:`fivdisc._kernels.tangent`), and ``d phi_T / dT = f(phi_T(x0))``.

The Floquet multipliers are the eigenvalues of ``M``. An autonomous orbit has one equal
to 1 (the flow direction); a direction collapsed by the flow (onto the stick manifold at
slip-to-stick, by a plastic impact) or a coordinate that is not free at x0 (``z``,
``zdot`` of a slider in contact, ``phidot`` of a sticking one) gives a multiplier 0.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

from fivdisc._kernels import layout as lay
from fivdisc.case import Case
from fivdisc.errors import FivdiscError
from fivdisc.integration import Integration, tangent_step
from fivdisc.model import Model, build_model

__all__ = ["PeriodicOrbit", "periodic_orbit"]

VERDICTS = ("stable", "unstable", "not converged")
# Halvings of a Newton step that does not reduce the residual before giving up.
_HALVINGS = 6


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit found by :func:`periodic_orbit`.

    Attributes
    ----------
    period : float
        T [s].
    state : ndarray
        A point on the orbit (the state layout of :mod:`fivdisc._kernels.layout`, the
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
        """The orbit as plain JSON types: period [s], multipliers (real, imag,
        modulus), verdict, residual."""
        return {
            "period": self.period,
            "multipliers": [{"real": float(m.real), "imag": float(m.imag),
                             "modulus": float(abs(m))} for m in self.multipliers],
            "verdict": self.verdict,
            "residual": self.residual,
            "iterations": self.iterations,
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
                   "trivial_multiplier": self.trivial},
        )
        return ds

    def __str__(self) -> str:
        lines = [f"periodic orbit: T = {self.period:.9g} s ({1 / self.period:.6g} Hz), "
                 f"{self.verdict}, residual {self.residual:.2e} after {self.iterations} "
                 f"Newton iteration{'' if self.iterations == 1 else 's'}",
                 "Floquet multipliers (modulus, real, imag):"]
        for i, m in enumerate(self.multipliers):
            note = "  flow direction" if i == self.trivial else ""
            lines.append(f"  {abs(m):.9f}  {m.real:+.9f}  {m.imag:+.9f}{note}")
        return "\n".join(lines)


def state_labels(model: Model) -> tuple[str, ...]:
    """Names of the state's coordinates: ``q_C01``, ``phi_1``, ``z_1`` and their rates."""
    ns = model.n_sliders
    pos = ([f"q_{lab}" for lab in model.labels] + [f"phi_{j + 1}" for j in range(ns)]
           + [f"z_{j + 1}" for j in range(ns)])
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
class _Shot:
    end: np.ndarray
    monodromy: np.ndarray
    rate_end: np.ndarray
    rate_start: np.ndarray
    free: np.ndarray


def _shoot(model: Model, x0: np.ndarray, phases: np.ndarray, period: float, rtol: float,
           atol: float) -> _Shot:
    """The flow map over ``period`` from ``x0`` with its Jacobian (steps capped at
    :func:`~fivdisc.integration.tangent_step`, so that directions the orbit hardly
    excites are integrated stably at any rtol)."""
    cap = tangent_step(model)
    if model.case.simulation.max_step > 0:
        cap = min(cap, model.case.simulation.max_step)
    run = Integration(model, x0, duration=period, output_rate=1.0 / period, rtol=rtol,
                      atol=atol, max_step=cap, phases=phases)
    run.set_tangents(np.eye(model.state_size))
    run.advance(0.0)
    rate_start = run.rhs()
    free = run.free()
    run.run_to(period)
    if run.status_name != "success":
        raise FivdiscError(f"periodic_orbit: the run over one period ended with "
                           f"{run.status_name} at t = {run.t:.9g} s")
    end = run.out_y[1, : model.state_size].copy()
    return _Shot(end, run.tangents().T, run.rhs(), rate_start, free)


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
    progress: bool = False,
) -> PeriodicOrbit:
    """Find a periodic orbit of a constant-speed case by shooting.

    Parameters
    ----------
    case : Case
        A case with ``speed.profile = "constant"`` (an autonomous system).
    guess : ndarray, optional
        A state near the orbit. Default: the state after a transient run from the
        case's initial state.
    period : float, optional
        A guess of the period [s]. Default: the first close return of the trajectory
        from the guess within `window`.
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
        the orbit) is integrated less accurately than the state: on the rigid-disc
        stick-slip oscillator the multipliers' moduli are off by 4e-6 at rtol 1e-10,
        2e-7 at 1e-11 and 1e-9 at 1e-12. The default 1e-12 makes them right to better
        than 1e-6, enough to tell whether a multiplier 1e-4 from the unit circle (as
        on the paper's Fig. 13 orbit) lies inside or outside it. ``atol`` defaults to
        ``1e-7 rtol``.
    tol : float
        Convergence: scaled residual ``|phi_T(x0) - x0|`` below this.
    max_iterations : int
        Newton iterations before giving up (verdict ``"not converged"``).
    progress : bool
        Say so on stderr when the kernel with tangent vectors compiles (first use).

    Returns
    -------
    PeriodicOrbit
    """
    if case.speed.profile != "constant":
        raise FivdiscError(f"periodic_orbit needs a constant disc speed (speed.profile = "
                           f"'constant'), not {case.speed.profile!r}: with a varying speed "
                           "the system is not autonomous and has no free period")
    for name, value in (("rtol", rtol), ("tol", tol), ("window", window)):
        if not value > 0:
            raise FivdiscError(f"{name} = {value!r} is invalid: must be > 0")
    if period is not None and not period > 0:
        raise FivdiscError(f"period = {period!r} is invalid: must be > 0 [s]")
    model = build_model(case)
    from fivdisc.simulate import initial_state

    atol_run = atol if atol is not None else rtol * 1e-7
    if guess is None:
        y0 = initial_state(model)
        duration = case.simulation.duration if transient is None else transient
        if not duration > 0:
            raise FivdiscError(f"transient = {duration!r} is invalid: must be > 0 [s]")
        run = Integration(model, y0, duration=duration, rtol=rtol, atol=atol_run)
        run.run_to(duration)
        phases = run.ph.copy()
        samples, dt = _probe(model, run.state, phases, window, rtol, atol_run)
        x0 = samples[0].copy()
        if period is None:
            period = _first_return(model, samples, dt)
    else:
        x0 = np.array(guess, dtype=float)
        if x0.shape != (model.state_size,):
            raise FivdiscError(f"guess has shape {x0.shape}: must be ({model.state_size},), "
                               "a state")
        if period is None:
            period = _first_return(model, *_probe(model, x0, phases, window, rtol, atol_run))
    phases = (np.full(model.n_sliders, lay.SLIP) if phases is None
              else np.asarray(phases, dtype=np.int64))

    sc = energy_scales(model)

    def attempt(x: np.ndarray, t: float) -> tuple[_Shot, float]:
        shot = _shoot(model, x, phases, t, rtol, atol_run)
        gap = (shot.end - x)[shot.free] / sc[shot.free]
        return shot, float(np.linalg.norm(gap) / (np.linalg.norm(shot.rate_start / sc) * t))

    from fivdisc.compilation import tangent_notice

    with tangent_notice(show=progress):
        shot, residual = attempt(x0, period)
    iterations = 0
    while residual >= tol and iterations < max_iterations:
        iterations += 1
        # Newton on (x0 / sc, T): [M - I, f(end); f(x0)^T, 0] (dx, dT) = (-gap, 0).
        free = shot.free
        m = int(free.sum())
        gap = (shot.end - x0)[free] / sc[free]
        jac = np.zeros((m + 1, m + 1))
        jac[:m, :m] = shot.monodromy[np.ix_(free, free)] * (sc[free][None, :] / sc[free][:, None])
        jac[:m, :m] -= np.eye(m)
        jac[:m, m] = shot.rate_end[free] / sc[free]
        jac[m, :m] = shot.rate_start[free] / sc[free]
        step = np.linalg.lstsq(jac, np.r_[-gap, 0.0], rcond=None)[0]
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
                trial = attempt(trial_x, trial_t)
            except FivdiscError:
                continue
            if trial[1] < residual:
                x0, period = trial_x, float(trial_t)
                shot, residual = trial
                break
        else:
            break
    converged = residual < tol
    assert shot is not None
    mult, vecs = np.linalg.eig(shot.monodromy)
    order = np.argsort(-np.abs(mult), kind="stable")
    mult, vecs = mult[order], vecs[:, order]
    trivial = _flow_multiplier(mult, vecs, shot.rate_start, sc)
    others = np.delete(np.abs(mult), trivial)
    if not converged:
        verdict = "not converged"
    else:
        verdict = "stable" if (others.size == 0 or others.max() < 1.0) else "unstable"
    return PeriodicOrbit(period=float(period), state=x0, phases=phases.copy(),
                         monodromy=shot.monodromy, multipliers=mult, trivial=trivial,
                         residual=residual, iterations=iterations, verdict=verdict,
                         labels=state_labels(model))


def _flow_multiplier(mult: np.ndarray, vecs: np.ndarray, flow: np.ndarray,
                     sc: np.ndarray) -> int:
    """Index of the flow direction's multiplier: among those near 1, the one whose
    eigenvector is most nearly parallel to the vector field at the start."""
    f = flow / sc
    f = f / (np.linalg.norm(f) or 1.0)
    near = np.flatnonzero(np.abs(mult - 1.0) < 1e-2)
    if near.size == 0:
        return int(np.argmin(np.abs(mult - 1.0)))
    cosines = [abs(np.vdot(vecs[:, i] / sc / np.linalg.norm(vecs[:, i] / sc), f))
               for i in near]
    return int(near[int(np.argmax(cosines))])
