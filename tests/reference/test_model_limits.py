"""Checks of the slow reference model (tests/reference/model.py) against analytic limits.

The reference is what the fast simulator is checked against, so it is itself checked here
against results that need no simulator: the rigid-disc stick-slip period, conservation of
the Jacobi integral, an exact power balance, the plastic impact map; and for the model
family (several sliders on either face, disc damping, friction laws): numbers of the
pre-family single-slider reference, symmetries (opposite faces, mirror, rotation), closed
forms of the damped free disc, the mechanical energy balance, equal friction laws, the
impact LCP against an independent solver and the consistency of the event table.
"""

from __future__ import annotations

import itertools
import math
from types import SimpleNamespace

import numpy as np
import pytest

from fivdisc.case import Case

import reference.model as rm

RIGID = rm.ModeData.from_lists([], [], [], [], [])  # no disc modes: N = N0


def _ns(table, **over) -> SimpleNamespace:
    """A case table as a namespace (the attributes of the fast code's model-family Case)."""
    return SimpleNamespace(**{**dict(table), **over})


def family_case(sliders=({},), disc=None, friction=None, speed=None, simulation=None):
    """A model-family case: ``sliders`` (dicts over Case().slider with angle 0, top face)
    and the other tables over Case()'s defaults, as ``types.SimpleNamespace`` objects."""
    base = Case()
    return SimpleNamespace(
        sliders=[_ns(base.slider, **{"angle": 0.0, "face": "top", **sl}) for sl in sliders],
        disc=_ns(base.disc, **(disc or {})),
        friction=_ns(base.friction, **(friction or {})),
        speed=_ns(base.speed, **(speed or {})),
        simulation=_ns(base.simulation, **(simulation or {})),
    )


def _kin(md: rm.ModeData, phi: float):
    lphi = md.l * phi
    g = md.R0 * np.where(md.is_sine, np.sin(lphi), np.cos(lphi))
    gp = md.R0 * md.l * np.where(md.is_sine, np.cos(lphi), -np.sin(lphi))
    return g, gp


def _split(md: rm.ModeData, y):
    n = md.n
    return y[:n], y[n : 2 * n], y[2 * n], y[2 * n + 1], y[2 * n + 2], y[2 * n + 3]


@pytest.fixture(scope="module")
def table1_modes():
    return rm.mode_data_from_case(Case())


# --------------------------------------------------------------------------- rigid disc
@pytest.mark.parametrize("omega", [2.0 * math.pi, 10.0])
def test_rigid_disc_stick_slip_period(omega):
    """Rigid disc (no modes, N = N0), alpha = 0 (mu = mu0), no in-plane damping.

    Stick from phi_k - A to phi_k + A at phidot = Omega (2A/Omega), then a free slip
    oscillation about phi_k = r0 mu0 N0 / (r0^2 k_phi) of frequency w until phidot = Omega
    again ((pi + 2 arctan(Omega / (w A))) / w).
    """
    case = Case(
        friction={"decay": 0.0},
        slider={"rotational_damping": 0.0},
        speed={"profile": "constant", "value": omega},
    )
    sl, fr = case.slider, case.friction
    inertia = sl.mass * sl.track_radius**2
    w = math.sqrt(sl.rotational_stiffness / inertia)
    amp = sl.track_radius * (fr.static - fr.kinetic_max) * sl.preload / sl.rotational_stiffness
    period = 2.0 * amp / omega + (math.pi + 2.0 * math.atan(omega / (w * amp))) / w

    res = rm.reference_simulate(case, 6.5 * period, mode_data=RIGID)
    sticks = np.array([t for t, _, _, kind, _ in res.events if kind == "stick"])
    assert sticks.size >= 5
    # From the first stick on the motion is exactly on the limit cycle (every slip starts
    # at phi_k + A with phidot = Omega), so every later stick-to-stick time is the period.
    # 1e-8: event times are located to ~1e-15 s and the dense output is good to
    # ~rtol = 1e-12; 1e-8 leaves orders of margin (measured 9e-15 and 1.6e-13).
    np.testing.assert_allclose(np.diff(sticks[1:]), period, rtol=1e-8)
    # every stick after the first lasts 2A/Omega (same reasoning for the tolerance); the
    # first one starts from the transient's phi, not from phi_k - A
    slips = np.array([t for t, _, _, kind, _ in res.events if kind == "slip"])
    k = min(sticks.size, slips.size)
    assert np.all(slips[:k] > sticks[:k])
    np.testing.assert_allclose(slips[1:k] - sticks[1:k], 2 * amp / omega, rtol=1e-8)
    # rigid disc: the normal force is the preload exactly (n = 0, nothing else enters N)
    out = res.evaluate(np.linspace(0.0, res.t_end, 50))
    np.testing.assert_array_equal(out["normal_force"], sl.preload)
    assert {e[3] for e in res.events} == {"stick", "slip"}


# --------------------------------------------------------------------------- Jacobi integral
def test_jacobi_integral_conserved_without_friction_and_damping(table1_modes):
    """No friction, no damping, constant speed: T2 - T0 + V is a first integral.

    Started with phi = phidot = 0 and f = 0 the slider's angle stays 0, so the term
    N phidot (g'.q) -- the work of the normal force along the disc's slope, which the
    model's phi equation does not balance -- is zero and the integral is exact.
    """
    md = table1_modes
    case = Case(
        friction={"static": 0.0, "kinetic_max": 0.0, "kinetic_min": 0.0},
        slider={"normal_damping": 0.0, "rotational_damping": 0.0},
        speed={"profile": "constant", "value": 50.0},
    )
    eq = rm.sliding_equilibrium(case, md)
    rng = np.random.default_rng(1)
    scale = np.max(np.abs(eq["q"]))
    q0 = eq["q"] * (1.0 + 0.3 * rng.standard_normal(md.n)) + 0.2 * scale * rng.standard_normal(md.n)
    qd0 = 0.3 * scale * md.omega * rng.standard_normal(md.n)
    res = rm.reference_simulate(
        case, 0.2, y0={"q": q0, "q_dot": qd0, "phi": 0.0, "phi_dot": 0.0}, mode_data=md
    )
    assert res.events == []  # stays in slip, in contact (no separation)
    out = res.evaluate(np.linspace(0.0, 0.2, 2001))
    assert out["normal_force"].min() > 0.0
    h = rm.jacobi_integral(case, out, mode_data=md)
    # 1e-8 relative: the integration error over 0.2 s (~1e4 steps at rtol = 1e-12)
    # accumulates to ~1e-12 (measured 2.4e-12); 1e-8 is the bound asked for.
    assert np.max(np.abs(h - h[0])) <= 1e-8 * abs(h[0])
    # a stricter scale: the energy that is actually exchanged (max of T2; measured 1.2e-11)
    t2 = rm.kinetic_energy_t2(case, out, md)
    assert np.max(np.abs(h - h[0])) <= 1e-8 * np.max(t2)


def _power(case, md, out):
    """dH/dt of the Jacobi integral along a contact motion at constant speed.

    From the equations of motion (gyroscopic terms drop out):
    N phidot (g'.q) + f (r0 phidot + h/(2 r0) g'.qdot) - r0^2 c_phi phidot^2 - c_z zdot^2.
    """
    sl = case.slider
    hk = case.disc.thickness / (2.0 * sl.track_radius)
    p = np.empty(out["t"].size)
    for i in range(p.size):
        _, gp = _kin(md, out["phi"][i, 0])
        p[i] = (
            out["normal_force"][i, 0] * out["phi_dot"][i, 0] * (gp @ out["q"][i])
            + out["friction_force"][i, 0]
            * (sl.track_radius * out["phi_dot"][i, 0] + hk * (gp @ out["q_dot"][i]))
            - sl.rotational_damping * out["phi_dot"][i, 0] ** 2
            - sl.normal_damping * out["z_dot"][i, 0] ** 2
        )
    return p


