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

import itertools
import json
import time
from dataclasses import dataclass, field
from os import PathLike
from typing import NamedTuple

import numpy as np

from fivdisc.analysis.checks import check_tol
from fivdisc.analysis.symmetry import (
    ORBIT_SYMMETRY,
    CaseSymmetry,
    Element,
    OrbitSymmetry,
    case_symmetry,
)
from fivdisc.case import Case
from fivdisc.engine.integration import Integration, LongRunNotice, tangent_step
from fivdisc.errors import ConvergenceError, FivdiscError
from fivdisc.model.build import Model, build_model
from fivdisc.model.layout import Phase

__all__ = ["PeriodicOrbit", "SavedStart", "Shooting", "SymmetricShooting", "orbit_symmetry",
           "periodic_orbit", "saved_start"]

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
    accuracy : float
        Where Newton stalled within the integration's own accuracy: that accuracy (the
        scaled change of ``phi_T(x0)`` when the integration tolerance is divided by 10),
        at which the orbit is converged; nan otherwise.
    symmetry : str
        The orbit's symmetry in words (``"pads stick in turn, T/3 apart"``, ``"in
        phase"``, ``"none"``), "" where the case has none.
    group : str
        The case's symmetry group in words, "" if none.
    note : str
        What else to know about the result (a tightened tolerance, a residual that would
        not go below the tolerance's level, a T/k solve).

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
    accuracy: float = float("nan")
    symmetry: str = ""
    group: str = ""
    note: str = ""

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
            "accuracy": None if np.isnan(self.accuracy) else self.accuracy,
            "symmetry": self.symmetry,
            "group": self.group,
            "note": self.note,
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
                   "start": self.start, "content": "periodic orbit",
                   "accuracy": self.accuracy, "symmetry": self.symmetry,
                   "group": self.group, "note": self.note},
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
                 (f"converged at the integration's accuracy {self.accuracy:.1e} (Newton "
                  "stalled there)") if not np.isnan(self.accuracy) else "",
                 f"symmetry of the case: {self.group}" if self.group else "",
                 f"symmetry of the orbit: {self.symmetry}" if self.group else "",
                 f"note: {self.note}" if self.note else "",
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

    def cycle(self, x0: np.ndarray, period: float):
        """One period of the orbit through ``x0`` (:func:`fivdisc.analysis.cycle.one_period`)
        with this shooting's phases, tolerances and step cap: its events are those of
        :meth:`shoot`'s run."""
        from fivdisc.analysis.cycle import one_period

        return one_period(self.model, self.held(x0), self.phases, period, self.rtol,
                          self.atol, max_step=self.cap)

    def held(self, x0: np.ndarray) -> np.ndarray:
        """``x0`` with the rate of every slider that sticks at the start set to the disc
        speed of this model: the kernel keeps a slider stuck at the start only if it
        moves exactly with the disc, so a point inside a stick phase stays one when the
        disc speed is changed (a continuation in the speed)."""
        stuck = np.flatnonzero(self.phases == Phase.STICK)
        if stuck.size == 0:
            return x0
        x0 = np.array(x0, dtype=float)
        x0[self.model.index("phi_dot") + stuck] = float(self.model.speed.omega(0.0))
        return x0

    def shoot(self, x0: np.ndarray, period: float, tangents: bool = True) -> Shot:
        """The flow map over ``period`` [s] from ``x0``, with its Jacobian if asked.

        Raises
        ------
        FivdiscError
            The run did not reach ``period`` (divergence, endless switching, ...).
        """
        nd = self.model.state_size
        x0 = self.held(x0)
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


