"""Continued periodic orbits against the independent scipy reference model.

``continue_orbit`` returns, per point of a branch, a point on the orbit, its period and its
Floquet multipliers (from the package's saltation-based monodromy). Here each chosen point is
fed to :func:`reference_model.reference_simulate` (plain scipy, written without the kernel):
the reference's flow over one period must return to the point, and the eigenvalues of a
monodromy built by finite differences of the reference's flow map must match the branch's
multipliers.

Layouts. The package's state is ``[q (n), phi (S), z (S), qdot (n), phidot (S), zdot (S)]``;
the reference takes ``y0 = [q, qdot, phi, phidot]`` for a start in contact (z, zdot follow the
disc there) and reports ``z``, ``z_dot`` in its dense output. A point of the branch lies in
slip, so its free coordinates are q, phi, qdot, phidot; z and zdot are slaved: the branch
reports two zero multipliers for them, and the finite-difference matrix built below has zero
columns for them. (A third multiplier is zero as well: the stick phase forgets the slider's
state.)
"""

from __future__ import annotations

import numpy as np
import pytest

from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.case import Case
from fivdisc.continuation.walk import continue_orbit

from reference.model import mode_data_from_case, reference_simulate

# A light disc with one axisymmetric mode and a damped slider under exponential friction: a
# stable stick-slip orbit ("slip+ > stick > slip+") whose disc-mode multipliers (~0.81) sit
# well inside the unit circle, so the branch has no fold or bifurcation on the range used.
LIGHT = Case(disc={"density": 720.0, "modes": [[0, 0]]},
             slider={"mass": 1.0, "normal_damping": 20.0}, speed={"value": 1.0})
KEY, TARGET, POINTS = "speed.value", 2.0, 12
RTOL = 1e-12  # reference's solve_ivp tolerances (its defaults; atol on every component)
ATOL = 1e-14
STEPS = (1e-4, 5e-5, 2.5e-5)  # finite-difference steps, as fractions of each coordinate's scale
PHASE_LABELS = {0: "slip", 1: "stick"}


def _blocks(size: int, n_sliders: int) -> dict[str, np.ndarray]:
    """Index arrays of the package's state blocks for 2 n + 4 S = size."""
    n, s = (size - 4 * n_sliders) // 2, n_sliders
    start = np.cumsum([0, n, s, s, n, s])
    names = ("q", "phi", "z", "q_dot", "phi_dot", "z_dot")
    sizes = (n, s, s, n, s, s)
    return {k: np.arange(b, b + m) for k, b, m in zip(names, start, sizes, strict=True)}


def _reference_run(case, x, phases, duration):
    """The reference started from the package state ``x`` (all sliders in contact)."""
    blk = _blocks(x.size, len(phases))
    y0 = np.concatenate([x[blk["q"]], x[blk["q_dot"]], x[blk["phi"]], x[blk["phi_dot"]]])
    return reference_simulate(case, duration, y0=y0, phase0=[int(p) for p in phases],
                              rtol=RTOL, atol=ATOL)


def _as_state(out: dict, i: int, size: int, n_sliders: int) -> np.ndarray:
    """Row i of the reference's dense output in the package's state layout."""
    blk = _blocks(size, n_sliders)
    x = np.empty(size)
    for name, idx in blk.items():
        x[idx] = out[name][i]
    return x


def _flow(case, x, phases, period):
    res = _reference_run(case, x, phases, period)
    return _as_state(res.evaluate([period]), 0, x.size, len(phases))


def _scales(case, res, size: int, n_sliders: int) -> np.ndarray:
    """Each coordinate's size on the orbit: the largest |x_j(t)| over one period; a disc
    velocity at least omega_k times its mode's displacement (the settled disc mode of this
    case barely moves, and its velocity scale must still be physical)."""
    out = res.evaluate(np.linspace(0.0, res.t_end, 401))
    blk = _blocks(size, n_sliders)
    scale = np.empty(size)
    for name, idx in blk.items():
        scale[idx] = np.max(np.abs(out[name]), axis=0)
    omega = mode_data_from_case(case).omega
    scale[blk["q_dot"]] = np.maximum(scale[blk["q_dot"]], omega * scale[blk["q"]])
    return scale


def _fd_monodromy(case, x, phases, period, free, scale):
    """Monodromy of the reference's flow map over ``period``: central differences in each
    free coordinate at steps ``STEPS * scale``, Richardson-extrapolated twice (the error
    terms h^2 and h^4 removed). Returns the matrix (zero columns for the slaved coordinates)
    and the largest change of the last extrapolation, an estimate of its error."""
    jac = np.zeros((x.size, x.size))
    change = 0.0
    for j in free:
        diffs = []
        for e in STEPS:
            h = e * scale[j]
            xp, xm = x.copy(), x.copy()
            xp[j] += h
            xm[j] -= h
            diffs.append((_flow(case, xp, phases, period) - _flow(case, xm, phases, period))
                         / (2.0 * h))
        r1 = (4.0 * diffs[1] - diffs[0]) / 3.0
        r2 = (4.0 * diffs[2] - diffs[1]) / 3.0
        jac[:, j] = (16.0 * r2 - r1) / 15.0
        # in the scaled coordinates x_i / scale_i, where the entries are O(1)
        change = max(change, np.max(np.abs(jac[free, j] - r2[free]) * scale[j] / scale[free]))
    return jac, change


