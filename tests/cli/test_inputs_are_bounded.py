"""Inputs that are not what a command reads are refused in one line before they are read
or used (issue 40, items 3 and 5): a device or a huge file as a case file, a netCDF file
whose attributes are damaged. One test per reproduction."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from fivdisc import Case, simulate
from fivdisc.files import MAX_TEXT_BYTES

from support.cli import messages, run_cli


def _refused(args: list, *words: str) -> str:
    result = run_cli(args)
    assert result.exception is None or isinstance(result.exception, SystemExit), result.output
    assert result.exit_code == 2, result.output
    lines = messages(result.stderr)
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    for word in words:
        assert word in lines[0], lines[0]
    return lines[0]


@pytest.mark.parametrize("command", ["modes", "simulate", "stability"])
def test_a_device_as_case_file_is_refused_before_reading(command: str) -> None:
    """/dev/zero was read until the process ran out of memory (killed by the system)."""
    start = time.perf_counter()
    _refused([command, "/dev/zero"], "/dev/zero is a device, not a file: give a TOML file")
    assert time.perf_counter() - start < 10


def test_a_huge_case_file_is_refused_before_reading(tmp_path: Path) -> None:
    path = tmp_path / "huge.toml"
    with path.open("wb") as f:
        f.truncate(MAX_TEXT_BYTES + 1)  # sparse: no disk used
    _refused(["simulate", path], "huge.toml is 16 MiB: an input text file must be at most 16 MiB")


def test_a_huge_case_from_a_pipe_is_read_up_to_the_limit_only(tmp_path: Path) -> None:
    """A pipe has no size: it is read up to the limit and refused beyond."""
    import os
    import threading

    fifo = tmp_path / "case.toml"
    os.mkfifo(fifo)

    def feed() -> None:
        with fifo.open("wb") as f:
            try:
                f.write(b"#" * (MAX_TEXT_BYTES + 2))
            except BrokenPipeError:
                pass

    writer = threading.Thread(target=feed, daemon=True)
    writer.start()
    _refused(["modes", fifo], "holds more than 16 MiB")


def test_a_flipped_bit_in_a_netcdf_attribute_is_a_damaged_file(tmp_path: Path) -> None:
    """A bit flipped in the header of the checksum attribute made netCDF4 raise
    AttributeError ("Can't open HDF5 attribute") out of check_netcdf: a traceback. Every
    single flip of the attribute's neighbourhood is now a damaged file, in one line."""
    path = tmp_path / "r.nc"
    simulate(Case(simulation={"duration": 0.01, "output_rate": 1000.0})).to_netcdf(path)
    data = path.read_bytes()
    at = data.find(b"fivdisc_checksum")
    assert at > 0
    for offset in range(at - 200, at + 40, 7):
        damaged = bytearray(data)
        damaged[offset] ^= 0x10
        flipped = tmp_path / "flipped.nc"
        flipped.write_bytes(bytes(damaged))
        result = run_cli(["plot", flipped, "-o", tmp_path / "f.png"])
        assert result.exception is None or isinstance(result.exception, SystemExit), (
            offset, result.exception)
        assert result.exit_code in (0, 2), result.output
        if result.exit_code == 2:
            assert "flipped.nc" in messages(result.stderr)[0]
