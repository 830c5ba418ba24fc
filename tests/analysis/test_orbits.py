"""Periodic orbits and Floquet multipliers against closed forms and finite differences."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.engine.integration import Integration
from fivdisc.errors import FivdiscError
from fivdisc.model.build import build_model

from support.cases import LIGHT, RIGID, rigid_disc_closed_form
from support.cli import run_cli


def test_rigid_disc_stick_slip_orbit():
    """Period to 1e-9; multipliers: 1 (flow), the disc mode's exp(lambda T) (to 1e-6, the
    accuracy the default tolerance is chosen for), and zeros: the stick collapse and the
    slider's z, zdot (slaved in contact)."""
    period, disc = rigid_disc_closed_form()
    orbit = periodic_orbit(RIGID, transient=4.0)
    assert orbit.verdict == "stable"
    assert orbit.period == pytest.approx(period, rel=1e-9)
    mult = orbit.multipliers
    assert mult[orbit.trivial] == pytest.approx(1.0, abs=1e-8)
    others = np.delete(mult, orbit.trivial)
    big = others[np.abs(others) > 0.5]
    assert big.size == 2
    assert np.sort_complex(big) == pytest.approx(np.sort_complex(disc), abs=1e-6)
    small = others[np.abs(others) <= 0.5]
    assert small.size == 3
    assert np.all(np.abs(small) < 1e-10)


def _return_map_jacobian(model, x0, phases, period, free):
    """Richardson-extrapolated central differences of the flow map over ``period``
    (see test_tangent for the steps and why they reach 1e-7 of the largest entry)."""
    def flow(x):
        run = Integration(model, x, duration=period, output_rate=1.0 / period, rtol=1e-12,
                          atol=1e-19, phases=phases)
        run.run_to(period)
        return run.out_y[1, : model.state_size].copy()

    jac = np.zeros((model.state_size, model.state_size))
    for j in np.flatnonzero(free):
        scale = max(abs(x0[j]), 1e-3 * np.max(np.abs(x0)))
        d = []
        for e in (1e-3, 5e-4, 2.5e-4):
            xp, xm = x0.copy(), x0.copy()
            xp[j] += e * scale
            xm[j] -= e * scale
            d.append((flow(xp) - flow(xm)) / (2 * e * scale))
        r1 = (4 * d[1] - d[0]) / 3
        r2 = (4 * d[2] - d[1]) / 3
        jac[:, j] = (16 * r2 - r1) / 15
    return jac


def test_multipliers_match_finite_differences_of_the_return_map():
    """The saltation-based monodromy's eigenvalues against those of a monodromy from
    finite differences of the flow map over one period, on a stick-slip orbit of a light
    disc (exponential friction, damped slider): moduli to 1e-6."""
    orbit = periodic_orbit(LIGHT, transient=2.0)
    assert orbit.verdict == "stable"
    model = build_model(LIGHT)
    run = Integration(model, orbit.state, duration=1.0, phases=orbit.phases)
    run.advance(0.0)
    fd = _return_map_jacobian(model, orbit.state, orbit.phases, orbit.period, run.free())
    ref = np.sort(np.abs(np.linalg.eigvals(fd)))
    assert np.sort(orbit.moduli) == pytest.approx(ref, abs=1e-6)


@pytest.mark.parametrize("mu", [1.0 + 1e-4, 1.0 - 1e-4, 1.0 + 1e-6])
def test_the_flow_multiplier_is_told_apart_near_a_fold(mu):
    """A monodromy built by hand as an orbit near a fold of cycles has it: the flow
    direction f with multiplier 1, a direction v at 1e-7 rad from f with multiplier mu
    close to 1 (the two eigenvectors merge at the fold), and -0.5 and 0.3 elsewhere. The
    non-trivial multipliers come out as mu, -0.5 and 0.3 to 1e-12, and the flow's as 1:
    the eigenvectors of mu and 1 are too nearly parallel to tell them apart, which is
    what labelled such orbits stable or unstable at random."""
    from fivdisc.analysis.orbits import Shooting, Shot

    rng = np.random.default_rng(7)
    f = rng.normal(size=4)
    f /= np.linalg.norm(f)
    w = rng.normal(size=4)
    w -= (w @ f) * f
    w /= np.linalg.norm(w)
    v = np.cos(1e-7) * f + np.sin(1e-7) * w
    basis = np.column_stack([f, v, rng.normal(size=4), rng.normal(size=4)])
    monodromy = basis @ np.diag([1.0, mu, -0.5, 0.3]) @ np.linalg.inv(basis)
    shooting = Shooting.__new__(Shooting)
    shooting.scale = np.ones(4)
    shot = Shot(end=np.zeros(4), monodromy=monodromy, rate_end=f, rate_start=f,
                free=np.ones(4, bool))
    mult, trivial = shooting.stability(shot)
    assert mult[trivial] == pytest.approx(1.0, abs=1e-9)
    others = np.sort(np.delete(mult, trivial).real)
    assert others == pytest.approx(np.sort([mu, -0.5, 0.3]), abs=1e-9)
    assert np.all(np.diff(np.abs(mult)) <= 0)  # largest modulus first


