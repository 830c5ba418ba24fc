"""Sliding equilibrium, linear stability and stability maps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from fivdisc import examples
from fivdisc.analysis.stability import (
    linear_stability,
    perturbation_test,
    stability_map,
)
from fivdisc.case import Case, load_case
from fivdisc.cli import cli
from fivdisc.errors import CaseError, SimulationError

from reference.model import (
    SLIP,
    _Model,
    _speed_pieces,
    mode_data_from_case,
)
from reference.model import (
    sliding_equilibrium as reference_equilibrium,
)
from support.cli import run_cli

PAPER = {
    "fig4": {"slider": {"normal_damping": 11.0, "rotational_damping": 1.0},
             "friction": {"decay": 10.0}, "speed": {"value": 10.0}},
    "fig6": {"slider": {"normal_damping": 1.0, "rotational_damping": 2.0},
             "friction": {"decay": 0.0}, "speed": {"value": 1.0}},
    "fig8": {"slider": {"normal_damping": 0.1, "rotational_damping": 0.1},
             "friction": {"decay": 1.0}, "speed": {"value": 2 * np.pi}},
    "fig13": {"slider": {"normal_damping": 2.0, "rotational_damping": 0.5},
              "friction": {"decay": 1.0}, "speed": {"value": 2 * np.pi}},
}


@pytest.mark.parametrize("name", sorted(PAPER))
def test_equilibrium_matches_reference(name):
    case = Case(**PAPER[name])
    eq = linear_stability(case).equilibrium
    ref = reference_equilibrium(case)
    # Both solve the same algebraic equations to ~1e-13 (hybr vs a secant in phi).
    np.testing.assert_allclose(eq.q, ref["q"], rtol=1e-9, atol=1e-12 * np.abs(ref["q"]).max())
    assert eq.phi == pytest.approx(ref["phi"], rel=1e-10)
    assert eq.normal_force == pytest.approx(ref["N"], rel=1e-10)


def _reference_jacobian(case: Case, q, phi) -> np.ndarray:
    """Central differences of the independent reference right-hand side, reordered to
    the variables (q, phi, qdot, phidot)."""
    md = mode_data_from_case(case)
    n = md.n
    fun = _Model(case, md).rhs(SLIP, 1, _speed_pieces(case.speed, 1.0)[0])
    # The reference state also carries the separation-phase gap and its rate (unused here).
    y0 = np.concatenate([q, np.zeros(n), [phi, 0.0, 0.0, 0.0]])
    scale = np.concatenate([np.full(n, np.abs(q).max()), np.full(n, 1.0), [1.0, 1.0]])
    jac = np.empty((2 * n + 2, 2 * n + 2))
    for i in range(2 * n + 2):
        h = 1e-6 * scale[i]
        yp, ym = y0.copy(), y0.copy()
        yp[i] += h
        ym[i] -= h
        jac[:, i] = (fun(0.0, yp)[: 2 * n + 2] - fun(0.0, ym)[: 2 * n + 2]) / (2 * h)
    order = np.r_[0:n, 2 * n, n : 2 * n, 2 * n + 1]
    return jac[np.ix_(order, order)]


@pytest.mark.parametrize("name", sorted(PAPER))
def test_eigenvalues_match_reference_finite_differences(name):
    case = Case(**PAPER[name])
    res = linear_stability(case)
    ref = _reference_jacobian(case, res.equilibrium.q, res.equilibrium.phi[0])
    lam_ref = np.linalg.eigvals(ref)
    radius = np.abs(lam_ref).max()
    # Central differences carry ~1e-9 relative error (h^2 truncation and rounding at
    # h = 1e-6); eigenvalues then agree to ~1e-8 of the spectral radius (~2.8e3 1/s).
    for lam in res.eigenvalues:
        assert np.min(np.abs(lam_ref - lam)) < 1e-7 * radius
    assert res.stable == bool(np.max(lam_ref.real) < 0)


def test_linearisation_agrees_with_perturbation_test():
    """Eigenvalues and the paper's perturb-and-simulate test agree on 60 cases across the
    boundary. The case is a one-mode, light disc under a 1 kg slider so that the eigenvalue
    crossing the boundary has rates of O(1-100) 1/s, which a 2 s simulation resolves; with
    the paper's disc the boundary in (c_z, c_phi) is set by disc modes growing or decaying
    at ~0.01 1/s, invisible in any affordable run. Cases within |Re(lambda)| < 1 1/s of
    the boundary are left out for the same reason (2 s resolves rates of a few 1/s)."""
    base = Case(
        disc={"density": 720.0, "modes": [[0, 0]]},
        slider={"mass": 1.0, "normal_damping": 20.0},
        speed={"value": 1.0},
        simulation={"output_rate": 500.0},
    )
    checked = {True: 0, False: 0}
    for alpha in (0.5, 1.0, 2.0, 3.0, 5.0):
        for c_phi in np.linspace(0.2, 4.0, 12):
            case = base.replace({"friction.decay": alpha, "slider.rotational_damping": c_phi})
            lin = linear_stability(case)
            if abs(lin.max_growth_rate) < 1.0:
                continue
            sim = perturbation_test(case, duration=2.0)
            assert sim.decays == lin.stable, (alpha, c_phi, lin.max_growth_rate, sim)
            checked[lin.stable] += 1
    assert checked[True] + checked[False] >= 50
    assert min(checked.values()) >= 10


def test_no_equilibrium_without_constant_speed():
    with pytest.raises(SimulationError, match="constant"):
        linear_stability(Case(speed={"profile": "accelerating", "initial": 1.0, "rate": 1.0}))


def test_stability_map_fast_path_is_exact():
    case = Case(speed={"value": 1.0})
    xs = np.linspace(1.0, 12.0, 4)
    ys = np.linspace(0.5, 3.0, 3)
    fast = stability_map(case, ("slider.normal_damping", xs), ("slider.rotational_damping", ys))
    for iy, y in enumerate(ys):
        for ix, x in enumerate(xs):
            point = case.replace({"slider.normal_damping": x, "slider.rotational_damping": y})
            slow = linear_stability(point).max_growth_rate
            assert fast["max_growth_rate"].values[iy, ix] == pytest.approx(slow, rel=1e-9,
                                                                           abs=1e-12)


def test_stability_map_boundary_separates_stable_above():
    case = Case(speed={"value": 1.0}, friction={"decay": 1.0})
    ds = stability_map(case, ("slider.normal_damping", np.linspace(4, 14, 6)),
                       ("slider.rotational_damping", np.linspace(0.2, 3.0, 30)))
    stable = ds["stable"].values.astype(bool)
    boundary = ds["boundary"].values
    assert np.isfinite(boundary).any()
    for ix, b in enumerate(boundary):
        if np.isfinite(b):
            ys = ds["slider.rotational_damping"].values
            assert stable[ys > b + 1e-9, ix].all()
            assert not stable[np.searchsorted(ys, b) - 1, ix]


def test_stability_map_rejects_bad_axis_values():
    with pytest.raises(CaseError, match=r"slider\.normal_damping"):
        stability_map(Case(), ("slider.normal_damping", [-1.0, 1.0]),
                      ("slider.rotational_damping", [0.1, 1.0]))


def test_stability_command(tmp_path):
    runner = CliRunner()
    out = runner.invoke(cli, ["stability"])
    assert out.exit_code == 0 and "unstable" in out.output and "phi" in out.output
    target = tmp_path / "map.nc"
    out = runner.invoke(cli, ["stability", "--x", "normal_damping=1:12:5",
                              "--y", "rotational_damping=0.2:3:4", "--curves", "decay=0,1",
                              "-o", str(target), "--no-progress"])
    assert out.exit_code == 0, out.output
    import xarray as xr

    ds = xr.open_dataset(target)
    assert ds["max_growth_rate"].dims == ("friction.decay", "slider.rotational_damping",
                                          "slider.normal_damping")
    assert ds["max_growth_rate"].shape == (2, 4, 5)
    assert ds["max_growth_rate"].attrs["units"] == "1/s"
    assert ds["slider.normal_damping"].attrs["units"] == "N s/m"
    np.testing.assert_allclose(ds["friction.decay"].values, [0.0, 1.0])
    bad = runner.invoke(cli, ["stability", "--x", "normal_dampin=1:2:3", "--y", "decay=0:1:2"])
    assert bad.exit_code == 2 and "did you mean 'slider.normal_damping'" in bad.output


def test_map_boundary_found_whichever_side_is_stable():
    """The issue's case: stable at high speed and low friction. With the stable side
    below (speed on y) or above (friction on y) the grid's boundary is found in the
    columns it crosses, at the same place."""
    case = load_case(examples.path("two-pads")).replace({"disc.damping_ratio": 0.002})
    speed = ("speed.value", np.linspace(1.0, 30.0, 8))
    friction = ("friction.kinetic_max", np.linspace(0.35, 0.8, 10))
    one = stability_map(case, speed, friction)
    other = stability_map(case, friction, speed)
    assert np.isfinite(one["boundary"].values).sum() >= 6
    assert np.isfinite(other["boundary"].values).sum() >= 6
    np.testing.assert_array_equal(one["stable"].values, other["stable"].values.T)


def test_stability_command_branches_and_boundary(tmp_path):
    import xarray as xr

    runner = CliRunner()
    out = runner.invoke(cli, ["stability", "fig03a", "--x", "rotational_damping=0:3:16",
                              "-o", str(tmp_path / "br.nc"), "--no-progress"])
    assert out.exit_code == 0, out.output
    assert "Hopf point at slider.rotational_damping = 0.98" in out.output
    ds = xr.open_dataset(tmp_path / "br.nc")
    assert ds["growth_rate"].dims == ("slider.rotational_damping", "branch")
    out = runner.invoke(cli, ["stability", "fig03b", "--boundary", "normal_damping=0:12",
                              "rotational_damping=0:3", "-o", str(tmp_path / "b.nc")])
    assert out.exit_code == 0, out.output
    assert "boundary curve 0 (open" in out.output and "C00" in out.output
    ds = xr.open_dataset(tmp_path / "b.nc")
    assert ds.sizes["point"] > 10 and ds.attrs["x_key"] == "slider.normal_damping"


@pytest.mark.parametrize(("args", "message"), [
    (["--x", "law=0:1:5"], "friction.law is invalid: its value 'exponential' is not a number"),
    (["--x", "decay=1:1:5"], "must be distinct"),
    (["--x", "decay=-1:1:5"], "friction.decay = -1.0 is invalid: must be >= 0"),
    (["--boundary", "decay=0:1", "decay=1:2"], "varies the same key"),
    (["--boundary", "decay=0:1", "normal_damping=1"], "write KEY=START:STOP"),
    (["--x", "decay=0:1:5", "--y", "decay=0:2:3"], "varies the same key"),
    (["--y", "decay=0:1:5"], "--y needs --x"),
    # Issue 28, item 4: a degenerate axis (START == STOP, or a value twice), also of
    # --y and --curves, and the option and value named.
    (["--x", "speed.value=0:0:5", "--y", "decay=0:1:2"],
     "--x = 'speed.value=0:0:5' is invalid: its values must be distinct"),
    (["--x", "decay=0:1:2", "--y", "speed.value=2,3,2"],
     "--y = 'speed.value=2,3,2' is invalid: its values must be distinct"),
    (["--x", "decay=0:1:2", "--y", "speed.value=1:2:2", "--curves", "slider.mass=0.1,0.1"],
     "--curves = 'slider.mass=0.1,0.1' is invalid: its values must be distinct"),
    (["--x", "decay=0:1:2", "--y", "speed.value=0,-0.0"], "its values must be distinct"),
])
def test_stability_command_refuses_bad_scans(args, message):
    out = run_cli(["stability", "fig03a", *args, "--no-progress"])
    assert out.exit_code == 2, out.output
    assert message in out.output and len(out.output.strip().splitlines()) == 1


def test_stability_command_refuses_a_case_without_sliding_equilibrium():
    out = run_cli(["stability", "fig10", "--x", "decay=0:1:5",
                                   "--no-progress"])
    assert out.exit_code == 2 and "no sliding equilibrium" in out.output
    assert len(out.output.strip().splitlines()) == 1


def test_a_map_without_any_sliding_equilibrium_says_so(tmp_path):
    """Issue 28, item 4: a map whose every point is NaN (no preload: no sliding
    equilibrium anywhere) was reported "stable at 0.0 % of the grid"."""
    case = tmp_path / "p0.toml"
    Case(slider={"preload": 0.0}).save(case)
    target = tmp_path / "map.nc"
    out = run_cli(["stability", str(case), "--x", "speed.value=1:2:3",
                                   "--y", "slider.mass=0.1:0.2:2", "-o", str(target),
                                   "--no-progress"])
    assert out.exit_code == 2, out.output
    assert out.stderr.startswith("error: stability map: no point of the grid (--x "
                                 "speed.value, --y slider.mass) has a sliding equilibrium")
    assert len(out.output.strip().splitlines()) == 1 and "stable at" not in out.output
    assert not target.exists()


def test_a_map_counts_stability_among_the_points_with_an_equilibrium(tmp_path):
    # One curve of the map without any equilibrium (zero preload), one with half of it
    # (none at zero speed): the percentages count only the points with an equilibrium.
    import xarray as xr

    target = tmp_path / "map.nc"
    out = run_cli(["stability", "--x", "speed.value=0:2:3",
                                   "--y", "slider.mass=0.1:0.2:2",
                                   "--curves", "slider.preload=0,1", "-o", str(target),
                                   "--no-progress"])
    assert out.exit_code == 0, out.output
    lines = out.stdout.splitlines()
    assert lines[1] == ("slider.preload = 0: no sliding equilibrium at any point of the grid "
                        "(no stability to map)")
    growth = xr.open_dataset(target)["max_growth_rate"].sel({"slider.preload": 1.0}).values
    known = np.isfinite(growth)
    assert known.sum() == 4 and not known[:, 0].any()  # none at zero speed
    share = (growth[known] < 0).mean()
    assert lines[2].startswith(f"slider.preload = 1: stable at {share:.1%} of the 4 grid "
                               "points with a sliding equilibrium (2 of 6 have none)")


def test_plot_command_draws_saved_branches_and_boundaries(tmp_path):
    runner = CliRunner()
    for args, name in ((["--x", "rotational_damping=0:3:8"], "br.nc"),
                       (["--boundary", "normal_damping=0:12", "rotational_damping=0:3"],
                        "b.nc")):
        saved = tmp_path / name
        out = runner.invoke(cli, ["stability", "fig03a", *args, "-o", str(saved),
                                  "--no-progress"])
        assert out.exit_code == 0, out.output
        figure = tmp_path / f"{name}.png"
        out = runner.invoke(cli, ["plot", str(saved), "-o", str(figure)])
        assert out.exit_code == 0, out.output
        assert figure.read_bytes()[:4] == b"\x89PNG"


def test_scans_without_output_write_beside_the_case_under_its_name(tmp_path, monkeypatch):
    """Without -o a scan wrote branches.nc, boundary.nc or stability.nc in the working
    directory whatever the case, so the scan of a second case silently replaced the
    first's. Like `fivdisc simulate`, each now writes beside the case file, named after
    it (a packaged example's in the working directory), and says where."""
    monkeypatch.chdir(tmp_path)
    for name in ("one", "two"):
        (tmp_path / "cases").mkdir(exist_ok=True)
        (tmp_path / "cases" / f"{name}.toml").write_text("[speed]\nvalue = 1.0\n")
    written = []
    for name in ("one", "two"):
        case = str(tmp_path / "cases" / f"{name}.toml")
        for args in (["--x", "speed.value=1:2:3"],
                     ["--x", "speed.value=1:2:3", "--y", "decay=0:1:2"],
                     ["--boundary", "speed.value=1:2", "decay=0:1"]):
            out = run_cli(["stability", case, *args, "--no-progress"])
            assert out.exit_code == 0, out.output
            written.append(out.output.split("wrote ", 1)[1].split()[0])
    assert written == [str(tmp_path / "cases" / f"{name}-{kind}.nc")
                       for name in ("one", "two") for kind in ("branches", "stability", "boundary")]
    assert all(Path(path).is_file() for path in written)
    assert not list(tmp_path.glob("*.nc"))
    example = run_cli(["stability", "fig03a", "--x",
                                       "rotational_damping=0:3:3", "--no-progress"])
    assert example.exit_code == 0, example.output
    assert (tmp_path / "fig03a-branches.nc").is_file()
