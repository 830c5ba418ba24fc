"""Every Hopf curve in a box of two keys and its codimension-two points, against what does
not use the curve tracer: closed forms of rigid-disc oscillators, direct eigenvalue
solves at the curves' points, and Hopf points and their first Lyapunov coefficients
along one-key scans (:func:`fivdisc.analysis.hopf.hopf_points`).

The rigid-disc Stribeck oscillator (test_normal_form) I phi'' + C phi' + K phi =
r N0 mu(r (Omega - phi')) has its Hopf curve in (Omega, C) where the damping vanishes,
C = -r^2 N0 mu'(r Omega), and l1 proportional to -mu'''(r Omega). With
mu = mu_1 + dmu exp(-s^2), s = r Omega / v_s:

    C(Omega) = 2 r^2 N0 dmu s exp(-s^2) / v_s,
    mu''' = dmu (12 s - 8 s^3) exp(-s^2) / v_s^3,

so l1 changes sign at s = sqrt(3/2): the Bautin point is at Omega = v_s sqrt(3/2) / r,
C = 2 r^2 N0 dmu sqrt(3/2) exp(-3/2) / v_s; subcritical above it in speed (below it
in damping), supercritical below.

Two sliders on a rigid disc are two independent oscillators. With the exponential law
each one's Hopf curve is C_j = r^2 N0 alpha dmu exp(-alpha r Omega); in
(Omega, C_0) with C_1 fixed, slider 1's curve is the line Omega = ln(r^2 N0 alpha dmu
/ C_1) / (alpha r), and it crosses slider 0's curve at C_0 = C_1: a double Hopf point,
the pairs at sqrt(K_j / I) each.
"""

from __future__ import annotations

import numpy as np
import pytest

from fivdisc import Case
from fivdisc.analysis.codimension import hopf_curve_lines, hopf_curves
from fivdisc.analysis.hopf import hopf_points
from fivdisc.analysis.stability import linear_stability
from fivdisc.errors import CaseError

R, N0, DMU, MASS = 0.1, 500.0, 0.25, 0.1
SPEED, DAMPING = "speed.value", "slider.rotational_damping"
STRIBECK = Case(disc={"modes": []}, slider={"rotational_damping": 0.2},
                friction={"law": "stribeck", "stribeck_velocity": 1.0,
                          "stribeck_exponent": 2.0}, speed={"value": 1.0})
BAUTIN = (np.sqrt(1.5) / R, 2 * R**2 * N0 * DMU * np.sqrt(1.5) * np.exp(-1.5))


@pytest.fixture(scope="module")
def stribeck():
    return hopf_curves(STRIBECK, (SPEED, (0.5, 30.0)), (DAMPING, (0.1, 1.2)))


def test_stribeck_curve_is_the_closed_form(stribeck):
    """One curve, edge to edge, every point on C(Omega) to 1e-9, the slider's mode at
    sqrt(K / I), on the stability boundary throughout."""
    ds = stribeck
    assert ds.sizes["curve_index"] == 1
    assert (str(ds["curve_start"].values[0]), str(ds["curve_end"].values[0])) == ("edge",
                                                                                   "edge")
    s = R * ds[SPEED].values
    np.testing.assert_allclose(ds[DAMPING].values, 2 * R**2 * N0 * DMU * s * np.exp(-s**2),
                               rtol=1e-9)
    np.testing.assert_allclose(ds["frequency"].values, np.sqrt(2000.0 / (MASS * R**2))
                               / (2 * np.pi), rtol=1e-9)
    assert set(ds["mode"].values) == {"phi"} and ds["on_boundary"].values.all()
    # l1 against the closed form at every point (test_normal_form derives it).
    third = DMU * (12 * s - 8 * s**3) * np.exp(-s**2)
    l1 = -(R**2) * N0 * third / (16 * MASS * np.sqrt(2000.0 / (MASS * R**2)))
    np.testing.assert_allclose(ds["l1"].values, l1, rtol=1e-6, atol=1e-12)


def test_bautin_point_where_the_closed_form_puts_it(stribeck):
    """Located to 1e-6 in both keys (found to ~1e-10)."""
    ds = stribeck
    assert list(ds["codim2_kind"].values) == ["bautin"]
    x, y = float(ds["codim2_x"].values[0]), float(ds["codim2_y"].values[0])
    assert abs(x - BAUTIN[0]) < 1e-6 and abs(y - BAUTIN[1]) < 1e-6
    text = "\n".join(hopf_curve_lines(ds))
    assert f"Bautin point (l1 = 0) on curve 0 at {SPEED} = 12.24744871" in text


