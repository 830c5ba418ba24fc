"""The first Lyapunov coefficient l1 of Hopf points, against what does not use its code:
Guckenheimer and Holmes' planar formula, the closed form of the rigid-disc Stribeck
oscillator derived by hand below, and the periodic orbits that the continuation finds at
the packaged cases' Hopf points and at the three-pad case of issue 36.

The rigid-disc oscillator. One slider on a disc whose modes do not move it (none, or only
(0, 0) modes, whose l = 0 gives g' = 0: they neither tilt the surface under the slider
nor feel its friction moment, and their own motion is linear and damped, so the centre
manifold has them at rest and N = N_eq there) is

    I phi'' + C phi' + K phi = r N mu(r (Omega - phi')),    I = m r^2.

With u = phi - phi_eq and mu expanded about u* = r Omega in the slip-speed change,
mu(r (Omega - u')) = mu - r mu' u' + r^2 mu'' u'^2 / 2 - r^3 mu''' u'^3 / 6 + ...,

    u'' + a u' + w^2 u = b2 u'^2 + b3 u'^3,
    a = (C + r^2 N mu') / I,  w^2 = K / I,  b2 = r^3 N mu'' / (2 I),  b3 = -r^4 N mu''' / (6 I).

The Hopf point is a = 0. The u'^2 term alone is reversible (t -> -t, u' -> -u') and so
adds nothing to l1, which is linear in the cubic and quadratic in the quadratic
coefficients; averaging the energy E = (u'^2 + w^2 u^2) / 2 over u' = V sin(w t),
dE/dt = -a u'^2 + b2 u'^3 + b3 u'^4 with <u'^4> = 3 V^4 / 8, gives
V' = V (-a / 2 + 3 b3 V^2 / 8): Re c1 = 3 b3 / 8 per (rad/s)^2 of slip-speed amplitude
V, and

    l1 = Re c1 / w = -r^4 N mu''' / (16 I w) = -r^2 N mu''' / (16 m w).

For the Stribeck law mu = mu_1 + dmu exp(-s^delta) + mu_v u, s = u / v_s:

    mu''' = dmu / v_s^3 [-delta^3 s^(3 delta - 3) + 3 delta^2 (delta - 1) s^(2 delta - 3)
                         - delta (delta - 1) (delta - 2) s^(delta - 3)] exp(-s^delta)

(the viscous part is linear and drops out); for the exponential law
mu''' = -alpha^3 dmu exp(-alpha u).
"""

from __future__ import annotations

import numpy as np
import pytest

from fivdisc import Case
from fivdisc.analysis.hopf import hopf_points
from fivdisc.analysis.normalform import lyapunov_coefficient
from fivdisc.case import load_case
from fivdisc.continuation.from_hopf import hopf_cycles
from fivdisc.examples import path
from fivdisc.model.build import build_model

R, MASS, K = 0.1, 0.1, 2000.0
OMEGA = np.sqrt(K / (MASS * R**2))
DMU = 0.6 - 0.35
PADS = "three_pads_issue36.toml"


def _stribeck_third(u: float, vs: float, delta: float) -> float:
    s = u / vs
    d = delta
    poly = (-(d**3) * s ** (3 * d - 3) + 3 * d**2 * (d - 1) * s ** (2 * d - 3)
            - d * (d - 1) * (d - 2) * s ** (d - 3))
    return DMU / vs**3 * poly * np.exp(-(s**d))


def _closed_form(normal_force: float, third: float) -> float:
    return -(R**2) * normal_force * third / (16.0 * MASS * OMEGA)


@pytest.mark.parametrize(("delta", "viscous", "damping"), [
    (2.0, 0.0, 0.2), (1.5, 0.003, 0.1), (1.0, 0.0, 0.5), (3.0, 0.0, 0.3)])
def test_rigid_disc_stribeck_oscillator_closed_form(delta, viscous, damping):
    """Every Hopf point of the rigid-disc Stribeck oscillator in speed (one or two: the
    ends of the window of negative damping), l1 to 1e-8 of the closed form, and the
    error estimate bounds the actual error."""
    vs = 1.0
    case = Case(disc={"modes": []}, slider={"rotational_damping": damping},
                friction={"law": "stribeck", "stribeck_velocity": vs,
                          "stribeck_exponent": delta, "viscous": viscous},
                speed={"value": 1.0})
    found = hopf_points(case, "speed.value", np.linspace(0.05, 40.0, 60))
    assert found
    for hp in found:
        expected = _closed_form(500.0, _stribeck_third(R * hp.value, vs, delta))
        assert hp.l1 == pytest.approx(expected, rel=1e-8)
        assert abs(hp.l1 - expected) <= max(hp.l1_error, 1e-12 * abs(expected))
        assert hp.l1_error < 1e-7 * abs(expected)
    if delta == 2.0:
        # mu''' > 0 at the lower end (s = 0.08), < 0 at the upper (s = 1.76).
        assert [hp.criticality for hp in found] == ["supercritical", "subcritical"]


