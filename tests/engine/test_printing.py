"""Results, summaries and eigenvalue tables print well and give their values (issue 13,
item 6); a file with several runs or a map is read by ``fivdisc plot`` (item 4)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from fivdisc import Case, FivdiscError, examples, linear_stability, load_case, open_result
from fivdisc import simulate as run
from fivdisc.cli import cli


@pytest.fixture(scope="module")
def pads():
    case = load_case(examples.path("two-pads")).replace({"simulation.duration": 0.05})
    return run(case).named("two-pads")


def test_result_repr_is_one_line(pads):
    text = repr(pads)
    assert "\n" not in text
    assert text.startswith("<fivdisc.Result two-pads: success, 0.05 s simulated, 2 slider(s), ")
    assert f"{pads.dataset.sizes['event']} events>" in text
    assert str(pads).splitlines()[1] == ("fivdisc simulation of two-pads: 2 sliders, disc at "
                                         "6.283 rad/s, 0.05 s")


def test_summary_prints_and_gives_values(pads):
    summary = pads.summary()
    lines = str(summary).splitlines()
    assert lines[0] == "status: success at t = 0.05 s"
    assert lines[1].startswith("slider 0 time in phase: slip ")
    assert lines[2].startswith("slider 1 time in phase: ")
    assert lines[-1].endswith("s (integration only)")
    # the values behind the text, per slider and in total
    phase = pads.dataset["phase"].values
    dt = np.diff(pads.dataset["time"].values)
    for j, slider in enumerate(summary.sliders):
        assert slider.time_in_phase["stick"] == pytest.approx(np.sum(dt[phase[:-1, j] == 1]))
        assert slider.peak_normal_force == pytest.approx(
            pads.dataset["normal_force"].values[:, j].max())
    assert summary.peak_normal_force == max(s.peak_normal_force for s in summary.sliders)
    # switches count instants (what simulation.max_switches limits), phase changes the
    # event table's rows (one instant may change several sliders)
    assert summary.switches == pads.dataset.attrs["n_switches"]
    assert summary.phase_changes == pads.dataset.sizes["event"] >= summary.switches
    table = summary.to_dataframe()
    assert list(table.index) == [0, 1] and "stick [s]" in table.columns
    assert summary.to_dict()["sliders"][1]["separations"] == summary.sliders[1].separations


def test_result_to_dataframe_is_the_per_slider_series(pads):
    """Issue 27, item 8: the README's ``.to_dataframe()`` exists on a result; its rows are
    the dataset's samples of each slider, its columns the per-slider variables."""
    ds = pads.dataset
    table = pads.to_dataframe()
    assert table.index.names == ["time", "slider"]
    assert len(table) == ds.sizes["time"] * ds.sizes["slider"]
    assert {"phi", "phi_dot", "normal_force", "friction_force", "phase", "disc_speed"} <= set(
        table.columns)
    assert "w" not in table.columns  # the disc's probes have their own dimension
    second = table.xs(1, level="slider")
    np.testing.assert_array_equal(second["normal_force"].to_numpy(),
                                  ds["normal_force"].values[:, 1])
    np.testing.assert_array_equal(second.index.to_numpy(), ds["time"].values)


def test_linear_stability_prints_a_table():
    stability = linear_stability(Case())
    assert "\n" not in repr(stability)
    assert repr(stability).startswith("<LinearStability at Omega = 6.28319 rad/s: unstable, ")
    lines = str(stability).splitlines()
    assert lines[0] == "sliding equilibrium at Omega = 6.28319 rad/s:"
    assert lines[2].split() == ["growth", "rate", "[1/s]", "frequency", "[Hz]", "mode"]
    table = stability.to_dataframe()
    assert list(table.columns) == ["growth_rate", "frequency_hz", "coordinate"]
    # one row per complex pair (or real eigenvalue), strongest first
    assert len(table) == np.sum(stability.eigenvalues.imag >= 0)
    assert table["growth_rate"].is_monotonic_decreasing
    assert len(lines) == 3 + len(table) + 1


def test_several_runs_and_maps_are_read_by_plot(pads, tmp_path):
    """A file of several runs (as fivdisc reproduce writes them) and a stability map."""
    path = tmp_path / "runs.nc"
    other = run(Case(simulation={"duration": 0.05})).named("one")
    xr.DataTree.from_dict({"a": pads.dataset, "b": other.dataset}).to_netcdf(path)
    runner = CliRunner()
    choose = runner.invoke(cli, ["plot", str(path), "-o", str(tmp_path / "f.png")])
    assert choose.exit_code == 2
    assert "runs.nc holds the runs a, b: choose one with --run LABEL" in choose.stderr
    drawn = runner.invoke(cli, ["plot", str(path), "--run", "b", "--kind", "phase", "-o",
                                str(tmp_path / "f.png")])
    assert drawn.exit_code == 0, drawn.output
    with pytest.raises(FivdiscError, match="holds the runs a, b: choose one with run="):
        open_result(path)
    assert open_result(path, run="b") == other
    assert open_result(path, run="a") == pads

    map_file = tmp_path / "map.nc"
    made = runner.invoke(cli, ["stability", "--x", "normal_damping=4:12:3", "--y",
                               "rotational_damping=0.5:3:3", "-o", str(map_file),
                               "--no-progress"])
    assert made.exit_code == 0, made.output
    drawn = runner.invoke(cli, ["plot", str(map_file), "-o", str(tmp_path / "map.svg")])
    assert drawn.exit_code == 0, drawn.output
    assert "slider normal damping" in (tmp_path / "map.svg").read_text()
    refused = runner.invoke(cli, ["plot", str(map_file), "--var", "phi"])
    assert refused.exit_code == 2 and "--var is not used for" in refused.stderr
