"""Continuation of periodic orbits in one case key, through their bifurcations.

A branch is followed by pseudo-arclength continuation of the shooting equations of
:mod:`fivdisc.analysis.orbits` with the parameter ``p`` as one more unknown. With ``x``
the free coordinates of the orbit's point, scaled (energy scales, divided by the first
orbit's size), ``T`` the period and ``p`` the key's value, each divided by its value at
the start, the unknowns are ``z = (x, T, p)`` and the equations

* ``phi_T(x; p) - x = 0``: the orbit closes;
* ``f(x_prev) . (x - x_prev) = 0``: the point moves orthogonally to the flow from the
  previous point's (which fixes it on the orbit);
* ``t_prev . (z - z_prev) = ds``: a step ``ds`` along the previous tangent.

The predictor is ``z_prev + ds t_prev``; a chord Newton corrector takes the previous
point's Jacobian: the monodromy (exact across every switch) for ``d phi_T / dx``, the
vector field for ``d phi_T / dT`` and a central difference for ``d phi_T / dp``; each
converged point gets its own, for its multipliers and tangent. A corrector that needs more than
:data:`_MAX_CORRECTION` of ``ds`` to converge, or whose tangent turns by more than 60
degrees, is refused and the step halved: so the branch moves continuously and never
jumps to a nearby orbit (orbits of nearly the same period coexist in the paper's cases).

Bifurcations are detected between consecutive points and located by a root of a test
function along the arclength (:func:`scipy.optimize.brentq`) or, for a change of the
event signature, by bisection, each to a relative accuracy of 1e-6 in the parameter:

* fold: the tangent's parameter component changes sign;
* period doubling: a real multiplier crosses -1;
* torus (Neimark-Sacker): a complex pair crosses the unit circle;
* discontinuity-induced: the event signature (:mod:`fivdisc.analysis.cycle`) changes;
  the multipliers on either side are reported, since they may jump there.
* grazing: a branch of slipping orbits lost where its slip speed touches zero ends
  there (the stick-slip orbits turn back from it).

A branch may also start at a Hopf point of the equilibrium
(:func:`fivdisc.analysis.hopf_cycle.hopf_cycles`): the first point is corrected with its
amplitude along the critical eigenvector held and the parameter free.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from fivdisc.analysis.cycle import Cycle, one_period
from fivdisc.analysis.orbits import (
    PeriodicOrbit,
    Shooting,
    Shot,
    energy_scales,
    periodic_orbit,
    verdict_of,
)
from fivdisc.case import Case, is_case_key
from fivdisc.errors import CaseError, ConvergenceError, FivdiscError
from fivdisc.integration import Integration
from fivdisc.model import Model, build_model, model_at

__all__ = ["Bifurcation", "check_key", "check_window", "continue_orbit", "doubled_start"]

# A corrector may move the point at most this many step lengths from the predictor.
_MAX_CORRECTION = 0.5
# Cosine of the largest turn of the tangent between consecutive points (60 degrees).
_MIN_COSINE = 0.5
_MAX_NEWTON = 10
# Relative step of the central difference d phi_T / dp.
_DP = 1e-6
# Relative accuracy in the parameter to which bifurcations are located.
_LOCATE = 1e-7
# A converged point is refined while its residual falls, to below this fraction of the
# tolerance (_Branch.correct) ...
_POLISH = 1e-2
# ... and until the last correction moved the period by less than this (relative): where a
# multiplier is near 1 the period's error is many times the residual (30 to 100 times on
# a stick-slip orbit whose multipliers are 0.98 to 0.99), so the residual alone does not
# hold it to 1e-9.
_SETTLED = 1e-11
# A multiplier whose imaginary part is below this (relative) is taken as real.
_REAL = 1e-6
# A lost branch of slipping orbits whose smallest slip speed is below this fraction of
# the disc speed ends grazing the stick boundary.
_GRAZING = 1e-3
INTERRUPTED = "interrupted (Ctrl-C)"
_DOUBLED_AMPLITUDE = 1e-4  # first doubled orbit's distance from the period doubling


@dataclass
class _Point:
    """A converged point of the branch."""

    z: np.ndarray
    x: np.ndarray
    shot: Shot
    jac: np.ndarray
    tangent: np.ndarray
    multipliers: np.ndarray
    trivial: int
    residual: float
    iterations: int
    cycle: Cycle | None = None

    @property
    def verdict(self) -> str:
        return verdict_of(self.multipliers, self.trivial)


@dataclass
class Bifurcation:
    """A bifurcation located on a branch.

    Attributes
    ----------
    kind : str
        ``"fold"``, ``"period doubling"``, ``"torus"``, ``"branch point"`` (a real
        multiplier through +1 without a fold), ``"signature change"``
        (discontinuity-induced) or ``"grazing"`` (the branch ends where its slip speed
        touches zero, at its last point).
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


@dataclass
class _Stop:
    reason: str = ""
    lost: bool = False


def check_key(case: Case, key: str, option: str = "key") -> float:
    """The current value of a numeric case key, or a one-line error.

    Raises
    ------
    CaseError
        The key is unknown, a simulation setting, or not a single number (a table, a
        list, a name, a switch).
    """
    if not is_case_key(key):
        from fivdisc.analysis.stability import resolve_key

        key = resolve_key(key, option)
    if key.startswith("simulation."):
        raise CaseError(f"{option} = {key!r} is invalid: the simulation settings do not "
                        "change the system, so its periodic orbits do not depend on them; "
                        "continue in a key of disc, slider(s), friction or speed")
    value = case.get(key)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise CaseError(f"{option} = {key!r} is invalid: its value {value!r} is not a number; "
                        "continuation needs a numeric key")
    return float(value)


