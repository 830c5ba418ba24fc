"""Outputs never destroy inputs: every output path is checked before any work, and written
through a temporary file renamed into place (issue 14, item 1)."""

from __future__ import annotations

import importlib
import os
import time
from pathlib import Path

import pytest

from fivdisc import Case, simulate
from fivdisc.errors import FivdiscError
from fivdisc.files import NETCDF, ZARR, check_output, figure_suffixes, write_atomic

from support.cli import run_cli

SHORT = Case(simulation={"duration": 0.01, "output_rate": 1000.0})


@pytest.fixture
def case_file(tmp_path: Path) -> Path:
    path = tmp_path / "v.toml"
    SHORT.save(path)
    return path


@pytest.fixture(scope="module")
def result_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("result") / "run.nc"
    simulate(SHORT).to_netcdf(path)
    return path


def _refused(args: list[str], *words: str) -> str:
    """Run the command line; it must end with exit status 2 and one line naming `words`."""
    result = run_cli(args)
    assert result.exit_code == 2, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    for word in words:
        assert word in lines[0]
    return lines[0]


# --- the helper ------------------------------------------------------------------------------


def test_check_output_accepts_a_new_or_existing_file(tmp_path: Path) -> None:
    assert check_output(tmp_path / "out.nc", "-o", NETCDF) == tmp_path / "out.nc"
    (tmp_path / "old.nc").write_bytes(b"old")
    assert check_output(tmp_path / "old.nc", "-o", NETCDF) == tmp_path / "old.nc"
    assert check_output(tmp_path / "store.zarr", "-o", ZARR, kind="directory")


@pytest.mark.parametrize(
    ("name", "words"),
    [
        ("out.txt", ["-o", "'.txt'", "must end in .nc"]),
        ("out", ["no suffix", "must end in .nc"]),
        ("missing/out.nc", ["does not exist", "create it first"]),
        ("v.toml/out.nc", ["does not exist"]),  # a file as the directory
        ("a_dir.nc", ["is a directory"]),
    ],
)
def test_check_output_refuses(tmp_path: Path, case_file: Path, name: str, words) -> None:
    (tmp_path / "a_dir.nc").mkdir()
    with pytest.raises(FivdiscError) as info:
        check_output(tmp_path / name, "-o", NETCDF, inputs=[case_file])
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"-o {tmp_path / name} is invalid")
    for word in words:
        assert word in message


def test_check_output_refuses_the_input_under_any_name(tmp_path: Path, case_file: Path) -> None:
    os.link(case_file, tmp_path / "hard.toml")
    (tmp_path / "soft.toml").symlink_to(case_file)
    for name in ("v.toml", "hard.toml", "soft.toml", "./sub/../v.toml"):
        (tmp_path / "sub").mkdir(exist_ok=True)
        with pytest.raises(FivdiscError, match="it is an input of this command"):
            check_output(tmp_path / name, "-o", (".toml",), inputs=[None, case_file])


def test_check_output_refuses_a_file_as_store(tmp_path: Path) -> None:
    (tmp_path / "s.zarr").write_text("x")
    with pytest.raises(FivdiscError, match="it is a file; give a directory name"):
        check_output(tmp_path / "s.zarr", "-o", ZARR, kind="directory")


def test_check_output_refuses_an_unwritable_directory(tmp_path: Path, monkeypatch) -> None:
    # As root, permissions do not bind; the answer of os.access is what the check relies on.
    locked = tmp_path / "locked"
    locked.mkdir()
    real_access = os.access
    monkeypatch.setattr(
        "fivdisc.files.os.access", lambda p, mode: Path(p) != locked and real_access(p, mode)
    )
    with pytest.raises(FivdiscError, match=f"the directory {locked} is not writable"):
        check_output(locked / "out.nc", "-o", NETCDF)


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write to any directory")
def test_check_output_refuses_a_read_only_directory(tmp_path: Path) -> None:
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o555)
    with pytest.raises(FivdiscError, match="is not writable"):
        check_output(locked / "out.nc", "-o", NETCDF)


def test_figure_suffixes_are_matplotlib_formats() -> None:
    assert {".png", ".pdf", ".svg"} <= set(figure_suffixes())
    assert ".nc" not in figure_suffixes()


def test_write_atomic_replaces_whole_or_not_at_all(tmp_path: Path) -> None:
    path = tmp_path / "out.txt"
    path.write_text("old")

    def fail(tmp: Path) -> None:
        tmp.write_text("half")
        raise KeyboardInterrupt  # interrupted mid-write

    with pytest.raises(KeyboardInterrupt):
        write_atomic(path, fail)
    assert path.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]  # no temporary left

    seen = []
    write_atomic(path, lambda tmp: (seen.append(tmp), tmp.write_text("new")))
    assert path.read_text() == "new"
    # written next to the target, under a hidden name with the same suffix
    assert seen[0].parent == tmp_path and seen[0].name.startswith(".") and seen[0].suffix == ".txt"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]


# --- every command ---------------------------------------------------------------------------


def test_simulate_onto_its_case_file_is_refused_before_running(case_file: Path) -> None:
    text = case_file.read_text()
    _refused(["simulate", str(case_file), "-o", str(case_file), "--no-progress"],
             "must end in .nc")
    assert case_file.read_text() == text
    # the default output of a case file named *.nc is the case file itself
    odd = case_file.with_suffix(".nc")
    case_file.rename(odd)
    _refused(["simulate", str(odd), "--no-progress"], "it is an input of this command")
    assert odd.read_text() == text