def test_disc_modes_that_do_not_move_the_slider():
    """(0, 0) modes on a damped disc: N at the equilibrium is less than N0 (the disc
    gives way under the preload), and the closed form holds with it."""
    case = Case(disc={"modes": [[0, 0], [1, 0]], "damping_ratio": 0.01},
                slider={"rotational_damping": 0.2},
                friction={"law": "stribeck", "stribeck_velocity": 1.0,
                          "stribeck_exponent": 2.0}, speed={"value": 1.0})
    found = hopf_points(case, "speed.value", np.linspace(0.2, 30.0, 40))
    assert len(found) == 2
    for hp in found:
        force = float(hp.equilibrium.normal_force[0])
        assert force < 499.0
        expected = _closed_form(force, _stribeck_third(R * hp.value, 1.0, 2.0))
        assert hp.l1 == pytest.approx(expected, rel=1e-8)
        assert hp.mode == "phi"


def test_rigid_disc_exponential_and_table_laws():
    """Exponential law: mu''' = -alpha^3 dmu exp(-alpha u), so l1 > 0 (subcritical) at
    every Hopf point. A table: mu''' is six times the cubic coefficient of the PCHIP
    piece the sliding speed lies on (scipy's interpolant, not fivdisc's)."""
    from scipy.interpolate import PchipInterpolator

    alpha, damping = 1.0, 0.5
    case = Case(disc={"modes": []}, slider={"rotational_damping": damping},
                friction={"decay": alpha}, speed={"value": 1.0})
    (hp,) = hopf_points(case, "speed.value", np.linspace(0.5, 30.0, 25))
    third = -(alpha**3) * DMU * np.exp(-alpha * R * hp.value)
    assert hp.l1 == pytest.approx(_closed_form(500.0, third), rel=1e-9)
    assert hp.criticality == "subcritical"
    speeds, values = [0.0, 0.2, 0.5, 1.0, 2.0], [0.6, 0.55, 0.45, 0.4, 0.38]
    table = Case(disc={"modes": []}, slider={"rotational_damping": 0.2},
                 friction={"law": "table", "static": 0.8, "speeds": speeds,
                           "values": values}, speed={"value": 1.0})
    found = hopf_points(table, "speed.value", np.linspace(0.1, 25.0, 50))
    curve = PchipInterpolator(speeds, values)
    slope = curve.derivative()
    slope.c[-1] += 0.2 / (R**2 * 500.0)
    assert len(found) == len(slope.roots(extrapolate=False)) >= 1
    third = curve.derivative(3)
    for hp in found:
        assert hp.l1 == pytest.approx(_closed_form(500.0, float(third(R * hp.value))),
                                      rel=1e-8)


def test_planar_formula_of_guckenheimer_and_holmes():
    """x' = -w y + f(x, y), y' = w x + g(x, y) with every quadratic and cubic term:
    16 a = f_xxx + f_xyy + g_xxy + g_yyy + (f_xy (f_xx + f_yy) - g_xy (g_xx + g_yy)
    - f_xx g_xx + f_yy g_yy) / w (Guckenheimer and Holmes, eq. 3.4.11), the amplitude
    that of x, and l1 = a / w."""
    rng = np.random.default_rng(3)
    w = 2.5
    # f = sum F[i, j] x^i y^j over 2 <= i + j <= 3, likewise g.
    terms = [(i, j) for i in range(4) for j in range(4) if 2 <= i + j <= 3]
    fc = {t: rng.normal() for t in terms}
    gc = {t: rng.normal() for t in terms}

    def jacobian(v):
        x, y = v
        jac = np.array([[0.0, -w], [w, 0.0]])
        for row, coef in ((0, fc), (1, gc)):
            for (i, j), c in coef.items():
                if i:
                    jac[row, 0] += c * i * x ** (i - 1) * y**j
                if j:
                    jac[row, 1] += c * j * x**i * y ** (j - 1)
        return jac

    def d(coef, i, j):
        from math import factorial

        return coef.get((i, j), 0.0) * factorial(i) * factorial(j)

    a = (d(fc, 3, 0) + d(fc, 1, 2) + d(gc, 2, 1) + d(gc, 0, 3)
         + (d(fc, 1, 1) * (d(fc, 2, 0) + d(fc, 0, 2)) - d(gc, 1, 1) * (d(gc, 2, 0)
            + d(gc, 0, 2)) - d(fc, 2, 0) * d(gc, 2, 0) + d(fc, 0, 2) * d(gc, 0, 2)) / w) / 16
    l1, error, c1 = lyapunov_coefficient(jacobian, np.zeros(2), w, 0, 0.1)
    assert l1 == pytest.approx(a / w, rel=1e-10, abs=1e-12)
    assert c1.real == pytest.approx(a, rel=1e-10, abs=1e-12)
    assert error < 1e-10


