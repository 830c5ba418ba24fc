"""The model family (several sliders on either face, a damped disc, friction laws) against
results that need no simulator: symmetry, closed-form eigenvalues, the energy balance,
identities between friction laws, and the impact complementarity problem."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

import fivdisc
from fivdisc.case import Case, load_case
from fivdisc.core import core_model, jacobian, kinetic_friction, solve_lcp
from fivdisc.engine.simulation import simulate
from fivdisc.examples import DIRECTORY as EXAMPLES
from fivdisc.model.build import build_model
from fivdisc.model.layout import Phase

from support.cases import kick

TIGHT = {"rtol": 1e-10, "atol": 1e-13}



# --- faces and symmetry ------------------------------------------------------------------


def test_identical_pads_on_both_faces_keep_the_disc_flat():
    """Two identical sliders at one angle, one per face: their normal forces and friction
    moments on the disc cancel, so the disc is not deflected and both move alike.

    The cancellation is exact up to round-off of the two normal forces (they come from one
    small linear solve), and each of the ~100 stick-slip switches in 0.3 s amplifies such
    a difference (a grazing crossing of |f| = mu_s N). Measured: the disc deflects by 3e-8
    of one slider's deflection and the angles differ by 7e-9 of their peak. A pad heavier
    by one part in a million already gives 2e-6 and 6e-5, so the bounds below separate
    symmetry from a near miss."""
    sim = {"duration": 0.3, "output_rate": 5000.0}
    single = np.max(np.abs(simulate(Case(simulation=sim)).dataset["q"].values))

    def asymmetry(bottom_mass: float) -> tuple[float, float]:
        case = Case(sliders=[{"face": "top"}, {"face": "bottom", "mass": bottom_mass}],
                    simulation=sim)
        ds = simulate(case).dataset
        assert ds.attrs["status"] == "success"
        phi = ds["phi"].values
        return (np.max(np.abs(ds["q"].values)) / single,
                np.max(np.abs(phi[:, 0] - phi[:, 1])) / np.max(np.abs(phi)))

    flat, alike = asymmetry(0.1)
    assert flat < 3e-7 and alike < 1e-7
    near_flat, near_alike = asymmetry(0.1 * (1 + 1e-6))
    assert near_flat > 5 * 3e-7 and near_alike > 5 * 1e-7


def test_bottom_face_is_the_mirror_image_of_the_top():
    """Reflecting w -> -w maps a top slider on a bottom one: q, z, gap... change sign,
    the in-plane motion and the forces do not."""
    top = Case(simulation={"duration": 0.2, "output_rate": 5000.0})
    bottom = top.replace({"slider.face": "bottom"})
    start = kick(top)
    a = simulate(top, initial=start).dataset
    b = simulate(bottom, initial={"q_dot": -start["q_dot"]}).dataset
    assert "separation" in list(a["event_kind"].values)
    assert list(a["event_kind"].values) == list(b["event_kind"].values)
    for var, sign in (("q", -1), ("z", -1), ("phi", 1), ("phi_dot", 1), ("normal_force", 1),
                      ("friction_force", 1), ("gap", 1)):
        peak = np.max(np.abs(a[var].values))
        assert np.max(np.abs(b[var].values - sign * a[var].values)) <= 1e-9 * peak, var


# --- disc damping --------------------------------------------------------------------------


def _free_disc_eigenvalues(case: Case, speed: float) -> tuple[np.ndarray, object]:
    """Eigenvalues of the disc's own equations: the slider flies (phase separation), so
    the disc block of the Jacobian is decoupled from it."""
    model = build_model(case.replace({"speed.value": speed}))
    y = np.zeros(model.state_size)
    jac = jacobian(core_model(model), 0.0, y, np.array([Phase.SEPARATION]), np.array([1]))
    n = model.n
    idx = np.r_[0:n, n + 2 : 2 * n + 2]
    return np.linalg.eigvals(jac[np.ix_(idx, idx)]), model


@pytest.mark.parametrize("frame", ["material", "space"])
def test_damped_spinning_disc_eigenvalues(frame):
    """With u = C + i D per doublet the disc obeys
    u'' - 2 i l Omega u' + (omega^2 - l^2 Omega^2) u + 2 zeta omega (u' - i l Omega u) = 0
    (material) or ... + 2 zeta omega u' = 0 (space frame). For exp(lambda t):
    material: lambda = +-i l Omega - zeta omega +- i omega sqrt(1 - zeta^2);
    space: lambda = +-i l Omega - zeta omega +- i omega sqrt(1 - zeta^2 +- 2 i zeta l Omega /
    omega) (the signs of l Omega paired)."""
    zetas = [0.01, 0.05, 0.002, 0.1]
    case = Case(disc={"damping_ratio": zetas, "damping_frame": frame})
    lam, model = _free_disc_eigenvalues(case, 40.0)
    omega_c = 40.0
    expected = []
    for (_, l), zeta in zip(case.disc.modes, zetas, strict=True):
        w = model.omega[list(model.l).index(l)]
        for spin in ((1, -1) if l else (0,)):
            rot = 1j * spin * l * omega_c
            if frame == "material":
                roots = [rot - zeta * w + s * 1j * w * np.sqrt(1 - zeta**2) for s in (1, -1)]
            else:
                root = np.sqrt(1 - zeta**2 + 2j * zeta * spin * l * omega_c / w)
                roots = [rot - zeta * w + s * 1j * w * root for s in (1, -1)]
            expected.extend(roots)
    expected = np.array(expected)
    assert lam.size == expected.size
    # Exact Jacobian (complex step) and a dense eigensolver: agreement to round-off of the
    # spectral radius (~2.8e3 1/s).
    scale = np.max(np.abs(expected))
    for value in expected:
        assert np.min(np.abs(lam - value)) <= 1e-10 * scale


def test_material_damping_enters_the_sliding_equilibrium():
    """Material damping acts on w_t + Omega w_theta, which a steady deflection w(theta)
    under a spinning disc does not make zero: it drags the deflection round (a phase lag),
    which space-frame damping does not."""
    base = Case(speed={"value": 20.0})
    eq0 = fivdisc.sliding_equilibrium(base)
    eq_space = fivdisc.sliding_equilibrium(
        base.replace({"disc.damping_ratio": 0.05, "disc.damping_frame": "space"}))
    eq_mat = fivdisc.sliding_equilibrium(base.replace({"disc.damping_ratio": 0.05}))
    np.testing.assert_allclose(eq_space.q, eq0.q, rtol=0, atol=1e-15)
    assert np.max(np.abs(eq_mat.q - eq0.q)) > 1e-3 * np.max(np.abs(eq0.q))


# --- energy --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "extra",
    [
        {"disc": {"damping_ratio": 0.01}},
        {"disc": {"damping_ratio": 0.01, "damping_frame": "space"}},
        {"speed": {"profile": "decelerating", "initial": 10.0, "duration": 0.5}},
        {"simulation": {"impact": False}},
    ],
    ids=["material", "space", "decelerating", "no-impact"],
)
def test_energy_balance_closes(extra):
    """Stored energy changes by the work of friction, drive, dampers and impacts: the
    kernel integrates each power with the state, so the balance closes to the integration
    error (rtol 1e-10: ~1e-9 of the energy turned over), well inside the 1e-6 asked."""
    sim = {"duration": 1.0, "energy_balance": True, "output_rate": 2000.0, **TIGHT}
    sim.update(extra.pop("simulation", {}))
    case = Case(sliders=[{"angle": 0.0}, {"angle": 1.0, "face": "bottom", "mass": 0.12}],
                simulation=sim, **extra)
    res = simulate(case, initial=kick(case))
    assert res.status == "success"
    kinds = list(res.dataset["event_kind"].values)
    assert "recontact" in kinds and "stick" in kinds
    balance = fivdisc.energy_balance(res)
    assert balance.attrs["relative_residual"] < 1e-6
    work = balance["work"].sel(time=balance["time"][-1])
    assert work.sel(energy_term="friction") < 0.0
    assert work.sel(energy_term="slider_damping") < 0.0
    assert work.sel(energy_term="impact_loss") < 0.0


def test_energy_balance_needs_the_recorded_work():
    res = simulate(Case(simulation={"duration": 0.01}))
    with pytest.raises(fivdisc.FivdiscError, match="energy_balance = true"):
        fivdisc.energy_balance(res)


# --- friction laws -------------------------------------------------------------------------


def test_stribeck_with_delta_one_is_the_exponential_law():
    """mu_1 + (mu_0 - mu_1) exp(-(u / v_s)^1) + 0 u is the exponential law with alpha = 1/v_s;
    the two runs differ only by rounding of the exponent (1e-16), far below 1e-9."""
    sim = {"duration": 0.2, "output_rate": 5000.0}
    exp = Case(friction={"decay": 4.0}, simulation=sim)
    strib = Case(friction={"law": "stribeck", "stribeck_velocity": 0.25, "stribeck_exponent": 1.0,
                           "viscous": 0.0}, simulation=sim)
    a, b = simulate(exp).dataset, simulate(strib).dataset
    assert list(a["event_kind"].values) == list(b["event_kind"].values)
    for var in ("phi", "friction_force", "q"):
        peak = np.max(np.abs(a[var].values))
        assert np.max(np.abs(a[var].values - b[var].values)) <= 1e-9 * peak, var


def test_table_law_reproduces_the_law_it_samples():
    """A table sampled from the exponential law: PCHIP's interpolation error e (measured
    here, independently of the kernel) bounds the error of the friction coefficient, so
    over the first slip and stick the friction force differs by at most e N, and the
    difference shrinks with e as the table is refined. (Later stick-to-slip switches are
    grazing crossings of |f| = mu_s N that amplify any difference a hundredfold each, so
    a long run measures the system's sensitivity, not the law.)"""
    alpha = 3.0
    sim = {"duration": 0.0035, "output_rate": 100000.0, **TIGHT}
    exact = simulate(Case(friction={"decay": alpha}, simulation=sim)).dataset
    assert list(exact["event_kind"].values) == ["stick"]
    fine = np.linspace(0.0, 2.0, 20001)
    diffs = []
    for points in (41, 161):
        speeds = np.linspace(0.0, 2.0, points)
        values = 0.35 + 0.25 * np.exp(-alpha * speeds)
        err = np.max(np.abs(PchipInterpolator(speeds, values)(fine)
                            - (0.35 + 0.25 * np.exp(-alpha * fine))))
        table = Case(friction={"law": "table", "speeds": speeds.tolist(),
                               "values": values.tolist()}, simulation=sim)
        got = simulate(table).dataset
        assert list(got["event_kind"].values) == ["stick"]
        diff = np.max(np.abs(got["friction_force"].values - exact["friction_force"].values))
        assert diff <= err * np.max(exact["normal_force"].values)
        diffs.append((diff, err))
    (coarse, e_coarse), (fine_diff, e_fine) = diffs
    assert fine_diff < coarse * 3 * e_fine / e_coarse


@pytest.mark.parametrize("law", [
    {"law": "stribeck", "stribeck_velocity": 0.3, "stribeck_exponent": 2.0, "viscous": 0.1},
    {"law": "table", "speeds": [0.0, 0.2, 0.5, 1.0], "values": [0.6, 0.5, 0.42, 0.4]},
])
def test_kernel_friction_law_matches_its_formula(law):
    """The compiled law against a direct evaluation (scipy PCHIP for the table)."""
    case = Case(friction={"static": 0.8, **law})
    cm = core_model(build_model(case))
    u = np.linspace(0.0, 1.5, 301)
    r = 0.1
    got = np.array([kinetic_friction(cm, r, 1, ui / r) for ui in u])
    if law["law"] == "stribeck":
        want = 0.35 + 0.25 * np.exp(-(u / 0.3) ** 2.0) + 0.1 * u
    else:
        want = PchipInterpolator(law["speeds"], law["values"])(np.minimum(u, 1.0))
    np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-15)