class SymmetricShooting(Shooting):
    """Shooting over ``T / k`` with the pads permuted: the fixed points of
    ``P^-1 phi_{T/k}``, the orbits with ``x(t + T/k) = P x(t)``
    (:mod:`fivdisc.analysis.symmetry`). :meth:`shoot` takes and returns what
    :class:`Shooting`'s does for the full period ``T`` (its end mapped back by
    ``P^-1``, its monodromy ``R = P^-1 d phi_{T/k}``, ``d end / dT`` the vector field
    over ``k``), so Newton shooting runs unchanged on it; :meth:`full` gives the full
    period's monodromy ``R^k``.

    Parameters
    ----------
    matrix : ndarray
        ``P`` of the symmetry.
    k : int
        The fraction of the period it shifts by.
    """

    def __init__(self, model: Model, phases: np.ndarray, rtol: float, atol: float,
                 matrix: np.ndarray, k: int, scale: np.ndarray | None = None) -> None:
        super().__init__(model, phases, rtol, atol, scale)
        self.matrix, self.k = matrix, int(k)
        self.inverse = np.linalg.inv(matrix)

    def at(self, model: Model) -> SymmetricShooting:
        return SymmetricShooting(model, self.phases, self.rtol, self.atol, self.matrix,
                                 self.k, self.scale)

    def shoot(self, x0: np.ndarray, period: float, tangents: bool = True) -> Shot:
        shot = super().shoot(x0, period / self.k, tangents)
        pinv = self.inverse
        return Shot(pinv @ shot.end, None if shot.monodromy is None else pinv @ shot.monodromy,
                    pinv @ shot.rate_end / self.k, shot.rate_start, shot.free)

    def full(self, shot: Shot) -> Shot:
        """The full period's shot from the reduced one: monodromy ``R^k``."""
        return Shot(shot.end, np.linalg.matrix_power(shot.monodromy, self.k),
                    shot.rate_end * self.k, shot.rate_start, shot.free)


def verdict_of(mult: np.ndarray, trivial: int) -> str:
    """``"stable"`` if every multiplier but the flow direction's lies inside the unit
    circle, else ``"unstable"``."""
    others = np.delete(np.abs(mult), trivial)
    return "stable" if (others.size == 0 or others.max() < 1.0) else "unstable"


@dataclass
class NewtonResult:
    """Where Newton shooting (:func:`newton_shooting`) ended: the last iterate
    ``(x0, period)`` [state, s], its shot and scaled residual, the iterations taken, and
    ``reason`` ("" when converged, else what ended the iteration)."""

    x0: np.ndarray
    period: float
    shot: Shot
    residual: float
    iterations: int
    reason: str
    # Where no step reduced the residual: the Newton step there (for _stall).
    step: np.ndarray | None = None


# A stall whose residual is within this many times the integration's accuracy is
# converged at that accuracy.
_FLOOR = 10.0
# The tightest tolerance a stall within the integration's accuracy is retried at.
_TIGHTEST = 1e-14
STALL = "no Newton step reduces the residual (the guess is too far)"


def accuracy_of(shooting: Shooting, x0: np.ndarray, period: float,
                end: np.ndarray | None = None) -> float:
    """The integration's accuracy at ``x0``: the scaled change of ``phi_T(x0)`` (relative
    to the orbit's size, the residual's measure) when the tolerances are divided by 10
    (at most to 1e-15)."""
    fine = Shooting(shooting.model, shooting.phases, max(shooting.rtol / 10, 1e-15),
                    max(shooting.atol / 10, 1e-30), shooting.scale)
    if isinstance(shooting, SymmetricShooting):
        fine = SymmetricShooting(shooting.model, shooting.phases, fine.rtol, fine.atol,
                                 shooting.matrix, shooting.k, shooting.scale)
    a = shooting.shoot(x0, period, tangents=False) if end is None else None
    b = fine.shoot(x0, period, tangents=False)
    end = a.end if a is not None else end
    size = np.linalg.norm(b.rate_start / shooting.scale) * period
    return float(np.linalg.norm((end - b.end)[b.free] / shooting.scale[b.free]) / size)


@dataclass
class Stall:
    """Why Newton shooting stalled: ``kind`` is ``"accuracy"`` (within the integration's
    accuracy), ``"discontinuous"`` (the shooting map jumps between the iterate and its
    linear model's fixed point) or ``"far"``; ``text`` says it in words."""

    kind: str
    text: str
    accuracy: float