def _signature(res, slider: int) -> str:
    """The reference's phase sequence of one slider, in the package's wording."""
    names = []
    for seg in res.segments:
        phase, sign = seg.phases[slider], seg.signs[slider]
        assert phase in PHASE_LABELS, "the orbit should stay in contact"
        name = PHASE_LABELS[phase] + ("+" if sign > 0 else "-" if sign < 0 else "")
        if not names or names[-1] != name:
            names.append(name)
    return " > ".join(names)


@pytest.fixture(scope="module")
def branch():
    orbit = periodic_orbit(LIGHT, transient=2.0)
    return continue_orbit(LIGHT, KEY, TARGET, orbit=orbit, max_points=POINTS)


def _check_point(branch, i):
    """At branch point i: the reference's closure ``|phi_T(x) - x| / |x|`` (2-norms) and,
    from its finite-difference monodromy, the sorted eigenvalue moduli with the largest
    change of the last Richardson step; and the branch's sorted multiplier moduli."""
    case = branch.case.replace({KEY: float(branch.parameter[i])})
    x = np.asarray(branch.dataset["state"].values[i], float)
    phases = np.atleast_1d(branch.dataset["phase"].values).astype(int)
    period = float(branch.period[i])
    blk = _blocks(x.size, phases.size)
    assert np.all(phases == 0), "the continuation's points lie in slip"
    free = np.concatenate([blk["q"], blk["phi"], blk["q_dot"], blk["phi_dot"]])

    res = _reference_run(case, x, phases, period)
    end = _as_state(res.evaluate([period]), 0, x.size, phases.size)
    closure = np.linalg.norm(end - x) / np.linalg.norm(x)
    for j in range(phases.size):
        assert _signature(res, j) == branch.dataset["signature"].values[i, j]

    scale = _scales(case, res, x.size, phases.size)
    jac, change = _fd_monodromy(case, x, phases, period, free, scale)
    fd = np.sort(np.abs(np.linalg.eigvals(jac)))
    mult = np.sort(np.abs(np.asarray(branch.multipliers[i])))
    return closure, change, fd, mult


def _assert_point(branch, i):
    closure, change, fd, mult = _check_point(branch, i)
    residual = float(branch.dataset["residual"].values[i])
    size = np.asarray(branch.dataset["state"].values[i]).size
    assert closure < np.sqrt(size) * residual + 1e-10, (
        f"point {i}: the reference misses the point by {closure:.2e} (residual {residual:.2e})"
    )
    assert change < 1e-7, f"point {i}: finite differences not converged ({change:.2e})"
    assert mult == pytest.approx(fd, abs=1e-6), f"point {i}"


def test_branch_point_closes_and_multipliers_match_the_reference(branch):
    """The middle point of the branch (the CI variant of the slow test below, whose
    docstring gives the tolerances)."""
    _assert_point(branch, POINTS // 2)


@pytest.mark.slow
def test_branch_multipliers_match_finite_differences_of_the_reference(branch):
    """First, middle and last points of a branch continued in the disc speed from 1 to
    about 1.5 rad/s.

    Closure: the package accepts a point when its scaled shooting residual is below
    ``tol`` (1e-8) and stores it (``residual``); the reference's relative 2-norm closure
    may differ from it by the choice of norm (at most sqrt(2 n + 4 S) between 2-norms of
    the same vector, whichever per-point scale is used: measured ratio 0.4 to 1.6) and by
    the reference's own error over one period, 2e-12 at the first point (an orbit
    converged to 3e-13), allowed 1e-10.

    Finite differences: DOP853 at rtol 1e-12 carries an error of ~1e-12 |x| that varies
    smoothly with the start; what does not (step-size choices, events located to a few
    eps) is ~1e-14 |x| (from the scatter of differences at steps 1e-5). Central
    differences at steps (1, 1/2, 1/4) h, h = 1e-4 of each coordinate's size on the orbit,
    extrapolated twice (h^2 and h^4 removed), weigh that noise by (64 * 4 + 20 * 2 + 1) /
    45 / (2 h) ~ 3e4, i.e. ~1e-9 in the scaled entries; the last extrapolation changes
    them by at most 2e-9 (asserted below 1e-7). A larger h = 1e-3 leaves a truncation
    error of 1e-6 in the disc-velocity column (the stick-slip switch times bend the flow
    map). The moduli so found agree with the branch's to ~5e-9; 1e-6 is the accuracy the
    package states for its multipliers at rtol 1e-12 (``periodic_orbit``), and the
    finite-difference side uses under 1 % of it (measured).
    """
    assert len(branch.parameter) == POINTS
    assert branch.parameter[-1] > branch.parameter[0] + 0.2
    for i in (0, POINTS // 2, POINTS - 1):
        _assert_point(branch, i)