def test_bautin_point_against_l1_along_one_key_scans(stribeck):
    """Along the speed at fixed damping (hopf_points, l1 at each Hopf point, no curve
    tracing): just above the located Bautin damping the upper Hopf point is
    supercritical, just below it subcritical, and l1 interpolated between the two scans
    vanishes at the located damping to 1e-6; the scan at that damping finds its Hopf
    point at the located speed."""
    x, y = float(stribeck["codim2_x"].values[0]), float(stribeck["codim2_y"].values[0])
    values = np.linspace(8.0, 20.0, 7)
    l1s = []
    for damping in (y * (1 + 1e-4), y * (1 - 1e-4)):
        (upper,) = hopf_points(STRIBECK.replace({DAMPING: damping}), SPEED, values)
        l1s.append(upper.l1)
    assert l1s[0] < 0 < l1s[1]
    root = y * (1 + 1e-4) + (l1s[0] / (l1s[0] - l1s[1])) * (-2e-4 * y)
    assert abs(root - y) < 1e-6
    (at,) = hopf_points(STRIBECK.replace({DAMPING: y}), SPEED, values)
    assert abs(at.value - x) < 1e-6
    assert abs(at.l1) < 1e-6 * abs(l1s[0]) * 1e4


@pytest.fixture(scope="module")
def two_sliders():
    case = Case(disc={"modes": []},
                sliders=[{"rotational_damping": 0.5},
                         {"rotational_damping": 0.5, "rotational_stiffness": 3000.0,
                          "angle": 3.0}],
                friction={"decay": 1.0}, speed={"value": 5.0})
    return case, hopf_curves(case, (SPEED, (2.0, 30.0)),
                             ("sliders.0.rotational_damping", (0.1, 1.0)))


def test_double_hopf_point_of_two_independent_sliders(two_sliders):
    _, ds = two_sliders
    assert ds.sizes["curve_index"] == 2
    assert sorted(ds["curve_mode"].values) == ["phi0", "phi1"]
    (i,) = np.flatnonzero(ds["codim2_kind"].values == "double_hopf")
    expected = (np.log(R**2 * N0 * DMU / 0.5) / R, 0.5)
    assert abs(ds["codim2_x"].values[i] - expected[0]) < 1e-6
    assert abs(ds["codim2_y"].values[i] - expected[1]) < 1e-6
    freqs = sorted([ds["codim2_frequency"].values[i], ds["codim2_other_frequency"].values[i]])
    np.testing.assert_allclose(freqs, np.sqrt(np.array([2000.0, 3000.0]) / (MASS * R**2))
                               / (2 * np.pi), rtol=1e-9)
    assert {int(ds["codim2_curve"].values[i]), int(ds["codim2_other_curve"].values[i])} == {0, 1}
    # Each slider's curve is on the stability boundary only where the other is stable.
    for c in range(2):
        sel = ds["hopf_curve"].values == c
        assert 0 < ds["on_boundary"].values[sel].sum() < sel.sum()


def test_curve_points_against_direct_eigenvalue_solves(two_sliders):
    """At every fifth point of each curve, the case rebuilt there has an eigenvalue on
    the imaginary axis (to 1e-9 of its size) at the stored frequency."""
    case, ds = two_sliders
    key = "sliders.0.rotational_damping"
    for i in range(0, ds.sizes["point"], 5):
        lam = linear_stability(case.replace({SPEED: float(ds[SPEED].values[i]),
                                             key: float(ds[key].values[i])})).eigenvalues
        omega = 2 * np.pi * float(ds["frequency"].values[i])
        near = lam[np.argmin(np.abs(lam - 1j * omega))]
        assert abs(near.real) < 1e-9 * abs(near)
        assert near.imag == pytest.approx(omega, rel=1e-9)


