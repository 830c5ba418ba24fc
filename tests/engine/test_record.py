"""A run's record (fivdisc.engine.record) writes the netCDF file xarray writes for its dataset.

``fivdisc simulate`` writes its result without importing xarray (issue 29, item 2): the
file must be the one ``xarray.Dataset.to_netcdf`` writes with its default encoding, so
that a reader cannot tell which wrote it. xarray is the reference here: both files'
checksums (every group's attributes and every variable's name, type, shape, stored
values and attributes, fivdisc.files.netcdf_checksum) must be equal, not merely the
decoded datasets.
"""

from __future__ import annotations

import pickle
from pathlib import Path

import netCDF4
import numpy as np
import pytest

from fivdisc import Case, open_result, simulate
from fivdisc.engine.record import Record
from fivdisc.engine.result import Result
from fivdisc.files import netcdf_checksum

CASES = {
    # The default case: events, one slider, two probes.
    "one slider": Case(simulation={"duration": 0.05}),
    # Two sliders on either face, the energy terms (a fifth coordinate, energy_term),
    # a decelerating disc.
    "two faces, energy": Case(
        sliders=[{"angle": 0.0}, {"angle": 1.0, "face": "bottom"}],
        speed={"profile": "decelerating", "initial": 10.0, "duration": 5.0},
        simulation={"duration": 0.05, "energy_balance": True},
    ),
    # No switch at all (no friction): an empty event dimension.
    "no events": Case(friction={"kinetic_max": 0.0, "kinetic_min": 0.0},
                      simulation={"duration": 0.02}),
    # One sample: shorter than an output interval.
    "one sample": Case(simulation={"duration": 1e-5}),
    # No probe: an empty probe dimension.
    "no probes": Case(simulation={"duration": 0.02, "probes": []}),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def record(request) -> Record:
    """The record of a run; each test makes its own result of it (reading a result's
    dataset turns its record into one)."""
    result = simulate(CASES[request.param], progress=False).named("case")
    assert isinstance(result._data, Record)
    return result._data


def _listing(path: Path) -> dict:
    """Dimensions, and per variable its type, dimensions and attribute names."""
    with netCDF4.Dataset(path) as root:
        return {"dimensions": {name: len(d) for name, d in root.dimensions.items()},
                "attributes": sorted(root.ncattrs()),
                "variables": {name: (str(v.dtype), v.dimensions, sorted(v.ncattrs()))
                              for name, v in root.variables.items()}}


def test_the_record_writes_the_file_xarray_writes(record: Record, tmp_path: Path) -> None:
    ours, theirs = tmp_path / "record.nc", tmp_path / "xarray.nc"
    record.to_netcdf(ours)
    record.to_xarray().to_netcdf(theirs)
    assert _listing(ours) == _listing(theirs)
    assert netcdf_checksum(ours) == netcdf_checksum(theirs)


def test_a_written_record_reads_back_as_its_dataset(record: Record, tmp_path: Path) -> None:
    path = tmp_path / "run.nc"
    result = Result(record)
    result.to_netcdf(path)
    back = open_result(path)
    assert isinstance(result._data, Record)  # written without building the dataset
    assert back == result
    assert back.summary() == result.summary()


def test_the_summary_of_a_record_is_that_of_its_dataset(record: Record) -> None:
    assert Result(record).summary() == Result(record.to_xarray()).summary()
    assert repr(Result(record)) == repr(Result(record.to_xarray()))


def test_a_result_pickles_with_its_record(record: Record) -> None:
    again = pickle.loads(pickle.dumps(Result(record)))
    assert isinstance(again._data, Record)
    assert again == Result(record)


def test_naming_a_result_leaves_the_original_as_it_was(record: Record) -> None:
    result = Result(record)
    other = result.named("other")
    assert other.name == "other" and result.name == "case"
    assert np.shares_memory(other._data["time"].values, result._data["time"].values)
    assert other.dataset.attrs["title"].startswith("fivdisc simulation of other: ")