class _Branch:
    """The continuation problem: the case, the key, scales and the point machinery."""

    def __init__(self, case: Case, key: str, phases: np.ndarray, period: float, rtol: float,
                 atol: float, tol: float) -> None:
        self.case, self.key = case, key
        self.base = build_model(case)
        self.p0 = check_key(case, key)
        self.rtol, self.atol, self.tol = rtol, atol, tol
        self.scale = energy_scales(self.base)
        self.shooting = Shooting(self.base, phases, rtol, atol, self.scale)
        self._models: dict[float, Model] = {}
        self.period0 = period
        self.ps = abs(self.p0) if self.p0 != 0 else 1.0

    # --- coordinates ----------------------------------------------------------------------

    def set_free(self, shot: Shot, x: np.ndarray) -> None:
        self.free = shot.free.copy()
        self.m = int(self.free.sum())
        self.xs = float(np.linalg.norm(shot.rate_start / self.scale) * self.period0)
        self.template = x.copy()

    def pack(self, x: np.ndarray, period: float, p: float) -> np.ndarray:
        return np.r_[x[self.free] / self.scale[self.free] / self.xs, period / self.period0,
                     p / self.ps]

    def unpack(self, z: np.ndarray) -> tuple[np.ndarray, float, float]:
        x = self.template.copy()
        x[self.free] = z[: self.m] * self.scale[self.free] * self.xs
        return x, float(z[self.m] * self.period0), float(z[self.m + 1] * self.ps)

    def model(self, p: float) -> Model:
        if p not in self._models:
            if len(self._models) > 64:
                self._models.clear()
            try:
                self._models[p] = model_at(self.base, self.case, {self.key: p})
            except CaseError as exc:
                # A corrector or predictor that leaves the key's allowed range has taken
                # too long a step: the walk halves it (and lands on a boundary target).
                raise ConvergenceError(str(exc), reason=str(exc)) from None
        return self._models[p]

    def shooter(self, p: float) -> Shooting:
        return self.shooting.at(self.model(p))

    # --- equations ------------------------------------------------------------------------

    def gap_of(self, shot: Shot, x: np.ndarray) -> np.ndarray:
        return (shot.end - x)[self.free] / self.scale[self.free] / self.xs

    def dgap_dp(self, x: np.ndarray, period: float, p: float) -> np.ndarray:
        """``d (phi_T - x) / d p`` in the scaled unknowns, by a central difference, or a
        one-sided one of the same order where ``p`` lies within the difference step of
        a bound of the key's range (a damping continued to zero)."""
        h = _DP * self.ps

        def end(q: float) -> np.ndarray:
            return self.shooter(q).shoot(x, period, tangents=False).end

        try:
            diff = (end(p + h) - end(p - h)) / (2 * h)
        except ConvergenceError:
            side = h if self._allowed(p + 2 * h) else -h
            diff = (4 * end(p + side) - end(p + 2 * side) - 3 * end(p)) / (2 * side)
        return diff[self.free] / self.scale[self.free] / self.xs * self.ps

    def _allowed(self, p: float) -> bool:
        try:
            self.model(p)
        except ConvergenceError:
            return False
        return True

    def jacobian(self, shot: Shot, shooting: Shooting, dp: np.ndarray,
                 ref: np.ndarray) -> np.ndarray:
        """``(m + 1, m + 2)``: the gap's and the phase condition's derivatives in z."""
        m = self.m
        if not np.array_equal(shot.free, self.free):
            raise FivdiscError("the orbit's point reached a switch (its free coordinates "
                               "changed)")
        base = shooting.jacobian(shot)
        jac = np.zeros((m + 1, m + 2))
        jac[:m, :m] = base[:m, :m]
        jac[:m, m] = base[:m, m] * self.period0 / self.xs
        jac[:m, m + 1] = dp
        jac[m, :m] = ref
        return jac

    def phase_row(self, shot: Shot) -> np.ndarray:
        f = shot.rate_start[self.free] / self.scale[self.free]
        return f / np.linalg.norm(f)

    def tangent(self, jac: np.ndarray, previous: np.ndarray | None, sign: float) -> np.ndarray:
        """Unit null vector of ``jac``, oriented along ``previous`` (or with the sign of
        its parameter component = ``sign``)."""
        _, _, vt = np.linalg.svd(jac)
        t = vt[-1]
        if previous is not None:
            if float(t @ previous) < 0:
                t = -t
        elif t[-1] * sign < 0:
            t = -t
        return t / np.linalg.norm(t)

    def correct(self, z_pred: np.ndarray, row: np.ndarray, target: float, ref: _Point,
                step: float, deadline: float) -> _Point:
        """Chord Newton on the gap, the phase condition about ``ref`` and
        ``row . z = target``, from ``z_pred``, each correction bounded (module docstring).

        The iterations take ``ref``'s Jacobian, factorised once, and runs of the flow map
        without tangents; once the residual is below the tolerance they go on while it
        falls, to below 1e-2 of it and until a correction moves the period by less than
        1e-11 (the residual bounds the period's error only to about itself times the
        conditioning, large where a multiplier is near 1), and the monodromy of the
        converged point comes from one run with tangents (the state's trajectory is the
        same with and without them).

        Raises
        ------
        ConvergenceError
            Not converged, or a correction too large (``reason`` says which).
        """
        from scipy.linalg import lu_factor, lu_solve

        m = self.m
        phase = self.phase_row(ref.shot)
        x_ref = ref.z[:m]
        lhs = np.vstack([ref.jac, row])
        lhs[m, :m] = phase
        lhs[m, m:] = 0.0
        factors = lu_factor(lhs)
        z = z_pred.copy()
        best = None
        moved = np.inf  # relative change of the period by the last correction
        polished = None
        reason = f"no convergence in {_MAX_NEWTON} iterations"
        for it in range(_MAX_NEWTON + 1):
            x, period, p = self.unpack(z)
            if not period > 0:
                reason = "the period reached zero"
                break
            shooting = self.shooter(p)
            try:
                shot = shooting.shoot(x, period, tangents=False)
            except FivdiscError as exc:
                reason = str(exc)
                break
            if not np.array_equal(shot.free, self.free):
                reason = "the orbit's point reached a switch"
                break
            residual = shooting.residual(shot, x, period)
            if best is not None and residual >= best[1]:
                break  # converged, and no longer falling: keep the best
            if residual < self.tol:
                if residual < _POLISH * self.tol and polished is None:
                    polished = it  # the iterations the step control counts
                best = (z, residual, it if polished is None else polished)
                if polished is not None and moved < _SETTLED:
                    break
            elif it == _MAX_NEWTON or time.monotonic() > deadline:
                reason = (f"no convergence in {_MAX_NEWTON} iterations" if it == _MAX_NEWTON
                          else "the time budget ran out")
                break
            rhs = -np.r_[self.gap_of(shot, x), phase @ (z[:m] - x_ref), row @ z - target]
            dz = lu_solve(factors, rhs)
            moved = abs(dz[m] / z[m])
            z = z + dz
            if best is None and np.linalg.norm(z - z_pred) > _MAX_CORRECTION * step:
                reason = "the corrector left the neighbourhood of the predictor"
                break
        if best is None:
            raise ConvergenceError(reason, reason=reason)
        z, residual, it = best
        point = self._linearised(z, phase, residual, it)
        if residual > _POLISH * self.tol:
            # The chord iterations stalled above the polish level (the previous point's
            # Jacobian no longer contracts well enough): one Newton step on this point's
            # own Jacobian, kept if it lowers the residual.
            lhs = np.vstack([point.jac, row])
            rhs = -np.r_[self.gap_of(point.shot, point.x), phase @ (z[:m] - x_ref),
                         row @ z - target]
            z_new = z + np.linalg.solve(lhs, rhs)
            x, period, p = self.unpack(z_new)
            try:
                shot = self.shooter(p).shoot(x, period, tangents=False)
                polished = (self.shooter(p).residual(shot, x, period)
                            if np.array_equal(shot.free, self.free) else np.inf)
            except FivdiscError:
                polished = np.inf
            if polished < residual:
                point = self._linearised(z_new, phase, polished, it + 1)
        return point

    def _linearised(self, z: np.ndarray, phase: np.ndarray, residual: float,
                    iterations: int) -> _Point:
        """The point ``z`` with its monodromy, multipliers and Jacobian (one run with
        tangents)."""
        x, period, p = self.unpack(z)
        shooting = self.shooter(p)
        shot = shooting.shoot(x, period)
        jac = self.jacobian(shot, shooting, self.dgap_dp(x, period, p), phase)
        mult, trivial = self.shooting.stability(shot)
        # The coordinates held by the contact (a slider's z, zdot) are the template's in
        # x; the kernel sets them from the disc's deflection, and after one period they
        # are those of this orbit: the point kept has them.
        held = ~shot.free
        x[held] = shot.end[held]
        return _Point(z, x, shot, jac, np.zeros_like(z), mult, trivial, residual, iterations)

    def finish(self, point: _Point, previous: np.ndarray | None, sign: float) -> _Point:
        point.tangent = self.tangent(point.jac, previous, sign)
        x, period, p = self.unpack(point.z)
        point.cycle = one_period(self.model(p), x, self.shooting.phases, period, self.rtol,
                                 self.atol)
        return point

    def step_from(self, a: _Point, s: float, deadline: float) -> _Point:
        """The point at arclength ``s`` from ``a`` along ``a``'s tangent."""
        pt = self.correct(a.z + s * a.tangent, a.tangent, float(a.tangent @ a.z) + s, a,
                          abs(s), deadline)
        return self.finish(pt, a.tangent, 1.0)

    def at_value(self, a: _Point, value: float, deadline: float) -> _Point:
        """The point at parameter ``value``, from ``a`` (secant to it along the tangent)."""
        target = value / self.ps
        s = (target - a.z[-1]) / a.tangent[-1]
        row = np.zeros_like(a.z)
        row[-1] = 1.0
        pt = self.correct(a.z + s * a.tangent, row, target, a, abs(s), deadline)
        return self.finish(pt, a.tangent, 1.0)