# --- several sliders -----------------------------------------------------------------------


def test_eight_sliders_run_with_their_own_phases():
    """Eight sliders round the disc, on alternating faces, kicked into flight: every one
    switches on its own, and the run completes."""
    sliders = [{"angle": 2 * np.pi * j / 8 + 0.1 * j, "face": "top" if j % 2 else "bottom",
                "preload": 400.0 + 20 * j} for j in range(8)]
    case = Case(sliders=sliders, simulation={"duration": 0.2, "output_rate": 2000.0,
                                             "energy_balance": True})
    res = simulate(case, initial=kick(case, 8.0))
    assert res.status == "success", res.message
    ds = res.dataset
    assert ds.sizes["slider"] == 8
    switched = set(ds["event_slider"].values[ds["event_kind"].values == "stick"])
    assert switched == set(range(8))
    assert "recontact" in list(ds["event_kind"].values)
    assert fivdisc.energy_balance(res).attrs["relative_residual"] < 1e-5


def _lcp_by_enumeration(dmat, gam):
    """Every active set tried; the one satisfying complementarity returned."""
    m = gam.size
    for mask in itertools.product([False, True], repeat=m):
        act = np.array(mask)
        lam = np.zeros(m)
        if act.any():
            lam[act] = np.linalg.solve(dmat[np.ix_(act, act)], -gam[act])
        w = gam + dmat @ lam
        if np.all(lam >= -1e-12) and np.all(w[~act] >= -1e-12):
            return lam, w
    raise AssertionError("no solution")


