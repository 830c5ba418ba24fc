"""The local pools of a sweep: threads and processes store the same results, an
interrupted thread-pool sweep stops at once and resumes, and a bad pool is refused."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
import xarray as xr

from fivdisc.case import Case
from fivdisc.engine.integration import Stopped, stop_thread_when
from fivdisc.engine.simulation import simulate
from fivdisc.sweep import SweepError, load_sweep, open_sweep, run_sweep
from fivdisc.sweep.store.health import read_mask

from support.cli import run_cli

# 8 points of 40 s simulated (about 0.3 s each on one core): long enough that Ctrl-C
# finds points in the middle of their integration; a section stores arrays too.
SWEEP = """
mode = "grid"
[base.simulation]
duration = 40.0
output_rate = 1000.0
[axes]
"speed.value" = "2.0:6.0:8"
[reduce]
keep = ["max_normal_force", "stick_fraction", "separated"]
[[reduce.section]]
variable = "normal_force"
at = "maxima"
after = 39.0
max_points = 50
"""


@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("pools") / "pools.toml"
    path.write_text(SWEEP, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def by_process(sweep_file: Path) -> Path:
    """The sweep on a 2-process pool, uninterrupted."""
    store = sweep_file.with_name("process.zarr")
    report = run_sweep(load_sweep(sweep_file), store, workers=2, progress=False,
                       pool="process")
    assert (report.computed, report.failed) == (8, {})
    return store


def _same(store: Path, other: Path) -> None:
    # equal but for the history attribute: when each store was made
    xr.testing.assert_identical(open_sweep(store).assign_attrs(history=""),
                                open_sweep(other).assign_attrs(history=""))


def test_threads_store_what_processes_store(sweep_file: Path, by_process: Path) -> None:
    store = sweep_file.with_name("thread.zarr")
    report = run_sweep(load_sweep(sweep_file), store, workers=2, progress=False,
                       pool="thread")
    assert (report.computed, report.failed) == (8, {})
    _same(store, by_process)


def _command(sweep_file: Path, store: Path) -> list[str]:
    """`fivdisc sweep` on 2 threads in a fresh interpreter, without the progress bar."""
    return [sys.executable, "-c", "from fivdisc.cli.sweep import sweep; sweep()",
            str(sweep_file), "-o", str(store), "--pool", "thread", "--workers", "2",
            "--no-progress"]


def test_an_interrupted_thread_pool_stops_at_once_and_resumes(
        sweep_file: Path, by_process: Path, tmp_path: Path) -> None:
    store = tmp_path / "resumed.zarr"
    # Ctrl-C: SIGINT to the whole process group, as a terminal sends it
    process = subprocess.Popen(_command(sweep_file, store), start_new_session=True,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120.0  # generous on a loaded machine
        while not (store.exists() and read_mask(store).sum() >= 2):
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, "the sweep made no progress"
            time.sleep(0.05)
        os.killpg(process.pid, signal.SIGINT)
        sent = time.monotonic()
        _, err = process.communicate(timeout=60)
        # The running points end at their integration's next call (about 0.05 s), not
        # at their end, and the process exits without waiting for them.
        stopped = time.monotonic() - sent
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
    assert process.returncode == 130, err
    interrupted = int(read_mask(store).sum())
    assert f"interrupted: {interrupted} of 8 points are stored" in err
    assert 2 <= interrupted < 8
    assert stopped < 5.0  # the interpreter's exit included; the points left take longer

    finished = subprocess.run(_command(sweep_file, store), capture_output=True, text=True,
                              timeout=300)
    assert finished.returncode == 0, finished.stderr
    assert f"8 points: {interrupted} already stored, {8 - interrupted} computed" in \
        finished.stdout
    _same(store, by_process)


def test_a_stopped_threads_integration_ends_at_its_next_call() -> None:
    case = Case().replace({"simulation.duration": 1000.0, "simulation.output_rate": 100.0})
    stop, raised = threading.Event(), []

    def work() -> None:
        stop_thread_when(stop)
        try:
            simulate(case)
        except Stopped as exc:
            raised.append(exc)

    thread = threading.Thread(target=work)
    thread.start()
    time.sleep(0.3)
    stop.set()
    start = time.monotonic()
    thread.join(timeout=30)
    assert not thread.is_alive()
    assert time.monotonic() - start < 2.0  # a 1000 s run takes some 10 s
    assert raised and str(raised[0]).startswith("stopped at t = ")
    # the main thread's integrations are not affected by any thread's event
    assert simulate(case.replace({"simulation.duration": 0.01})).ok


def test_a_bad_pool_is_refused_in_one_line(sweep_file: Path, tmp_path: Path) -> None:
    spec = load_sweep(sweep_file)
    with pytest.raises(SweepError, match=r"^pool = 'threads' is invalid: must be 'thread' "
                                         r"or 'process'$"):
        run_sweep(spec, tmp_path / "a.zarr", pool="threads")
    with pytest.raises(SweepError, match=r"^pool = 'thread' is invalid with a scheduler"):
        run_sweep(spec, tmp_path / "a.zarr", pool="thread", scheduler="tcp://127.0.0.1:1")
    assert not (tmp_path / "a.zarr").exists()
    result = run_cli(["sweep", str(sweep_file), "-o", tmp_path / "b.zarr", "--pool", "fork"])
    assert result.exit_code == 2
    assert "Invalid value for '--pool': 'fork' is not one of 'thread', 'process'." in \
        result.stderr
    assert not (tmp_path / "b.zarr").exists()