def _start_point(branch: _Branch, orbit: PeriodicOrbit, direction: float,
                 along: np.ndarray | None, deadline: float) -> _Point:
    """The first point: the orbit moved to the middle of its longest interval without a
    switch in which no slider sticks (so that the point stays away from switches along
    the branch, and no coordinate of it is held by a sticking slider).

    With ``along`` (branch switching at a period doubling: ``orbit`` is the orbit at the
    point traversed twice, ``along`` the eigenvector of its multiplier -1) the first
    point is a doubled orbit itself, of amplitude 1e-4 of the orbit's size along
    ``along``. At the period-doubling point the doubled orbits leave the twice-traversed
    one with the parameter changing only at second order: there two branches cross and
    the Jacobian is singular in both their directions, so no corrector converges from
    it. At a small amplitude, held while the parameter is free (as from a Hopf point),
    it is regular."""
    model = branch.base
    x, phases = orbit.state, orbit.phases
    if along is None:
        cyc = one_period(model, x, phases, orbit.period, branch.rtol, branch.atol)
        times = np.r_[0.0, cyc.switch_times, orbit.period]
        gaps = np.where(cyc.stick_free, np.diff(times), -1.0)
        i = int(np.argmax(gaps))
        shift = times[i] + 0.5 * gaps[i]
        if shift > 0:
            run = Integration(model, x, duration=shift, output_rate=1.0 / shift,
                              rtol=branch.rtol, atol=branch.atol, phases=phases)
            run.run_to(shift)
            x, phases = run.out_y[1, : model.state_size].copy(), run.ph.copy()
    branch.shooting = Shooting(model, phases, branch.rtol, branch.atol, branch.scale)
    if along is not None:
        branch.set_free(branch.shooting.shoot(x, orbit.period, tangents=False), x)
        unit = along / np.linalg.norm(along[branch.free] / branch.scale[branch.free]
                                      / branch.xs)
        return _hopf_start(branch, x, unit, _DOUBLED_AMPLITUDE, _DOUBLED_AMPLITUDE,
                           deadline)
    shot = branch.shooting.shoot(x, orbit.period)
    branch.set_free(shot, x)
    z = branch.pack(x, orbit.period, branch.p0)
    dp = branch.dgap_dp(x, orbit.period, branch.p0)
    jac = branch.jacobian(shot, branch.shooting, dp, branch.phase_row(shot))
    mult, trivial = branch.shooting.stability(shot)
    residual = branch.shooting.residual(shot, x, orbit.period)
    pt = _Point(z, x, shot, jac, np.zeros_like(z), mult, trivial, residual, 0)
    return branch.finish(pt, None, direction)