def test_orbit_needs_constant_speed():
    case = RIGID.replace({"speed": {"profile": "decelerating", "initial": 1.0,
                                    "duration": 10.0}})
    with pytest.raises(FivdiscError, match="constant disc speed"):
        periodic_orbit(case)
    with pytest.raises(FivdiscError, match="period = -1"):
        periodic_orbit(RIGID, period=-1.0)


def test_orbit_command_json_and_netcdf(tmp_path):
    path = tmp_path / "rigid.toml"
    path.write_text(RIGID.replace({"simulation.duration": 4.0}).to_toml())
    out = tmp_path / "orbit.nc"
    res = run_cli(["orbit", str(path), "--json", "--no-progress", "-o", str(out)])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    period, _ = rigid_disc_closed_form()
    assert data["period"] == pytest.approx(period, rel=1e-9)
    assert data["verdict"] == "stable"
    assert data["residual"] < 1e-8
    assert {"real", "imag", "modulus"} <= set(data["multipliers"][0])
    import xarray as xr

    with xr.open_dataset(out) as ds:
        assert ds.attrs["period"] == pytest.approx(period, rel=1e-9)
        assert ds["monodromy"].shape == (6, 6)


def test_paper_fig13_orbit_sits_just_outside_the_unit_circle():
    """The paper's Fig. 13 case (undamped disc, constant 2 pi rad/s): the shooting converges
    on a periodic orbit whose leading multipliers lie within 1e-3 of the unit circle.
    Whether they are inside or outside is a statement only if the moduli do not move with
    the integration tolerance: at rtol 1e-11 and 1e-12 they agree to 1e-7, a thousand
    times closer than their distance from 1."""
    from fivdisc.paper.cases import FIGURES

    case = FIGURES[13].case
    orbit = periodic_orbit(case, transient=5.0, window=0.05)
    assert orbit.residual < 1e-8
    again = periodic_orbit(case, guess=orbit.state, period=orbit.period, phases=orbit.phases,
                           rtol=1e-11)
    assert again.period == pytest.approx(orbit.period, rel=1e-9)
    lead = np.sort(orbit.moduli)[::-1][:4]
    assert np.sort(again.moduli)[::-1][:4] == pytest.approx(lead, abs=1e-7)
    assert abs(orbit.largest - 1.0) < 1e-3
    assert abs(orbit.largest - 1.0) > 1e-5
    assert orbit.verdict == ("unstable" if orbit.largest > 1.0 else "stable")


def test_state_labels_number_sliders_as_the_case_does():
    """Slider j is ``sliders.j`` in a case, ``slider j`` in every summary and ``phi{j}`` in
    the stability table, all from 0: an orbit's or a branch's coordinate labels must name
    the same slider, or a reader of the monodromy matrix puts one slider's row on
    another."""
    from fivdisc import load_case
    from fivdisc.analysis.orbits import state_labels
    from fivdisc.analysis.stability import linear_stability
    from fivdisc.examples import path

    case = load_case(path("two-pads"))
    labels = state_labels(build_model(case))
    angles = [lab for lab in labels if lab.startswith("phi_") and not lab.endswith("_dot")]
    assert angles == ["phi_0", "phi_1"]
    assert {"z_0", "z_1", "phi_0_dot", "z_1_dot"} <= set(labels)
    stability_names = {name for name in linear_stability(case).dominant
                       if name.startswith("phi")}
    assert stability_names <= {"phi0", "phi1"}
