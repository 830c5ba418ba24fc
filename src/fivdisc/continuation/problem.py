"""The continuation problem: the orbit's shooting equations with the key as one more
unknown, in scaled coordinates, and the corrector that solves them."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from fivdisc.analysis.cycle import Cycle, one_period
from fivdisc.analysis.orbits import (
    Shooting,
    Shot,
    energy_scales,
    verdict_of,
)
from fivdisc.case import Case
from fivdisc.continuation.checks import check_key
from fivdisc.continuation.settings import (
    DP_STEP,
    MAX_CORRECTION,
    MAX_NEWTON,
    POLISH,
    SETTLED,
    ContinuationSettings,
)
from fivdisc.errors import CaseError, ConvergenceError, FivdiscError
from fivdisc.model.build import Model, build_model, model_at


@dataclass
class Point:
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


class OrbitProblem:
    """The continuation problem: the case, the key, scales and the point machinery."""

    def __init__(self, case: Case, key: str, phases: np.ndarray, period: float,
                 settings: ContinuationSettings) -> None:
        self.case, self.key = case, key
        self.base = build_model(case)
        self.p0 = check_key(case, key)
        self.settings = settings
        self.rtol, self.atol, self.tol = settings.rtol, settings.atol_run, settings.tol
        self.scale = energy_scales(self.base)
        self.shooting = Shooting(self.base, phases, self.rtol, self.atol, self.scale)
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
        h = DP_STEP * self.ps

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

    def correct(self, z_pred: np.ndarray, row: np.ndarray, target: float, ref: Point,
                step: float, deadline: float) -> Point:
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
        reason = f"no convergence in {MAX_NEWTON} iterations"
        for it in range(MAX_NEWTON + 1):
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
                if residual < POLISH * self.tol and polished is None:
                    polished = it  # the iterations the step control counts
                best = (z, residual, it if polished is None else polished)
                if polished is not None and moved < SETTLED:
                    break
            elif it == MAX_NEWTON or time.monotonic() > deadline:
                reason = (f"no convergence in {MAX_NEWTON} iterations" if it == MAX_NEWTON
                          else "the time budget ran out")
                break
            rhs = -np.r_[self.gap_of(shot, x), phase @ (z[:m] - x_ref), row @ z - target]
            dz = lu_solve(factors, rhs)
            moved = abs(dz[m] / z[m])
            z = z + dz
            if best is None and np.linalg.norm(z - z_pred) > MAX_CORRECTION * step:
                reason = "the corrector left the neighbourhood of the predictor"
                break
        if best is None:
            raise ConvergenceError(reason, reason=reason)
        z, residual, it = best
        point = self._linearised(z, phase, residual, it)
        if residual > POLISH * self.tol:
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
                    iterations: int) -> Point:
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
        return Point(z, x, shot, jac, np.zeros_like(z), mult, trivial, residual, iterations)

    def finish(self, point: Point, previous: np.ndarray | None, sign: float) -> Point:
        point.tangent = self.tangent(point.jac, previous, sign)
        x, period, p = self.unpack(point.z)
        point.cycle = one_period(self.model(p), x, self.shooting.phases, period, self.rtol,
                                 self.atol)
        return point

    def step_from(self, a: Point, s: float, deadline: float) -> Point:
        """The point at arclength ``s`` from ``a`` along ``a``'s tangent."""
        pt = self.correct(a.z + s * a.tangent, a.tangent, float(a.tangent @ a.z) + s, a,
                          abs(s), deadline)
        return self.finish(pt, a.tangent, 1.0)

    def at_value(self, a: Point, value: float, deadline: float) -> Point:
        """The point at parameter ``value``, from ``a`` (secant to it along the tangent)."""
        target = value / self.ps
        s = (target - a.z[-1]) / a.tangent[-1]
        row = np.zeros_like(a.z)
        row[-1] = 1.0
        pt = self.correct(a.z + s * a.tangent, row, target, a, abs(s), deadline)
        return self.finish(pt, a.tangent, 1.0)
