"""Sweep stores are safe: one writer at a time, every point verified by its checksum,
damaged metadata rebuilt, ``fivdisc sweep --verify`` (issue 14, item 2).

The stores here are filled with made-up outcomes through :class:`SweepStore`, without
running simulations; ``test_sweep.py`` and ``test_sweep_dask.py`` run real sweeps.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from fivdisc.case import Case
from fivdisc.sweep import (
    Sweep,
    SweepError,
    SweepStore,
    open_sweep,
    run_sweep,
    verify_store,
)
from fivdisc.sweep.store.health import read_mask
from fivdisc.sweep.store.lock import store_lock
from fivdisc.sweep.store.sweep_store import PointOutcome

from support.cli import run_cli

N = 6
FAILED = 3  # the point whose run failed
SPEC = Sweep(
    base=Case(simulation={"duration": 0.01, "output_rate": 1000.0}),
    axes={"slider.normal_damping": [0.1 * (i + 1) for i in range(N)]},
    keep=["separated", "max_normal_force"],
)


def _outcome(i: int) -> PointOutcome:
    """Even points separate; every point has a force; point FAILED failed."""
    if i == FAILED:
        return PointOutcome(i, None, "RuntimeError: boom")
    return PointOutcome(i, {"separated": i % 2 == 0, "max_normal_force": 100.0 + i})


def _store(path: Path, points=range(N)) -> Path:
    with store_lock(path):
        SweepStore.open(path, SPEC).write([_outcome(i) for i in points])
    return path


@pytest.fixture
def store(tmp_path: Path) -> Path:
    return _store(tmp_path / "s.zarr")


def _mask(*indices: int) -> np.ndarray:
    mask = np.zeros(N, dtype=bool)
    mask[list(indices)] = True
    return mask


def _chunk(store: Path, name: str, i: int) -> Path:
    """Chunk file `i` of a variable (the N points fill one chunk, or N / BLOCK of them)."""
    return store / name / "c" / str(i)


def _tamper(store: Path, name: str, i: int, value) -> None:
    """Change one point's stored value through Zarr, its checksum left as it was."""
    import zarr

    zarr.open_array(store / name, mode="r+")[i] = value


BLOCK = 4  # points per chunk where a test sets it: chunks of points 0-3 and 4-5


@pytest.fixture
def blocks(monkeypatch, tmp_path: Path) -> Path:
    """A store of chunks of BLOCK points (every store of the test is laid out so)."""
    from fivdisc.sweep.store import layout

    monkeypatch.setattr(layout, "BLOCK_POINTS", BLOCK)
    return _store(tmp_path / "b.zarr")


# --- checksums -------------------------------------------------------------------------------


def test_a_complete_store_verifies(store: Path) -> None:
    health = verify_store(store)
    assert health.healthy and health.complete.all() and not health.damaged.any()
    np.testing.assert_array_equal(health.failed, _mask(FAILED))
    assert health.broken == () and health.holder is None
    data = open_sweep(store)
    assert data["done"].all()
    np.testing.assert_array_equal(data["max_normal_force"].values[[0, 5]], [100.0, 105.0])


def test_changed_values_fail_their_checksum(store: Path) -> None:
    # Zarr reads a missing chunk as the fill value, so without checksums point 1 would
    # pass for done with max_normal_force = NaN.
    _tamper(store, "max_normal_force", 1, np.nan)
    _tamper(store, "checksum", 2, 0)
    _tamper(store, "separated", 4, False)  # True, read back as the fill value False
    _tamper(store, "error", FAILED, "")
    _tamper(store, "done", 5, False)  # values written, flag not yet: incomplete, not damaged
    health = verify_store(store)
    np.testing.assert_array_equal(health.complete, _mask(0))
    np.testing.assert_array_equal(health.damaged, _mask(1, 2, FAILED, 4))
    assert not health.healthy
    np.testing.assert_array_equal(read_mask(store), _mask(0))
    np.testing.assert_array_equal(open_sweep(store)["done"].values, _mask(0))


def test_a_lost_chunk_equal_to_the_fill_value_loses_nothing(blocks: Path) -> None:
    # Points 4 and 5 did not fail (their error "" is the fill value): Zarr does not even
    # write their chunk.
    assert _chunk(blocks, "error", 0).exists() and not _chunk(blocks, "error", 1).exists()
    assert verify_store(blocks).complete.all()


