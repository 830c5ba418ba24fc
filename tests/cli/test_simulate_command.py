"""The ``fivdisc simulate`` command and the guard against endless switching."""

from __future__ import annotations

import importlib

import numpy as np
import pytest
import xarray as xr

from fivdisc import Case, simulate

from support.cli import run_cli


def _write(tmp_path, case: Case):
    path = tmp_path / "case.toml"
    case.save(path)
    return path


def test_simulate_writes_netcdf_with_units_and_summary(tmp_path):
    path = _write(tmp_path, Case(simulation={"duration": 0.05}))
    out = tmp_path / "out.nc"
    res = run_cli(["simulate", str(path), "-o", str(out), "--no-progress"])
    assert res.exit_code == 0, res.output
    for word in ("time in phase", "switches", "peak normal force", "wall time"):
        assert word in res.output
    ds = xr.open_dataset(out)
    for name, var in {**ds.data_vars, **ds.coords}.items():
        assert "units" in var.attrs and "long_name" in var.attrs, name
    assert ds.attrs["status"] == "success"
    assert Case.from_toml(ds.attrs["case"]) == Case(simulation={"duration": 0.05})
    assert set(ds["event_kind"].values) <= {"stick", "slip", "reversal", "separation",
                                            "recontact"}


def test_failed_run_saves_data_and_exits_nonzero(tmp_path):
    path = _write(tmp_path, Case(simulation={"duration": 0.2, "max_switches": 3}))
    out = tmp_path / "out.nc"
    res = run_cli(["simulate", str(path), "-o", str(out), "--no-progress"])
    assert res.exit_code == 1
    last = res.output.strip().splitlines()[-1]
    assert last.startswith("error: simulation failed") and "t = " in last
    ds = xr.open_dataset(out)
    assert ds.attrs["status"] == "max_switches"
    assert 0 < ds.sizes["time"] < 2001


def test_bad_case_file_is_one_line(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[slider]\nmas = 1.0\n")
    res = run_cli(["simulate", str(path)])
    assert res.exit_code == 2
    assert res.output.strip().count("\n") == 0 and "did you mean 'slider.mass'" in res.output
    missing = run_cli(["simulate", str(tmp_path / "nope.toml")])
    assert missing.exit_code == 2 and "Traceback" not in missing.output


def test_endless_switching_stops_with_status(monkeypatch):
    # No physical case here chatters (the phase choice prevents it), so the guard is
    # exercised by declaring any 5 consecutive switches less than 1 s apart "endless".
    integration = importlib.import_module("fivdisc.engine.integration")
    monkeypatch.setattr(integration, "ZENO_DT", 1.0)
    monkeypatch.setattr(integration, "ZENO_COUNT", 5)
    res = simulate(Case(simulation={"duration": 0.5}))
    assert res.status == "endless_switching"
    assert "endless switching" in res.message and "t = " in res.message
    # The first switch starts the count; five more within 1 s of each other trip it.
    assert res.dataset.attrs["n_switches"] == 6
    assert np.isfinite(res.dataset["phi"].values).all()


@pytest.mark.parametrize("argv", [["--help"], ["simulate", "--help"]])
def test_python_dash_m(argv):
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", "fivdisc", *argv], capture_output=True,
                         text=True, check=True)
    assert "Usage" in out.stdout
