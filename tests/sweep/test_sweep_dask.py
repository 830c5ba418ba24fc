"""Sweeps on a Dask distributed cluster give the local process pool's results."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import xarray as xr
from click.testing import CliRunner

from fivdisc.cli.sweep import sweep
from fivdisc.sweep import (
    SweepError,
    load_sweep,
    open_sweep,
    run_sweep,
    verify_store,
)
from fivdisc.sweep.store.health import read_mask

from support.cli import run_cli

distributed = pytest.importorskip("distributed")

# 6 points; the fastest disc separates within the 3 s runs, so both early-stopped and
# full runs are compared.
SWEEP = """
[base.speed]
profile = "decelerating"
duration = 35.0
[base.simulation]
duration = 3.0
output_rate = 1000.0
[axes]
"speed.initial" = [8.0, 14.0, 20.0]
"slider.normal_damping" = [0.1, 2.0]
[reduce]
keep = ["separated", "first_separation_time"]
"""


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(
        host="127.0.0.1",
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
    ) as cluster:
        yield cluster


def test_cluster_results_equal_the_local_pool(cluster, tmp_path) -> None:
    path = tmp_path / "sweep.toml"
    path.write_text(SWEEP, encoding="utf-8")
    local = run_sweep(load_sweep(path), tmp_path / "local.zarr", workers=2, progress=False)
    assert local.computed == 6

    store = tmp_path / "dask.zarr"
    result = CliRunner().invoke(
        sweep,
        [str(path), "-o", str(store), "--scheduler", cluster.scheduler_address, "--no-progress"],
    )
    assert result.exit_code == 0, result.output
    assert "6 points: 0 already stored, 6 computed" in result.output
    data = open_sweep(store)
    # equal but for the history attribute: when each store was made
    xr.testing.assert_identical(data.assign_attrs(history=""),
                                open_sweep(local.store).assign_attrs(history=""))
    assert data["separated"].any() and not data["separated"].all()


def test_workers_option_is_for_the_local_pool(cluster, tmp_path) -> None:
    path = tmp_path / "sweep.toml"
    path.write_text(SWEEP, encoding="utf-8")
    with pytest.raises(SweepError, match="workers = 2 is invalid with a scheduler"):
        run_sweep(
            load_sweep(path), tmp_path / "s.zarr", scheduler=cluster.scheduler_address, workers=2
        )


def test_unreachable_scheduler(tmp_path, monkeypatch) -> None:
    monkeypatch.setattr("fivdisc.sweep.run._CONNECT_TIMEOUT", 1.0)
    path = tmp_path / "sweep.toml"
    path.write_text(SWEEP, encoding="utf-8")
    with pytest.raises(SweepError, match=r"scheduler = 'tcp://127\.0\.0\.1:9': cannot connect"):
        run_sweep(
            load_sweep(path), tmp_path / "s.zarr", scheduler="tcp://127.0.0.1:9", progress=False
        )


@pytest.mark.parametrize(
    ("address", "words"),
    [
        ("not-an-address", ["scheduler = 'not-an-address' is invalid", "tcp://host:8786"]),
        ("", ["scheduler = '' is invalid"]),
        ("foo://x:1", ["unknown address scheme 'foo'"]),
        ("tcp://host:notaport", ["scheduler = 'tcp://host:notaport' is invalid"]),
    ],
)
def test_bad_scheduler_address_is_one_line_before_any_work(tmp_path, address, words) -> None:
    path = tmp_path / "sweep.toml"
    path.write_text(SWEEP, encoding="utf-8")
    store = tmp_path / "s.zarr"
    result = run_cli(["sweep", str(path), "-o", str(store), "--scheduler",
                                      address, "--no-progress"])
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("error: ") and result.stderr.count("\n") == 1
    for word in words:
        assert word in result.stderr
    assert not store.exists()


# A user reduction slow enough for the cluster to die between points.
SLOW_HELPER = """
import time


def slow(result):
    time.sleep(0.4)
    return result.summary().switches
"""

SLOW_SWEEP = """
[base.simulation]
duration = 0.01
output_rate = 1000.0
[axes]
"slider.normal_damping" = "0.1:1.2:12"
[reduce]
keep = ["separated", "dask_helper:slow"]
"""


def _python(*args: str, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, *args], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


def test_a_dying_cluster_ends_the_sweep_in_one_line_and_keeps_finished_points(
    tmp_path, monkeypatch
) -> None:
    """A scheduler killed mid-sweep (SIGKILL): the coordinator, a separate process as from
    a shell, ends with exit status 2 and one line on stderr, and the points stored before
    stay stored and whole."""
    (tmp_path / "dask_helper.py").write_text(SLOW_HELPER, encoding="utf-8")
    (tmp_path / "sweep.toml").write_text(SLOW_SWEEP, encoding="utf-8")
    # prepended: the fivdisc a PYTHONPATH names (a worktree's) stays the one imported
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(
        [str(tmp_path), *filter(None, [os.environ.get("PYTHONPATH")])]))
    store = tmp_path / "s.zarr"
    scheduler_file = tmp_path / "scheduler.json"
    scheduler = _python("-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                        "--port", "0", "--no-dashboard", "--scheduler-file",
                        str(scheduler_file), cwd=tmp_path)
    worker = coordinator = None
    try:
        deadline = time.monotonic() + 60.0
        while not scheduler_file.exists():
            assert time.monotonic() < deadline and scheduler.poll() is None
            time.sleep(0.1)
        time.sleep(0.2)  # the file is complete once written; let it land
        address = json.loads(scheduler_file.read_text())["address"]
        worker = _python("-m", "distributed.cli.dask_worker", "--scheduler-file",
                         str(scheduler_file), "--nthreads", "1", "--no-dashboard",
                         cwd=tmp_path)
        coordinator = _python("-m", "fivdisc", "sweep", "sweep.toml", "-o", str(store),
                              "--scheduler", address, "--no-progress", cwd=tmp_path)
        deadline = time.monotonic() + 180.0  # generous on a loaded machine
        while not (store.exists() and read_mask(store).sum() >= 2):
            assert coordinator.poll() is None, coordinator.communicate()
            assert time.monotonic() < deadline, "the sweep made no progress"
            time.sleep(0.05)
        scheduler.send_signal(signal.SIGKILL)
        _, err = coordinator.communicate(timeout=120)
    finally:
        for process in (coordinator, worker, scheduler):
            if process is not None and process.poll() is None:
                process.kill()
                process.communicate()
    kept = int(read_mask(store).sum())
    assert coordinator.returncode == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"error: lost the Dask cluster at {address} (")
    assert err.endswith(f"{kept} of 12 points are stored in {store}: restart the cluster and "
                        "rerun the same command to compute the rest\n")
    assert 2 <= kept < 12
    # what is kept is whole; rerunning resumes from it (see test_sweep.py)
    health = verify_store(store)
    assert health.healthy and int(health.complete.sum()) == kept and health.holder is None