def _stall(shooting: Shooting, sol: NewtonResult) -> Stall:
    """Classify a stall of Newton shooting at ``sol``'s iterate: within the integration's
    own accuracy, on a discontinuity of the shooting map (a line search along the Newton
    step, bisected to where the residual jumps, and the switches whose order flips
    there), or a guess too far."""
    from fivdisc.analysis.cycle import order_changes

    x0, period, r0 = sol.x0, sol.period, sol.residual
    eps = accuracy_of(shooting, x0, period, sol.shot.end)
    if r0 <= _FLOOR * eps:
        return Stall("accuracy", f"the residual {r0:.2e} is within {_FLOOR:g} times the "
                     f"integration's accuracy {eps:.1e}", eps)
    step = sol.step
    if step is None:
        return Stall("far", STALL, eps)
    free, sc = sol.shot.free, shooting.scale
    m = int(free.sum())

    def trial(frac: float) -> tuple[float, np.ndarray, float]:
        x = x0.copy()
        x[free] += frac * step[:m] * sc[free]
        t = period + frac * step[m]
        try:
            shot = shooting.shoot(x, t, tangents=False)
        except FivdiscError:
            return np.inf, x, t
        return shooting.residual(shot, x, t), x, t

    def departs(frac: float, res: float) -> bool:
        # the linear model's residual is (1 - frac) r0; a smooth map stays near it for
        # small steps, to second order
        return res > 2.0 * max((1.0 - frac) * r0, _FLOOR * eps)

    good, bad = 0.0, None
    for k in range(24, -1, -1):
        frac = 0.5**k
        res, _, _ = trial(frac)
        if departs(frac, res):
            bad = frac
            break
        good = frac
    if bad is None:
        return Stall("far", STALL, eps)
    lo_res, lo_x, lo_t = trial(good) if good > 0 else (r0, x0, period)
    hi_res, hi_x, hi_t = trial(bad)
    for _ in range(30):
        if bad - good <= 1e-9 * bad:
            break
        mid = 0.5 * (good + bad)
        res, x, t = trial(mid)
        if departs(mid, res):
            bad, hi_res, hi_x, hi_t = mid, res, x, t
        else:
            good, lo_res, lo_x, lo_t = mid, res, x, t
    if not (bad - good <= 1e-9 * bad and hi_res > 3.0 * lo_res):
        return Stall("far", STALL, eps)
    model, rtol, atol = shooting.model, shooting.rtol, shooting.atol
    try:
        base = Shooting(model, shooting.phases, rtol, atol, shooting.scale)
        flips = order_changes(base.cycle(lo_x, lo_t), base.cycle(hi_x, hi_t))
    except FivdiscError:
        flips = []
    where = ("; ".join(flips) if flips else
             "no switch changes order within the period (a switch at the period's end)")
    return Stall("discontinuous",
                 f"the shooting map is discontinuous at the iterate: along the Newton step "
                 f"the residual jumps from {lo_res:.2e} to {hi_res:.2e} within a relative "
                 f"{(bad - good) / bad:.0e} of the step (at {bad:.3g} of it), where the "
                 f"switches of different pads change order ({where}); the residual "
                 f"{r0:.2e} is {r0 / max(eps, 1e-300):.1e} times the integration's accuracy "
                 f"{eps:.1e}, so this is no orbit at the integration's accuracy: the "
                 "motion there may not be periodic (check with a forward run)", eps)


class OutOfTime(Exception):
    """A shot stopped at its :attr:`Shooting.deadline` (not a FivdiscError: a Newton
    step does not try a smaller step after it)."""