def test_a_lost_or_damaged_chunk_loses_its_points_and_a_rerun_recomputes_them(
        blocks: Path) -> None:
    reference = open_sweep(blocks)
    _chunk(blocks, "max_normal_force", 1).unlink()
    _chunk(blocks, "error", 0).write_bytes(b"garbage")
    health = verify_store(blocks)
    np.testing.assert_array_equal(health.damaged, _mask(*range(N)))
    # The damaged chunk is removed before the rerun writes into it (Zarr would read it
    # first, to write a point's part); only its points are recomputed.
    with store_lock(blocks):
        target = SweepStore.open(blocks, SPEC)
        assert not target.completed().any()
        assert not _chunk(blocks, "error", 0).exists()
        target.write([_outcome(i) for i in range(N)])
    assert verify_store(blocks).healthy
    xr.testing.assert_identical(open_sweep(blocks), reference)


def test_a_chunk_copied_from_other_points_fails(blocks: Path) -> None:
    # Zarr stores an edge chunk whole: chunk 0's copy decodes as points 4 and 5.
    for name in ("max_normal_force", "separated", "checksum", "error", "done"):
        if _chunk(blocks, name, 0).exists():
            _chunk(blocks, name, 1).write_bytes(_chunk(blocks, name, 0).read_bytes())
    np.testing.assert_array_equal(verify_store(blocks).damaged, _mask(4, 5))


def test_points_written_a_few_at_a_time_fill_their_chunks(tmp_path: Path, blocks: Path
                                                           ) -> None:
    # A sweep writes the points that finished in the last second, each write into the
    # chunks that hold them; the result is the store of one write.
    path = tmp_path / "parts.zarr"
    for part in ([5], [0, 2], [1, 3, 4]):
        _store(path, part)
    xr.testing.assert_identical(open_sweep(path).drop_attrs(), open_sweep(blocks).drop_attrs())
    assert verify_store(path).complete.all()


# --- damaged metadata ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("damage", "name"),
    [
        ("delete", "max_normal_force"),
        ("truncate", "max_normal_force"),
        ("delete", "checksum"),
        ("truncate", "done"),
        ("delete", "slider.normal_damping"),  # a coordinate
        ("truncate", "slider.normal_damping"),
    ],
)
def test_damaged_variables_are_reported_and_rebuilt(store: Path, damage: str, name: str) -> None:
    reference = open_sweep(store)
    if damage == "delete":
        for path in sorted((store / name).rglob("*"), reverse=True):
            path.unlink() if path.is_file() else path.rmdir()
        (store / name).rmdir()
    else:
        meta = store / name / "zarr.json"
        meta.write_bytes(meta.read_bytes()[:40])
    health = verify_store(store)
    assert health.broken == (name,) and not health.healthy
    with pytest.raises(SweepError, match=f"variable\\(s\\) {name} are missing or unreadable"):
        open_sweep(store)
    result = run_cli(["sweep", "--verify", str(store)])
    assert result.exit_code == 1 and name in result.stdout

    # Resuming rebuilds the variable's metadata; only the points whose values a deleted
    # variable held are lost (a truncated zarr.json leaves the chunk files).
    with store_lock(store):
        SweepStore.open(store, SPEC)
    health = verify_store(store)
    assert health.broken == ()
    lost = {"max_normal_force": _mask(*range(N)) & ~_mask(FAILED),  # NaN is the fill value
            "checksum": _mask(*range(N)), "done": _mask(*range(N))}.get(name, _mask())
    lost = lost if damage == "delete" else _mask()
    np.testing.assert_array_equal(health.complete, ~lost)
    _store(store, np.flatnonzero(lost))
    xr.testing.assert_identical(open_sweep(store), reference)


def test_damaged_group_metadata_is_one_line_and_rebuilt_by_a_rerun(store: Path) -> None:
    meta = store / "zarr.json"
    meta.write_bytes(meta.read_bytes()[:100])
    for call in (verify_store, open_sweep, read_mask):
        with pytest.raises(SweepError, match=r"s.zarr has damaged metadata \(.*zarr.json: .*\); "
                                             r"rerun the sweep that wrote it to rebuild it from "
                                             r"the sweep file, or delete the store to start "
                                             r"over$") as info:
            call(store)
        assert "\n" not in str(info.value)
    # Every chunk is intact: the rerun rebuilds the group from the sweep, computes nothing.
    report = run_sweep(SPEC, store, workers=1, progress=False)
    assert (report.already_done, report.computed) == (N, 0)
    assert verify_store(store).healthy