def _hopf_start(branch: _Branch, state: np.ndarray, direction: np.ndarray, eps: float,
                size: float, deadline: float) -> _Point:
    """The first point of the orbits born at a Hopf point: from ``state + eps direction``
    (the equilibrium and the critical eigenvector's real part, the period the branch's
    first), Newton with the amplitude along ``direction`` held at ``eps`` and the
    parameter free; the tangent points to larger amplitudes. The unknowns are measured
    in the orbit of amplitude ``size`` (not the first, small orbit's): so a step is a
    fraction of the way to ``size``."""
    x0 = state + eps * direction
    shot = branch.shooting.shoot(x0, branch.period0)
    branch.set_free(shot, x0)
    # The orbit's size is linear in its amplitude while it is small.
    branch.xs *= size / eps
    z0 = branch.pack(x0, branch.period0, branch.p0)
    row = z0 - branch.pack(state, branch.period0, branch.p0)
    row /= np.linalg.norm(row)
    dp = branch.dgap_dp(x0, branch.period0, branch.p0)
    jac = branch.jacobian(shot, branch.shooting, dp, branch.phase_row(shot))
    ref = _Point(z0, x0, shot, jac, np.zeros_like(z0), np.zeros(0), 0, np.inf, 0)
    pt = branch.correct(z0, row, float(row @ z0), ref, 1.0, deadline)
    return branch.finish(pt, row, 1.0)


def doubled_start(case: Case, state: np.ndarray, period: float, phases: np.ndarray,
                  rtol: float = 1e-12, atol: float | None = None
                  ) -> tuple[PeriodicOrbit, np.ndarray]:
    """The start of the branch of doubled orbits at a period-doubling point: the orbit's
    point taken with twice its period, and the direction in which the doubled orbits
    leave it (the eigenvector of the multiplier nearest -1).

    Returns
    -------
    orbit : PeriodicOrbit
        The orbit at the point with period ``2 period`` (its multipliers are those of
        the doubled period).
    along : ndarray
        The direction, for :func:`continue_orbit`'s ``along``.
    """
    atol = atol if atol is not None else rtol * 1e-7
    model = build_model(case)
    shooting = Shooting(model, phases, rtol, atol)
    shot = shooting.shoot(state, period)
    mult, vecs = np.linalg.eig(shot.monodromy)
    i = int(np.argmin(np.abs(mult + 1.0)))
    if abs(mult[i] + 1.0) > 0.05:
        raise FivdiscError(f"the point is no period-doubling point: no multiplier is near -1 "
                           f"(the nearest is {mult[i]:.4f})")
    along = np.real(vecs[:, i])
    double = shooting.shoot(state, 2.0 * period)
    dmult, trivial = shooting.stability(double)
    orbit = PeriodicOrbit(period=2.0 * period, state=state.copy(), phases=phases.copy(),
                          monodromy=double.monodromy, multipliers=dmult, trivial=trivial,
                          residual=shooting.residual(double, state, 2.0 * period),
                          iterations=0, verdict=verdict_of(dmult, trivial),
                          start="at a period-doubling point, twice its period")
    return orbit, along


# --- bifurcations ---------------------------------------------------------------------------


def _outside(mult: np.ndarray, trivial: int) -> tuple[int, int, int]:
    """Numbers of multipliers (flow direction left out) outside the unit circle: real
    positive, real negative, complex."""
    others = np.delete(mult, trivial)
    out = others[np.abs(others) > 1.0]
    real = np.abs(out.imag) <= _REAL * np.abs(out)
    return (int(np.sum(real & (out.real > 0))), int(np.sum(real & (out.real < 0))),
            int(np.sum(~real)))


def _nearest_to(mult: np.ndarray, trivial: int, kind: str) -> complex:
    others = np.delete(mult, trivial)
    if kind == "period doubling":
        return complex(others[np.argmin(np.abs(others + 1.0))])
    cplx = others[np.abs(others.imag) > _REAL * np.abs(others)]
    return complex(cplx[np.argmin(np.abs(np.abs(cplx) - 1.0))]) if cplx.size else 0j


def _test_value(pt: _Point, kind: str) -> float:
    if kind == "fold":
        return float(pt.tangent[-1])
    if kind == "period doubling":
        return float(_nearest_to(pt.multipliers, pt.trivial, kind).real + 1.0)
    if kind == "branch point":
        others = np.delete(pt.multipliers, pt.trivial)
        real = others[np.abs(others.imag) <= _REAL * np.abs(others)]
        return float(real.real[np.argmin(np.abs(real.real - 1.0))] - 1.0) if real.size else 1.0
    return float(abs(_nearest_to(pt.multipliers, pt.trivial, kind)) - 1.0)


def _of_kind(pt: _Point, kind: str) -> np.ndarray:
    """``pt``'s multipliers (flow direction left out) of the class whose passage makes
    ``kind``: real negative (period doubling), complex with a positive imaginary part
    (torus; one of each pair), real positive (branch point)."""
    others = np.delete(pt.multipliers, pt.trivial)
    real = np.abs(others.imag) <= _REAL * np.abs(others)
    if kind == "period doubling":
        return others[real & (others.real < 0)]
    if kind == "torus":
        return others[~real & (others.imag > 0)]
    return others[real & (others.real > 0)]


def _passage(mu: complex, kind: str) -> float:
    """One multiplier's test function: zero where it passes -1, the unit circle or +1."""
    if kind == "period doubling":
        return mu.real + 1.0
    if kind == "torus":
        return abs(mu) - 1.0
    return mu.real - 1.0


def _crossings(a: _Point, b: _Point, kind: str) -> list[tuple[complex, complex]]:
    """The multipliers of ``kind``'s class that pass between ``a`` and ``b``, each as its
    values at ``a`` and at ``b`` (matched by nearness)."""
    from scipy.optimize import linear_sum_assignment

    at_a, at_b = _of_kind(a, kind), _of_kind(b, kind)
    rows, cols = linear_sum_assignment(np.abs(at_a[:, None] - at_b[None, :]))
    return [(complex(at_a[i]), complex(at_b[j])) for i, j in zip(rows, cols, strict=True)
            if _passage(at_a[i], kind) * _passage(at_b[j], kind) < 0]