def _slip_amplitude(branch, hp) -> float:
    """Half the range of the slip speed of the slider that moves most, on the first
    orbit [rad/s]."""
    model = build_model(hp.case)
    rows = [abs(hp.eigenvector[model.index("phi_dot", j)]) for j in range(model.n_sliders)]
    j = int(np.argmax(rows))
    ds = branch.dataset
    return 0.5 * float(ds["phi_dot_max"].values[0, j] - ds["phi_dot_min"].values[0, j])


@pytest.mark.parametrize(("example", "updates", "values", "which", "rel"), [
    # The slider's own mode on a damped disc: on the stability boundary, subcritical.
    ("damped-disc", {}, (20.0, 30.0), "phi", 5e-4),
    # A measured (table) law: supercritical.
    ("measured-friction", {"speed": {"profile": "constant", "value": 2.0}}, (8.0, 10.0),
     "phi", 5e-4),
    # Disc modes of the paper's second example: C02 supercritical, C03 subcritical.
    ("fig13", {}, (3.0, 4.5), "C02", 1e-2),
    ("fig13", {}, (6.0, 6.6), "C03", 1e-2),
    # Issue 36's three pads: subcritical near 19.573 rad/s.
    (PADS, {}, (19.4, 19.8), "phi", 5e-4),
])
def test_sign_and_size_agree_with_the_continued_orbits(example, updates, values, which,
                                                       rel, pads_case):
    """The continuation's first orbit (at 1 % of the grazing amplitude) lies on the side
    that l1's sign says, and where the normal form puts an orbit of its slip-speed
    amplitude V: p - p_H = -omega l1 V^2 / (d Re lambda / dp), to 5e-4 (the next term is
    O(V) relative; 1e-2 for the disc modes, whose offsets of ~1e-6 rad/s meet the
    shooting tolerance)."""
    case = pads_case if example == PADS else load_case(path(example))
    found = [hp for hp in hopf_points(case.replace(updates), "speed.value",
                                      np.linspace(*values, 5))
             if hp.mode.startswith(which)]
    assert found
    for hp in found:
        branch = hopf_cycles(hp, values[1] if hp.direction < 0 else values[0],
                             max_points=1)
        assert branch.hopf()["criticality"] == hp.criticality
        offset = branch.parameter[0] - hp.value
        assert offset == pytest.approx(hp.orbit_offset * _slip_amplitude(branch, hp) ** 2,
                                       rel=rel)
        assert branch.hopf()["l1"] == hp.l1
        assert "agrees" in str(branch)
    if example == PADS:
        assert found[-1].value == pytest.approx(19.573, abs=1e-3)
        assert found[-1].on_boundary and found[-1].criticality == "subcritical"


@pytest.fixture(scope="module")
def pads_case():
    from pathlib import Path

    return load_case(Path(__file__).parents[1] / "data" / PADS)


def test_printed_and_stored_by_the_command_line(tmp_path):
    """fivdisc stability --x prints l1 with each Hopf point and stores it in the file;
    fivdisc continue --from-hopf keeps it in the branch file and says that the orbits
    agree."""
    import xarray as xr

    from fivdisc.continuation.branch import open_branch

    from support.cli import run_cli

    case = tmp_path / "rigid.toml"
    case.write_text(Case(disc={"modes": []}, slider={"rotational_damping": 0.5},
                         friction={"decay": 1.0}, speed={"value": 1.0}).to_toml())
    out = tmp_path / "branches.nc"
    res = run_cli(["stability", case, "--x", "speed.value=0.5:30:25", "--no-progress",
                   "-o", out])
    assert res.exit_code == 0, res.output
    assert "first Lyapunov coefficient l1 = 0.000221 s^2: subcritical" in res.output
    with xr.open_dataset(out) as ds:
        (l1,) = ds["hopf_l1"].values
        assert l1 == pytest.approx(1.0 * 0.5 / (16 * MASS * OMEGA), rel=1e-8)
        assert ds["hopf_l1_error"].values[0] < 1e-8 * l1
        from cf_xarray.units import units as registry

        assert registry.Unit(ds["hopf_l1"].attrs["units"]) == registry.Unit("s^2")
    branch = tmp_path / "cycles.nc"
    res = run_cli(["continue", case, "--key", "speed.value", "--to", "30", "--from-hopf",
                   "0.5:30:25", "--points", "2", "--no-progress", "-o", branch])
    assert res.exit_code == 0, res.output
    assert "subcritical (first Lyapunov coefficient l1 = 0.000221 s^2, agrees)" in res.output
    assert open_branch(branch).hopf()["l1"] == pytest.approx(l1, rel=1e-12)
