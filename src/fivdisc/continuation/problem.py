"""The continuation problem: the orbit's shooting equations with the key as one more
unknown, in scaled coordinates, and the corrector that solves them.

The orbit's point (its *anchor*) is kept away from switches: the first point is moved to
the middle of the orbit's longest interval without a switch, and a point whose switches
have drifted to within a quarter of that interval of it is moved again
(:meth:`OrbitProblem.reanchored`). An anchor inside a stick phase is well defined for
every value of the key: the stuck sliders' rates are held at the disc speed of the model
at that value (:meth:`~fivdisc.analysis.orbits.Shooting.held`)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from fivdisc.analysis.cycle import Cycle
from fivdisc.analysis.orbits import (
    Shooting,
    Shot,
    energy_scales,
    verdict_of,
)
from fivdisc.analysis.symmetry import OrbitSymmetry
from fivdisc.case import Case
from fivdisc.continuation.checks import check_key
from fivdisc.continuation.settings import (
    DP_CONSISTENT,
    DP_STEP,
    MAX_CORRECTION,
    MAX_NEWTON,
    NEAR_SWITCHES,
    POLISH,
    PREFER_FREE,
    REANCHOR,
    SETTLED,
    ContinuationSettings,
)
from fivdisc.engine.integration import Integration
from fivdisc.errors import CaseError, ConvergenceError, FivdiscError
from fivdisc.model.build import Model, build_model, model_at


@dataclass
class Point:
    """A converged point of the branch.

    ``z`` is in the unknowns of the anchor the point was made with; ``x``, ``period``,
    ``value`` and ``phases`` do not depend on it."""

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
    period: float = math.nan
    value: float = math.nan
    phases: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    # The d/dp column was taken one-sided: the held map jumps within DP_STEP of p.
    near_border: bool = False
    # The orbit's symmetry, and the eigenvalues of its reduced map R (if it has a
    # spatio-temporal symmetry of order k > 1).
    sym: OrbitSymmetry | None = None
    reduced: np.ndarray | None = None

    @property
    def symmetry(self) -> str:
        return self.sym.name if self.sym is not None else ""

    @property
    def k(self) -> int:
        return self.sym.k if self.sym is not None else 1

    @property
    def verdict(self) -> str:
        return verdict_of(self.multipliers, self.trivial)


class OrbitProblem:
    """The continuation problem: the case, the key, scales and the point machinery."""

    def __init__(self, case: Case, key: str, phases: np.ndarray, period: float,
                 settings: ContinuationSettings) -> None:
        from fivdisc.analysis.symmetry import case_symmetry

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
        self.xs: float | None = None
        # The case's symmetry (a key that changes one pad breaks it: the group is that of
        # the case at the start, and holds along the branch only for keys of every pad).
        self.group = case_symmetry(self.base)
        if self.group and not self._keeps_symmetry():
            self.group = case_symmetry(model_at(self.base, case, {key: self.p0 * 1.001
                                                                  + 1e-3}))
        self.reanchors = 0

    def _keeps_symmetry(self) -> bool:
        parts = self.key.split(".")
        return not (parts[0] == "sliders" and len(parts) > 2 and parts[1].isdigit())

    # --- coordinates ----------------------------------------------------------------------

    def set_free(self, shot: Shot, x: np.ndarray) -> None:
        """The unknowns' layout from a point and its shot: the free coordinates and the
        template of the others; the orbit's size (the scale of x) is the first point's
        and is kept when the anchor moves."""
        self.free = shot.free.copy()
        self.m = int(self.free.sum())
        if self.xs is None:
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

    def dgap_dp(self, x: np.ndarray, period: float, p: float,
                end_p: np.ndarray | None = None) -> tuple[np.ndarray, bool]:
        """``d (phi_T - x) / d p`` in the scaled unknowns, and whether it had to be taken
        on one side.

        A central difference, checked against the two one-sided ones: where they differ
        by more than :data:`DP_CONSISTENT` (relative), the held flow map jumps within the
        difference step of ``p`` (two sliders' switches change order there), and the
        difference is taken on the side whose steps ``h`` and ``h/2`` agree. Where ``p``
        lies within the step of a bound of the key's range (a damping continued to zero),
        a one-sided difference of the same order."""
        h = DP_STEP * self.ps

        def end(q: float) -> np.ndarray:
            return self.shooter(q).shoot(x, period, tangents=False).end

        def scaled(diff: np.ndarray) -> np.ndarray:
            return diff[self.free] / self.scale[self.free] / self.xs * self.ps

        try:
            up, down = end(p + h), end(p - h)
        except ConvergenceError:
            side = h if self._allowed(p + 2 * h) else -h
            diff = (4 * end(p + side) - end(p + 2 * side) - 3 * end(p)) / (2 * side)
            return scaled(diff), False
        mid = end(p) if end_p is None else end_p
        plus, minus = scaled((up - mid) / h), scaled((mid - down) / h)
        size = max(float(np.linalg.norm(plus)), float(np.linalg.norm(minus)), 1e-300)
        if float(np.linalg.norm(plus - minus)) <= DP_CONSISTENT * size:
            return scaled((up - down) / (2 * h)), False
        # Within h of a jump of the held map: the side whose halved step agrees.
        best = None
        for side, one in ((h, plus), (-h, minus)):
            try:
                half = scaled((end(p + side / 2) - mid) / (side / 2))
            except ConvergenceError:
                continue
            spread = float(np.linalg.norm(half - one)) / max(float(np.linalg.norm(one)),
                                                             1e-300)
            if best is None or spread < best[0]:
                best = (spread, 2 * half - one)  # Richardson: first order -> second
        if best is None:
            return scaled((up - down) / (2 * h)), True
        return best[1], True

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
        # One Newton step on the point's own Jacobian (the chord iterations used the
        # previous point's).
        lhs = np.vstack([point.jac, row])
        rhs = -np.r_[self.gap_of(point.shot, point.x), phase @ (z[:m] - x_ref),
                     row @ z - target]
        z_new = z + np.linalg.solve(lhs, rhs)
        x, period, p = self.unpack(z_new)
        shooting = self.shooter(p)
        try:
            shot = shooting.shoot(x, period, tangents=False)
            polished = (shooting.residual(shot, x, period)
                        if np.array_equal(shot.free, self.free) else np.inf)
        except FivdiscError:
            polished = np.inf
        if residual > POLISH * self.tol:
            # The chord iterations stalled above the polish level (the previous point's
            # Jacobian no longer contracts well enough): the step is kept, with its own
            # linearisation, if it lowers the residual.
            if polished < residual:
                point = self._linearised(z_new, phase, polished, it + 1)
        elif polished < POLISH * self.tol:
            # Polished, the step is taken all the same. The chord iterations' Jacobian
            # leaves the period off by up to the residual times the conditioning, large
            # where a multiplier is near 1 (1.4e-9 of the period at a residual of 7e-11
            # on the rigid-disc orbit); the point's own step takes it to the
            # integration's accuracy. Its Jacobian and multipliers are kept: the step
            # moves the point by about that much.
            x = shooting.held(x)
            held = ~shot.free
            x[held] = shot.end[held]
            point.z, point.x, point.residual = z_new, x, polished
        return point

    def _linearised(self, z: np.ndarray, phase: np.ndarray, residual: float,
                    iterations: int) -> Point:
        """The point ``z`` with its monodromy, multipliers and Jacobian (one run with
        tangents)."""
        x, period, p = self.unpack(z)
        shooting = self.shooter(p)
        shot = shooting.shoot(x, period)
        dp, near = self.dgap_dp(x, period, p, shot.end)
        jac = self.jacobian(shot, shooting, dp, phase)
        mult, trivial = self.shooting.stability(shot)
        # The coordinates held by the contact (a slider's z, zdot) and the stuck sliders'
        # rates are the template's in x; after one period they are those of this orbit:
        # the point kept has them.
        x = shooting.held(x)
        held = ~shot.free
        x[held] = shot.end[held]
        return Point(z, x, shot, jac, np.zeros_like(z), mult, trivial, residual, iterations,
                     near_border=near)

    def finish(self, point: Point, previous: np.ndarray | None, sign: float) -> Point:
        """The point's tangent, one period of its orbit (signature, measures, events) and
        its symmetry.

        Raises
        ------
        ConvergenceError
            A point that did not polish (its residual above 1e-2 of the tolerance) while
            switches of different sliders fall within :data:`NEAR_SWITCHES` of a period
            of each other: next to a border where they change order the shooting map
            jumps, and such a point need not be an orbit (the walk then halves its step).
        """
        point.tangent = self.tangent(point.jac, previous, sign)
        x, period, p = self.unpack(point.z)
        shooting = self.shooter(p)
        point.cycle = shooting.cycle(x, period)
        point.period, point.value = period, p
        point.phases = self.shooting.phases.copy()
        if point.residual > POLISH * self.tol and close_switches(point.cycle):
            reason = (f"the point did not polish (residual {point.residual:.1e}) next to "
                      "switches of different pads that nearly coincide")
            raise ConvergenceError(reason, reason=reason)
        self.symmetry_of(point)
        return point

    def symmetry_of(self, point: Point) -> None:
        """The orbit's symmetry, and its reduced map's eigenvalues (a spatio-temporal
        symmetry: the classification of its multipliers)."""
        if not self.group:
            return
        from fivdisc.analysis.orbits import orbit_symmetry

        sticks = "stick" in " ".join(point.cycle.signature)
        sym = orbit_symmetry(self.group, self.model(point.value), point.x, point.phases,
                             point.period, self.rtol, self.atol, sticks=sticks,
                             reduced=True)
        point.sym = sym
        if sym.reduced is not None:
            point.reduced = np.linalg.eigvals(sym.reduced * (self.scale[None, :]
                                                             / self.scale[:, None]))

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

    # --- the anchor -------------------------------------------------------------------------

    def anchored(self, x: np.ndarray, period: float, p: float, phases: np.ndarray,
                 cycle: Cycle | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The orbit through ``x`` (phases ``phases``) moved to the middle of its longest
        interval without a switch (one where no slider sticks if that is at least
        :data:`PREFER_FREE` as long): its point there and the phases."""
        model = self.model(p)
        shooting = Shooting(model, phases, self.rtol, self.atol, self.scale)
        if cycle is None:
            cycle = shooting.cycle(x, period)
        times, gaps, i = _intervals(cycle, period)
        shift = (times[i] + 0.5 * gaps[i]) if i > 0 else 0.5 * gaps[0] - (period - times[-2])
        shift %= period
        if not shift > 0:
            return shooting.held(x), np.asarray(phases, dtype=np.int64).copy()
        run = Integration(model, shooting.held(x), duration=shift, output_rate=1.0 / shift,
                          rtol=self.rtol, atol=self.atol, phases=phases, max_step=shooting.cap)
        run.run_to(shift)
        return run.out_y[1, : model.state_size].copy(), run.ph.copy()

    def point_at(self, x: np.ndarray, period: float, p: float, phases: np.ndarray,
                 direction: float, along: np.ndarray | None = None,
                 residual: float | None = None, iterations: int = 0) -> Point:
        """A first point (or a restart) from an orbit's point already anchored: the
        unknowns' layout, the Jacobian, the tangent (its parameter component of the sign
        ``direction``, or along ``along``)."""
        self.shooting = Shooting(self.base, phases, self.rtol, self.atol, self.scale)
        shooting = self.shooter(p)
        shot = shooting.shoot(x, period)
        self.set_free(shot, shooting.held(x))
        z = self.pack(self.template, period, p)
        dp, near = self.dgap_dp(self.template, period, p, shot.end)
        jac = self.jacobian(shot, shooting, dp, self.phase_row(shot))
        mult, trivial = self.shooting.stability(shot)
        res = shooting.residual(shot, self.template, period) if residual is None else residual
        x_pt = self.template.copy()
        held = ~shot.free
        x_pt[held] = shot.end[held]
        pt = Point(z, x_pt, shot, jac, np.zeros_like(z), mult, trivial, res, iterations,
                   near_border=near)
        pt.tangent = self.tangent(jac, None, direction)
        if along is not None and float(pt.tangent[-2:] @ along[-2:]) < 0:
            pt.tangent = -pt.tangent
        pt.cycle = shooting.cycle(self.template, period)
        pt.period, pt.value, pt.phases = period, p, self.shooting.phases.copy()
        self.symmetry_of(pt)
        return pt

    def reanchored(self, a: Point) -> Point:
        """``a`` moved along its orbit to the middle of its longest interval without a
        switch, if its switches have drifted to within :data:`REANCHOR` of the interval
        it lies in from it, or that interval has shrunk below ``REANCHOR`` of the
        longest; else ``a``. The unknowns' layout (free coordinates, phases,
        template) follows; the scales stay, so that a step keeps its meaning, and the
        tangent keeps its orientation in the period and the key (which do not depend on
        where the point lies)."""
        t = a.cycle.switch_times
        if t.size == 0:
            return a
        here = t[0] + (a.period - t[-1])
        _, gaps, i = _intervals(a.cycle, a.period)
        if min(t[0], a.period - t[-1]) >= REANCHOR * here and here >= REANCHOR * gaps[i]:
            return a
        x, phases = self.anchored(a.x, a.period, a.value, a.phases, a.cycle)
        self.reanchors += 1
        return self.point_at(x, a.period, a.value, phases, float(np.sign(a.tangent[-1])),
                             along=a.tangent, residual=a.residual, iterations=a.iterations)


def _intervals(cycle: Cycle, period: float) -> tuple[np.ndarray, np.ndarray, int]:
    """The start, the switches and the end of one period, the lengths of the intervals
    between them (the first, across the point, holding the last too; the last -1), and
    the interval the point belongs in: the longest in which no slider sticks if it is at
    least :data:`PREFER_FREE` of the longest of all (there every coordinate of the point
    is free, and one slider's branches keep their points where they always were), else
    the longest."""
    times = np.r_[0.0, cycle.switch_times, period]
    gaps = np.diff(times)
    gaps[0] += gaps[-1]
    gaps[-1] = -1.0
    free = np.where(np.asarray(cycle.stick_free, dtype=bool)[: gaps.size], gaps, -1.0)
    i = int(np.argmax(gaps))
    if free.max() >= PREFER_FREE * gaps[i]:
        i = int(np.argmax(free))
    return times, gaps, i


def close_switches(cycle: Cycle) -> bool:
    """Whether switches of different sliders fall within :data:`NEAR_SWITCHES` of a period
    of each other (simultaneous ones included: at a release cascade the shooting map
    jumps as soon as the cascade breaks)."""
    period = cycle.period
    ev = sorted(cycle.events)
    for (t1, _, j1), (t2, _, j2) in zip(ev, ev[1:] + ev[:1], strict=True):
        gap = (t2 - t1) % period
        if j1 != j2 and gap < NEAR_SWITCHES * period:
            return True
    return False