def _smooth_kinds(a: _Point, b: _Point) -> list[str]:
    kinds = []
    if a.tangent[-1] * b.tangent[-1] < 0:
        kinds.append("fold")
    oa, ob = _outside(a.multipliers, a.trivial), _outside(b.multipliers, b.trivial)
    if oa[1] != ob[1]:
        kinds.append("period doubling")
    if oa[2] != ob[2]:
        kinds.append("torus")
    if oa[0] != ob[0] and "fold" not in kinds:
        kinds.append("branch point")
    return kinds


def _located(branch: _Branch, a: _Point, b: _Point, s_ab: float, kind: str,
             deadline: float, depth: int = 0) -> list[tuple[_Point, _Point]]:
    """Each bifurcation of smooth ``kind`` between ``a`` and ``b``, located. Where several
    multipliers pass in one interval (two pairs leaving the unit circle close together)
    the interval is halved until each holds one, and each passage is followed by its own
    multiplier: the multiplier nearest the circle jumps from one pair to the other
    between them, and a root search on it would find the jump."""
    if kind == "fold":
        return [_locate(branch, a, b, s_ab, kind, deadline)]
    passing = _crossings(a, b, kind)
    if not passing:
        # No multiplier of the class passes: the count changed because a pair outside
        # the circle became two real ones (next to a fold) or the reverse, which is no
        # bifurcation of this kind.
        return []
    if len(passing) == 1 or depth == 6:
        # each followed by its own multiplier (still together after six halvings: the
        # straight-line guesses tell them apart)
        return [_locate(branch, a, b, s_ab, kind, deadline, track) for track in passing]
    mid = branch.step_from(a, 0.5 * s_ab, deadline)
    return [found for lo, hi in ((a, mid), (mid, b))
            for found in _located(branch, lo, hi, float(np.linalg.norm(hi.z - lo.z)), kind,
                                  deadline, depth + 1)]


def _locate(branch: _Branch, a: _Point, b: _Point, s_ab: float, kind: str,
            deadline: float, track: tuple[complex, complex] | None = None
            ) -> tuple[_Point, _Point]:
    """The bifurcation of ``kind`` between ``a`` and ``b`` (arclength ``s_ab`` apart):
    the located point, or for a signature change the two points bracketing it. With
    ``track`` (the passing multiplier at ``a`` and at ``b``), the test function is that
    multiplier's, followed from its straight-line guess."""
    from scipy.optimize import brentq

    p_tol = _LOCATE * max(abs(branch.unpack(a.z)[2]), 1e-12) / branch.ps
    if kind == "signature change":
        lo, hi, s_lo, s_hi = a, b, 0.0, s_ab
        key = a.cycle.cyclic()
        while abs(hi.z[-1] - lo.z[-1]) > p_tol and s_hi - s_lo > 1e-12:
            s = 0.5 * (s_lo + s_hi)
            mid = branch.step_from(a, s, deadline)
            if mid.cycle.cyclic() == key:
                lo, s_lo = mid, s
            else:
                hi, s_hi = mid, s
        return lo, hi
    memo: dict[float, _Point] = {0.0: a, s_ab: b}

    def value(s: float) -> float:
        if s not in memo:
            memo[s] = branch.step_from(a, s, deadline)
        near = _of_kind(memo[s], kind) if track is not None else np.zeros(0)
        if near.size == 0:
            return _test_value(memo[s], kind)
        guess = track[0] + (track[1] - track[0]) * s / s_ab
        return _passage(complex(near[np.argmin(np.abs(near - guess))]), kind)

    # |dp/ds| <= 1 in the scaled unknowns, so s to p_tol gives p to p_tol.
    s = brentq(value, 0.0, s_ab, xtol=p_tol, rtol=4 * np.finfo(float).eps)
    value(s)
    return memo[s], memo[s]


def _bifurcation(branch: _Branch, kind: str, lo: _Point, hi: _Point, index: int,
                 sides: tuple[_Point, _Point] | None = None) -> Bifurcation:
    """The record of a bifurcation located at ``lo`` (a smooth one, ``hi`` the same) or
    between ``lo`` and ``hi`` (a signature change). Its multipliers before and after are
    those of ``sides`` if given (the branch's points either side of a smooth one, where
    the passing multiplier shows), else of ``lo`` and ``hi``."""
    before, after = sides if sides is not None else (lo, hi)
    _, t_lo, p_lo = branch.unpack(lo.z)
    _, t_hi, p_hi = branch.unpack(hi.z)
    at = hi if kind == "signature change" else lo
    rotation = math.nan
    note = ""
    if kind == "torus":
        pair = _nearest_to(at.multipliers, at.trivial, kind)
        rotation = abs(math.atan2(pair.imag, pair.real)) / (2 * math.pi)
        note = f"a complex pair crosses the unit circle, rotation number {rotation:.6f}"
    elif kind == "period doubling":
        note = "a real multiplier crosses -1: an orbit of twice the period branches off"
    elif kind == "fold":
        note = "the branch turns back in the parameter (fold of cycles)"
    elif kind == "branch point":
        note = "a real multiplier crosses +1 without a fold"
    else:
        sides = [f"slider {j}: {u} -> {v}" for j, (u, v) in
                 enumerate(zip(lo.cycle.signature, hi.cycle.signature, strict=True)) if u != v]
        note = "the event signature changes (" + "; ".join(sides) + ")"
    return Bifurcation(kind=kind, parameter=0.5 * (p_lo + p_hi), period=0.5 * (t_lo + t_hi),
                       state=at.x.copy(), before=before.multipliers, after=after.multipliers,
                       signature_before=lo.cycle.signature, signature_after=hi.cycle.signature,
                       rotation=rotation, point=index, note=note)


# --- the driver -----------------------------------------------------------------------------


