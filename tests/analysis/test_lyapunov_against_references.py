"""Lyapunov exponents and their stated uncertainty against independent references: the
eigenvalues of the plain scipy reference model's Jacobian at a stable sliding equilibrium,
and the Floquet multipliers of a monodromy matrix built from the reference model's flow.

Both cases come from the trial of issue s33 (defect 8): a larger, thicker, damped disc
with Stribeck friction. Their exponents come in pairs with equal real parts and gaps of
only 0.19-0.48 1/s between pairs, so random tangent vectors take seconds to align with the
directions they measure; before the fix the exponents of a short measurement were several
of their uncertainties away from these references (the second exponent at the equilibrium
by about 5, the second on the orbit by about 4).
"""

from __future__ import annotations

import math

import numpy as np

from fivdisc.analysis.exponents import lyapunov
from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.case import Case
from fivdisc.engine.integration import fastest_time_scale
from fivdisc.model.build import build_model

DISC = {"inner_radius": 0.05, "outer_radius": 0.14, "thickness": 0.004,
        "modes": [[0, 0], [0, 1], [0, 2]], "damping_ratio": 0.001, "damping_frame": "space"}
FRICTION = {"law": "stribeck", "static": 0.8, "kinetic_max": 0.6, "kinetic_min": 0.35,
            "stribeck_velocity": 0.5, "stribeck_exponent": 2.0, "viscous": 0.02}
BOTTOM = {"face": "bottom", "angle": 1.0, "track_radius": 0.1, "mass": 0.12,
          "normal_stiffness": 3.5e4, "normal_damping": 0.15, "rotational_stiffness": 1800.0,
          "rotational_damping": 0.06, "preload": 250.0}
THREE = Case(
    disc=DISC, friction=FRICTION, speed={"value": 12.0},
    sliders=[
        {"face": "top", "angle": 0.0, "track_radius": 0.11, "mass": 0.08,
         "normal_stiffness": 4e4, "normal_damping": 0.2, "rotational_stiffness": 1500.0,
         "rotational_damping": 0.05, "preload": 200.0},
        {"face": "top", "angle": 2.1, "track_radius": 0.11, "mass": 0.1,
         "normal_stiffness": 3e4, "normal_damping": 0.1, "rotational_stiffness": 2000.0,
         "rotational_damping": 0.08, "preload": 150.0},
        BOTTOM,
    ],
    simulation={"initial_state": "equilibrium", "perturbation": {"phi": 1e-4}},
)
ONE = Case(disc=DISC, friction=FRICTION, speed={"value": 3.0}, sliders=[BOTTOM])

# [1/s] per [rad/s]: the bias of an exponent from integrating the tangent dynamics with
# steps of the state's size, at most about 1e-5 omega for a mode of omega [rad/s]
# (docs/saltation.md, "Step size and accuracy").
_STEP_BIAS = 1e-5


def _reference_eigenvalues(case: Case) -> np.ndarray:
    """Eigenvalues of the reference model's Jacobian at its own sliding equilibrium, by
    central differences of its right-hand side in (q, q_dot, phi, phi_dot); the steps
    (1e-9 on positions, 1e-6 on rates) give about 1e-6 1/s (trial s33, check (a))."""
    import reference.model as ref

    md = ref.mode_data_from_case(case)
    model = ref._Model(case, md)
    n, s = md.n, model.S
    eq = ref.sliding_equilibrium(case, md)
    rhs = model.rhs([ref.SLIP] * s, [1] * s, ref._Piece(0.0, math.inf,
                                                         float(case.speed.value), 0.0))
    y0 = np.zeros(2 * n + 4 * s)
    y0[:n] = eq["q"]
    y0[2 * n : 2 * n + s] = np.atleast_1d(eq["phi"])
    size = 2 * n + 2 * s  # the gaps stay closed in contact
    steps = np.r_[np.full(n, 1e-9), np.full(n, 1e-6), np.full(s, 1e-9), np.full(s, 1e-6)]
    jac = np.empty((size, size))
    for k, h in enumerate(steps):
        e = np.zeros_like(y0)
        e[k] = h
        jac[:, k] = (rhs(0.0, y0 + e)[:size] - rhs(0.0, y0 - e)[:size]) / (2 * h)
    return np.linalg.eigvals(jac)


