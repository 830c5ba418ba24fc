"""Figures as a researcher publishes them (issue 40, item 2): what each draws (axis
scales, lines, legend entries, titles), checked against the data it draws."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from matplotlib.contour import ContourSet

from fivdisc import plots
from fivdisc.analysis.boundary import stability_boundary
from fivdisc.analysis.eigenbranches import eigen_branches
from fivdisc.analysis.hopf import hopf_points, with_hopf_points
from fivdisc.analysis.stability import linear_stability, stability_map
from fivdisc.case import Case, load_case
from fivdisc.errors import FivdiscError
from fivdisc.examples import path
from fivdisc.files import write_netcdf

from support.cases import THREE_PADS
from support.cli import messages, run_cli


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


def _outside_canvas(fig) -> list[str]:
    """Texts drawn (titles, labels, legends, the tick labels shown) not wholly inside
    the figure's canvas."""
    from matplotlib.text import Text

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    canvas = fig.bbox.padded(0.5)
    axes = [*fig.axes, *(child for ax in fig.axes for child in ax.child_axes)]
    ticks = [(axis, t) for ax in axes for axis in (ax.xaxis, ax.yaxis)
             for tick in (*axis.majorTicks, *axis.minorTicks)
             for t in (tick.label1, tick.label2)]
    shown = {id(t) for ax in axes for axis in (ax.xaxis, ax.yaxis)
             for tick in axis._update_ticks() for t in (tick.label1, tick.label2)}
    hidden = {id(t) for _, t in ticks if id(t) not in shown}
    return [t.get_text() for t in fig.findobj(Text) if t.get_visible() and t.get_text()
            and id(t) not in hidden
            and not (canvas.contains(*t.get_window_extent(renderer).min)
                     and canvas.contains(*t.get_window_extent(renderer).max))]


# --- eigenvalue branches -----------------------------------------------------------------


@pytest.fixture(scope="module")
def three_pad_branches():
    values = np.linspace(0.5, 30.0, 60)
    ds = eigen_branches(THREE_PADS, "speed.value", values)
    return with_hopf_points(ds, hopf_points(THREE_PADS, "speed.value", values, branches=ds))


def test_a_small_instability_beside_a_large_one_gets_a_symmetric_log_axis(
        three_pad_branches):
    """The (0, 2) pair's 3 1/s beside the pads' 417 1/s: on a linear axis a flat line at
    zero; the symmetric-log axis is linear within +-1 1/s and shows it."""
    ds = three_pad_branches
    growth = ds["growth_rate"].values
    assert np.nanmax(growth) > 400 and 1.0 < np.nanmax(growth[:10, 6:8]) < 5.0
    bottom = plots.plot_eigen_branches(ds).axes[1]
    assert bottom.get_yscale() == "symlog"
    linthresh = bottom.yaxis.get_transform().linthresh
    assert linthresh <= 1.0
    assert "symmetric log" in bottom.get_ylabel()
    linear = plots.plot_eigen_branches(ds, growth_scale="linear").axes[1]
    assert linear.get_yscale() == "linear"
    # Rates of one size stay on a linear axis: the rigid disc's one slider mode.
    calm = eigen_branches(Case(disc={"modes": []}, slider={"rotational_damping": 0.5},
                               friction={"decay": 1.0}), "speed.value",
                          np.linspace(0.5, 30.0, 7))
    assert plots.plot_eigen_branches(calm).axes[1].get_yscale() == "linear"


def test_the_branch_key_sits_beside_the_axes_one_entry_per_mode(three_pad_branches):
    fig = plots.plot_eigen_branches(three_pad_branches)
    (legend,) = fig.legends
    labels = [t.get_text() for t in legend.get_texts()]
    upper = three_pad_branches["frequency"].values[0] > 0
    assert sorted(labels) == sorted(three_pad_branches["mode"].values[upper].tolist())
    assert _outside_canvas(fig) == []


def test_each_hopf_dot_has_its_mode_s_colour(three_pad_branches):
    """The dots tie each Hopf point to its branch in the key: filled in the colour of the
    branch its stored label names."""
    from matplotlib.colors import to_hex

    fig = plots.plot_eigen_branches(three_pad_branches)
    top = fig.axes[0]
    colour = {t.get_text(): to_hex(h.get_color()) for t, h in
              zip(fig.legends[0].get_texts(), fig.legends[0].legend_handles, strict=True)}
    dots = [line for line in top.lines if line.get_marker() == "o"]
    ds = three_pad_branches
    assert len(dots) == ds.sizes["hopf"] > 0
    for line, value, mode in zip(dots, ds["hopf"].values, ds["hopf_mode"].values,
                                 strict=True):
        assert line.get_xdata()[0] == value
        assert to_hex(line.get_markerfacecolor()) == colour[str(mode)]


