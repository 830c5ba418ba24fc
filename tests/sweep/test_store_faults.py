"""Issue 28, item 2: a sweep store's checks cover everything that gives a point its
meaning, and every damage the fault probe found is either repaired by a rerun of the
sweep or refused in one line saying what to delete.

Each reproduction is a parametrised case: the damage, what ``--verify`` reports (exit
status, the names it lists), and whether a rerun restores the store without recomputing
a point. The stores are filled with made-up outcomes (no simulations) except in the
dying-worker tests, which run small real sweeps. Time bounds are generous: they catch a
hang or an endless recompute, not a slow machine.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from fivdisc.case import Case
from fivdisc.sweep import (
    Sweep,
    SweepError,
    SweepStore,
    load_sweep,
    open_sweep,
    run_sweep,
    verify_store,
)
from fivdisc.sweep.store.lock import store_lock
from fivdisc.sweep.store.sweep_store import PointOutcome

from support.cli import run_cli

DAMPING = [0.1, 0.2, 0.3]
SPEED = [5.0, 6.0]
SPEC = Sweep(
    base=Case(simulation={"duration": 0.01, "output_rate": 1000.0}),
    axes={"slider.normal_damping": DAMPING, "speed.value": SPEED},
    keep=["separated", "max_abs_w"],
)
N = len(DAMPING) * len(SPEED)
BOUND = 60.0  # [s] far above what any case here takes; a hang or recompute loop exceeds it


def _outcome(i: int) -> PointOutcome:
    if i == 4:
        return PointOutcome(i, None, "RuntimeError: boom")
    return PointOutcome(i, {"separated": i % 2 == 0, "max_abs_w": 1e-6 * (i + 1)})


@pytest.fixture
def store(tmp_path: Path) -> Path:
    path = tmp_path / "s.zarr"
    with store_lock(path):
        SweepStore.open(path, SPEC).write([_outcome(i) for i in range(N)])
    return path


def _edit_json(path: Path, edit: Callable[[dict], None]) -> None:
    data = json.loads(path.read_text())
    edit(data)
    path.write_text(json.dumps(data))


def _set_attr(name: str, value: str) -> Callable[[Path], None]:
    return lambda store: _edit_json(store / "zarr.json",
                                    lambda d: d["attributes"].__setitem__(name, value))


def _set_meta(variable: str, key: str, value) -> Callable[[Path], None]:
    return lambda store: _edit_json(store / variable / "zarr.json",
                                    lambda d: d.__setitem__(key, value))


def _flip_bit(variable: str) -> Callable[[Path], None]:
    def flip(store: Path) -> None:
        chunk = store / variable / "c" / "0"
        data = bytearray(chunk.read_bytes())
        data[len(data) // 2] ^= 0x10
        chunk.write_bytes(bytes(data))
    return flip


def _rewrite_coordinate(store: Path) -> None:
    import zarr

    array = zarr.open_array(store / "speed.value", mode="r+")
    array[...] = np.array(SPEED[::-1])  # the data would sit on the wrong axis values


def _verify(store: Path) -> tuple[int, str, str]:
    result = run_cli(["sweep", "--verify", str(store)])
    return result.exit_code, result.stdout, result.stderr


def _timed_rerun(store: Path):
    start = time.perf_counter()
    report = run_sweep(SPEC, store, workers=1, progress=False)
    assert time.perf_counter() - start < BOUND
    return report


# --- damage that --verify names and a rerun repairs without recomputing -----------------------

REPAIRED = [
    # (id, damage, what --verify names)
    ("coordinate chunk deleted", lambda s: (s / "speed.value" / "c" / "0").unlink(),
     "speed.value"),
    ("coordinate values rewritten", _rewrite_coordinate, "speed.value"),
    ("coordinate bit flip", _flip_bit("speed.value"), "speed.value"),
    ("sweep_shape changed", _set_attr("sweep_shape", "[3, 3]"), "sweep_shape (group attribute)"),
    ("sweep_shape not JSON", _set_attr("sweep_shape", "[3, 2"), "sweep_shape (group attribute)"),
    ("sweep_variables changed", _set_attr("sweep_variables", '["separated", "error"]'),
     "sweep_variables (group attribute)"),
    ("sweep_sections changed", _set_attr("sweep_sections", '[{"name": "x", "max_points": 3}]'),
     "sweep_sections (group attribute)"),
    ("data_type changed", _set_meta("max_abs_w", "data_type", "float32"), "max_abs_w"),
    ("chunk_shape changed", _set_meta("max_abs_w", "chunk_grid", {
        "name": "regular", "configuration": {"chunk_shape": [2, 2]}}), "max_abs_w"),
    ("done data_type changed", _set_meta("done", "data_type", "uint8"), "done"),
]


@pytest.mark.parametrize(("damage", "named"), [(d, n) for _, d, n in REPAIRED],
                         ids=[i for i, _, _ in REPAIRED])
def test_damage_is_reported_and_repaired_by_a_rerun(store: Path, damage, named: str) -> None:
    reference = open_sweep(store)
    damage(store)
    status, out, err = _verify(store)
    assert status == 1, out
    assert f"variables with missing or damaged metadata: {named}" in out
    assert err.startswith("error: ") and err.count("\n") == 1
    with pytest.raises(SweepError, match=named.split(" ")[0]) as info:
        open_sweep(store)
    assert "\n" not in str(info.value)

    report = _timed_rerun(store)
    assert (report.already_done, report.computed) == (N, 0)  # every chunk was intact
    assert _verify(store)[0] == 0
    repaired = open_sweep(store)
    assert repaired.identical(reference.assign_attrs(history=repaired.attrs["history"]))


@pytest.mark.parametrize("damage", [
    lambda s: (s / "zarr.json").write_text((s / "zarr.json").read_text()[:120]),
    lambda s: (s / "zarr.json").write_text("{}"),
    _set_attr("sweep_definition", '{"format": 1}'),
], ids=["truncated", "emptied", "definition changed"])
def test_damaged_group_metadata_is_rebuilt_from_the_sweep(store: Path, damage) -> None:
    damage(store)
    status, _, err = _verify(store)
    assert status == 2 and err.count("\n") == 1 and "rerun the sweep that wrote it" in err
    report = _timed_rerun(store)
    assert (report.already_done, report.computed) == (N, 0)
    health = verify_store(store)
    assert health.healthy and health.complete.all()


def test_group_metadata_of_another_sweep_is_not_rebuilt(store: Path) -> None:
    (store / "zarr.json").write_text("{")
    other = Sweep(base=SPEC.base, keep=SPEC.keep,
                  axes={"slider.normal_damping": DAMPING, "speed.value": [7.0, 8.0]})
    with pytest.raises(SweepError, match=r"cannot be rebuilt from this sweep: its speed.value "
                                         r"are not this sweep's; delete .*s.zarr to start over$"):
        run_sweep(other, store, workers=1, progress=False)


def test_a_lost_variable_is_recomputed_once(store: Path) -> None:
    # Recompute-all loops came from metadata that a rerun rewrote the same wrong way.
    for path in sorted((store / "max_abs_w").rglob("*"), reverse=True):
        path.unlink() if path.is_file() else path.rmdir()
    health = verify_store(store)
    assert health.broken == ("max_abs_w",)
    with store_lock(store):
        target = SweepStore.open(store, SPEC)
        lost = ~target.completed()
        target.write([_outcome(i) for i in np.flatnonzero(lost)])
    assert verify_store(store).complete.all()
    with store_lock(store):
        assert SweepStore.open(store, SPEC).completed().all()


# --- the lock and temporary stores -----------------------------------------------------------


def test_the_lock_holds_through_a_symbolic_link(tmp_path: Path) -> None:
    store = tmp_path / "tw.zarr"
    link = tmp_path / "twlink.zarr"
    link.symlink_to(store.name)
    with store_lock(store):
        with pytest.raises(SweepError, match=f"{link} is in use by process {os.getpid()}"):
            run_sweep(SPEC, link, workers=1, progress=False)
    with store_lock(link):
        assert (tmp_path / "tw.zarr.lock").exists() and not (tmp_path / "twlink.zarr.lock").exists()
        with pytest.raises(SweepError, match="in use by process"):
            with store_lock(store):
                pass
        # Created through the link: the store is where it leads, the link stays a link.
        SweepStore.open(link, SPEC)
    assert link.is_symlink() and (store / "zarr.json").is_file()


@pytest.mark.parametrize("name", ["res.zarr.tmp-backup", "res.zarr.tmp-4242",
                                  "res.zarr.tmp-fivdisc-4242"])
def test_a_users_look_alike_siblings_are_kept(tmp_path: Path, name: str) -> None:
    sibling = tmp_path / name
    sibling.mkdir()
    (sibling / "zarr.json").write_text("{}")
    start = time.perf_counter()
    with store_lock(tmp_path / "res.zarr"):
        SweepStore.open(tmp_path / "res.zarr", SPEC)
    assert time.perf_counter() - start < BOUND
    assert (sibling / "zarr.json").read_text() == "{}"


# --- a dying worker --------------------------------------------------------------------------

HELPER = '''
import ctypes
import os
import signal
import tomllib


def deadly(result):
    """Largest |w|; the worker dies for normal_damping = 0.3."""
    case = tomllib.loads(result.dataset.attrs["case"])
    if case["slider"]["normal_damping"] == 0.3:
        {death}
    return result.summary().max_abs_w
'''


@pytest.mark.parametrize(("death", "reason"), [
    ("os._exit(3)", "exit status 3"),
    ("ctypes.string_at(0)", "killed by signal SIGSEGV"),
    ("os.kill(os.getpid(), signal.SIGKILL)", "killed by signal SIGKILL"),
], ids=["os._exit", "segfault", "sigkill"])
def test_a_point_whose_worker_dies_is_stored_as_failed(tmp_path: Path, monkeypatch, death: str,
                                                        reason: str) -> None:
    (tmp_path / "dying_helper.py").write_text(HELPER.format(death=death), encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    sweep = tmp_path / "s.toml"
    sweep.write_text(
        '[base.simulation]\nduration = 0.002\noutput_rate = 1000.0\n'
        '[axes]\n"slider.normal_damping" = [0.1, 0.2, 0.3, 0.4]\n'
        '[reduce]\nkeep = ["dying_helper:deadly"]\n', encoding="utf-8")
    spec = load_sweep(sweep)
    start = time.perf_counter()
    # A process pool: in a thread, the death would be the whole sweep's.
    report = run_sweep(spec, tmp_path / "s.zarr", workers=2, progress=False, pool="process")
    assert time.perf_counter() - start < 4 * BOUND
    assert list(report.failed) == [2]
    assert report.failed[2] == (f"the worker process died while computing this point ({reason}),"
                                " also when it was run again alone")
    data = open_sweep(tmp_path / "s.zarr")
    assert data["done"].all()
    assert np.isfinite(data["deadly"].values[[0, 1, 3]]).all()
    # The failure is stored: a rerun computes nothing.
    again = run_sweep(spec, tmp_path / "s.zarr", workers=2, progress=False, pool="process")
    assert (again.already_done, again.computed) == (4, 0)


# --- checking cost ---------------------------------------------------------------------------


def test_checking_an_empty_300_by_300_store_reads_no_chunk(tmp_path: Path) -> None:
    # The probe measured 73 s to check this empty store through Zarr (one chunk lookup
    # per point and variable); the check now lists the `done` chunks and reads nothing
    # else. The full cost is measured against Zarr in benchmarks/bench_store.py.
    spec = Sweep(base=SPEC.base, axes={"slider.normal_damping": "0.1:1.0:300",
                                       "speed.value": "1.0:30.0:300"}, keep=["separated"])
    path = tmp_path / "big.zarr"
    with store_lock(path):
        SweepStore.open(path, spec)
    start = time.perf_counter()
    health = verify_store(path)
    assert time.perf_counter() - start < 10.0
    assert health.healthy and health.complete.size == 90_000 and not health.complete.any()


def test_the_verify_command_in_a_fresh_process_is_bounded(store: Path) -> None:
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "fivdisc", "sweep", "--verify", str(store)],
                          capture_output=True, text=True, timeout=BOUND)
    assert done.returncode == 0 and time.perf_counter() - start < BOUND
    assert f"{N} points: {N} complete and verified (1 of them failed runs)" in done.stdout


def test_checking_a_full_store_opens_each_chunk_file_there_is_once(store: Path,
                                                                    monkeypatch) -> None:
    # A chunk equal to the fill value is never written (here: separated = False, the empty
    # errors); trying every point's file anyway cost a failed open each, and a full
    # store's check is as many file operations as there are chunk files (its cost, against
    # the former check, is measured in benchmarks/bench_store.py). Both ways of opening a
    # file are watched, so that a check opening files through Python's `open` counts too.
    import builtins

    existing = {str(f) for f in store.rglob("*") if f.is_file() and "/c/" in str(f)}
    opened: list[str] = []

    def watch(real):
        def opening(file, *args, **kwargs):
            if "/c/" in str(file):
                opened.append(str(Path(file)))
            return real(file, *args, **kwargs)
        return opening

    monkeypatch.setattr(os, "open", watch(os.open))
    monkeypatch.setattr(builtins, "open", watch(builtins.open))
    health = verify_store(store)
    monkeypatch.undo()
    assert health.healthy and health.complete.all()
    data_files = {f for f in existing if Path(f).relative_to(store).parts[0]
                  not in SPEC.axes}  # coordinates are read through Zarr, whole
    assert sorted(opened) == sorted(data_files)


def _checksum_of(digest: str, index: int, row: list) -> int:
    """The checksum of one point as its definition states it (one value at a time)."""
    import hashlib
    import math
    import struct

    h = hashlib.blake2b(f"{digest}:{index}".encode(), digest_size=8)
    for value in row:
        if isinstance(value, np.ndarray):  # a section's values: one NaN for every NaN
            token = np.where(np.isnan(value), np.nan, value).astype("<f8").tobytes()
        elif isinstance(value, bool | np.bool_):
            token = b"T" if value else b"F"
        elif isinstance(value, float | np.floating):
            token = b"nan" if math.isnan(value) else struct.pack("<d", float(value))
        else:
            token = str(value).encode()
        h.update(len(token).to_bytes(4, "little") + token)
    return int.from_bytes(h.digest(), "little") or 1


def test_checksums_a_column_at_a_time_are_the_point_by_point_definition() -> None:
    # Stores written before the checksum was computed a column at a time verify unchanged.
    from fivdisc.sweep.store.checksum import checksums
    from fivdisc.sweep.store.layout import STRING

    rng = np.random.default_rng(28)
    n = 40
    floats = np.where(rng.random(n) < 0.3, np.nan, rng.normal(size=n))
    floats[:2] = [-0.0, np.float64("-nan")]
    section = np.where(rng.random((n, 3)) < 0.3, np.nan, rng.normal(size=(n, 3)))
    columns = [rng.random(n) < 0.5, floats, section, rng.integers(0, 4, n).astype(np.int32),
               np.array(["", "RuntimeError: boom é"] * (n // 2), dtype=STRING)]
    indices = list(range(7, 7 + n))
    expected = [_checksum_of("d1g", i, [c[k] for c in columns]) for k, i in enumerate(indices)]
    assert checksums("d1g", indices, columns).tolist() == expected


# --- issue 40, item 6: stores repaired, not recomputed ---------------------------------------


def _raw_done(store: Path) -> np.ndarray:
    """The done flags as stored (not as open_sweep derives them)."""
    import zarr

    return zarr.open_array(store / "done", mode="r")[...].ravel()


def _repaired_without_recomputing(store: Path, reference) -> None:
    report = _timed_rerun(store)
    assert (report.already_done, report.computed) == (N, 0)
    status, out, _ = _verify(store)
    assert status == 0, out
    assert _raw_done(store).all()
    repaired = open_sweep(store)
    assert repaired.identical(reference.assign_attrs(history=repaired.attrs["history"]))


def test_a_deleted_group_metadata_file_is_rebuilt_from_the_sweep(store: Path) -> None:
    """A deleted top-level zarr.json (chunks intact) was "not a Zarr store" and the rerun
    refused it; a garbage one was rebuilt. Both are now."""
    reference = open_sweep(store)
    (store / "zarr.json").unlink()
    status, _, err = _verify(store)
    assert status == 2 and err.count("\n") == 1
    assert "zarr.json is missing); rerun the sweep that wrote it to rebuild it" in err
    _repaired_without_recomputing(store, reference)


def test_a_changed_codec_is_restored_and_the_points_kept(store: Path) -> None:
    """A codec changed in a variable's metadata made every chunk undecodable: all points
    recomputed. The rerun restores the sweep's codecs (those under which more points
    verify) and keeps every point."""
    reference = open_sweep(store)
    _set_meta("max_abs_w", "codecs", [{"name": "bytes", "configuration": {"endian": "little"}},
                                      {"name": "gzip", "configuration": {"level": 5}}])(store)
    status, out, _ = _verify(store)
    assert status == 1 and f"{N} damaged" in out
    _repaired_without_recomputing(store, reference)


def test_codecs_of_the_chunks_are_kept_where_the_sweeps_would_lose_points(store: Path) -> None:
    """Chunks written with other codecs (as another version of Zarr may) verify with the
    codecs their metadata names: the rerun leaves those, and recomputes nothing."""
    import zarr

    reference = open_sweep(store)
    path = store / "max_abs_w"
    values = zarr.open_array(path, mode="r")[...]
    meta = json.loads((path / "zarr.json").read_text())
    for chunk in (path / "c").rglob("*"):
        if chunk.is_file():
            chunk.unlink()
    array = zarr.create_array(path, shape=values.shape, chunks=tuple(
        meta["chunk_grid"]["configuration"]["chunk_shape"]), dtype="float64",
        fill_value=np.nan, compressors=[zarr.codecs.GzipCodec(level=5)], overwrite=True,
        dimension_names=meta["dimension_names"], attributes=meta["attributes"])
    array[...] = values
    assert verify_store(store).complete.all()
    _repaired_without_recomputing(store, reference)
    assert "gzip" in (path / "zarr.json").read_text()


@pytest.mark.parametrize("lost", ["done", "done/c"])
def test_lost_done_flags_keep_the_points_whose_checksums_hold(store: Path, lost: str) -> None:
    """A deleted done/ (or its chunks) lost every point: they were recomputed. The
    checksums cover the points' values, so the points verify without their flags, and the
    rerun rebuilds the metadata and writes the flags again."""
    import shutil

    reference = open_sweep(store)
    shutil.rmtree(store / lost)
    assert verify_store(store).complete.all()
    _repaired_without_recomputing(store, reference)


def test_verify_does_not_call_intact_points_not_computed(store: Path) -> None:
    """With done/c deleted, --verify said "6 not computed" and exit status 0: the points'
    values were intact. It says they verify, that their flags are lost, and that the store
    needs the rerun that writes them (status 1)."""
    import shutil

    shutil.rmtree(store / "done" / "c")
    status, out, err = _verify(store)
    assert f"{N} complete and verified (1 of them failed runs), 0 not computed, 0 damaged" in out
    assert f"{N} complete points lost their done flags (their values verify by their " \
           "checksums; a rerun writes the flags again)" in out
    assert status == 1 and err.startswith("error: ") and err.count("\n") == 1