def test_impact_lcp_is_solved_exactly():
    """Murty's principal pivoting against enumeration of all active sets, on random
    positive definite Delassus matrices with one approaching contact (the landing slider)
    and others at rest: complementarity holds, contacts that would pull are released."""
    rng = np.random.default_rng(3)
    released = 0
    for _ in range(200):
        m = int(rng.integers(2, 7))
        a = rng.normal(size=(m, m + 3))
        dmat = a @ a.T + 0.1 * np.eye(m)
        gam = np.zeros(m)
        gam[0] = -abs(rng.normal()) - 0.1
        w, lam = solve_lcp(dmat, gam, np.zeros(m, np.bool_))
        lam_ref, w_ref = _lcp_by_enumeration(dmat, gam)
        np.testing.assert_allclose(lam, lam_ref, atol=1e-12)
        np.testing.assert_allclose(w, w_ref, atol=1e-12)
        assert np.all(lam >= 0) and np.all(w >= -1e-12) and abs(lam @ w) < 1e-12
        released += int(np.sum(w > 1e-9))
    assert released > 20  # the sample does exercise releases


def test_forced_contacts_stay_closed():
    """A bilateral (forced) contact keeps zero gap velocity even when it needs a pull."""
    dmat = np.array([[2.0, 1.5], [1.5, 2.0]])
    gam = np.array([-1.0, 0.0])
    w, lam = solve_lcp(dmat, gam, np.array([False, False]))
    assert lam[1] == 0.0 and w[1] > 0.0
    w, lam = solve_lcp(dmat, gam, np.array([False, True]))
    assert w[1] == 0.0 and lam[1] < 0.0