def test_simulate_into_a_missing_directory_fails_before_running(case_file: Path,
                                                                monkeypatch) -> None:
    def never(*args, **kwargs):
        raise AssertionError("simulated before checking the output")

    # the module, not the function fivdisc.simulate that shadows it on the package
    monkeypatch.setattr(importlib.import_module("fivdisc.engine.simulation"), "simulate", never)
    _refused(["simulate", str(case_file), "-o", str(case_file.parent / "no" / "x.nc")],
             "does not exist")


def test_simulate_writes_atomically(case_file: Path, tmp_path: Path) -> None:
    out = tmp_path / "out.nc"
    out.write_bytes(b"previous")
    result = run_cli(["simulate", str(case_file), "-o", str(out),
                                      "--no-progress"])
    assert result.exit_code == 0, result.output
    assert out.read_bytes()[:4] == b"\x89HDF"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.nc", "v.toml"]


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["-o", "fig"], ["-o fig is invalid", "no suffix", ".png"]),
        (["-o", "fig.xyz"], ["'.xyz'", "is not supported"]),
        (["-o", "{result}"], ["'.nc'"]),
        (["-o", "missing/fig.png"], ["does not exist"]),
        (["--dpi", "100000"], ["--dpi 100000 is invalid", "must be <= 10239"]),
        (["--var", ""], ["--var '' is not a time series", "must be one of"]),
    ],
)
def test_plot_outputs_and_options(result_file: Path, tmp_path: Path, monkeypatch, args,
                                  words) -> None:
    monkeypatch.chdir(tmp_path)
    args = [a.format(result=result_file) for a in args]
    _refused(["plot", str(result_file), *args], *words)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_plot_writes_the_file_it_names(result_file: Path, tmp_path: Path) -> None:
    out = tmp_path / "fig.svg"
    result = run_cli(["plot", str(result_file), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output.strip() == f"wrote {out}"
    assert out.read_text().lstrip().startswith("<?xml")


def test_stability_map_output_checked_before_the_map(tmp_path: Path, monkeypatch) -> None:
    def never(*args, **kwargs):
        raise AssertionError("computed the map before checking the output")

    monkeypatch.setattr("fivdisc.analysis.stability.stability_map", never)
    grid = ["--x", "normal_damping=0:1:2", "--y", "rotational_damping=0:1:2"]
    _refused(["stability", *grid, "-o", str(tmp_path / "map.xyz")], "'.xyz'",
             "must end in .nc, ")
    _refused(["stability", *grid, "-o", str(tmp_path / "no" / "map.nc")], "does not exist")


def test_separation_map_figure_checked_before_the_sweep(tmp_path: Path) -> None:
    store = tmp_path / "map.zarr"
    start = time.perf_counter()
    _refused(["separation-map", "--x", "12:20:3", "--y", "4:16:3", "-o", str(store),
              "--figure", str(tmp_path / "fig.xyz"), "--no-progress"], "--figure", "'.xyz'")
    assert time.perf_counter() - start < 10.0
    assert not store.exists()
    _refused(["separation-map", "-o", str(tmp_path / "map.nc"), "--no-progress"],
             "must end in .zarr")


def test_sweep_store_checked(tmp_path: Path) -> None:
    sweep_file = tmp_path / "s.toml"
    sweep_file.write_text('[axes]\n"slider.mass" = [0.1]\n[reduce]\nkeep = ["separated"]\n')
    _refused(["sweep", str(sweep_file), "-o", str(tmp_path / "no" / "s.zarr")],
             "does not exist")
    _refused(["sweep", str(sweep_file), "-o", str(sweep_file)], "must end in .zarr")


def test_reproduce_outdir_checked(tmp_path: Path) -> None:
    _refused(["reproduce", "--figures", "3", "-o", str(tmp_path / "a" / "b")], "does not exist")
    assert not (tmp_path / "a").exists()
    (tmp_path / "file").write_text("x")
    result = run_cli(["reproduce", "--figures", "3", "-o", str(tmp_path / "file")])
    assert result.exit_code == 2 and "is a file" in result.stderr  # click's usage error
    assert (tmp_path / "file").read_text() == "x"


# --- issue 40, item 5: a killed write ----------------------------------------------------------

KILLED_WRITER = """
import os, signal, sys
from pathlib import Path
from fivdisc.files import write_atomic

def write(tmp: Path) -> None:
    tmp.write_bytes(b"half a file")
    os.kill(os.getpid(), signal.SIGKILL)  # killed while writing

write_atomic(Path(sys.argv[1]), write)
"""


def test_a_temporary_file_of_a_killed_write_is_removed_by_the_next(case_file: Path,
                                                                     tmp_path: Path) -> None:
    """A SIGKILL during -o left .r.PID.tmp.nc behind for good; the next write of the same
    output removes the leftovers of processes that no longer run (and of no other)."""
    import subprocess
    import sys

    out = tmp_path / "r.nc"
    killed = subprocess.run([sys.executable, "-c", KILLED_WRITER, str(out)], timeout=120)
    assert killed.returncode == -9
    left = list(tmp_path.glob(".r.*.tmp.nc"))
    assert len(left) == 1 and not out.exists()
    alive = tmp_path / f".r.{os.getppid()}.tmp.nc"  # a write under way in a live process
    alive.write_bytes(b"")
    mine = tmp_path / ".r.backup.tmp.nc"  # not a process id: a user's file
    mine.write_bytes(b"")
    result = run_cli(["simulate", case_file, "-o", out, "--no-progress"])
    assert result.exit_code == 0, result.output
    assert out.is_file()
    assert sorted(tmp_path.glob(".r.*.tmp.nc")) == sorted([alive, mine])
