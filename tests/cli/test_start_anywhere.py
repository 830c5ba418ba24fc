"""Start anywhere (issue 36, item 6): ``--from BRANCH --point K`` in ``orbit``, ``continue``
and ``simulate``; ``simulate --from FILE`` from a result's final state or an orbit."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.continuation.walk import continue_orbit

from support.cases import RIGID, rigid_disc_closed_form
from support.cli import run_cli


@pytest.fixture(scope="module")
def branch_file(tmp_path_factory):
    orbit = periodic_orbit(RIGID, transient=4.0)
    br = continue_orbit(RIGID.replace({"simulation.duration": 0.05}), "speed.value", 1.3,
                        orbit=orbit, max_points=5)
    path = tmp_path_factory.mktemp("branch") / "rigid.nc"
    br.to_netcdf(path)
    return path, br


def test_orbit_from_a_branch_point_is_that_point(branch_file):
    path, br = branch_file
    res = run_cli(["orbit", "--from", path, "--point", 2, "--json", "--no-progress"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out["period"] == pytest.approx(br.period[2], rel=1e-9)
    # a second route: the closed form at the point's speed
    assert out["period"] == pytest.approx(rigid_disc_closed_form(br.parameter[2])[0], rel=1e-8)
    assert f"from point 2 of the branch in {path}" in out["start"]


def test_continue_from_a_branch_point_starts_at_its_value(branch_file, tmp_path):
    path, br = branch_file
    out = tmp_path / "again.nc"
    res = run_cli(["continue", "--from", path, "--point", 1, "--key", "speed.value",
                   "--to", 1.25, "--points", 3, "-o", out, "--no-progress"])
    assert res.exit_code == 0, res.output
    again = xr.open_dataset(out)
    assert float(again["parameter"][0]) == pytest.approx(br.parameter[1], rel=1e-12)
    assert float(again["period"][0]) == pytest.approx(br.period[1], rel=1e-9)


def test_simulate_from_a_branch_point_runs_on_its_orbit(branch_file, tmp_path):
    """The run from point 3 stays on the orbit: its stick events come one period of the
    point apart (to 1e-9 of it: the run's tolerance) at the point's speed."""
    path, br = branch_file
    out = tmp_path / "run.nc"
    res = run_cli(["simulate", "--from", path, "--point", 3, "-o", out, "--no-progress"])
    assert res.exit_code == 0, res.output
    assert "started from point 3 of the branch" in res.stdout
    ds = xr.open_dataset(out)
    kinds = ds["event_kind"].values.astype(str)
    sticks = ds["event_time"].values[kinds == "stick"]
    assert sticks.size >= 3
    np.testing.assert_allclose(np.diff(sticks), br.period[3], rtol=1e-6)
    from fivdisc.case import Case

    assert Case.from_toml(ds.attrs["case"]).speed.value == br.parameter[3]

    # and on from that run's final state
    more = tmp_path / "more.nc"
    res = run_cli(["simulate", "--from", out, "-o", more, "--no-progress"])
    assert res.exit_code == 0, res.output
    first = xr.open_dataset(more)
    y0 = np.asarray(ds.attrs["final_state"])
    assert float(first["phi"].values[0].squeeze()) == pytest.approx(float(y0[1]), abs=1e-12)


def test_simulate_from_a_branch_point_at_another_value(branch_file, tmp_path, case_file):
    """--at runs the point's state at another value of the key (a forward run past an
    end); a case file's own value is not used silently: the output says which value runs.
    Second route: the run's sticks come at the closed form's period of the value run."""
    path, br = branch_file
    at = 1.05 * br.parameter[3]
    out = tmp_path / "at.nc"
    res = run_cli(["simulate", "--from", path, "--point", 3, "--at", at, "-o", out,
                   "--no-progress"])
    assert res.exit_code == 0, res.output
    assert f"note: run at speed.value = {at:.9g}, not the point's" in res.stdout
    ds = xr.open_dataset(out)
    sticks = ds["event_time"].values[ds["event_kind"].values.astype(str) == "stick"]
    # the stable orbit's disc mode decays by 0.92 a period: the last sticks are on the
    # orbit at the new value
    assert np.diff(sticks)[-1] == pytest.approx(rigid_disc_closed_form(at)[0], rel=1e-4)
    res = run_cli(["simulate", case_file(RIGID.replace({"speed.value": at})), "--from", path,
                   "--point", 3, "-o", tmp_path / "case.nc", "--no-progress"])
    assert res.exit_code == 0, res.output
    assert "the branch point's, not CASE_FILE's" in res.stdout
    bad = run_cli(["simulate", case_file(RIGID), "--at", 1.0, "-o", tmp_path / "b.nc"])
    assert bad.exit_code != 0 and "--at needs --from BRANCH" in bad.output


@pytest.mark.parametrize("command", [["orbit"], ["simulate", "-o", "x.nc"],
                                     ["continue", "--key", "speed.value", "--to", "2"]])
def test_a_point_needs_a_branch(command, tmp_path, case_file):
    res = run_cli([*command, case_file(RIGID), "--point", "1"])
    assert res.exit_code != 0
    assert "--point needs --from BRANCH" in res.output
