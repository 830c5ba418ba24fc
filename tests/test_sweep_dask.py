"""Sweeps on a Dask distributed cluster give the local process pool's results."""

from __future__ import annotations

import pytest
import xarray as xr
from click.testing import CliRunner

from fivdisc.cli.sweep import sweep
from fivdisc.sweep import SweepError, load_sweep, open_sweep, run_sweep

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
    assert "fivdisc-warm-kernel" in cluster.scheduler.worker_plugins
    data = open_sweep(store)
    xr.testing.assert_identical(data, open_sweep(local.store))
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
