"""Issue 28, item 5: result files are trustworthy.

Every netCDF file fivdisc writes holds a checksum of its data, checked when it is read
(``open_result``, ``fivdisc plot``) and before ``fivdisc reproduce`` reuses it; a full
disk while writing ends with one line and keeps the computed run where it can; a run of
one sample writes a file that reads back. Each reproduction of the fault probe is a
parametrised case with the expected one-line message and a time bound (generous: it
catches a hang, not a slow machine).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import netCDF4
import numpy as np
import pytest

from fivdisc import Case, open_result, simulate
from fivdisc.errors import AnalysisError, FivdiscError
from fivdisc.files import CHECKSUM, check_netcdf

from support.cli import run_cli
from support.files import through_xarray

SHORT = Case(simulation={"duration": 0.01, "output_rate": 1000.0})
BOUND = 60.0  # [s]


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("result") / "run.nc"
    simulate(SHORT).to_netcdf(path)
    return path


@pytest.fixture
def result_file(written: Path, tmp_path: Path) -> Path:
    path = tmp_path / "run.nc"
    path.write_bytes(written.read_bytes())
    return path


def _one_line(args: list[str], status: int = 2) -> str:
    start = time.perf_counter()
    result = run_cli(args)
    assert time.perf_counter() - start < BOUND
    assert result.exit_code == status, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    return lines[0]


# --- damage is found -------------------------------------------------------------------------


def _random_bytes_into(variable: str):
    """16 random bytes written over the stored values of `variable` (the probe wrote them
    at random offsets; here they land in data, where they would be read as such)."""
    def damage(path: Path) -> None:
        with netCDF4.Dataset(path) as ds:
            values = np.asarray(ds[variable][...]).tobytes()
        content = bytearray(path.read_bytes())
        at = content.find(values[:64])
        assert at > 0  # xarray stores these variables uncompressed and contiguous
        content[at + 8: at + 24] = np.random.default_rng(28).bytes(16)
        path.write_bytes(bytes(content))
    return damage


def _rewrite(variable: str | None, attribute: str | None = None):
    """A valid netCDF file with one value or attribute changed in place."""
    def damage(path: Path) -> None:
        with netCDF4.Dataset(path, "a") as ds:
            if variable is not None:
                ds[variable][0] = ds[variable][0] + 1.0
            else:
                ds.setncattr(attribute, "success" if ds.getncattr(attribute) != "success"
                             else "diverged")
    return damage


DAMAGES = {
    "random bytes in phi": _random_bytes_into("phi"),
    "random bytes in w": _random_bytes_into("w"),
    "random bytes in time": _random_bytes_into("time"),
    "a value rewritten": _rewrite("disc_speed"),
    "status rewritten": _rewrite(None, "status"),
}


@pytest.mark.parametrize("damage", DAMAGES.values(), ids=DAMAGES.keys())
def test_a_damaged_result_is_refused_in_one_line(result_file: Path, damage, tmp_path: Path
                                                  ) -> None:
    assert check_netcdf(result_file)
    damage(result_file)
    message = f"{result_file} is damaged: its data do not match the checksum stored in it"
    start = time.perf_counter()
    with pytest.raises(FivdiscError, match=message) as info:
        open_result(result_file)
    assert time.perf_counter() - start < BOUND and "\n" not in str(info.value)
    line = _one_line(["plot", str(result_file), "-o", str(tmp_path / "f.png")])
    assert message in line
    assert not (tmp_path / "f.png").exists()


def test_a_stability_map_is_checked_by_plot(tmp_path: Path) -> None:
    out = tmp_path / "map.nc"
    result = run_cli(["stability", "--x", "speed.value=2:20:3",
                                      "--y", "slider.normal_damping=0.1:0.5:3", "-o", str(out),
                                      "--no-progress"])
    assert result.exit_code == 0, result.output
    assert check_netcdf(out)
    with netCDF4.Dataset(out, "a") as ds:
        ds.setncattr("curve_key", "changed")
    line = _one_line(["plot", str(out), "-o", str(tmp_path / "m.png")])
    assert "map.nc is damaged: its data do not match the checksum" in line




def test_a_result_rewritten_through_xarray_keeps_its_checksum(result_file: Path,
                                                              tmp_path: Path) -> None:
    # Runs with and without events: an empty text variable (the events' kinds) used to
    # be stored as doubles without a fill value, and xarray's rewrite added one, so the
    # same data no longer matched their checksum.
    from fivdisc import examples, load_case

    quiet = tmp_path / "quiet.nc"
    simulate(load_case(examples.path("fig04")).replace({"simulation.duration": 0.05})
             ).to_netcdf(quiet)
    for path in (result_file, quiet):
        copy = through_xarray(path, tmp_path / f"copy-{path.name}")
        assert check_netcdf(copy)
        assert open_result(copy) == open_result(path)
    with netCDF4.Dataset(quiet) as ds:
        assert ds["event_kind"].size == 0 and ds["event_kind"].dtype is str


def test_the_checksum_is_the_documented_digest(tmp_path: Path) -> None:
    """netcdf_checksum is SHA-256 over, in order of name, each attribute and variable as a
    length-framed name and a length-framed token (type, shape, stored bytes), computed here
    by hand for a small file: files written before keep their checksums however the hash
    is fed (a large variable is hashed without copies)."""
    import hashlib

    from fivdisc.files import netcdf_checksum

    path = tmp_path / "small.nc"
    x = np.arange(6.0).reshape(3, 2)
    with netCDF4.Dataset(path, "w") as root:
        root.createDimension("a", 3)
        root.createDimension("b", 2)
        var = root.createVariable("x", np.float64, ("a", "b"))
        var[...] = x
        var.setncattr("units", "m")
        root.setncattr("title", "t")
        root.setncattr(CHECKSUM, "ignored")

    def framed(data: bytes) -> bytes:
        return len(data).to_bytes(8, "little") + data

    digest = hashlib.sha256()
    for name, token in (("group", b"s/"), ("attribute title", b"st"),
                        ("variable x", b"<f8(3, 2)" + x.tobytes()),
                        ("attribute x.units", b"sm")):
        digest.update(framed(name.encode()) + framed(token))
    assert netcdf_checksum(path) == digest.hexdigest()


def test_files_without_a_checksum_are_read_as_before(result_file: Path) -> None:
    # Files of a fivdisc before checksums (or of another program) are not refused.
    with netCDF4.Dataset(result_file, "a") as ds:
        ds.delncattr(CHECKSUM)
    assert not check_netcdf(result_file)
    assert open_result(result_file).status == "success"


def test_reproduce_does_not_reuse_an_altered_figure(tmp_path: Path) -> None:
    from fivdisc.paper.reproduce import reproduce

    first = reproduce([4], outdir=tmp_path, progress=False, workers=1)
    assert first.computed == (4,)
    again = reproduce([4], outdir=tmp_path, progress=False, workers=1)
    assert (again.computed, again.reused) == ((), (4,))
    stored = tmp_path / "fig04.nc"
    with netCDF4.Dataset(stored, "a") as ds:
        group = ds.groups[sorted(ds.groups)[0]] if ds.groups else ds
        name = next(n for n, v in group.variables.items()
                    if v.dtype is not str and v.dtype.kind == "f" and v.ndim == 1
                    and v.size > 1 and n != "time")
        group[name][1] = group[name][1] * 2.0 + 1.0
    start = time.perf_counter()
    third = reproduce([4], outdir=tmp_path, progress=False, workers=1)
    assert time.perf_counter() - start < 10 * BOUND
    assert third.computed == (4,) and check_netcdf(stored)


# --- a full disk -----------------------------------------------------------------------------

_LIMITED = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG
resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))
from fivdisc.cli import main
sys.argv = ["fivdisc", "simulate", sys.argv[1], "-o", sys.argv[2], "--no-progress"]
main()
"""