def test_power_balance_through_stick_slip(table1_modes):
    """With friction and damping, H(t1) - H(t0) equals the integral of the power.

    This checks the whole right-hand side (the coupled solve for N, the friction moment,
    both contact phases and their switches), not only its conservative part.
    """
    md = table1_modes
    case = Case(speed={"profile": "constant", "value": 10.0})
    res = rm.reference_simulate(case, 0.01, mode_data=md)
    kinds = {e[3] for e in res.events}
    assert {"stick", "slip"} <= kinds and "separation" not in kinds
    x, wts = np.polynomial.legendre.leggauss(40)
    work = 0.0
    for seg in res.segments:  # Gauss-Legendre on each smooth piece
        tm, th = 0.5 * (seg.t0 + seg.t1), 0.5 * (seg.t1 - seg.t0)
        out = res.evaluate(tm + th * x)
        work += th * np.sum(wts * _power(case, md, out))
    ends = res.evaluate(np.array([0.0, res.t_end]))
    h = rm.jacobi_integral(case, ends, mode_data=md)
    t2max = np.max(rm.kinetic_energy_t2(case, res.evaluate(np.linspace(0, res.t_end, 201)), md))
    # 1e-8 of the kinetic-energy scale: integration error ~1e-12, quadrature of each
    # segment (<= a few ms, smooth) with 40 points is exact to round-off; measured 7e-14.
    assert abs((h[1] - h[0]) - work) <= 1e-8 * t2max


# --------------------------------------------------------------------------- impact map
def test_impact_map_properties(table1_modes):
    """Plastic impact: equal normal velocities afterwards, positions and phidot unchanged,
    and the change of T2 = 1/2 sum M qdot^2 + 1/2 m zdot^2 is exactly -u (u/2 + b) / K,
    u = approach velocity, b = phidot g'.q, K = 1/m + sum g^2/M; T2 cannot increase when
    b = 0 (or u (u/2 + b) >= 0)."""
    md = table1_modes
    m = Case().slider.mass
    rng = np.random.default_rng(7)
    for trial in range(200):
        q = 1e-5 * rng.standard_normal(md.n)
        qd = 1e-2 * rng.standard_normal(md.n)
        phi = rng.uniform(-math.pi, math.pi)
        phid = 0.0 if trial % 2 == 0 else rng.uniform(-20.0, 20.0)
        g, gp = _kin(md, phi)
        w_dot = g @ qd + phid * (gp @ q)  # disc's normal velocity under the slider
        zd_minus = w_dot - abs(rng.standard_normal()) * 0.1  # approaching: gap closing
        qd_plus, zd_plus = rm.impact_map(md, m, q, qd, phi, phid, zd_minus)
        # relative to the velocity scale 0.1 m/s: round-off only
        assert abs(zd_plus - (g @ qd_plus + phid * (gp @ q))) <= 1e-14
        t2_minus = 0.5 * np.sum(md.M * qd**2) + 0.5 * m * zd_minus**2
        t2_plus = 0.5 * np.sum(md.M * qd_plus**2) + 0.5 * m * zd_plus**2
        u = zd_minus - w_dot
        b = phid * (gp @ q)
        k_inv = 1.0 / m + np.sum(g**2 / md.M)
        assert t2_plus - t2_minus == pytest.approx(-u * (0.5 * u + b) / k_inv, rel=1e-9, abs=1e-18)
        if phid == 0.0:
            assert t2_plus < t2_minus
        # momentum: the impulse on the slider is minus the generalised impulse on the disc
        p = m * (zd_plus - zd_minus)
        np.testing.assert_allclose(md.M * (qd_plus - qd), -p * g, atol=1e-15)


def _separated_start(case, md, phid, gap=2e-5, approach=0.1):
    eq = rm.sliding_equilibrium(case, md)
    rng = np.random.default_rng(3)
    q0 = eq["q"] + 0.2 * np.max(np.abs(eq["q"])) * rng.standard_normal(md.n)
    g, _ = _kin(md, eq["phi"])
    z0 = g @ q0 + gap
    return np.concatenate([q0, np.zeros(md.n), [eq["phi"], phid, z0, -approach]])


@pytest.mark.parametrize("phid", [0.0, 20.0])
def test_recontact_with_impact(table1_modes, phid):
    """Start separated (slider 20 um above the disc, falling): at re-contact the slider and
    the disc move together and the kinetic energy (T2) does not increase."""
    md = table1_modes
    case = Case(speed={"profile": "constant", "value": 20.0})
    y0 = _separated_start(case, md, phid)
    res = rm.reference_simulate(case, 2e-4, y0=y0, phase0=rm.SEPARATION, mode_data=md)
    assert res.events and res.events[0][3] == "recontact"
    imp = res.impacts[0]
    t_r = imp["t"]
    assert res.events[0][0] == t_r
    qm, qdm, phim, phidm, em, _ = _split(md, imp["y_minus"])
    qp, qdp, phip, phidp, _, _ = _split(md, imp["y_plus"])
    # the gap closed (located by the event to ~1e-15 s; 1e-15 m against um gaps)
    assert abs(em) <= 1e-15
    # positions and phidot are not changed by the impact
    np.testing.assert_array_equal(qm, qp)
    assert (phim, phidm) == (phip, phidp)
    g, gp = _kin(md, phip)
    disc_v = g @ qdp + phidp * (gp @ qp)
    # equal normal velocities after the impact (round-off of ~0.1 m/s velocities)
    assert imp["zdot_plus"] == pytest.approx(disc_v, abs=1e-14)
    assert imp["zdot_minus"] < g @ qdm + phidm * (gp @ qm)  # it was an approach
    # the later segment at t_r is in contact and reports the same normal velocity
    out = res.evaluate([t_r])
    assert out["phase"][0, 0] in rm.CONTACT_PHASES
    assert out["z_dot"][0, 0] == pytest.approx(imp["zdot_plus"], abs=1e-14)
    assert out["normal_force"][0, 0] >= 0.0
    # T2 does not increase (here b = phidot g'.q is small against the approach velocity)
    t2 = [
        0.5 * np.sum(md.M * qd**2) + 0.5 * case.slider.mass * zd**2
        for qd, zd in ((qdm, imp["zdot_minus"]), (qdp, imp["zdot_plus"]))
    ]
    assert t2[1] < t2[0]
    # and the evaluated output agrees with it on both sides of the switch (1e-12 relative:
    # dense output of the two segments at the same instant)
    before = res.evaluate([t_r * (1 - 1e-15)])
    assert rm.kinetic_energy_t2(case, before, md)[0] == pytest.approx(
        t2[0] + 0.5 * case.slider.mass * case.slider.track_radius**2 * phidm**2, rel=1e-9
    )


def test_recontact_without_impact(table1_modes):
    """impact = False: the disc's velocities are kept at re-contact (paper's Fig. 28 option)."""
    md = table1_modes
    case = Case(speed={"profile": "constant", "value": 20.0}, simulation={"impact": False})
    y0 = _separated_start(case, md, 0.0)
    res = rm.reference_simulate(case, 2e-4, y0=y0, phase0=rm.SEPARATION, mode_data=md)
    assert res.events[0][3] == "recontact"
    imp = res.impacts[0]
    np.testing.assert_array_equal(imp["y_minus"][md.n : 2 * md.n], imp["y_plus"][md.n : 2 * md.n])


