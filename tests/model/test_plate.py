"""Tests of :mod:`fivdisc.model.plate` against results that do not come from its own code.

References used: the numbers printed in the paper (Table 1 and the text after it), Leissa's
handbook table, the boundary conditions and orthogonality relations themselves, an
independent Rayleigh-Ritz solution written here, and scipy's adaptive quadrature.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import sys
import types

import numpy as np
import pytest
from numpy.polynomial import legendre
from scipy import integrate, linalg, optimize

from fivdisc.errors import ModeError
from fivdisc.model.plate import AnnularPlate

from support.cli import run_cli

TABLE1 = {
    "inner_radius": 0.044,
    "outer_radius": 0.12,
    "thickness": 0.002,
    "density": 7200.0,
    "youngs_modulus": 150e9,
    "poisson_ratio": 0.211,
}
A, B, NU = TABLE1["inner_radius"], TABLE1["outer_radius"], TABLE1["poisson_ratio"]
K_MAX, L_MAX = 3, 10


@pytest.fixture(scope="module")
def plate() -> AnnularPlate:
    return AnnularPlate(**TABLE1)


def _mass_factor(l: int) -> float:
    """``modal_mass / int_a^b R^2 r dr``: rho h times int_0^{2 pi} cos^2(l theta) dtheta."""
    return TABLE1["density"] * TABLE1["thickness"] * (2.0 * math.pi if l == 0 else math.pi)


def _gauss(a: float, b: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = legendre.leggauss(n)
    return a + 0.5 * (b - a) * (x + 1.0), 0.5 * (b - a) * w


# --- independent reference: Rayleigh-Ritz ------------------------------------------------------


def _ritz_basis(
    r: np.ndarray, a: float, b: float, n_basis: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """psi_j = u^2 P_j(x), u = (r - a) / (b - a), x = 2u - 1, and its first two r-derivatives.

    The factor u^2 builds in the clamped conditions R(a) = R'(a) = 0; the free conditions at b
    are natural ones of the energy functional, so the basis need not satisfy them.
    """
    h = b - a
    u = ((r - a) / h)[:, None]
    x = 2.0 * u[:, 0] - 1.0
    eye = np.eye(n_basis)
    p = legendre.legvander(x, n_basis - 1)
    dp = np.stack([legendre.legval(x, legendre.legder(eye[j], 1)) for j in range(n_basis)], 1)
    d2p = np.stack([legendre.legval(x, legendre.legder(eye[j], 2)) for j in range(n_basis)], 1)
    # d/dr = (2 / h) d/dx and du/dr = 1 / h.
    dp, d2p = dp * (2.0 / h), d2p * (2.0 / h) ** 2
    psi = u**2 * p
    d1 = 2.0 * u * p / h + u**2 * dp
    d2 = 2.0 * p / h**2 + 4.0 * u * dp / h + u**2 * d2p
    return psi, d1, d2


@functools.lru_cache(maxsize=64)
def _ritz(
    l: int,
    n_basis: int,
    a: float = A,
    b: float = B,
    nu: float = NU,
) -> tuple[np.ndarray, np.ndarray]:
    """Frequency parameters beta [1/m] (ascending) and mass-normalised Ritz vectors.

    Strain energy of the Kirchhoff plate in polar coordinates (Leissa, ch. 1) for one harmonic,
    integrated over theta:
    U ~ int [ (lap R)^2 - 2 (1 - nu) ( R'' (R'/r - l^2 R / r^2) - l^2 (R'/r - R/r^2)^2 ) ] r dr,
    kinetic energy ~ omega^2 rho h int R^2 r dr, so K c = beta^4 M c. The integrands are
    polynomials times powers of 1/r, analytic on [a, b] (the pole r = 0 lies outside); 80 Gauss
    nodes integrate them to round-off for n_basis <= 32 and a / b >= 0.04.
    """
    r, w = _gauss(a, b, 80)
    psi, d1, d2 = _ritz_basis(r, a, b, n_basis)
    rr = r[:, None]
    lap = d2 + d1 / rr - l * l * psi / rr**2
    hoop = d1 / rr - l * l * psi / rr**2
    twist = d1 / rr - psi / rr**2
    wr = (w * r)[:, None]
    stiffness = (
        lap.T @ (wr * lap)
        - (1.0 - nu) * (d2.T @ (wr * hoop) + hoop.T @ (wr * d2))
        + 2.0 * (1.0 - nu) * l * l * twist.T @ (wr * twist)
    )
    mass = psi.T @ (wr * psi)
    # Solve M c = mu K c (mu = beta^-4): the Cholesky factor of the stiffness is far better
    # conditioned than that of the polynomial mass matrix, and the low modes are the largest mu,
    # which eigh gets to full relative accuracy.
    mu, vectors = linalg.eigh(mass, stiffness)
    mu, vectors = mu[::-1], vectors[:, ::-1]
    vectors = vectors / np.sqrt(np.einsum("ij,ik,kj->j", vectors, mass, vectors))
    return mu**-0.25, vectors


# With 32 basis functions the Ritz values for k <= 3, l <= 10 have converged to ~1e-13
# (test_ritz_reference_is_converged), far below every tolerance used against them.
N_RITZ = 32


def test_ritz_reference_is_converged() -> None:
    # The reference is only as good as its convergence: 24 and 32 functions must agree far
    # better than the 1e-9 asked of plate.py below (observed ~1e-13).
    for l in range(L_MAX + 1):
        coarse = _ritz(l, 24)[0][: K_MAX + 1]
        fine = _ritz(l, N_RITZ)[0][: K_MAX + 1]
        np.testing.assert_allclose(coarse, fine, rtol=1e-10)


# --- frequencies -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("k", "l", "omega_paper", "hz_paper"),
    [(0, 0, 1492, 237), (0, 1, 1517, 241), (0, 2, 1824, 290), (0, 3, 2774, 442)],
)
def test_table1_frequencies(plate: AnnularPlate, k: int, l: int, omega_paper, hz_paper) -> None:
    mode = plate.mode(k, l)
    # The paper prints whole rad/s and Hz, so each value is within 0.5 of the exact one; that
    # is tighter than 0.1 % (0.5 / 1492 = 0.034 %).
    assert abs(mode.omega - omega_paper) <= 0.5
    assert abs(mode.frequency_hz - hz_paper) <= 0.5
    assert mode.omega == pytest.approx(omega_paper, rel=1e-3)


def test_seven_lowest_frequencies_with_doublets(plate: AnnularPlate) -> None:
    # The paper's first seven frequencies count each l >= 1 mode twice (cos and sin). Taking
    # the lowest seven of all modes k <= 3, l <= 10 also checks that no lower mode exists.
    omegas = []
    for l in range(L_MAX + 1):
        for k in range(K_MAX + 1):
            omegas += [plate.mode(k, l).omega] * (1 if l == 0 else 2)
    lowest = np.sort(omegas)[:7]
    # Rounded to whole rad/s in the paper: 0.5 is the rounding error.
    np.testing.assert_allclose(lowest, [1492, 1517, 1517, 1824, 1824, 2774, 2774], atol=0.5)


@pytest.mark.parametrize(("l", "lambda2"), [(0, 13.0), (1, 13.3), (2, 14.7), (3, 18.5)])
def test_handbook_frequency_parameters(l: int, lambda2: float) -> None:
    # Leissa, Vibration of Plates (NASA SP-160), annular plate clamped inside, free outside,
    # a/b = 0.5, nu = 0.3, no nodal circle. The table has three significant figures from 1960s
    # computations (up to 0.4 % rounding; its 18.5 for l = 3 is 0.34 % below the 18.56 found
    # here and by the Ritz solution), so 0.5 %: it still catches a wrong boundary condition,
    # e.g. nu = 0.25 instead of 0.3 in the free-edge terms moves l = 3 by 2 %.
    disc = AnnularPlate(0.5, 1.0, 0.01, 2700.0, 70e9, 0.3)
    mode = disc.mode(0, l)
    rigidity, rho_h = disc.flexural_rigidity, disc.density * disc.thickness
    computed = mode.omega * disc.outer_radius**2 * math.sqrt(rho_h / rigidity)
    assert computed == pytest.approx(lambda2, rel=5e-3)


@pytest.mark.parametrize("l", range(L_MAX + 1))
def test_frequencies_match_ritz(plate: AnnularPlate, l: int) -> None:
    # Ritz is converged to ~1e-13 and brentq stops at ~1e-15 relative; the two agree to
    # ~1e-13 in practice. 1e-9 leaves room for other LAPACK/Bessel builds yet would catch any
    # error in a boundary condition (those shift beta by percent).
    ritz = _ritz(l, N_RITZ)[0][: K_MAX + 1]
    np.testing.assert_allclose(plate.frequency_parameters(l, K_MAX + 1), ritz, rtol=1e-9)
    rho_h = TABLE1["density"] * TABLE1["thickness"]
    omega_ritz = ritz**2 * math.sqrt(plate.flexural_rigidity / rho_h)
    omegas = [plate.mode(k, l).omega for k in range(K_MAX + 1)]
    np.testing.assert_allclose(omegas, omega_ritz, rtol=1e-9)


@pytest.mark.parametrize("l", range(L_MAX + 1))
def test_no_root_missed_or_repeated(plate: AnnularPlate, l: int) -> None:
    ritz = _ritz(l, N_RITZ)[0]
    # Every Ritz value below the cut-off (halfway between the 4th and 5th) must be matched by
    # exactly one root of plate.py: a missed root shifts the list, a double one repeats it.
    cut = 0.5 * (ritz[K_MAX] + ritz[K_MAX + 1])
    roots = plate.frequency_parameters(l, K_MAX + 3)
    below = roots[roots < cut]
    assert below.size == K_MAX + 1
    np.testing.assert_allclose(below, ritz[: K_MAX + 1], rtol=1e-9)
    # Consecutive roots are about pi / (b - a) apart; a quarter of that is "clearly separated".
    assert np.all(np.diff(roots) > 0.25 * math.pi / (B - A))


@pytest.mark.parametrize("l", [0, 1, 10, 40])
def test_small_hub_many_diameters(l: int) -> None:
    # Regression: with a small hub and many nodal diameters the determinant is zero to round-off
    # near beta = 0 (J_l and I_l become parallel); that once gave a spurious root there.
    a, b, nu = 0.005, 0.12, 0.3
    disc = AnnularPlate(a, b, 0.002, 7800.0, 200e9, nu)
    ritz = _ritz(l, N_RITZ, a, b, nu)[0][: K_MAX + 1]
    # Same reasoning as test_frequencies_match_ritz (Ritz converged to ~1e-12 here).
    np.testing.assert_allclose(disc.frequency_parameters(l, K_MAX + 1), ritz, rtol=1e-9)


def test_frequency_parameters_prefix_and_count(plate: AnnularPlate) -> None:
    # The first n roots must not depend on how many are asked for (cache buckets differ).
    many = plate.frequency_parameters(2, 11)
    assert many.shape == (11,)
    np.testing.assert_array_equal(plate.frequency_parameters(2, 3), many[:3])
    assert plate.frequency_parameters(2, 0).shape == (0,)
    assert plate.mode(9, 2).beta == many[9]


# --- shapes ------------------------------------------------------------------------------------


def _all_modes(plate: AnnularPlate):
    return [plate.mode(k, n) for n in range(L_MAX + 1) for k in range(K_MAX + 1)]


def test_boundary_conditions(plate: AnnularPlate) -> None:
    r = np.linspace(A, B, 201)  # the scales below need the right order of magnitude only
    for mode in _all_modes(plate):
        l2 = mode.l**2
        # Natural scale of each derivative: its largest magnitude over the plate.
        s0, s1, s2, s3 = (np.max(np.abs(mode.shape(r, d))) for d in range(4))
        r0, r1, r2, r3 = (mode.shape(B, d) for d in range(4))
        moment = r2 + NU * (r1 / B - l2 * r0 / B**2)
        moment_scale = s2 + NU * (s1 / B + l2 * s0 / B**2)
        # (lap R)' - (1 - nu) (l^2 / r^2) (R' - R / r), with (lap R)' differentiated by hand.
        lap_prime = r3 + r2 / B - r1 / B**2 - l2 * r1 / B**2 + 2.0 * l2 * r0 / B**3
        shear = lap_prime - (1.0 - NU) * (l2 / B**2) * (r1 - r0 / B)
        shear_scale = s3 + s2 / B + (2.0 - NU) * l2 * s1 / B**2 + (3.0 - NU) * l2 * s0 / B**3
        residuals = [
            abs(mode.shape(A)) / s0,
            abs(mode.shape(A, 1)) / s1,
            abs(moment) / moment_scale,
            abs(shear) / shear_scale,
        ]
        # Exact conditions: round-off gives ~1e-15; a wrong sign or term gives O(1). 1e-8
        # tolerates the root's finite brentq tolerance on any platform.
        assert max(residuals) < 1e-8, (mode.k, mode.l, residuals)


def test_orthogonality(plate: AnnularPlate) -> None:
    # 200 Gauss nodes integrate these smooth shapes (at most ~8 half waves) to round-off.
    r, w = _gauss(A, B, 200)
    for l in range(L_MAX + 1):
        shapes = np.array([plate.mode(k, l).shape(r) for k in range(K_MAX + 1)])
        gram = shapes @ (shapes * (w * r)).T
        norm = np.sqrt(np.outer(np.diag(gram), np.diag(gram)))
        off = np.abs(gram / norm - np.eye(K_MAX + 1))
        # Orthogonality follows from self-adjointness with exact boundary conditions; round-off
        # gives ~1e-15, an inexact root ~ its relative error. 1e-8 as asked.
        assert off.max() < 1e-8, l


@pytest.mark.parametrize("l", [0, 1, 5, 10])
def test_shapes_match_ritz(plate: AnnularPlate, l: int) -> None:
    # R^2 / M is what enters the dynamics and is free of normalisation; compare it with the
    # mass-normalised Ritz shape (its M is 1 with the same theta factor).
    r = np.linspace(A, B, 41)
    psi = _ritz_basis(r, A, B, N_RITZ)[0]
    vectors = _ritz(l, N_RITZ)[1]
    for k in range(K_MAX + 1):
        mode = plate.mode(k, l)
        ours = mode.shape(r) ** 2 * _mass_factor(l) / mode.modal_mass
        ritz = (psi @ vectors[:, k]) ** 2
        # Ritz shapes converge like the square root of the eigenvalue error, ~1e-12 here;
        # 1e-8 of the peak value is still far below any modelling effect.
        assert np.max(np.abs(ours - ritz)) < 1e-8 * np.max(ritz), (k, l)


def test_derivatives_match_finite_differences(plate: AnnularPlate) -> None:
    r = np.linspace(A + 1e-3, B - 1e-3, 17)
    step = 1e-6  # [m]: central-difference error ~ step^2 R''' ~ 1e-12 relative, round-off ~1e-10
    for mode in (plate.mode(0, 0), plate.mode(3, 4), plate.mode(2, 10)):
        for d in range(1, 4):
            fd = (mode.shape(r + step, d - 1) - mode.shape(r - step, d - 1)) / (2 * step)
            exact = mode.shape(r, d)
            scale = np.max(np.abs(exact))
            assert np.max(np.abs(fd - exact)) < 1e-7 * scale, (mode.k, mode.l, d)


def test_normalisation(plate: AnnularPlate) -> None:
    r = np.linspace(A, B, 801)
    for mode in _all_modes(plate):
        values = np.abs(mode.shape(r))
        i = int(np.argmax(values))
        # Refine the grid's peak (it may fall between grid points) with a bounded search.
        found = optimize.minimize_scalar(
            lambda s, m=mode: -abs(m.shape(s)),
            bounds=(r[max(i - 1, 0)], r[min(i + 1, r.size - 1)]),
            method="bounded",
            options={"xatol": 1e-12},
        )
        peak = max(values[i], -found.fun)
        # max |R| = 1 is imposed to round-off; near the maximum |R| is flat, so a peak located
        # to 1e-12 m is exact to ~1e-16.
        assert peak == pytest.approx(1.0, abs=1e-12)
        assert values.max() <= 1.0 + 1e-12
        assert mode.shape(B) > 0.0


@pytest.mark.parametrize(("k", "l"), [(0, 0), (1, 0), (0, 3), (3, 10)])
def test_modal_mass_is_kinetic_energy_of_the_shape(plate: AnnularPlate, k: int, l: int) -> None:
    # M = rho h int_0^{2 pi} int_a^b (R cos(l theta))^2 r dr dtheta, evaluated here with scipy's
    # adaptive quad in r and the trapezoidal rule in theta (exact for trigonometric
    # polynomials), so the pi / 2 pi factor of plate.py is checked as well.
    mode = plate.mode(k, l)
    radial = integrate.quad(lambda s: mode.shape(s) ** 2 * s, A, B, epsabs=0, epsrel=1e-12)[0]
    theta = np.linspace(0.0, 2.0 * math.pi, 64, endpoint=False)
    angular = np.mean(np.cos(l * theta) ** 2) * 2.0 * math.pi
    expected = TABLE1["density"] * TABLE1["thickness"] * radial * angular
    # quad was asked for 1e-12; the quadrature in plate.py is converged to round-off.
    assert mode.modal_mass == pytest.approx(expected, rel=1e-10)


def test_physics_independent_of_normalisation(plate: AnnularPlate) -> None:
    # Rescale the shape (sign flip included) and recompute its modal mass from the definition:
    # R(r)^2 / M, the only way R enters the dynamics, must not move; omega does not depend on
    # the shape at all.
    r, w = _gauss(A, B, 200)
    for mode in (plate.mode(0, 0), plate.mode(2, 3)):
        scaled = dataclasses.replace(mode, coefficients=tuple(-3.7 * c for c in mode.coefficients))
        scaled = dataclasses.replace(
            scaled, modal_mass=_mass_factor(mode.l) * np.sum(w * r * scaled.shape(r) ** 2)
        )
        # Round-off relative to the peak (the Bessel terms cancel near the clamped edge).
        np.testing.assert_allclose(scaled.shape(r), -3.7 * mode.shape(r), rtol=0, atol=1e-13)
        physical = mode.shape(r) ** 2 / mode.modal_mass
        np.testing.assert_allclose(
            scaled.shape(r) ** 2 / scaled.modal_mass,
            physical,
            rtol=0,
            atol=1e-12 * physical.max(),
        )
        assert scaled.omega == mode.omega == plate.mode(mode.k, mode.l).omega


def test_shape_scalar_and_array(plate: AnnularPlate) -> None:
    mode = plate.mode(1, 2)
    assert isinstance(mode.shape(0.1), float)
    grid = np.linspace(A, B, 6).reshape(2, 3)
    assert mode.shape(grid, 2).shape == (2, 3)
    assert mode.shape(grid)[1, 2] == pytest.approx(mode.shape(B), rel=1e-14)


# --- input checking ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("inner_radius", -0.01),
        ("inner_radius", 0.2),  # a >= b: named as outer_radius must exceed inner_radius
        ("outer_radius", 0.044),
        ("thickness", 0.0),
        ("density", float("nan")),
        ("youngs_modulus", "150e9"),
        ("poisson_ratio", 0.6),
        ("poisson_ratio", -1.0),
        ("poisson_ratio", True),
    ],
)
def test_bad_plate_parameters(name: str, value) -> None:
    with pytest.raises(ModeError) as info:
        AnnularPlate(**{**TABLE1, name: value})
    message = str(info.value)
    assert "\n" not in message
    assert ("outer_radius" if name == "inner_radius" and value == 0.2 else name) in message
    assert "allowed" in message


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda p: p.mode(-1, 0), "k"),
        (lambda p: p.mode(0, -1), "l"),
        (lambda p: p.mode(1.5, 0), "k"),
        (lambda p: p.mode(0, True), "l"),
        (lambda p: p.frequency_parameters(0, -2), "count"),
        (lambda p: p.modes([(0, 1, 2)]), "(k, l)"),
        (lambda p: p.mode(0, 1).shape(0.2), "r"),
        (lambda p: p.mode(0, 1).shape(0.1, 4), "derivative"),
    ],
)
def test_bad_mode_requests(plate: AnnularPlate, call, name: str) -> None:
    with pytest.raises(ModeError) as info:
        call(plate)
    assert name in str(info.value)
    assert "\n" not in str(info.value)


def test_from_disc_takes_any_object_with_the_fields() -> None:
    disc = types.SimpleNamespace(**TABLE1, modes=[(0, 0)])
    assert AnnularPlate.from_disc(disc) == AnnularPlate(**TABLE1)
    with pytest.raises(ModeError, match="thickness"):
        AnnularPlate.from_disc(types.SimpleNamespace(inner_radius=0.04, outer_radius=0.1))


# --- speed -------------------------------------------------------------------------------------


# --- the `fivdisc modes` command ---------------------------------------------------------------


@pytest.fixture
def stub_case(monkeypatch: pytest.MonkeyPatch) -> types.ModuleType:
    """A stand-in for fivdisc.case with the API the command relies on."""
    module = types.ModuleType("fivdisc.case")

    class Case:
        def __init__(self) -> None:
            self.disc = types.SimpleNamespace(**TABLE1, modes=[(0, 0), (0, 1), (1, 2)])

    def load_case(path):
        case = Case()
        case.disc.modes = [(-1, 0)] if "bad" in str(path) else [(0, 3)]
        return case

    module.Case, module.load_case = Case, load_case
    monkeypatch.setitem(sys.modules, "fivdisc.case", module)
    return module


def _run(args: list[str]):

    return run_cli(args)


def test_cli_table(stub_case: types.ModuleType) -> None:
    result = _run(["modes"])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert "omega [rad/s]" in lines[0] and "modal mass [kg]" in lines[0]
    rows = [line.split() for line in lines[1:4]]
    assert [row[:2] for row in rows] == [["0", "0"], ["0", "1"], ["1", "2"]]
    assert float(rows[0][2]) == pytest.approx(1491.93, abs=0.01)


def test_cli_json_and_case_file(stub_case: types.ModuleType, tmp_path) -> None:
    case_file = tmp_path / "case.toml"
    case_file.write_text("")
    result = _run(["modes", str(case_file), "--json"])
    assert result.exit_code == 0, result.output
    (row,) = json.loads(result.output)
    assert set(row) == {"k", "l", "omega", "frequency_hz", "modal_mass"}
    mode = AnnularPlate(**TABLE1).mode(0, 3)
    assert (row["k"], row["l"]) == (0, 3)
    assert row["omega"] == pytest.approx(mode.omega, rel=1e-12)
    assert row["frequency_hz"] == pytest.approx(mode.frequency_hz, rel=1e-12)
    assert row["modal_mass"] == pytest.approx(mode.modal_mass, rel=1e-12)


def test_cli_errors_are_one_line(stub_case: types.ModuleType, tmp_path) -> None:
    case_file = tmp_path / "bad.toml"
    case_file.write_text("")
    result = _run(["modes", str(case_file)])
    assert result.exit_code == 2
    assert "k = -1" in result.output


def test_cli_with_the_real_case_module() -> None:
    from fivdisc.case import Case

    result = _run(["modes", "--json"])
    assert result.exit_code == 0, result.output
    rows = json.loads(result.output)
    assert [(row["k"], row["l"]) for row in rows] == [tuple(m) for m in Case().disc.modes]


@pytest.mark.parametrize(
    ("a", "b", "nu"),
    [(0.01, 0.1, 0.3), (0.05, 0.1, 0.3), (0.09, 0.1, 0.33), (0.02, 0.3, 0.2),
     (0.1, 0.15, -0.2), (0.044, 0.12, 0.45)],
)
@pytest.mark.parametrize("l", [0, 1, 5])
def test_other_geometries_match_ritz(a: float, b: float, nu: float, l: int) -> None:
    # Narrow and wide annuli, negative and near-incompressible Poisson ratios: the same
    # converged Ritz reference (observed agreement ~3e-12), tolerance as for Table 1.
    disc = AnnularPlate(a, b, 0.002, 7800.0, 200e9, nu)
    ritz = _ritz(l, N_RITZ, a, b, nu)[0][: K_MAX + 1]
    np.testing.assert_allclose(disc.frequency_parameters(l, K_MAX + 1), ritz, rtol=1e-9)


def test_stored_modes_are_the_solved_ones_to_the_last_bit(monkeypatch, tmp_path) -> None:
    """The modes a later process reads from fivdisc.model.mode_cache (so that it imports no root
    finder) are exactly those solved: a model is bit for bit the same either way. A
    damaged file, or one stamped by other sources, is ignored."""
    from fivdisc.model import mode_cache as plate_cache
    from fivdisc.model import plate as plate_module

    monkeypatch.setenv("FIVDISC_CACHE_DIR", str(tmp_path))
    # Without the packaged modes (tests/model/test_mode_seed.py), so that all are stored.
    monkeypatch.setattr(plate_cache, "_seeded", dict)

    def modes():
        plate_module.clear_cache()
        monkeypatch.setattr(plate_cache, "_modes", None)
        plate = AnnularPlate(A, B, 0.002, 7800.0, 200e9, NU)
        return [dataclasses.astuple(plate.mode(k, l)) for l in (0, 1, 2, 5) for k in range(3)]

    solved = modes()
    stored = tmp_path / "fivdisc-plate-modes.json"
    assert len(json.loads(stored.read_text())["modes"]) == 12
    assert modes() == solved  # read back: the same numbers
    # Their values at a model's radii (sliders, probes) too, stored by the first call and
    # read back as that request computed them (numpy's vectorised Bessel functions may
    # round a radius differently within another array: the request is the key).
    plate = AnnularPlate(A, B, 0.002, 7800.0, 200e9, NU)
    requests = [np.array([A, 0.1, B]), np.array([0.1]), np.array([0.09, 0.1, 0.11, 0.1])]
    computed = [plate.mode(k, 2).shape(r, d) for r in requests for k in range(3)
                for d in (0, 1)]
    monkeypatch.setattr(plate_cache, "_modes", None)
    again = [plate.mode(k, 2).shape(r, d) for r in requests for k in range(3) for d in (0, 1)]
    assert all(np.array_equal(a, b) for a, b in zip(again, computed, strict=True))
    text = json.loads(stored.read_text())
    key = next(iter(text["modes"]))
    text["modes"][key][0] *= 1.5
    stored.write_text(json.dumps({**text, "stamp": "other sources"}))
    assert modes() == solved  # a stale stamp: solved again
    stored.write_text("{not json")
    assert modes() == solved
    plate_module.clear_cache()