@dataclass
class _Walk:
    points: list[_Point] = field(default_factory=list)
    bifurcations: list[Bifurcation] = field(default_factory=list)
    stop: _Stop = field(default_factory=_Stop)


def continue_orbit(
    case: Case,
    key: str,
    to: float,
    *,
    orbit: PeriodicOrbit | None = None,
    along: np.ndarray | None = None,
    back_to: float | None = None,
    max_points: int = 200,
    step: float = 0.02,
    max_step: float = 0.1,
    min_step: float = 1e-6,
    rtol: float = 1e-12,
    atol: float | None = None,
    tol: float = 1e-8,
    time_budget: float = 3600.0,
    progress: bool = False,
    **search,
):
    """Follow a periodic orbit of ``case`` as ``key`` goes to ``to``, and locate the
    bifurcations on the way.

    Parameters
    ----------
    case : Case
        A constant-speed case.
    key : str
        A numeric case key (``speed.value``, ``slider.normal_damping``,
        ``sliders.1.preload``, ``friction.decay``, ``disc.damping_ratio``, ...).
    to : float
        Where the continuation stops [the key's unit]; its side of the case's value sets
        the direction. A branch that turns at a fold stops where the key comes back past
        ``back_to`` (the walk's window runs from there to ``to``).
    orbit : PeriodicOrbit, optional
        The orbit to start from (at the case's value of ``key``). Default: found as
        :func:`~fivdisc.analysis.orbits.periodic_orbit` finds it, with ``search`` as its
        keyword arguments (``transient``, ``period``, ``guess``, ``phases``, ...).
    along : ndarray, optional
        Branch switching: the first step leaves ``orbit``'s point in this state
        direction instead of along the branch through it (see :func:`doubled_start`).
    back_to : float, optional
        The window's other end [the key's unit]: once the branch has turned at a fold, it
        stops where the key comes back past this value, on a point corrected to it.
        Default: the case's value. On the case's value or on its side away from ``to``;
        give a value beyond the range the orbits span to follow a closed branch (an
        isola) round.
    max_points : int
        Most points on the branch (the first included).
    step, max_step, min_step : float
        First, largest and smallest arclength step, in the scaled unknowns (the orbit's
        point over its size, the period over the first period, the parameter over its
        first value): a step of 0.02 changes them by about 2 %.
    rtol, atol, tol : float
        Integration tolerances and the shooting residual's tolerance, as for
        :func:`~fivdisc.analysis.orbits.periodic_orbit`.
    time_budget : float
        Wall time after which the continuation stops [s].
    progress : bool
        Show the points on a terminal (stderr).

    Returns
    -------
    Branch
        The points, their measures and multipliers, the bifurcations and why the
        continuation stopped (:class:`fivdisc.analysis.branch.Branch`).

    Raises
    ------
    CaseError
        ``key`` is not a numeric key, or ``to`` is not an allowed value of it.
    ConvergenceError
        No periodic orbit to start from.

    Notes
    -----
    The method is in the module's docstring and on the documentation's continuation
    page. Step control: after a point that took at most 3 corrector iterations the step
    grows by 1.5, after 7 or more it halves; a refused or failed step is halved, and a
    step below ``min_step`` ends the branch as lost.
    """
    p0 = _check_options(case, key, to, max_points, step, max_step, min_step, tol,
                        time_budget)
    if back_to is None:
        back_to = p0
    check_window(key, p0, to, back_to)
    atol_run = atol if atol is not None else rtol * 1e-7
    if orbit is None:
        orbit = periodic_orbit(case, rtol=rtol, atol=atol_run, tol=tol, progress=progress,
                               **search)
    elif not orbit.converged:
        raise ConvergenceError("the start is not a converged periodic orbit", result=orbit,
                               reason="not converged")
    direction = 1.0 if to > p0 else -1.0
    branch = _Branch(case, key, orbit.phases, orbit.period, rtol, atol_run, tol)
    return _run(branch, lambda deadline: _start_point(branch, orbit, direction, along,
                                                      deadline), to,
                max_points, step, max_step, min_step, time_budget, progress, orbit.start,
                back_to)


def check_window(key: str, p0: float, to: float, back_to: float, option: str = "back_to"
                 ) -> None:
    """A one-line refusal of a window's far end ``back_to`` that is not finite or lies
    between the start's value ``p0`` and ``to``."""
    if not (np.isfinite(back_to) and (back_to - p0) * (to - p0) <= 0):
        raise CaseError(f"{option} = {back_to!r} is invalid: must be a finite value of {key} "
                        f"at the start's value {p0:g} or on its side away from {to:g}")


def _check_options(case: Case, key: str, to: float, max_points: int, step: float,
                   max_step: float, min_step: float, tol: float, time_budget: float) -> float:
    """The one-line refusals of :func:`continue_orbit`'s arguments; the key's value."""
    if case.speed.profile != "constant":
        raise FivdiscError(f"continuation needs a constant disc speed (speed.profile = "
                           f"'constant'), not {case.speed.profile!r}: with a varying speed "
                           "the system is not autonomous and has no periodic orbits")
    p0 = check_key(case, key)
    if not np.isfinite(to):
        raise CaseError(f"to = {to!r} is invalid: must be a finite value of {key}")
    case.replace({key: float(to)})  # the target must be an allowed value
    if to == p0:
        raise CaseError(f"to = {to!r} is invalid: it is the case's own value of {key}; "
                        "give the value to continue to")
    for name, value in (("step", step), ("max_step", max_step), ("min_step", min_step),
                        ("time_budget", time_budget), ("tol", tol)):
        if not (np.isfinite(value) and value > 0):
            raise FivdiscError(f"{name} = {value!r} is invalid: must be a finite number > 0")
    if not min_step <= step <= max_step:
        raise FivdiscError(f"step = {step!r} is invalid: must lie between min_step = "
                           f"{min_step!r} and max_step = {max_step!r}")
    if not (isinstance(max_points, int) and max_points >= 1):
        raise FivdiscError(f"max_points = {max_points!r} is invalid: must be an integer >= 1")
    return p0