def newton_shooting(shooting: Shooting, x0: np.ndarray, period: float, tol: float,
                    max_iterations: int, deadline: float, bar=None) -> NewtonResult:
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
                return NewtonResult(x0, period, shot, residual, iterations,
                               "the time budget ran out")
            except FivdiscError:
                continue
            trial_res = shooting.residual(trial, trial_x, trial_t)
            if trial_res < residual:
                x0, period, shot, residual = trial_x, float(trial_t), trial, trial_res
                break
        else:
            if residual >= tol:
                reason = STALL
            return NewtonResult(x0, period, shot, residual, iterations, reason, step)
        if bar is not None:
            bar.update()
            bar.set_postfix_str(f"residual {residual:.2e}")
    return NewtonResult(x0, period, shot, residual, iterations, reason)


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
    T is then k times the minimal period. The return is measured on every coordinate
    free at the start and the stuck sliders' rates too: a point inside a stick phase
    has its slider's rate held, and a slider slipping back through its stick angle half
    a period later would otherwise look like a return."""
    x0 = shooting.held(x0)
    stuck = np.zeros(x0.size, dtype=bool)
    rates = shooting.model.index("phi_dot")
    stuck[rates + np.flatnonzero(shooting.phases == Phase.STICK)] = True
    sc = shooting.scale
    for k in range(_MAX_DIVISOR, 1, -1):
        try:
            shot = shooting.shoot(x0, period / k, tangents=False)
        except FivdiscError:
            continue
        keep = shot.free | stuck
        size = np.linalg.norm(shot.rate_start / sc) * period / k
        if np.linalg.norm(((shot.end - x0) / sc)[keep]) < _CLOSES * size:
            return k
    return 1
def _probe(model: Model, x0: np.ndarray, phases: np.ndarray | None, window: float,
           rtol: float, atol: float) -> tuple[np.ndarray, float]:
    """Samples of the trajectory from ``x0`` over ``window`` (about 200 per period of the
    fastest mode kept; the output fills in the contact coordinates), and their spacing."""
    # (a rigid disc has no modes: the sliders' own motion is slower than 1e4 samples/s)
    rate = max(200.0 * float(np.max(model.omega, initial=0.0)) / (2 * np.pi), 1e4)
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
    symmetric: bool = False,
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
    symmetric : bool
        Where the case has a symmetry group (identical pads equally spaced,
        :func:`fivdisc.analysis.symmetry.case_symmetry`) and the motion from the guess
        has a spatio-temporal symmetry ``x(t + T/k) = P x(t)`` (the pads in turn), solve
        ``P^-1 phi_{T/k}(x) = x`` instead of the full period (:class:`SymmetricShooting`):
        k times shorter runs, the orbit symmetric by construction; its multipliers are
        the full period's (``R^k``).

    Returns
    -------
    PeriodicOrbit
        A converged orbit at its minimal period, with its symmetry (``symmetry``,
        ``group``) when the case has one.

    Raises
    ------
    ConvergenceError
        Newton shooting did not converge within its budgets; its ``result`` is the
        last iterate, a :class:`PeriodicOrbit` whose ``converged`` is False and whose
        ``verdict`` is ``"not converged"``, and its ``reason`` says which budget ran out,
        or why no step reduces the residual. A stall within the integration's own
        accuracy is retried once at a tenth of ``rtol`` (not below 1e-14) and, stalling
        there again, is a converged orbit at that accuracy (its ``accuracy``); a stall
        where the shooting map is discontinuous (the switches of different pads change
        order between the iterate and its linear model's fixed point) says so and names
        the switches.
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
    phases = (np.full(model.n_sliders, Phase.SLIP) if phases is None
              else np.asarray(phases, dtype=np.int64))
    shooting: Shooting = Shooting(model, phases, rtol, atol_run)
    deadline = time.monotonic() + time_budget
    group = case_symmetry(model)
    notes = []
    if symmetric:
        shooting = _symmetric(group, model, x0, phases, period, rtol, atol_run)
        notes.append(f"solved over T/{shooting.k} with the pads permuted (x(T/{shooting.k}) "
                     "= P x(0)); multipliers of the full period")

    from fivdisc.engine.progress import progress_bar

    shooting.shoot(x0, min(period, 1e-6), tangents=True)  # the tangents' set-up
    _announce_shots(shooting, x0, period, time_budget)
    # A shot stops at the budget (with many sliders one takes minutes), with some room
    # left for the minimal period's and the multipliers' work after the iteration.
    shooting.deadline = deadline
    try:
        with progress_bar(max_iterations, "Newton shooting", "iteration",
                          show=progress) as bar:
            sol = newton_shooting(shooting, x0, period, tol, max_iterations, deadline, bar)
    except OutOfTime as exc:  # in the first shot: no iterate to report
        raise ConvergenceError(f"periodic_orbit: not converged: time_budget = "
                               f"{time_budget:g} s ran out ({exc})", result=None,
                               reason="the time budget ran out") from None
    accuracy = float("nan")
    try:
        if sol.reason == STALL:
            stall = _stall(shooting, sol)
            if stall.kind == "accuracy" and shooting.rtol > _TIGHTEST:
                # Once more at a tenth of the tolerance: a residual set by the integration's
                # error falls with it; one that does not is that accuracy's.
                tight = max(shooting.rtol / 10, _TIGHTEST)
                shooting = (shooting.__class__(model, phases, tight, tight * 1e-7,
                                               shooting.matrix, shooting.k)
                            if isinstance(shooting, SymmetricShooting)
                            else Shooting(model, phases, tight, tight * 1e-7))
                shooting.deadline = deadline
                again = newton_shooting(shooting, sol.x0, sol.period, tol, max_iterations, deadline,
                                bar)
                again.iterations += sol.iterations
                notes.append(f"Newton stalled within the integration's accuracy "
                             f"({stall.accuracy:.1e}) at rtol {rtol:g}: solved again at rtol "
                             f"{tight:g}")
                sol = again
                if sol.reason == STALL:
                    stall = _stall(shooting, sol)
            if sol.reason == STALL and stall.kind == "accuracy":
                sol.reason = ""
                accuracy = stall.accuracy
            elif sol.reason == STALL:
                sol.reason = stall.text
        elif not sol.reason and sol.residual > _POLISH * tol:
            # Converged, but the polishing step did not take the residual below the
            # tolerance's level: why not, from a fresh Newton step.
            if sol.step is None:
                sol.step = np.linalg.lstsq(shooting.jacobian(sol.shot),
                                           np.r_[-shooting.gap(sol.shot, sol.x0), 0.0],
                                           rcond=None)[0]
            stall = _stall(shooting, sol)
            if stall.kind == "discontinuous":
                notes.append(f"converged to the tolerance {tol:g} but no further: "
                             f"{stall.text}")
            elif stall.kind == "accuracy":
                accuracy = stall.accuracy
        if not sol.reason and not isinstance(shooting, SymmetricShooting):
            # The minimal period, if the budget leaves time for it (else the orbit
            # converged at a period that may be a multiple).
            k = _returns_at(shooting, sol.x0, sol.period)
            if k > 1:
                again = newton_shooting(shooting, sol.x0, sol.period / k, tol, max_iterations,
                                deadline)
                if not again.reason and abs(again.period * k / sol.period - 1.0) < 1e-6:
                    again.iterations += sol.iterations
                    sol = again
    except OutOfTime:
        pass
    shooting.deadline = None
    shot = sol.shot
    if isinstance(shooting, SymmetricShooting):
        shot = shooting.full(shot if shot.monodromy is not None
                             else shooting.shoot(sol.x0, sol.period))
    mult, trivial = shooting.stability(shot)
    # The coordinates the contact holds (a slider's z, zdot in contact) and the stuck
    # sliders' rates are not unknowns: the state kept has them as the flow gives them.
    x_end = shooting.held(sol.x0)
    if not sol.reason and not isinstance(shooting, SymmetricShooting):
        held = ~sol.shot.free
        x_end[held] = sol.shot.end[held]
    symmetry = ""
    if group and not sol.reason:
        symmetry = orbit_symmetry(group, model, x_end, phases, sol.period, rtol,
                                  atol_run).name
    if not sol.reason and model.n_sliders > 1:
        together = _coinciding(shooting, x_end, sol.period)
        if together:
            notes.append(f"switches of different pads coincide ({together}): the orbit lies "
                         "where pieces of the flow map meet, and its multipliers are those "
                         "of the order in which the integration makes the coinciding "
                         "switches; a perturbation, which parts them, may decay or grow at "
                         "another rate")
    orbit = PeriodicOrbit(period=float(sol.period), state=x_end, phases=phases.copy(),
                          monodromy=shot.monodromy, multipliers=mult, trivial=trivial,
                          residual=sol.residual, iterations=sol.iterations,
                          verdict="not converged" if sol.reason else verdict_of(mult, trivial),
                          labels=state_labels(model), start=start, accuracy=accuracy,
                          symmetry=symmetry, group=group.description if group else "",
                          note="; ".join(notes))
    if sol.reason:
        hint = ("" if sol.reason.startswith("the shooting map is discontinuous")
                else "; try a longer transient, a period guess, or a start nearer the orbit")
        raise ConvergenceError(
            f"periodic_orbit: not converged: {sol.reason}; residual {sol.residual:.2e} "
            f"(tolerance {tol:g}) with period {sol.period:.6g} s{hint}", result=orbit,
            reason=sol.reason)
    return orbit


def _coinciding(shooting: Shooting, x0: np.ndarray, period: float) -> str:
    """The switches of different sliders at one instant on the orbit through ``x0``, in
    words ("" if none)."""
    from fivdisc.analysis.cycle import EVENT_WORDS, SIMULTANEOUS

    base = Shooting(shooting.model, shooting.phases, shooting.rtol, shooting.atol,
                    shooting.scale)
    try:
        events = base.cycle(x0, period).events
    except FivdiscError:
        return ""
    out = []
    for (t1, k1, j1), (t2, k2, j2) in itertools.pairwise(events):
        if j1 != j2 and t2 - t1 <= SIMULTANEOUS * period:
            out.append(f"pad {j1}'s {EVENT_WORDS[k1]} and pad {j2}'s {EVENT_WORDS[k2]}")
    return ", ".join(dict.fromkeys(out))


def _symmetric(group, model: Model, x0: np.ndarray, phases: np.ndarray, period: float,
               rtol: float, atol: float) -> SymmetricShooting:
    """The T/k shooting of the spatio-temporal symmetry the motion from ``x0`` shows
    (to 1e-2 of its size: it is not converged yet)."""
    if not group:
        raise FivdiscError(f"symmetric: the case has no symmetry ({group.description}): "
                           "identical pads equally spaced on a face are needed")
    found = orbit_symmetry(group, model, x0, phases, period, rtol, atol, tol=1e-2)
    if found.shift is None:
        raise FivdiscError("symmetric: the motion found has no spatio-temporal symmetry of "
                           f"the case's group ({group.description}): no x(T/k) = P x(0)"
                           + (f" (it is {found.name}: solve it over the full period)"
                              if found else "") + "; leave out --symmetric")
    return SymmetricShooting(model, phases, rtol, atol, found.shift.matrix, found.k)


def orbit_symmetry(group: CaseSymmetry, model: Model, x0: np.ndarray, phases: np.ndarray,
                   period: float, rtol: float = 1e-12, atol: float | None = None,
                   tol: float = ORBIT_SYMMETRY, sticks: bool | None = None,
                   reduced: bool = False) -> OrbitSymmetry:
    """The symmetry of the orbit through ``x0`` (phases ``phases``, period ``period``)
    under the elements of ``group``.

    Parameters
    ----------
    tol : float
        A symmetry holds where ``|x(T/k) - P x(0)|`` (scaled, relative to the orbit's size
        ``|f(x0)| T``) is below this.
    sticks : bool, optional
        Whether the pads stick on the orbit (for the name); default: ``phases`` says.
    reduced : bool
        Also compute ``R = P^-1 d phi_{T/k}`` of a spatio-temporal symmetry (its
        ``reduced``).
    """
    if not group:
        return OrbitSymmetry("none")
    atol = rtol * 1e-7 if atol is None else atol
    shooting = Shooting(model, phases, rtol, atol)
    scale = shooting.scale
    # the coordinates held by the contact as the flow sets them (a guess may not have)
    x0 = shooting.held(x0)
    whole = shooting.shoot(x0, period, tangents=False)
    x0[~whole.free] = whole.end[~whole.free]
    ends: dict[int, np.ndarray] = {}
    size = np.nan
    for k in sorted({el.order for el in group.elements}, reverse=True):
        try:
            shot = shooting.shoot(x0, period / k, tangents=False)
        except FivdiscError:
            continue
        ends[k] = shot.end
        size = float(np.linalg.norm(shot.rate_start / scale) * period)

    def dist(a: np.ndarray, b: np.ndarray) -> float:
        return float(np.linalg.norm((a - b) / scale) / size)

    spatial = tuple(el for el in group.elements if dist(el.matrix @ x0, x0) < tol)
    worst = max((dist(el.matrix @ x0, x0) for el in spatial), default=0.0)
    best: tuple[int, Element, float] | None = None
    for k, end in ends.items():
        for el in group.elements:
            if el.order != k or el in spatial:
                continue
            d = dist(end, el.matrix @ x0)
            if d < tol:
                best = (k, el, d)
                break
        if best is not None:
            break
    if sticks is None:
        sticks = _sticks(model, x0, phases, period, rtol, atol)
    verb = "stick" if sticks else "move"
    parts = []
    if best is not None:
        k, el, d = best
        worst = max(worst, d)
        parts.append(f"pads {verb} in turn, T/{k} apart" if "turn" in el.label
                     and "mirror" not in el.label else
                     f"the faces {verb} in turn, T/{k} apart" if el.label.startswith("mirror")
                     else f"pads {verb} in turn, T/{k} apart, mirrored")
    if spatial:
        if len(spatial) == len(group.elements):
            parts.append("in phase")
        else:
            parts.append(" and ".join(
                ("the faces in mirror image" if el.label.startswith("mirror") else
                 f"alike after a {el.label}") for el in spatial))
    name = "; ".join(parts) if parts else "none"
    if best is None:
        return OrbitSymmetry(name, spatial, None, 1, worst)
    k, el, _ = best
    red = None
    if reduced:
        shot = shooting.shoot(x0, period / k)
        red = np.linalg.solve(el.matrix, shot.monodromy)
    return OrbitSymmetry(name, spatial, el, k, worst, red)


def _sticks(model: Model, x0: np.ndarray, phases: np.ndarray, period: float, rtol: float,
            atol: float) -> bool:
    """Whether a pad sticks on the orbit through ``x0`` over one period."""
    from fivdisc.engine.integration import Integration

    if np.any(phases == Phase.STICK):
        return True
    run = Integration(model, x0, duration=period, rtol=rtol, atol=atol, phases=phases)
    run.run_to(period)
    _, rows = run.events()
    return bool(np.any(rows[:, 2] == Phase.STICK)) if rows.size else False


class SavedStart(NamedTuple):
    """A start read from a file fivdisc wrote (:func:`saved_start`)."""

    #: The case stored in the file (for a branch point: with its key at the point's
    #: value), or None.
    case: Case | None
    #: The state to start from.
    state: np.ndarray
    #: Each slider's phase at that state.
    phases: np.ndarray
    #: The orbit's period [s] (None for a simulation result).
    period: float | None
    #: Where it came from, for an orbit's ``start``.
    start: str
    #: For a branch point: the branch's key and the point's value (else "" and None).
    key: str = ""
    value: float | None = None


BRANCH_CONTENT = "continuation branch"


def saved_start(path: str | PathLike[str], point: int | None = None) -> SavedStart:
    """A start from a file fivdisc wrote: an orbit (``fivdisc orbit -o``; its state,
    phases and period), a simulation result (its final state and phases) or a branch
    point (``fivdisc continue -o``; point ``point``, default its last: the point's state,
    phases and period, and the case with the branch's key at the point's value, and a
    bifurcation curve's second key at its value there).

    Raises
    ------
    FivdiscError
        The file holds none of these, ``point`` is given for a file that is not a
        branch, or is not one of the branch's points.
    """
    from fivdisc.files import read_dataset

    ds = read_dataset(path, "--from")
    text = ds.attrs.get("case")
    case = Case.from_toml(text) if text else None
    content = ds.attrs.get("content")
    if content == BRANCH_CONTENT and "state" in ds:
        count = int(ds.sizes["point"])
        k = count - 1 if point is None else point
        if not (isinstance(k, int | np.integer) and -count <= k < count):
            raise FivdiscError(f"--point {point} is invalid: the branch in {path} has "
                               f"{count} point(s), numbered from 0")
        k = int(k) % count
        key = str(ds.attrs["key"])
        value = float(ds["parameter"].values[k])
        phase = ds["phase"].values
        phases = (phase[k] if phase.ndim == 2 else phase).astype(np.int64)
        where = f"{key} = {value:.10g}"
        if case is not None:
            case = case.replace({key: value})
            if "second_parameter" in ds:
                # a point of a bifurcation curve in two keys: the second key's value too
                key2 = str(ds.attrs["key2"])
                value2 = float(ds["second_parameter"].values[k])
                case = case.replace({key2: value2})
                where += f", {key2} = {value2:.10g}"
        return SavedStart(case, ds["state"].values[k].astype(float), phases,
                          float(ds["period"].values[k]),
                          f"from point {k} of the branch in {path} ({where})", key, value)
    if point is not None:
        raise FivdiscError(f"--point {point} needs --from a branch (fivdisc continue -o); "
                           f"{path} holds no branch")
    if content == "periodic orbit" and "state" in ds:
        return SavedStart(case, ds["state"].values.astype(float),
                          ds["phase"].values.astype(np.int64), float(ds.attrs["period"]),
                          f"from the orbit in {path}")
    if "final_state" in ds.attrs and "final_phase" in ds.attrs:
        state = np.atleast_1d(np.asarray(ds.attrs["final_state"], dtype=float))
        phases = np.atleast_1d(np.asarray(ds.attrs["final_phase"], dtype=np.int64))
        return SavedStart(case, state, phases, None,
                          f"from the final state of the run in {path}")
    raise FivdiscError(f"--from {path}: holds neither a periodic orbit (fivdisc orbit -o), "
                       "a simulation result (fivdisc simulate -o) nor a branch (fivdisc "
                       "continue -o)")