# --------------------------------------------------------------------------- speed profiles
def test_speed_profiles_and_breakpoints():
    """Piecewise-linear speed profiles; kinks are integration breakpoints (segment ends)."""
    dec = Case(speed={"profile": "decelerating", "initial": 10.0, "duration": 0.004}).speed
    om, od = rm.speed_at(dec, [0.0, 0.002, 0.004, 0.005])
    np.testing.assert_allclose(om, [10.0, 5.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(od, [-2500.0, -2500.0, 0.0, 0.0])
    tab = Case(speed={"profile": "table", "times": [0.0, 1.0, 2.0], "values": [1.0, 3.0, 2.0]})
    om, od = rm.speed_at(tab.speed, [0.5, 1.0, 1.5, 3.0])
    np.testing.assert_allclose(om, [2.0, 3.0, 2.5, 2.0])
    np.testing.assert_allclose(od, [2.0, -1.0, -1.0, 0.0])

    case = Case(
        speed={"profile": "decelerating", "initial": 10.0, "duration": 0.004},
        friction={"decay": 0.0},
    )
    res = rm.reference_simulate(case, 0.006, mode_data=RIGID)
    assert any(seg.t1 == 0.004 for seg in res.segments)  # stopped at t_max
    out = res.evaluate([0.003, 0.0055])
    np.testing.assert_allclose(out["Omega"], [2.5, 0.0], atol=1e-14)


def test_printed_gyroscopic_sign_option(table1_modes):
    """printed_gyroscopic_sign: the D equations carry +2 l M Omega Cdot on the left.

    That form is not skew, so without friction and damping the Jacobi integral changes at
    the rate -4 l M Omega Cdot Ddot per doublet (and is conserved with the right sign)."""
    md = table1_modes
    kw = {
        "friction": {"static": 0.0, "kinetic_max": 0.0, "kinetic_min": 0.0},
        "slider": {"normal_damping": 0.0, "rotational_damping": 0.0},
        "speed": {"profile": "constant", "value": 50.0},
    }
    rng = np.random.default_rng(5)
    y0 = {
        "q": 1e-6 * rng.standard_normal(md.n),
        "q_dot": 1e-3 * rng.standard_normal(md.n),
        "phi": 0.0,
        "phi_dot": 0.0,
    }
    x, wts = np.polynomial.legendre.leggauss(40)
    for printed in (False, True):
        case = Case(**kw, simulation={"printed_gyroscopic_sign": printed})
        res = rm.reference_simulate(case, 0.01, y0=y0, mode_data=md)
        assert res.events == []
        cos_idx = np.flatnonzero((md.l >= 1) & ~md.is_sine)
        work = 0.0
        for seg in res.segments:
            # the only segment boundaries are the run's ends; split into 50 panels
            edges = np.linspace(seg.t0, seg.t1, 51)
            for a, b in itertools.pairwise(edges):
                out = res.evaluate(0.5 * (a + b) + 0.5 * (b - a) * x)
                qd = out["q_dot"]
                rate = (
                    -4.0
                    * 50.0
                    * np.sum(
                        md.l[cos_idx] * md.M[cos_idx] * qd[:, cos_idx] * qd[:, cos_idx + 1], axis=1
                    )
                )
                work += 0.5 * (b - a) * np.sum(wts * rate)
        h = rm.jacobi_integral(case, res.evaluate([0.0, 0.01]), mode_data=md)
        t2 = rm.kinetic_energy_t2(case, res.evaluate(np.linspace(0.0, 0.01, 101)), md)
        expected = work if printed else 0.0
        # 1e-8 of the kinetic-energy scale, as in the other energy checks
        assert abs((h[1] - h[0]) - expected) <= 1e-8 * np.max(t2)
        if printed:
            assert abs(work) > 1e-4 * np.max(t2)  # the check is not vacuous


# =========================================================================== model family
# --------------------------------------------------------------------------- pre-family numbers
# The single-slider reference before the model family (this file's module at commit 2122f1f),
# run on Case() (rest, 0.02 s) and on Case() with q_dot[0] = 20 (0.004 s, max_step 1e-5).
PRE_FAMILY_STICK_SLIP = [
    (0.0006168905266214459, "stick"),
    (0.0037168408284286186, "slip"),
    (0.006523448776816456, "stick"),
    (0.010126149664363818, "slip"),
    (0.012836870204179479, "stick"),
    (0.015448625242522442, "slip"),
    (0.018191445106266295, "stick"),
]
PRE_FAMILY_Q_AT_0_0123 = [
    -0.0005542092442380504,
    -0.0009952614661184287,
    -3.65712011449214e-05,
    -0.0009902003248617433,
    -5.734788003254479e-05,
    -0.00023503690649274737,
    4.900828401042875e-07,
]
PRE_FAMILY_KICK = [(0.00020184172920351348, "separation"), (0.0038818863993674174, "recontact")]
PRE_FAMILY_KICK_IMPACT = (-14.948589479513426, -4.737864391126883)  # zdot before, after
PRE_FAMILY_KICK_Q_AT_0_0031 = [
    -0.013311044141741979,
    8.60192986260776e-05,
    1.2206128753825334e-06,
    4.916508646320544e-05,
    1.3925599609132995e-06,
    -4.029828665399646e-05,
    -1.7131880167071507e-06,
]


def test_single_slider_reproduces_pre_family_reference(table1_modes):
    """S = 1, top face, undamped disc, exponential law: the extended reference gives the
    numbers of the pre-family reference, both from a Case (``case.slider``) and from a
    family case (``case.sliders = [slider]``, angle 0, top).

    The equations are the same; what differs is round-off (an (n+3) instead of an (n+2)
    dense system) and, inside steps that cross v = 0, the friction law's smooth
    continuation below u = 0 instead of mu(|u|).  Measured: event times within 7e-15 s,
    q within 2e-14 of its peak; the tolerances (1e-12 s, 1e-9) leave orders of margin."""
    md = table1_modes
    res = rm.reference_simulate(Case(), 0.02, mode_data=md)
    fam = rm.reference_simulate(family_case(), 0.02, mode_data=md)
    assert fam.events == res.events  # the two case forms run the same computation
    assert [e[3] for e in res.events] == [k for _, k in PRE_FAMILY_STICK_SLIP]
    assert all(e[4] == 0 for e in res.events)
    np.testing.assert_allclose(
        [e[0] for e in res.events], [t for t, _ in PRE_FAMILY_STICK_SLIP], rtol=0, atol=1e-12
    )
    q = res.evaluate([0.0123])["q"][0]
    np.testing.assert_allclose(q, PRE_FAMILY_Q_AT_0_0123, rtol=0, atol=1e-9 * np.abs(q).max())

    q_dot = np.zeros(md.n)
    q_dot[0] = 20.0
    kick = rm.reference_simulate(Case(), 0.004, y0={"q_dot": q_dot}, mode_data=md, max_step=1e-5)
    assert [e[3] for e in kick.events[:2]] == [k for _, k in PRE_FAMILY_KICK]
    np.testing.assert_allclose(
        [e[0] for e in kick.events[:2]], [t for t, _ in PRE_FAMILY_KICK], rtol=0, atol=1e-12
    )
    imp = kick.impacts[0]
    np.testing.assert_allclose(
        (imp["zdot_minus"], imp["zdot_plus"]), PRE_FAMILY_KICK_IMPACT, rtol=1e-9
    )
    q = kick.evaluate([0.0031])["q"][0]
    np.testing.assert_allclose(q, PRE_FAMILY_KICK_Q_AT_0_0031, rtol=0, atol=1e-9 * np.abs(q).max())


# --------------------------------------------------------------------------- symmetries
def _kick(md, scale=1.0):
    q_dot = np.zeros(md.n)
    q_dot[[0, 1, 3, 6]] = np.array([12.0, 8.0, -6.0, 3.0]) * scale
    return q_dot


def _rotate(md, x, angle):
    """Modal coordinates of the disc pattern rotated by ``angle``: w'(theta) = w(theta - angle)."""
    x = np.array(x, float)
    out = x.copy()
    for i in np.flatnonzero((md.l >= 1) & ~md.is_sine):
        c, s = math.cos(md.l[i] * angle), math.sin(md.l[i] * angle)
        out[..., i] = c * x[..., i] - s * x[..., i + 1]
        out[..., i + 1] = s * x[..., i] + c * x[..., i + 1]
    return out


def _away_from(times, jumps, gap=1e-6):
    """Times more than ``gap`` from every switch (a switch is a jump of N, f or velocities)."""
    if len(jumps) == 0:
        return times
    keep = np.all(np.abs(times[:, None] - np.asarray(jumps)[None, :]) > gap, axis=1)
    return times[keep]


def test_base_angle_rotates_the_disc_pattern(table1_modes):
    """The disc is axisymmetric: a slider with base angle theta and the disc state rotated
    by theta is the angle-0 motion rotated (phi, z, N, f equal; (C, D) rotated by l theta),
    here through separation and re-contact.  Both runs take the same steps; only round-off
    of the trigonometric terms differs (measured 1e-14), so 1e-10 of each peak."""
    md, theta = table1_modes, 0.7
    runs = {}
    for angle in (0.0, theta):
        case = family_case(sliders=[{"angle": angle}], speed={"value": 10.0})
        y0 = {"q_dot": _rotate(md, _kick(md), angle)}
        runs[angle] = rm.reference_simulate(case, 0.004, y0=y0, mode_data=md, max_step=1e-5)
    a, b = runs[0.0], runs[theta]
    assert [e[1:] for e in a.events] == [e[1:] for e in b.events]
    assert {"separation", "recontact"} <= {e[3] for e in a.events}
    np.testing.assert_allclose([e[0] for e in a.events], [e[0] for e in b.events], atol=1e-12)
    t = _away_from(np.linspace(0.0, 0.004, 801), [e[0] for e in a.events])
    oa, ob = a.evaluate(t), b.evaluate(t)
    for var in ("phi", "phi_dot", "z", "z_dot", "gap", "normal_force", "friction_force"):
        assert np.max(np.abs(oa[var] - ob[var])) <= 1e-10 * np.max(np.abs(oa[var])), var
    for var in ("q", "q_dot"):
        diff = _rotate(md, oa[var], theta) - ob[var]
        assert np.max(np.abs(diff)) <= 1e-10 * np.max(np.abs(oa[var])), var


def _belt_period(slider, friction, omega):
    """Stick-slip period of the 1-DOF oscillator on a belt (N = N0, alpha = 0, no damping):
    stick over 2A at phidot = Omega, then a free slip half-swing (see the rigid-disc test)."""
    inertia = slider.mass * slider.track_radius**2
    w = math.sqrt(slider.rotational_stiffness / inertia)
    amp = (
        slider.track_radius
        * (friction.static - friction.kinetic_max)
        * slider.preload
        / slider.rotational_stiffness
    )
    return 2.0 * amp / omega + (math.pi + 2.0 * math.atan(omega / (w * amp))) / w


def test_opposite_faces_same_angle_keep_the_disc_flat(table1_modes):
    """Two identical sliders at the same angle on opposite faces: their normal forces and
    friction moments cancel on the disc (sigma_j N_j g and sigma_j h/(2r) f_j g' with
    sigma = +1, -1), so a disc starting flat stays flat (q = 0 up to round-off, against a
    single slider's ~1e-3) and both sliders move alike.  With q = 0 each slider is the
    belt oscillator (N = N0): its stick-slip period is the closed form (as in the
    rigid-disc test, 1e-8).  Simultaneous switches are logged in slider order."""
    md = table1_modes
    omega = 10.0
    friction = {"decay": 0.0}
    slider = {"angle": 0.4, "rotational_damping": 0.0}
    pair = family_case(
        sliders=[{**slider, "face": "top"}, {**slider, "face": "bottom"}],
        friction=friction,
        speed={"value": omega},
    )
    period = _belt_period(pair.sliders[0], pair.friction, omega)
    res = rm.reference_simulate(pair, 4.6 * period, mode_data=md)
    single = rm.reference_simulate(
        family_case(sliders=[slider], friction=friction, speed={"value": omega}),
        0.5 * period,
        mode_data=md,
    )
    q_scale = np.max(np.abs(single.evaluate(np.linspace(0, 0.5 * period, 51))["q"]))
    out = res.evaluate(np.linspace(0.0, res.t_end, 1001))
    assert np.max(np.abs(out["q"])) <= 1e-12 * q_scale
    for var in ("phi", "phi_dot", "normal_force", "friction_force"):
        a, b = out[var][:, 0], out[var][:, 1]
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(a)), var
    np.testing.assert_allclose(out["z"][:, 0], -out["z"][:, 1], atol=1e-12 * q_scale)
    np.testing.assert_allclose(out["normal_force"], pair.sliders[0].preload, rtol=1e-12)
    # events in pairs at one instant, slider 0 first
    ev = res.events
    assert len(ev) >= 6 and len(ev) % 2 == 0
    for e0, e1 in zip(ev[0::2], ev[1::2], strict=True):
        assert e0[0] == e1[0] and e0[1:4] == e1[1:4] and (e0[4], e1[4]) == (0, 1)
    sticks = np.array([e[0] for e in ev if e[3] == "stick" and e[4] == 0])
    # from the first stick on the motion is on the limit cycle (see the rigid-disc test)
    assert sticks.size >= 4
    np.testing.assert_allclose(np.diff(sticks[1:]), period, rtol=1e-8)


def test_bottom_face_mirrors_top_face(table1_modes):
    """A slider on the bottom face is the mirror image of one on the top face: with the
    disc's initial velocities negated, q -> -q, z -> -z and phi, N, f, the gap and every
    switch are the same, through separation and a plastic re-contact.  The two runs are
    the same floating-point operations up to signs (measured: identical), so 1e-12."""
    md = table1_modes
    runs = {}
    for face, sign in (("top", 1.0), ("bottom", -1.0)):
        case = family_case(sliders=[{"face": face, "angle": 0.3}], speed={"value": 10.0})
        y0 = {"q_dot": sign * _kick(md)}
        runs[face] = rm.reference_simulate(case, 0.004, y0=y0, mode_data=md, max_step=1e-5)
    top, bottom = runs["top"], runs["bottom"]
    assert [e[1:] for e in top.events] == [e[1:] for e in bottom.events]
    assert {"separation", "recontact"} <= {e[3] for e in top.events}
    np.testing.assert_allclose(
        [e[0] for e in top.events], [e[0] for e in bottom.events], rtol=0, atol=1e-15
    )
    t = np.linspace(0.0, 0.004, 801)
    a, b = top.evaluate(t), bottom.evaluate(t)
    for var, sign in (
        ("q", -1),
        ("q_dot", -1),
        ("z", -1),
        ("z_dot", -1),
        ("phi", 1),
        ("phi_dot", 1),
        ("gap", 1),
        ("normal_force", 1),
        ("friction_force", 1),
    ):
        assert np.max(np.abs(a[var] - sign * b[var])) <= 1e-12 * np.max(np.abs(a[var])), var


# --------------------------------------------------------------------------- disc damping
@pytest.mark.parametrize(
    ("frame", "omega"),
    [("material", 50.0), ("space", 50.0), ("material", 2000.0), ("space", 2000.0)],
)
def test_damped_free_disc_matches_closed_form(frame, omega):
    """A free damped disc (the slider is held 10 mm away by a negative preload and never
    touches) at constant speed: every doublet X = C + i D is a sum of the two closed-form
    exponentials of :func:`reference_model.free_doublet_eigenvalues` (module docstring:
    lambda = i l Omega - zeta omega +/- i omega sqrt(1 - zeta^2) for material damping,
    i l Omega - zeta omega +/- i sqrt(omega^2 (1 - zeta^2) + 2 i zeta omega l Omega) for
    space-fixed damping).  At 2000 rad/s the space-fixed l = 1 backward wave is beyond
    its critical speed and grows.  Over 0.02 s (up to ~9 periods) DOP853 at rtol 1e-12
    is good to ~3e-10 of each coordinate's peak (measured); 1e-8."""
    zetas = [0.05, 0.02, 0.03, 0.01]
    case = family_case(
        sliders=[{"preload": -300.0}],
        disc={"damping_ratio": zetas, "damping_frame": frame},
        speed={"value": omega},
    )
    md = rm.mode_data_from_case(case)
    rng = np.random.default_rng(2)
    q0, qd0 = 1e-6 * rng.standard_normal(md.n), 1e-3 * rng.standard_normal(md.n)
    y0 = {"q": q0, "q_dot": qd0, "phi": 0.0, "phi_dot": omega, "z": 0.01, "z_dot": 0.0}
    t_end = 0.02
    res = rm.reference_simulate(case, t_end, y0=y0, phase0=rm.SEPARATION, mode_data=md)
    assert res.events == []
    t = np.linspace(0.0, t_end, 1001)
    out = res.evaluate(t)
    assert out["gap"].min() > 0.009
    expected = np.empty_like(out["q"])
    other = np.empty_like(out["q"])  # the other frame's closed form, to show it differs
    i = 0
    for (_, l), zeta in zip(case.disc.modes, zetas, strict=True):
        x0 = q0[i] + (1j * q0[i + 1] if l else 0.0)
        x1 = qd0[i] + (1j * qd0[i + 1] if l else 0.0)
        other_frame = "space" if frame == "material" else "material"
        for target, fr in ((expected, frame), (other, other_frame)):
            lam = rm.free_doublet_eigenvalues(md.omega[i], l, omega, zeta, fr)
            a = (x1 - lam[1] * x0) / (lam[0] - lam[1])
            x = a * np.exp(lam[0] * t) + (x0 - a) * np.exp(lam[1] * t)
            target[:, i] = x.real
            if l:
                target[:, i + 1] = x.imag
        i += 2 if l else 1
    peak = np.max(np.abs(expected), axis=0)
    assert np.all(np.max(np.abs(out["q"] - expected), axis=0) <= 1e-8 * peak)
    assert np.max(np.abs(other - expected) / peak) > 1e-3  # the frames are told apart
    if frame == "space" and omega == 2000.0:
        assert np.max(np.abs(expected[-100:, 1])) > np.max(np.abs(expected[:100, 1]))


def test_damping_ratio_scalar_equals_list():
    """One damping ratio for all modes equals the same value listed per mode (exactly)."""
    kw = {"sliders": [{"preload": -300.0}], "speed": {"value": 30.0}}
    y0 = {"q_dot": np.linspace(-1e-3, 1e-3, 7), "phi_dot": 30.0, "z": 0.01, "z_dot": 0.0}
    outs = []
    for ratio in (0.02, [0.02] * 4):
        case = family_case(**kw, disc={"damping_ratio": ratio})
        res = rm.reference_simulate(case, 2e-3, y0=y0, phase0=rm.SEPARATION)
        outs.append(res.evaluate(np.linspace(0, 2e-3, 11))["q"])
    np.testing.assert_array_equal(outs[0], outs[1])


# --------------------------------------------------------------------------- energy balance
CASCADE = {  # two sliders, opposite faces, a disc kick: separations and a re-contact cascade
    "sliders": [
        {"face": "top", "angle": 0.0},
        {"face": "bottom", "angle": 1.0, "mass": 0.05, "preload": 300.0},
    ],
    "speed": {"value": 10.0},
}


def _cascade_kick(md):
    q_dot = np.zeros(md.n)
    q_dot[0], q_dot[3] = 8.0, -4.0
    return q_dot


IN_FLIGHT = {  # a stronger kick, slider 1 at 2 rad: slider 0 lands while slider 1 flies
    "sliders": [
        CASCADE["sliders"][0],
        {**CASCADE["sliders"][1], "angle": 2.0},
    ],
    "speed": {"value": 10.0},
}


@pytest.mark.parametrize(
    ("scenario", "frame"), [("cascade", "material"), ("cascade", "space"), ("in_flight", "space")]
)
def test_energy_balance_with_damping_friction_and_impacts(scenario, frame):
    """Along two-slider runs with disc damping, slider dampers, the Stribeck law,
    separations and plastic impacts (two-contact impacts and a cascade cut by the
    min-flight rule; or a landing while the other slider flies), the change of the total
    mechanical energy E equals the work of friction, drive, moving surface, dampers and
    the impacts (module docstring: dE/dt = a.(Q - D) on the material velocity;
    Delta E = -|du|_W^2 / 2 - sum lam sigma v g'.q).  E comes from the states, the powers
    from N, f and the kinematics, the impact terms from the impulses.  Each solver step is
    integrated with 8-point Gauss-Legendre (exact to round-off for the degree-7 dense
    output); measured residual 1e-15 to 4e-13 of E; asked 1e-6."""
    base = CASCADE if scenario == "cascade" else IN_FLIGHT
    case = family_case(
        sliders=[
            {**base["sliders"][0], "normal_damping": 2.0},
            {**base["sliders"][1], "rotational_damping": 0.5},
        ],
        disc={"damping_ratio": [0.002, 0.01, 0.005, 0.02], "damping_frame": frame},
        friction={
            "law": "stribeck",
            "stribeck_velocity": 0.2,
            "stribeck_exponent": 1.5,
            "viscous": 0.02,
        },
        speed=base["speed"],
    )
    md = rm.mode_data_from_case(case)
    kick = _cascade_kick(md) * (1.0 if scenario == "cascade" else 2.5)
    t_end = 0.006 if scenario == "cascade" else 0.004
    res = rm.reference_simulate(case, t_end, y0={"q_dot": kick}, mode_data=md, max_step=1e-5)
    if scenario == "cascade":
        assert any(len(i["contacts"]) == 2 for i in res.impacts)
    else:  # a landing with the other slider in flight: its zdot must not jump
        assert any(len(i["contacts"]) == 1 for i in res.impacts)
    terms = rm.energy_terms(res, np.linspace(t_end / 3, t_end, 3))
    assert np.all(terms["impact_loss"][-1:] < 0.0) and terms["impact_surface"][-1] != 0.0
    assert terms["friction"][-1] < 0.0 and terms["disc_damping"][-1] != 0.0
    scale = np.max(np.abs(terms["energy"]))
    assert np.max(np.abs(terms["residual"])) <= 1e-6 * scale
    # the balance is not trivially met: each booked term is >= 10x the tolerance
    for name in (
        "friction",
        "drive",
        "surface",
        "slider_damping",
        "disc_damping",
        "impact_loss",
        "impact_surface",
    ):
        assert abs(terms[name][-1]) > 1e-5 * scale, name


@pytest.mark.parametrize(
    ("omega_dot_terms", "printed"), [(True, False), (False, False), (True, True)]
)
def test_energy_balance_on_an_accelerating_disc_with_model_options(omega_dot_terms, printed):
    """An accelerating disc (Omegadot = 3000 rad/s^2) with material damping, one slider at
    an angle: the stated model balances without an "options" term (the Omegadot and
    gyroscopic terms do no work on the material velocity); dropping the Omegadot terms or
    taking the printed gyroscopic sign adds exactly the work of the generalised forces
    written out from those flags.  Measured residual 3e-13 of E; asked 1e-6."""
    case = family_case(
        sliders=[{"angle": 0.5}],
        disc={"damping_ratio": 0.01},
        speed={"profile": "accelerating", "initial": 5.0, "rate": 3000.0},
        simulation={"omega_dot_terms": omega_dot_terms, "printed_gyroscopic_sign": printed},
    )
    res = rm.reference_simulate(case, 0.01)
    assert {"stick", "slip"} <= {e[3] for e in res.events}
    terms = rm.energy_terms(res)
    energy = abs(terms["energy"][0])
    assert abs(terms["residual"][0]) <= 1e-6 * energy
    if omega_dot_terms and not printed:
        assert terms["options"][0] == 0.0
    else:
        assert abs(terms["options"][0]) > 1e-3 * energy  # the option's work is booked


# --------------------------------------------------------------------------- friction laws
def _compare_runs(a, b, t_end, rtol):
    assert [e[1:] for e in a.events] == [e[1:] for e in b.events]
    t = _away_from(np.linspace(0.0, t_end, 2001), [e[0] for e in a.events])
    oa, ob = a.evaluate(t), b.evaluate(t)
    for var in ("q", "q_dot", "phi", "phi_dot", "normal_force", "friction_force"):
        assert np.max(np.abs(oa[var] - ob[var])) <= rtol * np.max(np.abs(oa[var])), var
    return max(abs(x[0] - y[0]) for x, y in zip(a.events, b.events, strict=True))


def test_stribeck_with_delta_one_equals_exponential(table1_modes):
    """mu1 + (mu0 - mu1) exp(-(u / v_s)^1) + 0 u is the exponential law with alpha = 1/v_s:
    the runs (stick-slip, 0.02 s) agree to round-off of u / v_s against u / v_s (1e-12)."""
    v_s = 0.3
    exp_run = rm.reference_simulate(
        family_case(friction={"law": "exponential", "decay": 1.0 / v_s}),
        0.02,
        mode_data=table1_modes,
    )
    str_run = rm.reference_simulate(
        family_case(
            friction={
                "law": "stribeck",
                "stribeck_velocity": v_s,
                "stribeck_exponent": 1.0,
                "viscous": 0.0,
            }
        ),
        0.02,
        mode_data=table1_modes,
    )
    assert {"stick", "slip"} <= {e[3] for e in exp_run.events}
    assert _compare_runs(exp_run, str_run, 0.02, 1e-12) <= 1e-14


def test_table_law_reproduces_exponential(table1_modes):
    """A table sampled from the exponential law every 2.5 mm/s up to 4 m/s (the run slides
    at up to ~2.9 m/s) reproduces the exponential run within the interpolation error:
    PCHIP is off by at most 6e-9 here (checked below), 2e-8 of mu; the run's relative
    differences are of that order (measured 1e-8 on f, 2e-9 on phi, event times 4e-12 s).
    Asked: 10x the relative interpolation error, event times 1e-9 s."""
    from scipy.interpolate import PchipInterpolator

    fr, v_s = Case().friction, 0.3
    speeds = np.linspace(0.0, 4.0, 1601)

    def law(u):
        return fr.kinetic_min + (fr.kinetic_max - fr.kinetic_min) * np.exp(-u / v_s)

    fine = np.linspace(0.0, 4.0, 400001)
    err = np.max(np.abs(PchipInterpolator(speeds, law(speeds))(fine) - law(fine)))
    assert err < 1e-8
    exp_run = rm.reference_simulate(
        family_case(friction={"law": "exponential", "decay": 1.0 / v_s}),
        0.02,
        mode_data=table1_modes,
    )
    tab_run = rm.reference_simulate(
        family_case(friction={"law": "table", "speeds": speeds, "values": law(speeds)}),
        0.02,
        mode_data=table1_modes,
    )
    phi_dot = exp_run.evaluate(np.linspace(0, 0.02, 4001))["phi_dot"]
    u_max = np.max(0.1 * np.abs(phi_dot - 2 * np.pi))
    assert u_max < 4.0  # inside the table
    assert _compare_runs(exp_run, tab_run, 0.02, 10.0 * err / fr.kinetic_min) <= 1e-9


def test_friction_law_values():
    """Each law at a few speeds, and its continuation below u = 0 (module docstring)."""
    ex = rm.FrictionLaw(SimpleNamespace(static=0.8, kinetic_max=0.6, kinetic_min=0.35, decay=2.0))
    assert ex(0.5) == pytest.approx(0.35 + 0.25 * math.exp(-1.0), rel=1e-15)
    assert ex(-1e-3) == pytest.approx(0.35 + 0.25 * math.exp(2e-3), rel=1e-15)
    law = "law"
    st = rm.FrictionLaw(
        SimpleNamespace(
            **{law: "stribeck"},
            static=0.8,
            kinetic_max=0.6,
            kinetic_min=0.35,
            stribeck_velocity=0.1,
            stribeck_exponent=2.0,
            viscous=0.05,
        )
    )
    assert st(0.2) == pytest.approx(0.35 + 0.25 * math.exp(-4.0) + 0.01, rel=1e-15)
    assert st(-1e-3) == pytest.approx(0.6 - 0.05e-3, rel=1e-15)  # slope mu_v at 0 (delta > 1)
    tab = rm.FrictionLaw(
        SimpleNamespace(
            **{law: "table"}, static=0.8, speeds=[0.0, 0.5, 1.0], values=[0.6, 0.45, 0.4]
        )
    )
    assert tab(0.5) == 0.45 and tab(3.0) == 0.4 and tab(1.0) == 0.4
    assert 0.4 < tab(0.75) < 0.45  # monotone interpolation between monotone data
    slope = (tab(1e-7) - tab(0.0)) / 1e-7
    assert tab(-1e-3) == pytest.approx(0.6 - slope * 1e-3, rel=1e-9)  # linear below 0


# --------------------------------------------------------------------------- impact LCP
def _lcp_by_nnls(G, gm):
    """The LCP as the QP min 1/2 lam.G lam + lam.gm, lam >= 0 (G symmetric positive
    definite), i.e. with G = L L^T the non-negative least-squares problem
    min |L^T lam + L^-1 gm|: solved by Lawson-Hanson (scipy.optimize.nnls), an algorithm
    independent of the reference's enumeration of active sets."""
    from scipy.optimize import nnls

    L = np.linalg.cholesky(G)
    return nnls(L.T, -np.linalg.solve(L, gm))[0]


def test_impact_lcp_complementarity_and_uniqueness(table1_modes):
    """Random multi-contact impacts (S = 2..6 sliders, random faces, angles, velocities):
    lam >= 0, gammadot+ >= 0, lam gammadot+ = 0 (to round-off of the velocity scale), the
    velocities obey u+ = u- + W^-1 A^T lam, and lam equals the solution of the equivalent
    non-negative least-squares problem to 1e-9 of the largest impulse (both are exact
    active-set solutions; the NNLS one carries the conditioning of G, up to ~1e4 here)."""
    md = table1_modes
    rng = np.random.default_rng(11)
    released = 0
    for _ in range(60):
        k = int(rng.integers(2, 7))
        sigma = rng.choice([-1.0, 1.0], k)
        g, gp, _ = rm._shapes(md, np.tile(md.R0, (k, 1)), rng.uniform(0, 2 * np.pi, k))
        q = 1e-5 * rng.standard_normal(md.n)
        qd = 0.05 * rng.standard_normal(md.n)
        phid = rng.uniform(-5.0, 5.0, k)
        m = rng.uniform(0.05, 0.2, k)
        zd = g @ qd + phid * (gp @ q) + sigma * 0.05 * rng.standard_normal(k)
        out = rm.plastic_impact(md.M, m, sigma, g, gp, q, qd, phid, zd)
        lam, gp_plus = out["lam"], out["gap_rate_plus"]
        vscale = np.max(np.abs(out["gap_rate_minus"]))
        assert np.all(lam >= 0.0)
        assert np.all(gp_plus >= -1e-14 * vscale)
        assert np.all(np.abs(lam * gp_plus) <= 1e-14 * vscale * np.max(lam, initial=1e-300))
        # after the impact the gap rates follow from the velocities
        b = sigma * phid * (gp @ q)
        np.testing.assert_allclose(
            sigma * (out["zdot"] - g @ out["qdot"]) - b, gp_plus, atol=1e-13 * vscale
        )
        np.testing.assert_allclose(
            md.M * (out["qdot"] - qd), -(sigma * lam) @ g, atol=1e-14 * np.max(np.abs(md.M * qd))
        )
        G = (sigma[:, None] * sigma) * ((g / md.M) @ g.T) + np.diag(1.0 / m)
        np.testing.assert_allclose(
            lam, _lcp_by_nnls(G, out["gap_rate_minus"]), atol=1e-9 * max(np.max(lam), 1e-300)
        )
        released += int(np.sum((lam == 0.0) & (out["gap_rate_minus"] < 0.0)))
    assert released > 0  # some approaching contacts were released by the others' impulses


def test_impact_lcp_releases_a_contact_that_would_need_tension(table1_modes):
    """Slider 1 rests on the top face; slider 0 lands on the top face at the same point.
    Its impulse pushes the disc down, away from slider 1, whose contact would need a
    tensile impulse to stay closed: it is released (lam = 0, gap opening).  With slider 1
    on the bottom face the same landing presses into it: both contacts take impulses."""
    md = table1_modes
    g, gp, _ = rm._shapes(md, np.tile(md.R0, (2, 1)), np.array([0.3, 0.3]))
    q, qd, phid, m = np.zeros(md.n), np.zeros(md.n), np.zeros(2), np.array([0.1, 0.1])
    for faces, both in (([1.0, 1.0], False), ([1.0, -1.0], True)):
        sigma = np.array(faces)
        zd = np.array([-0.1 * sigma[0], 0.0])  # slider 0 approaches, slider 1 at rest on it
        out = rm.plastic_impact(md.M, m, sigma, g, gp, q, qd, phid, zd)
        assert out["lam"][0] > 0.0 and out["gap_rate_plus"][0] == 0.0
        if both:
            assert out["lam"][1] > 0.0 and out["gap_rate_plus"][1] == 0.0
        else:
            assert out["lam"][1] == 0.0 and out["gap_rate_plus"][1] > 1e-3
            # forcing the contact (the cascade rule's bilateral form) needs tension
            forced = rm.plastic_impact(md.M, m, sigma, g, gp, q, qd, phid, zd, forced=[1])
            assert forced["lam"][1] < 0.0 and forced["gap_rate_plus"][1] == 0.0


def test_single_contact_lcp_is_the_paper_closed_form(table1_modes):
    """S = 1 on the top face: the LCP solution is the paper's Eqs. 54-56 (impact_map), for
    approaching sliders on a moving, sloped disc; the T2 change is lam.b - |du|_W^2 / 2.
    Round-off of ~0.1 m/s velocities: 1e-14 absolute."""
    md = table1_modes
    m = Case().slider.mass
    rng = np.random.default_rng(5)
    for _ in range(100):
        q, qd = 1e-5 * rng.standard_normal(md.n), 1e-2 * rng.standard_normal(md.n)
        phi, phid = rng.uniform(-np.pi, np.pi), rng.uniform(-20.0, 20.0)
        g, gp, _ = rm._shapes(md, md.R0[None, :], np.array([phi]))
        zd = g[0] @ qd + phid * (gp[0] @ q) - 0.1 * abs(rng.standard_normal())
        qd_paper, zd_paper = rm.impact_map(md, m, q, qd, phi, phid, zd)
        out = rm.plastic_impact(md.M, [m], [1.0], g, gp, q, qd, [phid], [zd])
        np.testing.assert_allclose(out["qdot"], qd_paper, rtol=0, atol=1e-14)
        assert out["zdot"][0] == pytest.approx(zd_paper, abs=1e-14)
        t2 = [
            0.5 * np.sum(md.M * v**2) + 0.5 * m * z**2 for v, z in ((qd, zd), (qd_paper, zd_paper))
        ]
        assert t2[1] - t2[0] == pytest.approx(out["dT2"], rel=1e-9, abs=1e-18)


# --------------------------------------------------------------------------- event tables
def _check_event_table(res, case):
    """Consistency of the event table with itself and with the trajectory."""
    S = len(case.sliders)
    start = res.evaluate([0.0])["phase"][0]
    current = {j: None for j in range(S)}
    for j in range(S):  # initial phase, before any t = 0 event
        first = next((e for e in res.events if e[4] == j), None)
        current[j] = first[1] if first is not None and first[0] == 0.0 else start[j]
    times = [e[0] for e in res.events]
    assert times == sorted(times)
    transitions = {
        "stick": {(rm.SLIP, rm.STICK)},
        "slip": {(rm.STICK, rm.SLIP)},
        "reversal": {(rm.SLIP, rm.SLIP)},
        "separation": {(rm.SLIP, rm.SEPARATION), (rm.STICK, rm.SEPARATION)},
        "recontact": {(rm.SEPARATION, p) for p in (rm.SLIP, rm.STICK, rm.SEPARATION)},
    }
    for t, old, new, kind, j in res.events:
        assert 0 <= j < S
        assert old == current[j], (t, kind, j)  # each slider's events chain
        assert (old, new) in transitions[kind], (t, kind)
        current[j] = new
    # after the last event of each slider at each instant, the trajectory is in that phase
    last = {}
    for t, _, new, _, j in res.events:
        last[(t, j)] = new
    for (t, j), new in last.items():
        if t < res.t_end:
            assert res.evaluate([t])["phase"][0, j] == new
    # inside the segments: contact needs N >= 0, stick |f| <= mu_s N, slip s v >= 0, and a
    # separated slider's gap >= 0 (round-off of the located switches: 1e-9 relative)
    mu_s = case.friction.static
    for k, seg in enumerate(res.segments):
        out = res.evaluate_segment(k, np.linspace(seg.t0, seg.t1, 12)[1:-1])
        for j in range(S):
            n0 = case.sliders[j].preload
            if seg.phases[j] == rm.SEPARATION:
                assert np.all(out["gap"][:, j] >= -1e-12)
            else:
                assert np.all(out["normal_force"][:, j] >= -1e-9 * n0)
            if seg.phases[j] == rm.STICK:
                f, nf = np.abs(out["friction_force"][:, j]), out["normal_force"][:, j]
                assert np.all(f <= mu_s * nf + 1e-9 * n0)
            if seg.phases[j] == rm.SLIP:
                v = out["disc_speed"] - out["phi_dot"][:, j]
                assert np.all(seg.signs[j] * v >= -1e-9)


@pytest.mark.parametrize("impact", [True, False])
def test_two_sliders_separation_and_recontact(impact):
    """Two different sliders at different angles on opposite faces, a disc kick: both
    separate and land again.  The run completes, the event table is consistent (each
    slider's events chain, kinds match their phases, the trajectory is in the phase the
    table says, phase conditions hold inside the segments).  With the impact, some
    landings strike the other slider's contact (two-contact LCPs) and one cascade is cut
    by the min-flight rule (a kept, forced contact; Zeno flights shrinking); without it
    the disc's velocities pass a re-contact unchanged and the slider takes the disc's."""
    case = family_case(**CASCADE, simulation={"impact": impact})
    md = rm.mode_data_from_case(case)
    res = rm.reference_simulate(
        case, 0.006, y0={"q_dot": _cascade_kick(md)}, mode_data=md, max_step=1e-5
    )
    kinds = [e[3] for e in res.events]
    assert {"separation", "recontact", "stick", "slip"} <= set(kinds)
    assert {e[4] for e in res.events if e[3] == "recontact"} == {0, 1} or not impact
    _check_event_table(res, case)
    assert len(res.impacts) == kinds.count("recontact")
    n = md.n
    ends = np.array([seg.t1 for seg in res.segments])
    for imp in res.impacts:
        # a slider in flight is not struck: its zdot is continuous through the impact
        k = int(np.flatnonzero(ends == imp["t"])[-1]) if np.any(ends == imp["t"]) else None
        if k is not None:
            before, after = res.evaluate_segment(k, [imp["t"]]), res.evaluate([imp["t"]])
            for j in set(range(2)) - set(imp["contacts"]):
                assert after["z_dot"][0, j] == pytest.approx(before["z_dot"][0, j], rel=1e-12)
        assert np.all(imp["gap_rate_minus"][imp["contacts"].index(imp["slider"])] < 0.0)
        if not impact:
            np.testing.assert_array_equal(imp["y_minus"][n : 2 * n], imp["y_plus"][n : 2 * n])
            assert imp["contacts"] == [imp["slider"]]
    if impact:
        assert any(len(i["contacts"]) == 2 for i in res.impacts)
        cascade = [i for i in res.impacts if i["forced"]]
        assert cascade, "a cascade cut by min_flight_time"
        times = np.array([i["t"] for i in res.impacts if i["t"] <= cascade[0]["t"]])
        flights = np.diff(times[-4:])
        assert np.all(flights[1:] < flights[:-1])  # ever shorter flights
        for imp in res.impacts:  # complementarity on the free contacts
            free = [k for k, i in enumerate(imp["contacts"]) if i not in imp["forced"]]
            assert np.all(imp["lam"][free] >= 0.0) and np.all(imp["gap_rate_plus"] >= 0.0)
        # energy: the balance holds through impacts and cut cascade
        terms = rm.energy_terms(res)
        assert abs(terms["residual"][0]) <= 1e-6 * abs(terms["energy"][0])
    else:
        terms = rm.energy_terms(res)
        assert abs(terms["residual"][0]) <= 1e-6 * abs(terms["energy"][0])


def test_sliders_on_a_rigid_disc_are_independent_belt_oscillators():
    """Rigid disc (no modes): N_j = N0_j and the sliders do not interact; each has the
    belt oscillator's stick-slip period with its own parameters (1e-8, as for S = 1)."""
    omega = 2.0 * np.pi
    sliders = [
        {"rotational_damping": 0.0},
        {
            "rotational_damping": 0.0,
            "mass": 0.05,
            "rotational_stiffness": 3e3,
            "preload": 300.0,
            "track_radius": 0.08,
            "angle": 2.0,
            "face": "bottom",
        },
    ]
    case = family_case(sliders=sliders, friction={"decay": 0.0}, speed={"value": omega})
    periods = [_belt_period(s, case.friction, omega) for s in case.sliders]
    res = rm.reference_simulate(case, 6.5 * max(periods), mode_data=RIGID)
    for j, period in enumerate(periods):
        sticks = np.array([e[0] for e in res.events if e[3] == "stick" and e[4] == j])
        assert sticks.size >= 5
        np.testing.assert_allclose(np.diff(sticks[1:]), period, rtol=1e-8)
    assert abs(periods[0] - periods[1]) > 1e-3 * periods[0]


def test_sliding_equilibrium_of_several_sliders_is_a_rest_point():
    """Three sliders (different radii, angles, faces) on a disc with material damping,
    whose l Omega terms stay at rest: at the computed sliding equilibrium the slip
    right-hand side vanishes (accelerations 1e-9 of their scale omega^2 q)."""
    case = family_case(
        sliders=[
            {"angle": 0.0},
            {"angle": 2.0, "face": "bottom", "track_radius": 0.09},
            {"angle": 4.0, "preload": 200.0},
        ],
        disc={"damping_ratio": 0.02},
        speed={"value": 30.0},
    )
    md = rm.mode_data_from_case(case)
    eq = rm.sliding_equilibrium(case, md)
    model = rm._Model(case, md)
    y = np.concatenate([eq["q"], np.zeros(md.n), eq["phi"], np.zeros(3), np.zeros(6)])
    r = model.solve([rm.SLIP] * 3, [1] * 3, 0.0, y, rm._speed_pieces(case.speed, 1.0)[0])
    scale = np.max(md.omega**2 * np.abs(eq["q"]))
    assert np.max(np.abs(r["qdd"])) <= 1e-9 * scale
    np.testing.assert_allclose(r["N"], eq["N"], rtol=1e-12)
    assert np.max(np.abs(r["phidd"])) <= 1e-9 * np.max(
        case.sliders[0].rotational_stiffness * np.abs(eq["phi"]) / 1e-3
    )
    assert np.all(eq["N"] > 0.0) and np.ptp(eq["N"]) > 1.0  # the sliders load each other


def test_a_slider_that_cannot_press_starts_separated():
    """At t = 0 a slider whose contact would need N < 0 (here a pulling preload) starts
    separated, logged as a separation at t = 0; the other slider stays in contact."""
    case = family_case(sliders=[{}, {"preload": -50.0, "angle": 1.0}])
    res = rm.reference_simulate(case, 1e-3)
    assert res.events[0] == (0.0, rm.SLIP, rm.SEPARATION, "separation", 1)
    assert all(e[4] == 0 for e in res.events[1:])
    out = res.evaluate([0.0, 5e-4])
    assert list(out["phase"][:, 1]) == [rm.SEPARATION] * 2
    assert out["gap"][1, 1] > 0.0 and out["phase"][0, 0] in rm.CONTACT_PHASES