def test_command_line_writes_draws_and_prints(tmp_path, stribeck):
    """fivdisc stability --hopf-curves: the dataset (CF), a figure, the printed curves
    and points; bad use is refused in one line."""
    import xarray as xr

    from support.cf_check import check_cf
    from support.cli import run_cli

    case = tmp_path / "stribeck.toml"
    case.write_text(STRIBECK.to_toml())
    box = [f"{SPEED}=0.5:30", f"{DAMPING}=0.1:1.2"]
    out = tmp_path / "curves.nc"
    res = run_cli(["stability", case, "--hopf-curves", *box, "-o", out])
    assert res.exit_code == 0, res.output
    assert "Hopf curve 0 (phi, 225.079-225.079 Hz" in res.output
    assert f"Bautin point (l1 = 0) on curve 0 at {SPEED} = 12.24744871" in res.output
    with xr.open_dataset(out) as ds:
        check_cf(ds)
        np.testing.assert_allclose(ds["codim2_x"].values, stribeck["codim2_x"].values,
                                   rtol=1e-12)
    png = tmp_path / "curves.png"
    res = run_cli(["stability", case, "--hopf-curves", *box, "-o", png])
    assert res.exit_code == 0, res.output
    assert png.stat().st_size > 10000
    bad = run_cli(["stability", case, "--hopf-curves", *box, "--boundary", *box])
    assert bad.exit_code == 2 and "give one" in bad.output
    bad = run_cli(["stability", case, "--hopf-curves", f"{SPEED}=0.5", box[1]])
    assert bad.exit_code == 2 and "write KEY=START:STOP" in bad.output


def test_bad_boxes_are_refused():
    with pytest.raises(CaseError, match="empty"):
        hopf_curves(STRIBECK, (SPEED, (1.0, 1.0)), (DAMPING, (0.1, 1.0)))
    with pytest.raises(CaseError, match="same key"):
        hopf_curves(STRIBECK, (SPEED, (1.0, 2.0)), (SPEED, (0.1, 1.0)))
    with pytest.raises(CaseError, match=r"slider\.rotational_damping = -1"):
        hopf_curves(STRIBECK, (SPEED, (1.0, 2.0)), (DAMPING, (-1.0, 1.0)))
    with pytest.raises(CaseError, match="seeds = 1"):
        hopf_curves(STRIBECK, (SPEED, (1.0, 2.0)), (DAMPING, (0.1, 1.0)), seeds=1)


def test_curve_ends_where_the_equilibrium_ceases_to_exist():
    """The paper's undamped disc near the l = 2 critical speed, over the slider's normal
    damping (which does not enter the equilibrium): the slider's curve ends where its
    normal force reaches zero. There the reference model's normal force (written from
    the equations alone) changes sign within 1e-9 of the speed, and one-key scans in the
    damping just inside (hopf_points) find the Hopf point at the located damping plus
    the slope times the distance, linear to 1e-6; the Bautin test does not take the
    pole of l1 there (the slip speed's share of the mode vanishing) for a zero. The
    other curves cross: a double Hopf point of the slider's mode with C01 and one of the
    two backward waves (D02, D03)."""
    from reference.model import sliding_equilibrium as reference

    case = Case()
    ds = hopf_curves(case, (SPEED, (880.0, 912.2)), ("slider.normal_damping", (0.0, 1.0)),
                     seeds=8)
    kinds = list(ds["codim2_kind"].values)
    (i,) = np.flatnonzero(ds["codim2_kind"].values == "existence")
    x, y = float(ds["codim2_x"].values[i]), float(ds["codim2_y"].values[i])
    # One label per mode (issue 40): there the slider's in-plane mode proper (all of its
    # energy in phi, -50 1/s) is "phi"; the critical pair, 61 % phi and 36 % C00, is C00.
    mode = str(ds["codim2_mode"].values[i])
    assert mode == "C00"
    assert "normal force reaches zero" in str(ds["codim2_note"].values[i])
    assert reference(case.replace({SPEED: x * (1 - 1e-9)}))["N"] > 0
    assert reference(case.replace({SPEED: x * (1 + 1e-9)}))["N"] < 0
    found = []
    for dx in (1e-5, 2e-5):
        (hp,) = [h for h in hopf_points(case.replace({SPEED: x - dx}),
                                        "slider.normal_damping", np.linspace(0, 0.1, 11))
                 if h.mode == mode]
        found.append(hp.value)
    # Extrapolated to the located speed: the located damping.
    assert abs(2 * found[0] - found[1] - y) < 1e-6
    assert kinds.count("double_hopf") == 2 and "bautin" not in [
        k for k, c in zip(kinds, ds["codim2_curve"].values, strict=True)
        if ds["curve_mode"].values[c] == mode]