def test_the_growth_scale_is_an_option_of_both_commands(three_pad_branches, tmp_path):
    saved = tmp_path / "branches.nc"
    write_netcdf(saved, three_pad_branches.to_netcdf)
    res = run_cli(["plot", saved, "--growth-scale", "linear", "-o", tmp_path / "b.png"])
    assert res.exit_code == 0, res.output
    case = tmp_path / "three.toml"
    case.write_text(THREE_PADS.to_toml())
    res = run_cli(["stability", case, "--x", "speed.value=0.5:30:20", "--growth-scale",
                   "symlog", "-o", tmp_path / "s.png", "--no-progress"])
    assert res.exit_code == 0, res.output
    res = run_cli(["stability", case, "--growth-scale", "symlog"])
    assert res.exit_code == 2
    assert "--growth-scale is used only by the figure of --x alone" in messages(res.stderr)[0]


# --- the stability boundary over a map ------------------------------------------------------


def test_the_exact_boundary_replaces_the_grid_line_where_they_disagree():
    """On a 5 x 5 grid the interpolated boundary strays from the exact curve; with the
    exact curve given, it is drawn over the shading and the grid's own contour line is
    not drawn at all (the shading keeps the grid's field)."""
    case = load_case(path("fig03a"))
    box = [("slider.normal_damping", (0.0, 12.0)), ("slider.rotational_damping", (0.0, 3.0))]
    exact = stability_boundary(case, *box)
    grid = stability_map(case, *[(key, np.linspace(*ends, 5)) for key, ends in box])
    # The two disagree: the grid's boundary at its columns against the exact curve.
    xs, ys = exact["slider.normal_damping"].values, exact["slider.rotational_damping"].values
    order = np.argsort(xs)
    columns = grid["slider.normal_damping"].values
    coarse = grid["boundary"].values
    known = np.isfinite(coarse) & (columns >= xs.min()) & (columns <= xs.max())
    assert np.max(np.abs(coarse[known] - np.interp(columns[known], xs[order], ys[order]))) > 0.05

    ax = plots.plot_stability_map(grid, boundary=exact).axes[0]
    contours = [c for c in ax.collections if isinstance(c, ContourSet)]
    assert contours and all(c.filled for c in contours)  # shading only, no grid line
    drawn = [line for line in ax.lines if line.get_xydata().size]
    assert len(drawn) == np.unique(exact["branch"].values).size
    for line in drawn:
        assert line.get_zorder() > max(c.get_zorder() for c in contours)
        x, y = line.get_data()
        assert np.all(np.isin(x, xs)) and np.all(np.isin(y, ys))
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "exact boundary" in labels and "grid boundary" not in labels
    # Without the exact curve the grid's line is drawn, as before.
    alone = plots.plot_stability_map(grid).axes[0]
    assert any(not c.filled for c in alone.collections if isinstance(c, ContourSet))


# --- spectrogram of a braking run -----------------------------------------------------------


@pytest.fixture(scope="module")
def braking():
    """0.2 s of the three pads braking from 22 rad/s to rest in 2 s, named long."""
    from fivdisc import simulate

    case = THREE_PADS.replace({
        "speed": {"profile": "decelerating", "initial": 22.0, "duration": 2.0},
        "simulation": {"duration": 0.2, "output_rate": 10000.0}})
    return simulate(case).named("three-pad-brake-study-at-22-rad-per-s")


def test_the_spectrogram_title_fits_two_lines_and_a_braking_run_gets_a_speed_axis(braking):
    fig = braking.plot("spectrogram", slider=1)
    ax = fig.axes[0]
    title = ax.get_title().split("\n")
    assert len(title) == 2
    assert title[0].startswith("three-pad-brake-study-at-22-rad-per-s: spectrogram of ")
    assert "slider 1" in title[0] and "disc slowing from 22 rad/s" in title[1]
    (top,) = ax.child_axes
    assert top.get_xlabel() == "disc speed [rad/s]"
    # Its ends read the disc's speed at the time axis' ends.
    speed = braking.dataset["disc_speed"]
    fig.canvas.draw()
    t0, t1 = ax.get_xlim()
    ends = sorted(float(speed.interp(time=t)) for t in (t0, t1))
    assert sorted(top.get_xlim()) == pytest.approx(ends, rel=1e-9)
    assert ends[1] == pytest.approx(22.0) and ends[0] < 22.0  # slowing
    assert _outside_canvas(fig) == []
    # A run at constant speed has none.
    from fivdisc import simulate

    steady = simulate(Case(simulation={"duration": 0.05})).plot("spectrogram")
    assert steady.axes[0].child_axes == []