def test_exponents_at_a_stable_sliding_equilibrium_are_the_reference_eigenvalues():
    """Three sliders at a stable sliding equilibrium: the trajectory from the perturbed
    equilibrium stays on it, so the exponents are the real parts of the eigenvalues
    (-1.1497 twice, -1.6280 twice, then -1.9995). Over a 3 s measurement after an 8 s
    transient, in which the tangent vectors align, each of the first three is within
    three of its stated uncertainties of the reference, plus the integration's bias bound
    for that mode's frequency (1e-5 x 1.9-2.4e3 rad/s, about 0.02 1/s). The
    uncertainties are small enough for the check to tell the pairs apart (their gap is
    0.48 1/s)."""
    lam = _reference_eigenvalues(THREE)
    lam = lam[np.argsort(-lam.real, kind="stable")][:3]
    assert np.all(lam.real < 0)
    spec = lyapunov(THREE, n=3, transient=8.0, duration=3.0)
    tolerance = 3 * spec.uncertainty + _STEP_BIAS * np.abs(lam.imag)
    assert np.all(np.abs(spec.exponents - lam.real) <= tolerance), (
        spec.exponents, spec.uncertainty, lam.real)
    assert np.all(tolerance < 0.2) and spec.conclusive.all()


def test_exponents_on_a_stick_slip_orbit_are_the_reference_floquet_exponents():
    """One slider on a stable stick-slip orbit (T = 7.16 ms). The reference exponents are
    log|mu| / T of a monodromy matrix from central differences (relative step 1e-5) of
    the reference model's flow over one period (DOP853, rtol 1e-12) from a point of the
    orbit that fivdisc.periodic_orbit found; the reference closes the orbit there to
    1e-9 of the state. The orbit starts in stick, whose collapse of phi_dot gives the
    multiplier 0: that column is left out. The first exponent is 0 (the flow direction),
    the next pair -1.9489 1/s, 0.19 1/s above the next. Over 3 s after an 8 s transient
    both exponents are within three of their uncertainties (plus the integration's bias
    bound, 1e-5 of the fastest frequency)."""
    from reference.model import reference_simulate

    orbit = periodic_orbit(ONE, transient=1.5)
    model = build_model(ONE)
    n, half, period = model.n, model.state_size // 2, orbit.period
    x = orbit.state
    y0 = np.r_[x[:n], x[half : half + n], x[n], x[half + n]]

    def flow(y):
        return reference_simulate(ONE, period, y0=y).state(period)[0][: y.size]

    assert np.linalg.norm(flow(y0) - y0) < 1e-9 * np.linalg.norm(y0)
    assert orbit.phases[0] == 1  # stick: phi_dot is not free
    kept = np.r_[0 : 2 * n + 1]
    scale = np.r_[np.full(n, np.abs(y0[:n]).max()), np.full(n, np.abs(y0[n : 2 * n]).max()),
                  abs(y0[2 * n])]
    monodromy = np.empty((kept.size, kept.size))
    for k, i in enumerate(kept):
        e = np.zeros_like(y0)
        e[i] = 1e-5 * scale[k]
        monodromy[:, k] = (flow(y0 + e) - flow(y0 - e))[kept] / (2 * e[i])
    floquet = np.sort(np.log(np.abs(np.linalg.eigvals(monodromy))) / period)[::-1][:2]
    assert abs(floquet[0]) < 1e-6  # the flow direction: the reference is periodic

    spec = lyapunov(ONE, n=2, transient=8.0, duration=3.0)
    bias = _STEP_BIAS * fastest_time_scale(model)[1]
    assert np.all(np.abs(spec.exponents - floquet) <= 3 * spec.uncertainty + bias), (
        spec.exponents, spec.uncertainty, floquet)
    assert spec.uncertainty[1] < 0.1