@pytest.mark.slow
def test_three_pads_in_speed_and_disc_damping():
    """Issue 36's three pads over (speed, disc damping): one curve per pad's mode, near
    19.20, 19.34 and 19.573 rad/s and a fraction of a hertz apart, traced apart; the
    last is subcritical and the stability boundary above the backward wave's curve, on
    which the Hopf point of the one-key scan at the case's damping lies; the Bautin
    points on the disc modes' curves against the sign of l1 at one-key scans just beside
    them."""
    from pathlib import Path

    from fivdisc.case import load_case

    case = load_case(Path(__file__).parents[1] / "data" / "three_pads_issue36.toml")
    key = "disc.damping_ratio"
    ds = hopf_curves(case, (SPEED, (5.0, 40.0)), (key, (0.0005, 0.006)))
    modes = list(ds["curve_mode"].values)
    pads = [c for c, m in enumerate(modes) if m.startswith("phi")]
    assert len(pads) == 3
    centres = sorted(float(np.median(ds[SPEED].values[ds["hopf_curve"].values == c]))
                     for c in pads)
    np.testing.assert_allclose(centres, [19.205, 19.344, 19.573], atol=5e-3)
    (hp,) = hopf_points(case, SPEED, np.linspace(19.4, 19.8, 5))
    assert hp.on_boundary and hp.criticality == "subcritical"
    last = next(c for c in pads if abs(centres[2] - np.median(
        ds[SPEED].values[ds["hopf_curve"].values == c])) < 5e-3)
    sel = ds["hopf_curve"].values == last
    at = np.interp(0.003, ds[key].values[sel], ds[SPEED].values[sel])
    assert abs(at - hp.value) < 1e-3  # chords of the curve, 0.02 of the box apart
    assert (ds["l1"].values[sel] > 0).all()
    for i in np.flatnonzero(ds["codim2_kind"].values == "bautin"):
        x, y = float(ds["codim2_x"].values[i]), float(ds["codim2_y"].values[i])
        freq = float(ds["codim2_frequency"].values[i])
        signs = []
        for damping in (y * (1 - 1e-3), y * (1 + 1e-3)):
            found = [h for h in hopf_points(case.replace({key: damping}), SPEED,
                                            np.linspace(x - 0.5, x + 0.5, 5))
                     if abs(h.frequency - freq) < 1.0]
            (h,) = found
            assert abs(h.value - x) < 0.1
            signs.append(np.sign(h.l1))
        assert signs[0] == -signs[1]


def test_the_figure_draws_each_style_as_one_line(stribeck):
    """A curve is drawn in runs of one style: the subcritical part of the Stribeck curve
    (past its Bautin point) is one dashed line through all its points, not a line per
    segment (dashes restart on every line, so short segments looked solid)."""
    import matplotlib

    matplotlib.use("Agg")
    from fivdisc.plots import plot_hopf_curves

    fig = plot_hopf_curves(stribeck)
    lines = [ln for ln in fig.axes[0].get_lines() if len(ln.get_xdata()) > 1]
    dashed = [ln for ln in lines if ln.get_linestyle() == "--"]
    solid = [ln for ln in lines if ln.get_linestyle() == "-"]
    sub = int((stribeck["l1"].values > 0).sum())
    assert dashed and solid
    assert max(len(ln.get_xdata()) for ln in dashed) >= sub - 1


def test_every_hopf_curve_is_traced_once():
    """Three pads over (speed, disc damping) in the box of the bistable-region tutorial:
    each eigenvalue's Hopf curve once. The disc mode C02's curve bends sharply where it
    meets the pads' (the Bautin point), and a seed on it lay farther from the traced
    chords than their tolerance: it was traced a second time. Second route: at each
    curve's middle point, solved afresh, a pair lies on the imaginary axis at the curve's
    frequency."""
    from pathlib import Path

    from fivdisc.case import load_case

    case = load_case(Path(__file__).parents[1] / "data" / "three_pads_issue36.toml")
    key = "disc.damping_ratio"
    ds = hopf_curves(case, (SPEED, (15.0, 50.0)), (key, (0.002, 0.004)))
    modes = [str(m) for m in ds["curve_mode"].values]
    assert sorted(modes) == ["C02", "phi~0", "phi~1", "phi~2"]
    for c in range(ds.sizes["curve_index"]):
        sel = np.flatnonzero(ds["hopf_curve"].values == c)
        mid = sel[sel.size // 2]
        point = case.replace({SPEED: float(ds[SPEED].values[mid]),
                              key: float(ds[key].values[mid])})
        lam = linear_stability(point).eigenvalues
        # a pair on the imaginary axis at the curve's frequency
        i = int(np.argmin(np.abs(lam.imag / (2 * np.pi) - ds["frequency"].values[mid])))
        assert abs(lam[i].real) < 1e-6 * abs(lam[i])