def test_a_full_disk_during_simulate_is_one_line(tmp_path: Path) -> None:
    # A file size limit fails the writes as a full disk does (the netCDF library reports
    # both as "NetCDF: HDF error"), here for the temporary directory too.
    case = tmp_path / "c.toml"
    Case(simulation={"duration": 0.05, "output_rate": 20000.0}).save(case)
    out = tmp_path / "out.nc"
    env = {**os.environ, "TMPDIR": str(tmp_path / "spare")}
    (tmp_path / "spare").mkdir()
    done = subprocess.run([sys.executable, "-c", _LIMITED, str(case), str(out)],
                          capture_output=True, text=True, timeout=BOUND * 4, env=env)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr
    assert lines[0].startswith(f"error: cannot write {out}: NetCDF: HDF error; ")
    assert lines[0].endswith("free space and run again")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.toml", "spare"]
    assert list((tmp_path / "spare").iterdir()) == []


def test_a_full_disk_keeps_the_run_in_the_temporary_directory(tmp_path: Path, monkeypatch
                                                              ) -> None:
    import errno
    import tempfile

    from fivdisc.engine.record import Record

    full, spare = tmp_path / "full", tmp_path / "spare"
    full.mkdir()
    spare.mkdir()
    original = Record.to_netcdf  # what fivdisc simulate writes with

    def to_netcdf(self, path, *args, **kwargs):
        if Path(path).parent == full:
            Path(path).write_bytes(b"CDF half")
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return original(self, path, *args, **kwargs)

    monkeypatch.setattr(Record, "to_netcdf", to_netcdf)
    monkeypatch.setattr(tempfile, "tempdir", str(spare))
    case = tmp_path / "c.toml"
    SHORT.save(case)
    line = _one_line(["simulate", str(case), "-o", str(full / "out.nc"), "--no-progress"])
    kept = spare / f"fivdisc-out-{os.getpid()}.nc"
    assert line == (f"error: cannot write {full / 'out.nc'}: No space left on device; "
                    f"{line.split('; ')[1]}; the run is kept in {kept}: move it to "
                    f"{full / 'out.nc'} when space is freed")
    assert list(full.iterdir()) == []  # no half file
    assert open_result(kept).dataset.sizes["time"] == 11