# --- branches of periodic orbits ------------------------------------------------------------


@pytest.fixture(scope="module")
def hopf_branch():
    from fivdisc.continuation.from_hopf import hopf_cycles

    case = Case(disc={"modes": []}, slider={"rotational_damping": 0.5},
                friction={"decay": 1.0}, speed={"value": 1.0})
    (point,) = hopf_points(case, "speed.value", np.linspace(0.5, 30.0, 25))
    return hopf_cycles(point, 30.0, max_points=12)


def test_a_branch_figure_names_its_key_and_draws_the_sliding_equilibrium(hopf_branch):
    from fivdisc.plots.branch import plot_branch

    fig = plot_branch(hopf_branch, "normal_force", equilibrium=True)
    ax = fig.axes[0]
    assert ax.get_xlabel() == r"disc speed $\Omega_c$ [rad/s]"
    assert "speed.value" not in ax.get_title()
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "sliding equilibrium, stable" in labels and "sliding equilibrium, unstable" in labels
    grey = [line for line in ax.lines if line.get_color() == "0.35"
            and line.get_linestyle() in ("-", "--") and line.get_xydata().size > 2]
    assert {line.get_linestyle() for line in grey} == {"-", "--"}
    # Second route: the plain equilibrium solve at points of the drawn curve, and its
    # stability: unstable below the Hopf speed, stable above.
    hopf = hopf_branch.hopf()["value"]
    for line in grey:
        x, y = line.get_data()
        for value, force in zip(x[:: max(1, x.size // 3)], y[:: max(1, x.size // 3)],
                                strict=True):
            lin = linear_stability(hopf_branch.case.replace({"speed.value": value}))
            assert force == pytest.approx(lin.equilibrium.normal_force[0], rel=1e-9)
            if abs(value - hopf) > 1e-6 * hopf:
                assert lin.stable == (line.get_linestyle() == "-")
                assert lin.stable == (value > hopf)
    with pytest.raises(FivdiscError, match="no period"):
        plot_branch(hopf_branch, "period", equilibrium=True)


def test_the_command_draws_a_branch_with_its_equilibrium(hopf_branch, tmp_path):
    saved = tmp_path / "hopf.nc"
    hopf_branch.to_netcdf(saved)
    res = run_cli(["plot", saved, "--var", "phi_dot", "--equilibrium", "-o",
                   tmp_path / "b.png"])
    assert res.exit_code == 0, res.output


# --- what fivdisc plot refuses ---------------------------------------------------------------


@pytest.fixture(scope="module")
def map_file(tmp_path_factory):
    out = tmp_path_factory.mktemp("maps") / "map.nc"
    res = run_cli(["stability", "fig03b", "--x", "normal_damping=4:14:4",
                   "--y", "rotational_damping=0.2:3:4", "-o", out, "--no-progress"])
    assert res.exit_code == 0, res.output
    return out


@pytest.mark.parametrize(("option", "word"), [
    (["--kind", "spectrum"], "--kind"), (["--kind", "timeseries"], "--kind"),
    (["--slider", "1"], "--slider"), (["--growth-scale", "symlog"], "--growth-scale"),
    (["--equilibrium"], "--equilibrium"),
])
def test_a_map_refuses_the_options_of_other_figures(map_file, tmp_path, option, word):
    res = run_cli(["plot", map_file, *option, "-o", tmp_path / "m.png"])
    assert res.exit_code == 2
    (line,) = messages(res.stderr)
    assert line.startswith(f"error: {word} is not used for ")
    assert not (tmp_path / "m.png").exists()
    assert run_cli(["plot", map_file, "-o", tmp_path / "m.png"]).exit_code == 0


def test_a_netcdf_file_fivdisc_did_not_write_is_refused(tmp_path):
    """A file with a time axis and a variable named phi, but no fivdisc checksum or
    source: not drawn as a result, neither by the command nor by open_result."""
    from fivdisc.engine.result import open_result

    t = np.linspace(0.0, 0.1, 101)
    foreign = tmp_path / "foreign.nc"
    xr.Dataset({"phi": ("time", np.sin(2 * np.pi * 50 * t), {"units": "rad"})},
               coords={"time": t}, attrs={"source": "a data logger"}).to_netcdf(foreign)
    res = run_cli(["plot", foreign, "-o", tmp_path / "f.png"])
    assert res.exit_code == 2
    (line,) = messages(res.stderr)
    assert "foreign.nc was not written by fivdisc" in line
    assert not (tmp_path / "f.png").exists()
    with pytest.raises(FivdiscError, match="was not written by fivdisc"):
        open_result(foreign)