def test_a_store_of_an_older_format_is_refused(store: Path) -> None:
    meta = store / "zarr.json"
    data = json.loads(meta.read_text())
    del data["attributes"]["store_format"]
    meta.write_text(json.dumps(data))
    with pytest.raises(SweepError, match="store format 1, this version writes 5"):
        verify_store(store)


def test_a_store_of_one_point_per_chunk_is_read_and_verified_not_resumed(
        tmp_path: Path, monkeypatch) -> None:
    # Format 4, as earlier versions of fivdisc wrote it: one point per chunk.
    from fivdisc.sweep.store import layout as module

    monkeypatch.setattr(module, "BLOCK_POINTS", 1)
    path = _store(tmp_path / "old.zarr")
    monkeypatch.undo()
    assert len(list((path / "max_normal_force" / "c").iterdir())) == N - 1  # FAILED's is NaN
    meta = path / "zarr.json"
    data = json.loads(meta.read_text())
    data["attributes"]["store_format"] = 4
    meta.write_text(json.dumps(data))
    reference = open_sweep(_store(tmp_path / "new.zarr"))
    health = verify_store(path)
    assert health.healthy and health.complete.all()
    np.testing.assert_array_equal(health.failed, _mask(FAILED))
    _tamper(path, "max_normal_force", 2, 1.0)
    np.testing.assert_array_equal(verify_store(path).damaged, _mask(2))
    _tamper(path, "max_normal_force", 2, 102.0)
    xr.testing.assert_identical(open_sweep(path).drop_attrs(), reference.drop_attrs())
    # complete: a rerun (as `fivdisc bifurcation` does before drawing) computes nothing
    report = run_sweep(SPEC, path, workers=1, progress=False)
    assert (report.already_done, report.computed) == (N, 0)
    # a point missing: refused before any work, the store left as it was (its flag and
    # checksum unset: a lost flag alone is no missing point, the checksum verifies it)
    _tamper(path, "done", 5, False)
    _tamper(path, "checksum", 5, 0)
    files = sorted((f, f.read_bytes()) for f in path.rglob("*") if f.is_file())
    with pytest.raises(SweepError, match=r"old.zarr holds one point per chunk \(store format "
                                         r"4\); this version reads it but resumes only stores "
                                         r"of format 5: rerun the sweep into a new store$"):
        run_sweep(SPEC, path, workers=1, progress=False)
    assert sorted((f, f.read_bytes()) for f in path.rglob("*") if f.is_file()) == files


# --- one coordinator per store ---------------------------------------------------------------


def test_a_second_coordinator_is_refused_and_told_who_holds_the_store(tmp_path: Path) -> None:
    path = tmp_path / "s.zarr"
    with store_lock(path):
        owner = json.loads((tmp_path / "s.zarr.lock.owner").read_text())
        assert owner["pid"] == os.getpid() and owner["host"] == socket.gethostname()
        with pytest.raises(SweepError) as info:
            run_sweep(SPEC, path, workers=1, progress=False)
        message = str(info.value)
        assert message.startswith(f"{path} is in use by process {os.getpid()} on host "
                                  f"{socket.gethostname()} (running since ")
        assert message.endswith("wait for that sweep to end or stop it, then rerun")
        assert not path.exists()  # the new store was not started
    assert not (tmp_path / "s.zarr.lock.owner").exists()
    _store(path)  # free again


