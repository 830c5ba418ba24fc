"""Every dataset fivdisc writes follows the CF conventions and names its dimensions after
what they are (issue 12, item 3); results read back as they were written (issue 12, item
4; issue 13, item 4)."""

from __future__ import annotations

import pickle
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from fivdisc import Case, FivdiscError, examples, load_case, open_result, simulate

from support.cf_check import check_cf
from support.cli import run_cli

SHORT = {"simulation.duration": 0.05, "simulation.output_rate": 2000.0}


@pytest.fixture(scope="module")
def two_pads():
    """Two sliders with the energy balance recorded: every variable a result can hold."""
    case = load_case(examples.path("two-pads")).replace(
        {**SHORT, "simulation.energy_balance": True})
    return simulate(case)


def test_simulation_result(two_pads, tmp_path):
    path = tmp_path / "run.nc"
    two_pads.to_netcdf(path)
    with xr.open_dataset(path) as ds:
        check_cf(ds)
        assert ds.cf["T"].name == "time" and ds["time"].attrs["standard_name"] == "time"
        assert ds["phi"].dims == ("time", "slider")
        assert ds.attrs["title"].startswith("fivdisc simulation: 2 sliders, disc at 6.283 rad/s")


def test_result_round_trips_through_netcdf_and_pickle(two_pads, tmp_path):
    path = tmp_path / "run.nc"
    two_pads.to_netcdf(path)
    back = open_result(path)
    xr.testing.assert_identical(back.dataset, two_pads.dataset)
    assert back == two_pads
    assert pickle.loads(pickle.dumps(two_pads)) == two_pads
    assert back.summary() == two_pads.summary()
    # ... and a round trip of the round trip changes nothing either
    back.to_netcdf(tmp_path / "again.nc")
    assert open_result(tmp_path / "again.nc") == two_pads


def test_open_result_names_what_else_a_file_is(tmp_path):
    (tmp_path / "text.nc").write_text("not netCDF")
    with pytest.raises(FivdiscError, match=r"cannot read .*text\.nc as a fivdisc result"):
        open_result(tmp_path / "text.nc")
    with pytest.raises(FileNotFoundError):
        open_result(tmp_path / "none.nc")
    out = tmp_path / "map.nc"
    _map_command(out)
    with pytest.raises(FivdiscError, match=r"map\.nc is a stability map \(fivdisc stability\): "
                       "read it with xarray.open_dataset, draw it with fivdisc plot"):
        open_result(out)


def _map_command(out: Path, *extra: str) -> None:
    run = run_cli(["stability", "fig03b", "--x", "normal_damping=4:12:3",
                                   "--y", "rotational_damping=0.5:3:3", *extra, "-o", str(out),
                                   "--no-progress"])
    assert run.exit_code == 0, run.output


@pytest.mark.parametrize("curves", [False, True])
def test_stability_map(tmp_path, curves):
    out = tmp_path / "map.nc"
    _map_command(out, *(["--curves", "decay=0,10"] if curves else []))
    with xr.open_dataset(out) as ds:
        check_cf(ds)
        keys = ["slider.rotational_damping", "slider.normal_damping"]
        assert list(ds["max_growth_rate"].dims) == (["friction.decay"] if curves else []) + keys
        assert ds["boundary"].dims[-1] == "slider.normal_damping"
        assert ds["boundary"].attrs["units"] == "N m s/rad"
        assert ds["slider.normal_damping"].attrs["long_name"] == "slider normal damping"
        assert ds["slider.normal_damping"].attrs["symbol"] == "c_z"
        assert ds.attrs["case_name"] == "fig03b"


def _open_quietly(store: Path) -> xr.Dataset:
    """xarray.open_zarr as a user calls it, any warning an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return xr.open_zarr(store).load()


def test_sweep_store_opens_on_its_grid_without_warnings(tmp_path):
    from fivdisc.sweep import Sweep, open_sweep, run_sweep

    spec = Sweep(base=Case(simulation={"duration": 0.02, "output_rate": 1000.0}),
                 axes={"slider.normal_damping": [0.1, 0.5], "speed.value": [5.0, 6.0, 7.0]},
                 keep=["max_normal_force", "separated"])
    run_sweep(spec, tmp_path / "s.zarr", workers=1, progress=False)
    ds = _open_quietly(tmp_path / "s.zarr")
    check_cf(ds)
    assert ds["max_normal_force"].dims == ("slider.normal_damping", "speed.value")
    assert ds["speed.value"].attrs["units"] == "rad/s"
    np.testing.assert_array_equal(ds["speed.value"], [5.0, 6.0, 7.0])
    # open_sweep gives the same grid, its done flags verified
    mine = open_sweep(tmp_path / "s.zarr")
    xr.testing.assert_equal(mine["max_normal_force"], ds["max_normal_force"])
    assert mine["done"].all()


def test_zip_sweep_is_along_points(tmp_path):
    from fivdisc.sweep import Sweep, run_sweep

    spec = Sweep(base=Case(simulation={"duration": 0.02, "output_rate": 1000.0}), mode="zip",
                 axes={"slider.normal_damping": [0.1, 0.5], "speed.value": [5.0, 7.0]},
                 keep=["max_normal_force"])
    run_sweep(spec, tmp_path / "z.zarr", workers=1, progress=False)
    ds = _open_quietly(tmp_path / "z.zarr")
    check_cf(ds)
    assert ds["max_normal_force"].dims == ("point",)
    np.testing.assert_array_equal(ds["speed.value"], [5.0, 7.0])


def test_separation_map_store(tmp_path):
    store = tmp_path / "map.zarr"
    run = run_cli(["separation-map", "--x", "12:20:2", "--y", "0.5:1:2",
                                   "-o", str(store), "--workers", "1", "--no-progress"])
    assert run.exit_code == 0, run.output
    ds = _open_quietly(store)
    check_cf(ds)
    assert ds["separated"].dims == ("speed.initial", "speed.duration")
    assert ds["speed.duration"].attrs["long_name"] == "time to stop"
