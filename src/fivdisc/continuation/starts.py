"""The first point of a branch: from a periodic orbit, from a Hopf point of the
equilibrium, or on the doubled orbits at a period doubling."""

from __future__ import annotations

import numpy as np

from fivdisc.analysis.cycle import one_period
from fivdisc.analysis.orbits import (
    PeriodicOrbit,
    Shooting,
    verdict_of,
)
from fivdisc.case import Case
from fivdisc.continuation.problem import OrbitProblem, Point
from fivdisc.continuation.settings import DOUBLED_AMPLITUDE
from fivdisc.engine.integration import Integration
from fivdisc.errors import FivdiscError
from fivdisc.model.build import build_model


def start_point(problem: OrbitProblem, orbit: PeriodicOrbit, direction: float,
                 along: np.ndarray | None, deadline: float) -> Point:
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
    model = problem.base
    x, phases = orbit.state, orbit.phases
    if along is None:
        cyc = one_period(model, x, phases, orbit.period, problem.rtol, problem.atol)
        times = np.r_[0.0, cyc.switch_times, orbit.period]
        gaps = np.where(cyc.stick_free, np.diff(times), -1.0)
        i = int(np.argmax(gaps))
        shift = times[i] + 0.5 * gaps[i]
        if shift > 0:
            run = Integration(model, x, duration=shift, output_rate=1.0 / shift,
                              rtol=problem.rtol, atol=problem.atol, phases=phases)
            run.run_to(shift)
            x, phases = run.out_y[1, : model.state_size].copy(), run.ph.copy()
    problem.shooting = Shooting(model, phases, problem.rtol, problem.atol, problem.scale)
    if along is not None:
        problem.set_free(problem.shooting.shoot(x, orbit.period, tangents=False), x)
        unit = along / np.linalg.norm(along[problem.free] / problem.scale[problem.free]
                                      / problem.xs)
        return hopf_start(problem, x, unit, DOUBLED_AMPLITUDE, DOUBLED_AMPLITUDE,
                           deadline)
    shot = problem.shooting.shoot(x, orbit.period)
    problem.set_free(shot, x)
    z = problem.pack(x, orbit.period, problem.p0)
    dp = problem.dgap_dp(x, orbit.period, problem.p0)
    jac = problem.jacobian(shot, problem.shooting, dp, problem.phase_row(shot))
    mult, trivial = problem.shooting.stability(shot)
    residual = problem.shooting.residual(shot, x, orbit.period)
    pt = Point(z, x, shot, jac, np.zeros_like(z), mult, trivial, residual, 0)
    return problem.finish(pt, None, direction)


def hopf_start(problem: OrbitProblem, state: np.ndarray, direction: np.ndarray, eps: float,
                size: float, deadline: float) -> Point:
    """The first point of the orbits born at a Hopf point: from ``state + eps direction``
    (the equilibrium and the critical eigenvector's real part, the period the branch's
    first), Newton with the amplitude along ``direction`` held at ``eps`` and the
    parameter free; the tangent points to larger amplitudes. The unknowns are measured
    in the orbit of amplitude ``size`` (not the first, small orbit's): so a step is a
    fraction of the way to ``size``."""
    x0 = state + eps * direction
    shot = problem.shooting.shoot(x0, problem.period0)
    problem.set_free(shot, x0)
    # The orbit's size is linear in its amplitude while it is small.
    problem.xs *= size / eps
    z0 = problem.pack(x0, problem.period0, problem.p0)
    row = z0 - problem.pack(state, problem.period0, problem.p0)
    row /= np.linalg.norm(row)
    dp = problem.dgap_dp(x0, problem.period0, problem.p0)
    jac = problem.jacobian(shot, problem.shooting, dp, problem.phase_row(shot))
    ref = Point(z0, x0, shot, jac, np.zeros_like(z0), np.zeros(0), 0, np.inf, 0)
    pt = problem.correct(z0, row, float(row @ z0), ref, 1.0, deadline)
    return problem.finish(pt, row, 1.0)


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