def test_the_lock_holds_across_processes_and_ends_with_its_holder(tmp_path: Path) -> None:
    path = _store(tmp_path / "s.zarr")
    holder = subprocess.Popen(
        [sys.executable, "-c",
         "import sys, time\nfrom fivdisc.sweep.store.sweep_store import store_lock\n"
         f"with store_lock({str(path)!r}):\n    print('held', flush=True)\n    time.sleep(60)"],
        stdout=subprocess.PIPE, text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "held"
        result = run_cli(["sweep", "--verify", str(path)])
        assert result.exit_code == 0 and f"being written by process {holder.pid}" in result.stdout
        with pytest.raises(SweepError, match=f"in use by process {holder.pid} on host"):
            with store_lock(path):
                pass
    finally:
        holder.kill()  # SIGKILL: no cleanup; the operating system drops the lock
        holder.wait()
    assert (tmp_path / "s.zarr.lock.owner").exists()  # stale record of the dead holder
    with store_lock(path):
        assert json.loads((tmp_path / "s.zarr.lock.owner").read_text())["pid"] == os.getpid()


def test_only_the_temporary_store_a_dead_coordinator_recorded_is_removed(tmp_path: Path
                                                                         ) -> None:
    # A coordinator killed while creating the store left its record and temporary store.
    dead = tmp_path / "s.zarr.tmp-fivdisc-999999"
    (dead / "done").mkdir(parents=True)
    (tmp_path / "s.zarr.lock.owner").write_text(json.dumps(
        {"pid": 999999, "host": "h", "since": "then", "command": "fivdisc sweep",
         "temporary": dead.name}))
    # The user's own files of similar names are not the program's.
    for name in ("s.zarr.tmp-backup", "s.zarr.tmp-123", "s.zarr.tmp-fivdisc-5"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "keep").write_text("mine")
    _store(tmp_path / "s.zarr")
    assert sorted(p.name for p in tmp_path.iterdir() if "tmp" in p.name) == [
        "s.zarr.tmp-123", "s.zarr.tmp-backup", "s.zarr.tmp-fivdisc-5"]
    assert verify_store(tmp_path / "s.zarr").complete.all()


# --- fivdisc sweep --verify ------------------------------------------------------------------


def test_verify_command(store: Path) -> None:
    result = run_cli(["sweep", "--verify", str(store)])
    assert result.exit_code == 0, result.output
    assert result.stdout == (f"{store}: 6 points: 6 complete and verified (1 of them failed "
                             "runs), 0 not computed, 0 damaged\n")
    _tamper(store, "max_normal_force", 4, np.nan)
    _tamper(store, "done", 5, False)
    result = run_cli(["sweep", "--verify", str(store)])
    assert result.exit_code == 1
    assert "4 complete and verified (1 of them failed runs), 1 not computed, 1 damaged" in \
        result.stdout
    assert "damaged points (values lost or not matching their checksums): 4\n" in result.stdout
    assert result.stderr.startswith("error: ") and result.stderr.count("\n") == 1


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["sweep", "--verify", "{store}", "{sweep}"], ["takes no sweep file"]),
        (["sweep", "--verify", "{store}", "--workers", "2"], ["takes no sweep file"]),
        (["sweep"], ["missing SWEEP_FILE"]),
    ],
)
def test_verify_usage(store: Path, tmp_path: Path, args, words) -> None:
    sweep = tmp_path / "s.toml"
    sweep.write_text("", encoding="utf-8")
    result = run_cli([a.format(store=store, sweep=sweep) for a in args])
    assert result.exit_code == 2 and "Usage:" in result.stderr
    for word in words:
        assert word in result.stderr


def test_verify_of_something_else_is_one_line(tmp_path: Path) -> None:
    (tmp_path / "empty.zarr").mkdir()
    for target, words in ((tmp_path / "empty.zarr", "has no zarr.json"),
                          (tmp_path / "none.zarr", "no such directory")):
        start = time.perf_counter()
        result = run_cli(["sweep", "--verify", str(target)])
        assert result.exit_code == 2 and time.perf_counter() - start < 5.0
        assert result.stderr.count("\n") == 1 and words in result.stderr


# --- chunks of many points -------------------------------------------------------------------


@pytest.mark.parametrize(("shape", "max_points"), [
    ((300, 300), []), ((5000,), []), ((1000, 10), []), ((2, 3, 4), []), ((7, 400, 3), []),
    ((300, 300), [1000]), ((40,), [200_000]),
])
def test_a_chunk_is_a_run_of_at_most_1024_consecutive_points(shape, max_points) -> None:
    from fivdisc.sweep.store.layout import point_chunks

    chunks = point_chunks(shape, max_points)
    size = int(np.prod(chunks))
    # as many points as fit, under both bounds (a section's values: 8 bytes each)
    bound = min(1024, max(1, 2**20 // (8 * max([1, *max_points]))))
    assert size <= bound and (size == int(np.prod(shape)) or size > bound // 2)
    # consecutive in C order: whole axes after the last one cut, one point before it
    cut = [k for k, (c, n) in enumerate(zip(chunks, shape, strict=True)) if c < n]
    if cut:
        assert all(c == 1 for c in chunks[:cut[-1]])


def test_a_grid_of_300_by_300_is_stored_in_100_chunks_per_variable(tmp_path: Path) -> None:
    import zarr

    spec = Sweep(base=SPEC.base, axes={"slider.normal_damping": "0.1:1.0:300",
                                       "speed.value": "1.0:30.0:300"}, keep=["separated"])
    with store_lock(tmp_path / "big.zarr"):
        SweepStore.open(tmp_path / "big.zarr", spec)
    for name in ("separated", "error", "checksum", "done"):
        assert zarr.open_array(tmp_path / "big.zarr" / name, mode="r").chunks == (3, 300)