def _run(branch: _Branch, first, to: float, max_points: int, step: float, max_step: float,
         min_step: float, time_budget: float, progress: bool, start: str,
         back_to: float | None = None):
    """The first point (``first(deadline)``), then the walk to ``to`` (and, after a fold,
    back to ``back_to``, default the first point's value): the branch."""
    from fivdisc.analysis.branch import Branch
    from fivdisc.analysis.lyapunov import warm_tangent_kernel
    from fivdisc.progress import progress_bar
    from fivdisc.split_compile import compile_split_tangents

    # A start from a Hopf point or a saved orbit is the first use of the kernel with
    # tangent vectors, minutes of compiling in a fresh installation: say so (as
    # periodic_orbit does) before the first point, whose time it is not.
    compile_split_tangents()
    warm_tangent_kernel(show=progress or None)
    deadline = time.monotonic() + time_budget
    walk = _Walk()
    with progress_bar(max_points, f"continuing in {branch.key}", "point",
                      show=progress) as bar:
        walk.points.append(first(deadline))
        bar.update()
        try:
            _walk(branch, walk, to, back_to, max_points, step, max_step, min_step,
                  deadline, bar)
        except KeyboardInterrupt:
            # The points and bifurcations so far are a branch: kept, as a time budget
            # running out keeps them.
            walk.stop = _Stop(INTERRUPTED)
    walk.bifurcations = _without_fold_echoes(walk.bifurcations)
    return Branch.from_walk(branch, walk, start)


def _without_fold_echoes(found: list[Bifurcation]) -> list[Bifurcation]:
    """``found`` without the branch points next to a fold.

    At a fold the critical multiplier passes +1 where the parameter turns; the two test
    functions (the multiplier, the tangent's parameter component) are different
    quantities, so where the fold lies within their errors of a point of the branch the
    passage may be counted in the interval beside the turn. A fold is that passage; it
    is not reported twice."""
    folds = [b.point for b in found if b.kind == "fold"]
    return [b for b in found
            if not (b.kind == "branch point" and any(abs(b.point - f) <= 1 for f in folds))]


def _walk(branch: _Branch, walk: _Walk, to: float, back_to: float | None, max_points: int,
          ds: float, max_step: float, min_step: float, deadline: float, bar) -> None:
    target = to / branch.ps
    side = np.sign(target - walk.points[0].z[-1])
    # Once the branch has turned at a fold, it stops where the key comes back past
    # `began` away from `to`, as AUTO stops at the far end of its window; the walk
    # covers the range from there to `to` and no more.
    began = branch.unpack(walk.points[0].z)[2] if back_to is None else back_to
    lo_period, hi_period = branch.period0 / 100.0, branch.period0 * 100.0
    while len(walk.points) < max_points:
        a = walk.points[-1]
        if time.monotonic() > deadline:
            walk.stop = _Stop("the time budget ran out")
            return
        # A predictor past the target goes to the target itself: beyond it the key may
        # leave its allowed range (a damping continued to zero).
        landing = np.sign(target - (a.z[-1] + ds * a.tangent[-1])) != side
        try:
            b = branch.at_value(a, to, deadline) if landing else branch.step_from(a, ds,
                                                                                 deadline)
            if float(b.tangent @ a.tangent) < _MIN_COSINE:
                reason = "the tangent turned by more than 60 degrees"
                raise ConvergenceError(reason, reason=reason)
        except ConvergenceError as exc:
            ds *= 0.5
            if ds < min_step:
                _, _, p = branch.unpack(a.z)
                end = _vanishing(branch, a, len(walk.points) - 1)
                if end is None and _slip_margin(branch, a) < _GRAZING:
                    walk.bifurcations.append(_grazing(branch, a, len(walk.points) - 1))
                    walk.stop = _Stop(f"the orbit grazes the stick boundary at {branch.key} "
                                      f"= {p:.9g} and does not persist past it")
                elif end is None:
                    walk.stop = _Stop(f"the orbit is lost at {branch.key} = {p:.9g}: "
                                      f"{exc.reason}", lost=True)
                else:
                    walk.bifurcations.append(end)
                    walk.stop = _Stop(f"the orbit does not persist past the signature change "
                                      f"at {branch.key} = {end.parameter:.9g}")
                return
            continue
        _, period, _ = branch.unpack(b.z)
        if not lo_period < period < hi_period:
            walk.stop = _Stop(f"the period left [{lo_period:.3g}, {hi_period:.3g}] s "
                              "(a period growing without bound: a homoclinic orbit?)")
            return
        passed = landing or np.sign(target - b.z[-1]) != side
        turned = any(f.kind == "fold" for f in walk.bifurcations)
        back = turned and _away(branch, b, began, to) and not _away(branch, a, began, to)
        if (passed and not landing) or back:
            try:
                b = branch.at_value(a, began if back else to, deadline)
            except ConvergenceError:
                ds *= 0.5
                continue
        found = len(walk.bifurcations)
        _record(branch, walk, a, b, float(np.linalg.norm(b.z - a.z)), deadline)
        walk.points.append(b)
        folds = [f for f in walk.bifurcations if f.kind == "fold"]
        if back or (not turned and folds and _away(branch, b, began, to)):
            walk.stop = _Stop(f"the branch turned at the fold at {branch.key} = "
                              f"{folds[-1].parameter:.9g} and came back to {branch.key} = "
                              f"{began:.9g}, the other end of its window")
            bar.update()
            return
        again = _closed(walk.bifurcations, found)
        if again is not None:
            walk.stop = _Stop(f"the branch closed on itself (an isola): it passed the fold at "
                              f"{branch.key} = {again.parameter:.9g} a second time")
            return
        bar.update()
        _, _, p = branch.unpack(b.z)
        bar.set_postfix_str(f"{branch.key} = {p:.6g}, T = {period:.6g} s")
        if passed:
            walk.stop = _Stop(f"reached {branch.key} = {to:.9g}")
            return
        if b.iterations <= 3:
            ds = min(ds * 1.5, max_step)
        elif b.iterations >= 7:
            ds = max(ds * 0.5, min_step)
    walk.stop = _Stop(f"the largest number of points ({max_points}) is reached")