# --- examples ------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["two-pads", "damped-disc", "stribeck", "measured-friction"])
def test_family_examples_run(name):
    case = load_case(EXAMPLES / f"{name}.toml").replace({"simulation.duration": 0.1})
    res = simulate(case)
    assert res.status == "success"
    assert res.dataset.sizes["slider"] == len(case.sliders)


def _flights(ds) -> list[tuple[float, float]]:
    """(start, duration) of every completed flight of every slider, in time order."""
    out = []
    for j in range(ds.sizes["slider"]):
        start = None
        for t, kind, s in zip(ds["event_time"].values, ds["event_kind"].values,
                              ds["event_slider"].values, strict=True):
            if s != j:
                continue
            if kind == "separation":
                start = t
            elif kind == "recontact" and start is not None:
                out.append((float(start), float(t - start)))
                start = None
    return sorted(out)


@pytest.mark.parametrize("min_flight", [1e-11, 1e-8])
def test_impact_cascade_is_resolved_then_closed(min_flight):
    """A top slider at 0 and a bottom one at pi on a disc rocking in its one-diameter mode:
    each landing pushes the disc away from the other slider, which flies a little and
    lands, releasing the first... Each flight is about ten times shorter than the one
    before (the gap's velocity after release scales with the landing speed, which scales
    with the flight); the cascade is followed until a flight would be shorter than
    simulation.min_flight_time, then closed. The flight-time prediction is parabolic,
    exact to first order for such short flights, so no flight is below half the minimum."""
    case = Case(sliders=[{"face": "top"}, {"face": "bottom", "angle": np.pi}],
                simulation={"duration": 0.1, "output_rate": 2000.0, "energy_balance": True,
                            "min_flight_time": min_flight, **TIGHT})
    q_dot = np.zeros(build_model(case).n)
    q_dot[1] = 8.0
    res = simulate(case, initial={"q_dot": q_dot})
    assert res.status == "success", res.message
    flights = _flights(res.dataset)
    durations = np.array([d for _, d in flights])
    assert durations.min() >= 0.5 * min_flight
    # Find the cascades: runs of consecutive flights shrinking by more than 5 each.
    ratios = durations[:-1] / durations[1:]
    cascade = (ratios > 5.0) & (ratios < 20.0)
    assert np.sum(cascade) >= 4
    assert np.any(durations < 100 * min_flight)
    assert fivdisc.energy_balance(res).attrs["relative_residual"] < 1e-6