# --- a run of one sample ---------------------------------------------------------------------


ONE_SAMPLE = [
    {"duration": 1e-5},  # shorter than the output interval
    {"duration": 0.01, "output_rate": 10.0},  # one output interval longer than the run
]


@pytest.mark.parametrize("simulation", ONE_SAMPLE,
                         ids=["duration 1e-5", "output interval past the end"])
@pytest.mark.parametrize("kind", ["timeseries", "phase", "friction", "normal-force"])
def test_a_run_of_one_sample_reads_back_and_is_drawn(tmp_path: Path, simulation: dict,
                                                     kind: str) -> None:
    run = simulate(Case(simulation=simulation))
    assert run.dataset.sizes["time"] == 1
    path = tmp_path / "one.nc"
    run.to_netcdf(path)
    assert open_result(path) == run
    assert open_result(path).summary().end_time == simulation["duration"]
    # Every file fivdisc writes reads back, and plot draws what there is: one sample, a
    # marker (a line through one point would draw nothing).
    figure = tmp_path / "one.png"
    done = run_cli(["plot", str(path), "--kind", kind, "-o", str(figure)])
    assert done.exit_code == 0, done.output
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    (line,) = run.plot(kind).axes[0].lines
    assert line.get_marker() == "o" and len(line.get_xdata()) == 1


@pytest.mark.parametrize("kind", ["spectrum", "spectrogram"])
def test_a_spectrum_of_one_sample_is_refused_saying_why(tmp_path: Path, kind: str) -> None:
    path = tmp_path / "one.nc"
    simulate(Case(simulation=ONE_SAMPLE[0])).to_netcdf(path)
    line = _one_line(["plot", str(path), "--kind", kind, "-o", str(tmp_path / "one.png")])
    assert line == (f"error: --kind {kind} needs at least 2 samples: {path} holds one (a run "
                    "shorter than its output interval, or one that failed at its start), which "
                    "has no frequencies; draw it with --kind timeseries, or simulate longer or "
                    "with a higher simulation.output_rate")
    with pytest.raises(AnalysisError, match="holds 1 sample"):
        open_result(path).plot(kind)
    line = _one_line(["plot", str(path), "--window", "0:1", "-o", str(tmp_path / "one.png")])
    assert line == f"error: --window is not used for {path}: it holds one sample, drawn whole"


@pytest.mark.parametrize("command", [["plot"], ["continue", "--key", "speed.value", "--to",
                                                "13", "--from"], ["orbit", "--from"]])
def test_a_case_file_given_for_a_result_is_named_so(tmp_path, command):
    """A case file (TOML) where a command reads a file fivdisc wrote: one line saying it
    is not a netCDF file, not that a result is damaged."""
    case = tmp_path / "case.toml"
    case.write_text("[speed]\nvalue = 12.3\n")
    result = run_cli([*command, str(case)])
    assert result.exit_code == 2, result.output
    assert "is not a netCDF file" in result.output
    assert "damaged" not in result.output