def _away(branch: _Branch, point: _Point, began: float, to: float) -> bool:
    """Whether ``point``'s key lies past ``began`` on the side away from ``to``."""
    return (branch.unpack(point.z)[2] - began) * (to - began) < 0


def _closed(found: list[Bifurcation], new: int) -> Bifurcation | None:
    """An earlier fold that one of ``found[new:]`` repeats (the same parameter and period
    to 1e-5, ten times the location's accuracy), else None: the branch is a closed curve
    and has come round."""
    for b in found[new:]:
        if b.kind != "fold":
            continue
        for earlier in found[:new]:
            if (earlier.kind == "fold"
                    and abs(earlier.parameter - b.parameter) <= 1e-5 * abs(b.parameter)
                    and abs(earlier.period - b.period) <= 1e-5 * b.period):
                return earlier
    return None


def _slip_margin(branch: _Branch, a: _Point) -> float:
    """The smallest slip speed ``|Omega - phidot|`` over ``a``'s orbit, relative to the
    disc speed, over the sliders that slip throughout (infinite if none does: a lost
    stick-slip orbit has not grazed)."""
    _, _, p = branch.unpack(a.z)
    speed = p if branch.key == "speed.value" else branch.case.speed.value
    speed = abs(speed)
    margins = []
    for j, sig in enumerate(a.cycle.signature):
        if sig.startswith("slip") and "stick" not in sig:
            hi = a.cycle.measures["phi_dot_max"][j]
            lo = a.cycle.measures["phi_dot_min"][j]
            margins.append(min(abs(speed - hi), abs(speed - lo)))
    return min(margins) / speed if margins and speed > 0 else np.inf


def _grazing(branch: _Branch, a: _Point, index: int) -> Bifurcation:
    """The end of a branch of slipping orbits lost where its slip speed touches zero."""
    _, period, p = branch.unpack(a.z)
    return Bifurcation(kind="grazing", parameter=p, period=period, state=a.x.copy(),
                       before=a.multipliers, after=a.multipliers,
                       signature_before=a.cycle.signature, signature_after=a.cycle.signature,
                       point=index,
                       note=f"the slip speed touches zero (smallest {_slip_margin(branch, a):.1e}"
                       " of the disc speed): a stick phase appears and the slipping orbits "
                       "end (the stick-slip orbits leave from here)")


def _vanishing(branch: _Branch, a: _Point, index: int) -> Bifurcation | None:
    """Where the branch is lost just after ``a``: if the flow from ``a``'s point changes
    its event signature within a relative change of the key of 1e-3 ahead, the orbit
    ends at that change (the flow map jumps there, as where a stick phase splits). It is
    bracketed with ``a``'s point held, then located to 1e-6 by bisection on the orbits
    themselves: the last value at which the corrector finds the orbit with ``a``'s
    signature. None if the signature does not change."""
    x, period, p = branch.unpack(a.z)
    ahead = np.sign(a.tangent[-1]) or 1.0
    key = a.cycle.cyclic()
    scale = max(abs(p), branch.ps * 1e-3)

    def cycle(q: float) -> Cycle:
        return one_period(branch.model(q), x, branch.shooting.phases, period, branch.rtol,
                          branch.atol)

    lo, hi, far = p, None, None
    for k in range(11):
        q = p + ahead * scale * 1e-6 * 2.0**k
        try:
            c = cycle(q)
        except FivdiscError:
            continue
        if c.cyclic() != key:
            hi, far = q, c
            break
        lo = q
    if hi is None:
        return None
    # Refined on the orbits themselves: the last value at which the corrector still finds
    # the orbit with its signature, the flow from that orbit's point changing its
    # signature at the upper end of the bracket (where the corrector fails short of the
    # change, the held point decides).
    deadline = time.monotonic() + 600.0
    last, lo = a, p

    def beyond(q: float) -> Cycle | None:
        x_last, period_last, _ = branch.unpack(last.z)
        c = one_period(branch.model(q), x_last, branch.shooting.phases, period_last,
                       branch.rtol, branch.atol)
        return c if c.cyclic() != key else None

    far = beyond(hi)
    if far is None:
        return None
    while abs(hi - lo) > _LOCATE * scale:
        mid = 0.5 * (lo + hi)
        try:
            pt = branch.at_value(last, mid, deadline)
        except ConvergenceError:
            pt = None
        if pt is not None and pt.cycle.cyclic() == key:
            last, lo = pt, mid
            far = beyond(hi) or far
            continue
        changed = beyond(mid)
        if changed is not None:
            hi, far = mid, changed
        else:
            lo = mid
    x, period, _ = branch.unpack(last.z)
    shot = branch.shooter(hi).shoot(x, period)
    after, _ = branch.shooting.stability(shot)
    sides = [f"slider {j}: {u} -> {v}" for j, (u, v) in
             enumerate(zip(last.cycle.signature, far.signature, strict=True)) if u != v]
    return Bifurcation(kind="signature change", parameter=0.5 * (lo + hi), period=period,
                       state=x.copy(), before=last.multipliers, after=after,
                       signature_before=last.cycle.signature, signature_after=far.signature,
                       point=index,
                       note="the event signature changes (" + "; ".join(sides) + ") and the "
                       "orbit does not persist past it (multipliers after: of the flow map "
                       "from the last orbit's point)")


def _record(branch: _Branch, walk: _Walk, a: _Point, b: _Point, s_ab: float,
            deadline: float) -> None:
    """Locate and record the bifurcations between consecutive points ``a`` and ``b``."""
    index = len(walk.points) - 1
    if a.cycle.cyclic() != b.cycle.cyclic():
        try:
            lo, hi = _locate(branch, a, b, s_ab, "signature change", deadline)
        except ConvergenceError:
            lo, hi = a, b
        walk.bifurcations.append(_bifurcation(branch, "signature change", lo, hi, index))
        return
    for kind in _smooth_kinds(a, b):
        try:
            found = _located(branch, a, b, s_ab, kind, deadline)
        except (ConvergenceError, ValueError):
            found = [(a, b)]
        walk.bifurcations.extend(_bifurcation(branch, kind, lo, hi, index, sides=(a, b))
                                 for lo, hi in found)

