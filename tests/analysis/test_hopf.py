"""Eigenvalue branches, mode couplings, existence limits and Hopf points, each against a
reference that does not use the code under test: closed forms of the rigid-disc limit,
the plain eigen-solve bisected by hand, the reference model's equilibrium, and
textbook two-degree-of-freedom eigenvalues."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator
from scipy.special import lambertw

from fivdisc import Case
from fivdisc.analysis.eigenbranches import eigen_branches, follow, mode_couplings
from fivdisc.analysis.hopf import hopf_points
from fivdisc.analysis.stability import linear_stability
from fivdisc.engine.integration import Integration
from fivdisc.errors import CaseError
from fivdisc.examples import path
from fivdisc.model.build import build_model

from reference.model import sliding_equilibrium as reference_equilibrium

# The rigid-disc limit: no disc modes, so N = N0 and the slider is the oscillator
# I phi'' + C phi' + K phi = r mu(r (Omega - phi')) N0 on a belt moving at r Omega.
# Linearised about steady sliding its damping is C + r^2 N0 mu'(u) (u = r Omega): the
# equilibrium loses stability where that crosses zero, at omega = sqrt(K / I).
R, N0, MASS, K = 0.1, 500.0, 0.1, 2000.0
INERTIA = MASS * R**2
OMEGA_HOPF = np.sqrt(K / INERTIA)
RIGID = {"disc": {"modes": []}, "slider": {"rotational_damping": 0.5}}


def _rigid(friction: dict, **slider) -> Case:
    return Case(**{**RIGID, "slider": {**RIGID["slider"], **slider}}, friction=friction,
                speed={"value": 1.0})


def _check(points, expected_values, omega=OMEGA_HOPF):
    assert len(points) == len(expected_values)
    for hp, value in zip(points, sorted(expected_values), strict=True):
        # Located to 1e-12 relative by Brent's method; 1e-8 is the promise.
        assert hp.value == pytest.approx(value, rel=1e-8)
        assert hp.omega == pytest.approx(omega, rel=1e-8)
        assert abs(hp.eigenvalue.real) < 1e-9 * abs(hp.eigenvalue)


def test_rigid_disc_exponential_law_in_speed_and_damping():
    alpha, dmu, c = 1.0, 0.6 - 0.35, 0.5
    case = _rigid({"decay": alpha})
    # c = r^2 N0 alpha dmu exp(-alpha r Omega)  <=>  Omega = ln(r^2 N0 alpha dmu / c) / (alpha r)
    speed = np.log(R**2 * N0 * alpha * dmu / c) / (alpha * R)
    found = hopf_points(case, "speed.value", np.linspace(0.5, 30.0, 25))
    _check(found, [speed])
    # Faster sliding weakens the negative slope: stability is gained as Omega rises.
    assert found[0].direction == -1 and found[0].on_boundary
    damping = R**2 * N0 * alpha * dmu * np.exp(-alpha * R * 4.0)
    found = hopf_points(case.replace({"speed.value": 4.0}), "slider.rotational_damping",
                        np.linspace(0.05, 3.0, 20))
    _check(found, [damping])
    assert found[0].direction == -1


@pytest.mark.parametrize("viscous", [0.0, 0.002])
def test_rigid_disc_stribeck_law_exponent_one(viscous):
    vs, dmu, c = 0.5, 0.25, 0.5
    case = _rigid({"law": "stribeck", "stribeck_velocity": vs, "stribeck_exponent": 1.0,
                   "viscous": viscous})
    # mu' = -(dmu / vs) exp(-u / vs) + mu_v = -c / (r^2 N0)
    slope = c / (R**2 * N0) + viscous
    u = -vs * np.log(vs * slope / dmu)
    _check(hopf_points(case, "speed.value", np.linspace(0.5, 30.0, 25)), [u / R])


def test_rigid_disc_stribeck_law_exponent_two_has_two_hopf_points():
    vs, dmu, c = 1.0, 0.25, 0.2
    case = _rigid({"law": "stribeck", "stribeck_velocity": vs, "stribeck_exponent": 2.0},
                  rotational_damping=c)
    # dmu 2 u / vs^2 exp(-(u/vs)^2) = s with s = c / (r^2 N0); x = (u / vs)^2 gives
    # -2 x exp(-2 x) = -2 (s vs / (2 dmu))^2: x = -W_k(...) / 2 on both real branches
    # of Lambert's W, the two ends of the speed window of negative damping.
    s = c / (R**2 * N0)
    arg = -2.0 * (s * vs / (2.0 * dmu)) ** 2
    speeds = [vs * np.sqrt(-lambertw(arg, k).real / 2.0) / R for k in (0, -1)]
    found = hopf_points(case, "speed.value", np.linspace(0.2, 30.0, 40))
    _check(found, speeds)
    assert [hp.direction for hp in found] == [1, -1]


def test_rigid_disc_table_law():
    speeds, values = [0.0, 0.2, 0.5, 1.0, 2.0], [0.6, 0.55, 0.45, 0.4, 0.38]
    case = _rigid({"law": "table", "static": 0.8, "speeds": speeds, "values": values},
                  rotational_damping=0.2)
    # The slope of the PCHIP curve equals -c / (r^2 N0) where the damping vanishes.
    slope = PchipInterpolator(speeds, values).derivative()
    slope.c[-1] += 0.2 / (R**2 * N0)
    roots = slope.roots(extrapolate=False)
    found = hopf_points(case, "speed.value", np.linspace(0.1, 25.0, 50))
    _check(found, list(roots / R))


def _growth_near(case: Case, key: str, value: float, omega: float) -> float:
    lam = linear_stability(case.replace({key: value})).eigenvalues
    return float(lam[np.argmin(np.abs(lam - 1j * omega))].real)


@pytest.mark.parametrize(("example", "key", "values"), [
    ("fig03a", "slider.rotational_damping", np.linspace(0.0, 3.0, 16)),
    ("fig03a", "friction.decay", np.linspace(0.0, 10.0, 11)),
])
def test_full_model_hopf_points_equal_bisection_of_the_plain_eigen_solve(example, key,
                                                                         values):
    from fivdisc.case import load_case

    case = load_case(path(example))
    found = hopf_points(case, key, values)
    assert found
    for hp in found:
        # A dense bracket, then plain bisection on the case rebuilt at every value.
        half = 0.05 * np.ptp(values)
        dense = np.linspace(max(hp.value - half, values.min()),
                            min(hp.value + half, values.max()), 41)
        growth = [_growth_near(case, key, v, hp.omega) for v in dense]
        i = int(np.flatnonzero(np.diff(np.sign(growth)))[0])
        lo, hi = dense[i], dense[i + 1]
        g_lo = growth[i]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            g = _growth_near(case, key, mid, hp.omega)
            lo, hi, g_lo = (mid, hi, g) if (g < 0) == (g_lo < 0) else (lo, mid, g_lo)
        assert hp.value == pytest.approx(0.5 * (lo + hi), rel=1e-8)


def test_hopf_orbit_start_returns_after_one_period():
    """The full-layout state and eigenvector start a small orbit: integrated over
    2 pi / omega from state + eps Re(v), the (undamped at the Hopf point) linear motion
    comes back to its start up to the nonlinear O(eps^2) terms."""
    case = _rigid({"decay": 1.0})
    hp = hopf_points(case, "speed.value", np.linspace(0.5, 30.0, 25))[0]
    model = build_model(hp.case)
    assert hp.state.shape == hp.eigenvector.shape == (model.state_size,)
    eps = 1e-6
    start = hp.state + eps * hp.eigenvector.real
    run = Integration(model, start, duration=hp.period, rtol=1e-12, atol=1e-16)
    run.run_to(hp.period)
    assert np.linalg.norm(run.state[: model.state_size] - start) < 1e-3 * eps


def test_follow_keeps_crossing_branches_and_finds_flutter():
    # Crossing without coupling: diag(1 + p, 2 - p) swaps order at p = 0.5; followed, each
    # branch stays a straight line.
    ps = np.linspace(0.0, 1.0, 21)
    lam = np.array([1j * np.array([1 + p, 2 - p, -(1 + p), -(2 - p)]) for p in ps])
    scrambled = np.array([row[np.argsort(row.imag)] for row in lam])
    followed = follow(scrambled)
    assert np.allclose(np.diff(followed.imag, 2, axis=0), 0.0)
    assert mode_couplings(followed) == []
    # Follower-force flutter: x'' + [[k1, p], [-p, k2]] x = 0 has
    # lambda^2 = -(k1 + k2) / 2 +- sqrt(((k1 - k2) / 2)^2 - p^2): frequencies merge and a
    # growth rate leaves zero at p = |k1 - k2| / 2.
    k1, k2 = 1.0, 2.0
    ps = np.linspace(0.0, 1.0, 101)
    rows = []
    for p in ps:
        mat = np.block([[np.zeros((2, 2)), np.eye(2)],
                        [-np.array([[k1, p], [-p, k2]]), np.zeros((2, 2))]])
        rows.append(np.linalg.eigvals(mat))
    found = mode_couplings(follow(np.array(rows)))
    assert len(found) == 1
    assert ps[found[0][0]] == pytest.approx(abs(k1 - k2) / 2, abs=ps[1] - ps[0])


def test_a_frequency_crossing_of_modes_already_apart_in_growth_is_no_coupling():
    """Two modes of different sliders (a three-slider trial case at 1.5 rad/s: 191.2 and
    191.7 Hz, growth rates 238 and 315 1/s) cross in frequency while their growth rates,
    apart by 5 % of the frequency, go on parting: the eigenvalues never come near each
    other, so nothing couples there. A coupling is two eigenvalues meeting: just outside
    the merged interval their growth rates agree as closely as their frequencies."""
    ps = np.linspace(0.0, 1.0, 21)
    lam = []
    for p in ps:
        a = 0.3 * p + 1j * (1.0 + 0.2 * p)   # grows faster and faster
        b = -0.1 + 1j * (1.2 - 0.2 * p)      # decays; the frequencies cross at p = 0.5
        lam.append([a, b, a.conjugate(), b.conjugate()])
    assert mode_couplings(follow(np.array(lam))) == []


def test_existence_limit_where_the_reference_normal_force_vanishes():
    # Near the l = 2 critical speed the disc's static compliance grows without bound
    # and the slider's normal force falls to zero.
    ds = eigen_branches(Case(), "speed.value", np.linspace(880.0, 916.0, 9))
    (limit,) = ds["existence_limit"].values
    below = reference_equilibrium(Case(speed={"value": limit * (1 - 1e-9)}))["N"]
    above = reference_equilibrium(Case(speed={"value": limit * (1 + 1e-9)}))["N"]
    assert below > 0 > above
    assert np.isnan(ds["growth_rate"].values[-1]).all()


@pytest.mark.parametrize(("example", "updates", "key", "values"), [
    ("default", {"speed.value": 1.0}, "slider.rotational_damping", (0.5, 3.0)),
    ("two-pads", {}, "sliders.1.preload", (200.0, 800.0)),
    ("damped-disc", {}, "disc.damping_ratio", (0.0, 0.01)),
    ("damped-disc", {"disc.damping_frame": "space"}, "speed.value", (1.0, 20.0)),
    ("stribeck", {"speed.value": 2.0}, "friction.stribeck_velocity", (0.05, 0.5)),
    ("measured-friction", {"speed": {"profile": "constant", "value": 2.0}}, "speed.value",
     (0.5, 10.0)),
])
def test_branches_match_plain_eigenvalues_at_every_value(example, updates, key, values):
    """Several sliders, damping in either frame, every friction law, keys the model is
    patched for and keys it is rebuilt for: at every value the followed equilibrium and
    eigenvalues equal a plain solve of the case rebuilt there."""
    from fivdisc.case import load_case

    case = load_case(path(example)).replace(updates)
    values = np.linspace(*values, 5)
    ds = eigen_branches(case, key, values)
    lam = ds["growth_rate"].values + 2j * np.pi * ds["frequency"].values
    for i, v in enumerate(values):
        plain = linear_stability(case.replace({key: v}))
        # The same Jacobian solved twice: agreement to round-off of the spectral radius.
        assert np.allclose(np.sort_complex(lam[i]), np.sort_complex(plain.eigenvalues),
                           rtol=1e-9, atol=1e-9 * np.abs(plain.eigenvalues).max())
        np.testing.assert_allclose(ds["normal_force"].values[i],
                                   plain.equilibrium.normal_force, rtol=1e-10)


@pytest.mark.parametrize(("key", "values", "match"), [
    ("friction.law", [0.0, 1.0], "not a number"),
    ("slider.normal_damping", [1.0, 1.0], "empty"),
    ("slider.normal_damping", [1.0], "at least 2"),
    ("slider.normal_damping", [-1.0, 1.0], r"slider\.normal_damping = -1"),
])
def test_bad_scans_are_refused_before_any_work(key, values, match):
    with pytest.raises(CaseError, match=match):
        eigen_branches(Case(), key, values)


def test_no_equilibrium_at_the_start_is_refused():
    with pytest.raises(CaseError, match="no sliding equilibrium"):
        eigen_branches(Case(), "speed.value", [915.0, 930.0])


def test_hopf_eigenvector_in_the_full_layout_on_a_flexible_disc():
    """On the paper's disc: the equilibrium state is a rest point of the slip equations,
    the eigenvector solves J v = lambda v on every free row of the full Jacobian, and its
    z rows are the change of the disc's w under the slider (from the plate's mode shapes,
    independent of the kernel)."""
    from fivdisc import core
    from fivdisc.case import load_case
    from fivdisc.engine.equilibrium import slip_phases

    case = load_case(path("fig03a"))
    hp = hopf_points(case, "slider.rotational_damping", np.linspace(0.0, 3.0, 16))[0]
    model = build_model(hp.case)
    ph, sg = slip_phases(model)
    jac = core.jacobian(core.core_model(model), 0.0, hp.state, ph, sg)
    n, free = model.n, np.r_[0 : model.n + 1, model.n + 2 : 2 * model.n + 3]
    residual = jac[np.ix_(free, free)] @ hp.eigenvector[free] - hp.eigenvalue * hp.eigenvector[free]
    # Complex-step Jacobian exact to round-off: residual ~ eps |J| |v|.
    assert np.linalg.norm(residual) < 1e-9 * abs(hp.eigenvalue)
    slider = hp.case.sliders[0]
    theta = slider.angle

    def w(y):
        shape = model.shape_matrix([slider.track_radius], [theta + y[n]])[0]
        return float(shape @ y[:n])

    z = model.index("z")
    assert hp.state[z] == pytest.approx(w(hp.state), rel=1e-12)
    for part in (hp.eigenvector.real, hp.eigenvector.imag):
        # Steps of 1e-7 (m, rad) on a static deflection of ~1e-3 m: round-off ~1e-12 and
        # truncation ~(l * 1e-7)^2 of the change; measured agreement ~1e-7 relative.
        h = 1e-7 / np.abs(part[: n + 1]).max()
        change = (w(hp.state + h * part) - w(hp.state - h * part)) / (2 * h)
        assert part[z] == pytest.approx(change, rel=1e-6)
