"""The first point of a branch: from a periodic orbit, from a Hopf point of the
equilibrium, or on the doubled orbits at a period doubling."""

from __future__ import annotations

import numpy as np

from fivdisc.analysis.orbits import (
    PeriodicOrbit,
    Shooting,
    verdict_of,
)
from fivdisc.case import Case
from fivdisc.continuation.problem import OrbitProblem, Point
from fivdisc.continuation.settings import DOUBLED_AMPLITUDE
from fivdisc.errors import FivdiscError
from fivdisc.model.build import build_model


def start_point(problem: OrbitProblem, orbit: PeriodicOrbit, direction: float,
                along: np.ndarray | None, deadline: float) -> Point:
    """The first point: the orbit moved to the middle of its longest interval without a
    switch (so that the point stays away from switches along the branch; inside a stick
    phase the stuck sliders' rates are held at the disc speed, whatever the key's
    value).

    With ``along`` (branch switching at a period doubling or a symmetry breaking:
    ``orbit`` is the orbit at the point, traversed twice for a period doubling, ``along``
    the critical eigenvector) the first point is an orbit of the new branch itself, of
    amplitude 1e-4 of the orbit's size along ``along``. At the bifurcation point the new
    orbits leave the old one with the parameter changing only at second order: there two
    branches cross and the Jacobian is singular in both their directions, so no
    corrector converges from it. At a small amplitude, held while the parameter is free
    (as from a Hopf point), it is regular."""
    model = problem.base
    x, phases = orbit.state, orbit.phases
    if along is not None:
        problem.shooting = Shooting(model, phases, problem.rtol, problem.atol, problem.scale)
        problem.set_free(problem.shooting.shoot(x, orbit.period, tangents=False), x)
        unit = along / np.linalg.norm(along[problem.free] / problem.scale[problem.free]
                                      / problem.xs)
        return hopf_start(problem, x, unit, DOUBLED_AMPLITUDE, DOUBLED_AMPLITUDE,
                          deadline)
    x, phases = problem.anchored(x, orbit.period, problem.p0, phases)
    return problem.point_at(x, orbit.period, problem.p0, phases, direction,
                            residual=orbit.residual)


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
    dp, _ = problem.dgap_dp(x0, problem.period0, problem.p0, shot.end)
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


def broken_start(case: Case, state: np.ndarray, period: float, phases: np.ndarray,
                 bifurcation: dict, rtol: float = 1e-12, atol: float | None = None
                 ) -> tuple[PeriodicOrbit, np.ndarray]:
    """The start of the branch of orbits that break a symmetric orbit's symmetry, at a
    symmetry-breaking point (:func:`fivdisc.analysis.symmetry.classify_reduced`): the
    orbit's point, and the direction in which the orbits without the symmetry leave it
    (the real part of the eigenvector of the monodromy's critical multiplier, the one
    nearest +1 other than the flow direction's: at the bifurcation it is +1).

    Where the crossing is a Neimark-Sacker bifurcation of the reduced map near, not at,
    an m:k resonance, the motions that bifurcate are tori drifting slowly through the
    orbit's k images, not orbits: the branch exists only if the corrector converges
    from here (it says so when it does not).

    Returns
    -------
    orbit : PeriodicOrbit
        The orbit at the point (period ``period``).
    along : ndarray
        The direction, for :func:`continue_orbit`'s ``along``.
    """
    atol = atol if atol is not None else rtol * 1e-7
    model = build_model(case)
    shooting = Shooting(model, phases, rtol, atol)
    shot = shooting.shoot(state, period)
    mult, trivial = shooting.stability(shot)
    values, vecs = np.linalg.eig(shot.monodromy)
    f = shot.rate_start / shooting.scale
    f /= np.linalg.norm(f)
    # the flow direction's eigenvector is f; the critical one is the other nearest +1
    scores = np.abs(values - 1.0)
    flow = int(np.argmax([abs(np.vdot(f, vecs[:, i] / shooting.scale)) /
                          np.linalg.norm(vecs[:, i] / shooting.scale)
                          for i in range(values.size)]))
    scores[flow] = np.inf
    i = int(np.argmin(scores))
    if scores[i] > 0.05:
        raise FivdiscError(
            f"no branch of orbits leaves the symmetry breaking at {bifurcation['parameter']:.10g}: "
            f"no multiplier but the flow direction's is near +1 (the nearest is "
            f"{values[i]:.4f}); its critical pair crosses the unit circle away from +1, so "
            "the motions born there are tori (quasi-periodic), not periodic orbits")
    along = np.real(vecs[:, i])
    if np.linalg.norm(along) < 1e-6 * np.linalg.norm(vecs[:, i]):
        along = np.imag(vecs[:, i])
    orbit = PeriodicOrbit(period=period, state=state.copy(), phases=phases.copy(),
                          monodromy=shot.monodromy, multipliers=mult, trivial=trivial,
                          residual=shooting.residual(shot, state, period), iterations=0,
                          verdict=verdict_of(mult, trivial),
                          start=f"at the symmetry breaking at {bifurcation['parameter']:.10g}")
    return orbit, along
