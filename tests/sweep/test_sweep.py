"""Sweeps: file format and validation, reductions, resumable Zarr store, CLI, separation maps."""

from __future__ import annotations

import contextlib
import math
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from fivdisc import examples
from fivdisc.case import Case
from fivdisc.cli.sweep import separation_map, sweep
from fivdisc.engine.simulation import simulate
from fivdisc.errors import CaseError, FivdiscError
from fivdisc.sweep import (
    BUILTIN,
    Sweep,
    SweepError,
    load_sweep,
    open_sweep,
    run_sweep,
)
from fivdisc.sweep.reductions import evaluate, resolve, stop_events
from fivdisc.sweep.run import run_point
from fivdisc.sweep.spec import parse_range
from fivdisc.sweep.store.health import read_mask

# A user reduction, importable by the workers through PYTHONPATH / sys.path.
HELPER = '''
import time
import tomllib


def fragile(result):
    """Number of switches; fails on purpose for the fastest disc."""
    time.sleep(0.6)  # slow enough to interrupt a sweep between points, however fast the solver
    case = tomllib.loads(result.dataset.attrs["case"])
    if case["speed"]["initial"] >= 20.0:
        raise ValueError("too fast for this test")
    return result.summary().switches
'''

# 12 points of about 0.7 s each; the user reduction needs whole runs and fails for
# the 3 points with initial = 20.
SWEEP = """
mode = "grid"
[base.speed]
profile = "decelerating"
[base.simulation]
output_rate = 1000.0
[axes]
"speed.initial" = "8.0:20.0:4"
"speed.duration" = [2.0, 4.0, 6.0]
[link]
"simulation.duration" = "speed.duration"
[reduce]
keep = ["separated", "first_separation_time", "stick_fraction", "max_normal_force",
        "sweep_helper:fragile"]
"""


def _short(**updates) -> Case:
    """A short decelerating case (0.05 s at 1 kHz output)."""
    values = {
        "speed.profile": "decelerating",
        "speed.initial": 10.0,
        "speed.duration": 5.0,
        "simulation.duration": 0.05,
        "simulation.output_rate": 1000.0,
    }
    return Case().replace(values | updates)


def _sweep_text(axes: str, keep: str = '["separated"]', extra: str = "") -> str:
    return f"""
[base.simulation]
duration = 0.05
output_rate = 1000.0
[axes]
{axes}
[reduce]
keep = {keep}
{extra}
"""


@pytest.fixture(scope="module")
def helper_dir(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("helper")
    (path / "sweep_helper.py").write_text(HELPER, encoding="utf-8")
    return path


@pytest.fixture(autouse=True)
def _helper_on_path(helper_dir, monkeypatch) -> None:
    # spawned workers inherit sys.path; subprocesses get PYTHONPATH
    monkeypatch.syspath_prepend(str(helper_dir))
    # prepended: the fivdisc a PYTHONPATH names (a worktree's) stays the one imported
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(
        [str(helper_dir), *filter(None, [os.environ.get("PYTHONPATH")])]))


@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("sweep") / "sweep.toml"
    path.write_text(SWEEP, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def reference(sweep_file, helper_dir, tmp_path_factory) -> Path:
    """The sweep run without interruption on a 2-process pool."""
    sys.path.insert(0, str(helper_dir))
    try:
        store = tmp_path_factory.mktemp("reference") / "reference.zarr"
        report = run_sweep(load_sweep(sweep_file), store, workers=2, progress=False)
    finally:
        sys.path.remove(str(helper_dir))
    assert (report.already_done, report.computed) == (0, 12)
    return store


# --- file format -----------------------------------------------------------------------------


def test_ranges_are_inclusive_linspaces() -> None:
    assert parse_range("6.0:20.0:8") == pytest.approx(np.linspace(6.0, 20.0, 8).tolist())
    assert parse_range("1:5:5") == [1, 2, 3, 4, 5]
    assert all(isinstance(v, int) for v in parse_range("0:10:3"))
    assert parse_range("0:1:3") == [0.0, 0.5, 1.0]
    assert parse_range("2.5:2.5:1") == [2.5]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("1:2", 'must be "start:stop:n"'),
        ("a:2:3", 'must be "start:stop:n"'),
        ("1:2:0", "n must be >= 1"),
        ("1:2:1", "n = 1 needs start == stop"),
        ("1:inf:3", "must be finite"),
    ],
)
def test_bad_ranges(text: str, message: str) -> None:
    with pytest.raises(SweepError, match=message):
        parse_range(text, "axes.'x'")


def test_grid_order_zip_and_links() -> None:
    grid = Sweep.from_toml(
        _sweep_text('"speed.value" = [1.0, 2.0, 3.0]\n"slider.mass" = "0.1:0.2:2"')
    )
    assert grid.shape == (3, 2) and grid.n_points == 6
    # C order: the first axis varies slowest
    assert grid.updates(1) == {"speed.value": 1.0, "slider.mass": 0.2}
    assert grid.updates(2) == {"speed.value": 2.0, "slider.mass": 0.1}
    assert grid.cases[5].speed.value == 3.0 and grid.cases[5].slider.mass == 0.2
    zipped = Sweep.from_toml(
        'mode = "zip"\n'
        + _sweep_text(
            '"speed.initial" = [1.0, 2.0]\n"speed.duration" = [5.0, 6.0]',
            extra='[link]\n"simulation.duration" = "speed.duration"',
        ).replace("[base.simulation]", '[base.speed]\nprofile = "decelerating"\n[base.simulation]')
    )
    assert zipped.shape == (2,)
    assert [c.speed.duration for c in zipped] == [5.0, 6.0]
    assert [c.simulation.duration for c in zipped] == [5.0, 6.0]


def test_base_file_is_relative_to_the_sweep_file(tmp_path) -> None:
    (tmp_path / "cases").mkdir()
    (tmp_path / "cases" / "base.toml").write_text("[slider]\nmass = 0.2\n", encoding="utf-8")
    path = tmp_path / "cases" / "sweep.toml"
    path.write_text(
        'base = "base.toml"\n[axes]\n"speed.value" = [1.0]\n[reduce]\nkeep = ["separated"]\n'
    )
    spec = load_sweep(path)
    assert spec.base.slider.mass == 0.2
    path.write_text(path.read_text().replace("base.toml", "missing.toml"))
    with pytest.raises(
        SweepError, match=r"sweep\.toml: base = 'missing\.toml' is invalid: no file"
    ):
        load_sweep(path)


@pytest.mark.parametrize("override", [
    '[override.simulation]\nduration = 0.5\n[override.slider]\npreload = 400.0\n',
    '[override]\n"simulation.duration" = 0.5\n"slider.preload" = 400.0\n',
])
def test_override_changes_the_base_file_in_place(tmp_path, override) -> None:
    """Issue 27, item 6: a sweep changes keys of its base file without a copy of it."""
    (tmp_path / "brake2.toml").write_text("[slider]\nmass = 0.2\n[simulation]\nduration = 3.0\n")
    path = tmp_path / "sweep.toml"
    path.write_text('base = "brake2.toml"\n' + override
                    + '[axes]\n"speed.value" = [1.0]\n[reduce]\nkeep = ["separated"]\n')
    spec = load_sweep(path)
    assert spec.base == Case(slider={"mass": 0.2, "preload": 400.0},
                             simulation={"duration": 0.5})


def test_override_errors_and_the_toml_conflict_explained(tmp_path) -> None:
    (tmp_path / "brake2.toml").write_text("")
    path = tmp_path / "sweep.toml"
    rest = '[axes]\n"speed.value" = [1.0]\n[reduce]\nkeep = ["separated"]\n'
    # The form a user tries first is not TOML: say why, and what to write instead.
    path.write_text('base = "brake2.toml"\n[base.simulation]\nduration = 2.0\n' + rest)
    with pytest.raises(SweepError, match=r"base = \"FILE\" and a \[base\.TABLE\] table cannot "
                       r"both be in a TOML file .* \[override\] table"):
        load_sweep(path)
    path.write_text('base = "brake2.toml"\n[override.simulation]\nduratoin = 2.0\n' + rest)
    with pytest.raises(SweepError, match=r"unknown key 'override\.simulation\.duratoin': not a "
                       r"case key; did you mean 'simulation\.duration'\?"):
        load_sweep(path)
    path.write_text('base = "brake2.toml"\n[override.simulation]\nduration = -1.0\n' + rest)
    with pytest.raises(CaseError, match=r"override: .*simulation\.duration"):
        load_sweep(path)


def test_fig27_example_is_the_separation_map_default() -> None:
    from fivdisc.sweep import separation_sweep

    example = load_sweep(examples.path("sweep_fig27"))
    assert example.shape == (40, 40)
    assert example.stop_on == ("separation",)
    assert example.digest == separation_sweep().digest


@pytest.mark.parametrize(
    ("axes", "keep", "extra", "message"),
    [
        (
            '"speed.vlaue" = [1.0]',
            '["separated"]',
            "",
            r"axes: unknown case key 'speed\.vlaue'; did you mean 'speed\.value'\?",
        ),
        (
            '"speed.value" = [1.0]',
            '["separted"]',
            "",
            r"unknown reduction 'separted'; did you mean 'separated'\?",
        ),
        ('"speed.value" = [1.0]', "[]", "", r"reduce\.keep = \[\] is invalid: must be a non-emp"),
        (
            '"speed.value" = [1.0]',
            '["no_such_module:f"]',
            "",
            r"'no_such_module:f' is invalid: cannot import 'no_such_module'",
        ),
        (
            '"speed.value" = [1.0]',
            '["sweep_helper:fragil"]',
            "",
            r"has no function 'fragil'; did you mean 'fragile'\?",
        ),
        ('"speed.value" = [1.0]', '["separated", "separated"]', "", "would both be stored"),
        ('"speed.value" = [1.0, 1.0]', '["separated"]', "", "repeats the value 1.0"),
        ('"speed.value" = []', '["separated"]', "", "must be a non-empty list"),
        ('"speed.value" = "1:2"', '["separated"]', "", r"axes\.'speed\.value' = '1:2'"),
        (
            '"speed.value" = [1.0]',
            '["separated"]',
            'mode = "mesh"',
            r"mode = 'mesh' is invalid: must be one of 'grid', 'zip'",
        ),
        (
            '"speed.value" = [1.0]',
            '["separated"]',
            '[link]\n"simulation.duraton" = "x"',
            r"link: unknown case key 'simulation\.duraton'; did you mean 'simulation\.duration'",
        ),
    ],
)
def test_invalid_sweeps_are_refused(axes: str, keep: str, extra: str, message: str) -> None:
    text = _sweep_text(axes, keep)
    # top-level keys must precede the tables
    text = f"{extra}\n{text}" if extra.startswith("mode") else f"{text}\n{extra}"
    with pytest.raises(SweepError, match=message) as info:
        Sweep.from_toml(text, source="s.toml")
    assert str(info.value).startswith("s.toml: ")
    assert "\n" not in str(info.value)


def test_unknown_file_keys_and_zip_lengths() -> None:
    with pytest.raises(SweepError, match=r"unknown key 'axis'; did you mean 'axes'\?"):
        Sweep.from_toml("axis = 1\n" + _sweep_text('"speed.value" = [1.0]'))
    with pytest.raises(SweepError, match=r"unknown key 'reduce\.kep'"):
        Sweep.from_toml(_sweep_text('"speed.value" = [1.0]').replace("keep =", "kep ="))
    with pytest.raises(SweepError, match=r"needs axes of equal length: 'speed\.value' has 2"):
        Sweep.from_toml(
            'mode = "zip"\n' + _sweep_text('"speed.value" = [1.0, 2.0]\n"slider.mass" = [0.1]')
        )


def test_every_point_is_validated_before_running(tmp_path) -> None:
    path = tmp_path / "bad.toml"
    # points 2 and 5 (t_max = 0) are invalid; the first is named
    path.write_text(
        _sweep_text('"speed.initial" = [1.0, 2.0]\n"speed.duration" = "2.0:0.0:3"').replace(
            "[base.simulation]", '[base.speed]\nprofile = "decelerating"\n[base.simulation]'
        )
    )
    with pytest.raises(
        CaseError,
        match=r"point 2 \(speed\.initial = 1\.0, speed\.duration = "
        r"0\.0\): speed\.duration = 0\.0 is invalid: must be > 0",
    ):
        load_sweep(path)
    store = tmp_path / "bad.zarr"
    result = CliRunner().invoke(sweep, [str(path), "-o", str(store), "--no-progress"])
    assert isinstance(result.exception, CaseError)
    assert not store.exists()


def test_speed_key_of_another_profile_names_the_point() -> None:
    with pytest.raises(
        CaseError,
        match=r"point 0 .*unknown key 'speed\.duration' for speed "
        "profile 'constant'",
    ):
        Sweep.from_toml(_sweep_text('"speed.duration" = [1.0]'))


def test_definition_hash_follows_the_definition(tmp_path) -> None:
    text = _sweep_text('"speed.value" = "1.0:2.0:3"')
    a, b = Sweep.from_toml(text), Sweep.from_toml(text)
    assert a.definition == b.definition and len(a.digest) == 64
    assert Sweep.from_toml(text.replace("1.0:2.0:3", "1.0:2.0:4")).digest != a.digest
    assert Sweep.from_toml(text.replace("0.05", "0.06")).digest != a.digest
    # the same points written as a list, or with integers, are the same sweep
    assert Sweep.from_toml(text.replace('"1.0:2.0:3"', "[1.0, 1.5, 2.0]")).digest == a.digest
    integers = _sweep_text('"speed.value" = "2:6:3"')
    assert Sweep.from_toml(integers).axes == {"speed.value": (2.0, 4.0, 6.0)}
    assert (
        Sweep.from_toml(integers).digest
        == Sweep.from_toml(integers.replace('"2:6:3"', "[2.0, 4.0, 6.0]")).digest
    )


# --- reductions ------------------------------------------------------------------------------


def test_early_stop_only_when_every_kept_value_is_decided() -> None:
    assert stop_events(resolve(["separated"])) == ("separation",)
    assert stop_events(resolve(["separated", "first_separation_time"])) == ("separation",)
    assert stop_events(resolve(["separated", "stick_fraction"])) == ()
    assert stop_events(resolve(["separated", "sweep_helper:fragile"])) == ()


def test_builtin_reductions_match_the_run() -> None:
    case = _short(**{"simulation.duration": 0.2})
    keep = [n for n, r in BUILTIN.items() if n not in ("dominant_frequency", "max_growth_rate")]
    values = evaluate(case, keep)
    result = simulate(case)
    summary = result.summary()
    spent = summary.sliders[0].time_in_phase
    assert values["separated"] is (summary.separations > 0)
    assert math.isnan(values["first_separation_time"]) == (summary.separations == 0)
    assert values["stick_fraction"] == pytest.approx(spent["stick"] / sum(spent.values()))
    assert values["separation_fraction"] == pytest.approx(spent["separation"] / sum(spent.values()))
    assert values["max_abs_w"] == summary.max_abs_w
    assert values["max_normal_force"] == summary.peak_normal_force


def test_separation_reductions_stop_at_the_first_separation() -> None:
    case = _short(**{"speed.initial": 20.0, "speed.duration": 35.0, "simulation.duration": 4.0})
    first = simulate(case, stop_on=("separation",))
    assert first.status == "stopped"
    values = evaluate(case, ["separated", "first_separation_time"])
    assert values == {"separated": True, "first_separation_time": first.events("separation")[0]}


def test_analysis_reductions() -> None:
    values = evaluate(
        Case().replace({"simulation.duration": 0.2, "simulation.output_rate": 2000.0}),
        ["dominant_frequency", "max_growth_rate"],
    )
    assert values["dominant_frequency"] > 0 and math.isfinite(values["max_growth_rate"])


def test_largest_lyapunov_is_stored_with_its_inconclusive_mark() -> None:
    # Issue 28, item 3: no reader sees the exponent without whether it is usable; kept
    # once, whatever the order, and a reduction kept twice is still refused.
    def names(keep):
        return [r.name for r in resolve(keep)]

    assert names(["largest_lyapunov", "separated"]) == [
        "largest_lyapunov", "largest_lyapunov_inconclusive", "separated"]
    assert names(["largest_lyapunov_inconclusive", "largest_lyapunov"]) == [
        "largest_lyapunov_inconclusive", "largest_lyapunov"]
    assert BUILTIN["largest_lyapunov_inconclusive"].dtype == "bool"
    with pytest.raises(SweepError, match="would both be stored as 'largest_lyapunov'"):
        resolve(["largest_lyapunov", "largest_lyapunov"])


def test_max_growth_rate_needs_constant_speed() -> None:
    with pytest.raises(SweepError, match="'max_growth_rate' needs a constant disc speed"):
        Sweep(base=_short(), axes={"speed.initial": [1.0]}, keep=["max_growth_rate"])


def test_a_failing_point_is_returned_with_its_message() -> None:
    outcome = run_point(3, _short(**{"simulation.max_switches": 1}), ("separated",))
    assert (outcome.index, outcome.values) == (3, None)
    assert outcome.error.startswith("simulation max_switches: simulation.max_switches = 1")
    outcome = run_point(0, _short(**{"speed.initial": 20.0}), ("sweep_helper:fragile",))
    assert outcome.error == "ValueError: too fast for this test"
    # a worker that cannot import a user reduction records that too
    outcome = run_point(0, _short(), ("sweep_helper_gone:f",))
    assert "cannot import 'sweep_helper_gone'" in outcome.error


# --- running and storing ---------------------------------------------------------------------


def test_store_holds_values_failures_and_definition(reference, sweep_file) -> None:
    spec = load_sweep(sweep_file)
    data = open_sweep(reference)
    # on the grid's own axes, named after the keys, in the sweep's order
    assert data["separated"].dims == ("speed.initial", "speed.duration")
    assert dict(data.sizes) == {"speed.initial": 4, "speed.duration": 3}
    np.testing.assert_array_equal(data["speed.duration"], [2.0, 4.0, 6.0])
    assert data["done"].all()
    assert data.attrs["sweep_hash"] == spec.digest
    assert data.attrs["sweep_definition"] == spec.definition
    assert data["speed.initial"].attrs["units"] == "rad/s"
    assert data["speed.initial"].attrs["long_name"] == "initial disc speed"
    failed = (data["speed.initial"] == 20.0).broadcast_like(data["error"]).values
    np.testing.assert_array_equal(data["error"].values != "", failed)
    assert set(data["error"].values[failed]) == {"ValueError: too fast for this test"}
    assert np.isnan(data["fragile"].values[failed]).all()
    assert not data["separated"].values[failed].any()
    # every other point holds exactly what a run in this process gives, at its place
    # on the axes (point 7 of the C-ordered 4 x 3 grid is the third speed, second duration)
    for index, at in ((0, {"speed.initial": 8.0, "speed.duration": 2.0}),
                      (7, {"speed.initial": 16.0, "speed.duration": 4.0})):
        assert spec.updates(index) == at
        expected = evaluate(spec.cases[index], spec.keep)
        for name, value in expected.items():
            np.testing.assert_equal(data[name].sel(at).item(), value)


def test_rerun_computes_nothing_and_other_sweeps_are_refused(reference, sweep_file) -> None:
    report = run_sweep(load_sweep(sweep_file), reference, workers=1, progress=False)
    assert (report.already_done, report.computed) == (12, 0)
    assert sorted(report.failed) == [9, 10, 11]
    changed = Sweep.from_toml(SWEEP.replace("[2.0, 4.0, 6.0]", "[2.0, 4.0, 7.0]"))
    with pytest.raises(
        SweepError,
        match=r"holds a different sweep \(its definition differs "
        r"in: axes\); write to a new store",
    ):
        run_sweep(changed, reference, progress=False)
    result = CliRunner().invoke(sweep, [str(sweep_file), "-o", str(reference), "--no-progress"])
    assert result.exit_code == 0, result.output
    assert "12 points: 12 already stored, 0 computed" in result.output
    assert "3 points failed" in result.output and "too fast for this test" in result.output


def test_damaged_points_count_as_not_done(reference, sweep_file, tmp_path) -> None:
    import zarr

    store = tmp_path / "damaged.zarr"
    shutil.copytree(reference, store)

    def tamper(name: str, point: int, value) -> None:  # the checksum left as it was
        zarr.open_array(store / name, mode="r+")[np.unravel_index(point, (4, 3))] = value

    tamper("stick_fraction", 1, 0.5)
    tamper("max_normal_force", 2, 1.0)
    tamper("done", 3, False)  # values written, flag not yet
    # lost: Zarr reads a lost chunk as NaN, so only the point's checksum tells
    tamper("max_normal_force", 4, np.nan)
    expected = np.ones(12, dtype=bool)
    expected[[1, 2, 3, 4]] = False
    np.testing.assert_array_equal(read_mask(store), expected)
    np.testing.assert_array_equal(open_sweep(store)["done"].values.ravel(), expected)
    report = run_sweep(load_sweep(sweep_file), store, workers=1, progress=False)
    assert (report.already_done, report.computed) == (8, 4)
    xr.testing.assert_identical(open_sweep(store), open_sweep(reference))


def test_not_a_sweep_store(tmp_path, sweep_file) -> None:
    (tmp_path / "x.zarr").mkdir()
    with pytest.raises(SweepError, match="exists and is not a Zarr store"):
        run_sweep(load_sweep(sweep_file), tmp_path / "x.zarr", progress=False)
    with pytest.raises(SweepError, match=r"workers = 0 is invalid: must be an integer >= 1"):
        run_sweep(load_sweep(sweep_file), tmp_path / "y.zarr", workers=0)
    assert not (tmp_path / "y.zarr").exists()


def _session(sid: int) -> list[int]:
    """Live processes of a session (Linux /proc)."""
    pids = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        with contextlib.suppress(OSError):
            fields = (entry / "stat").read_text().rpartition(")")[2].split()
            if int(fields[3]) == sid and fields[0] != "Z":
                pids.append(int(entry.name))
    return pids


def _command(sweep_file: Path, store: Path, *extra: str) -> list[str]:
    """`fivdisc sweep` in a fresh interpreter, without the progress bar."""
    return [sys.executable, "-c", "from fivdisc.cli.sweep import sweep; sweep()",
            str(sweep_file), "-o", str(store), *extra, "--no-progress"]


def _start(sweep_file: Path, store: Path, pool: str) -> subprocess.Popen:
    return subprocess.Popen(
        _command(sweep_file, store, "--workers", "1", "--pool", pool), start_new_session=True,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )


def _wait_for_points(process: subprocess.Popen, store: Path, count: int) -> None:
    deadline = time.monotonic() + 180.0  # generous on a loaded machine
    while not (store.exists() and read_mask(store).sum() >= count):
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "the sweep made no progress"
        time.sleep(0.05)


@pytest.mark.parametrize("pool", ["thread", "process"])
def test_interrupted_and_killed_sweeps_resume(reference, sweep_file, tmp_path, pool) -> None:
    store = tmp_path / "resumed.zarr"
    # Ctrl-C: SIGINT to the whole process group, as a terminal sends it
    process = _start(sweep_file, store, pool)
    try:
        _wait_for_points(process, store, 2)
        os.killpg(process.pid, signal.SIGINT)
        _, err = process.communicate(timeout=60)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
    assert process.returncode == 130, err
    # No named semaphore of a terminated worker left for the resource tracker to report.
    assert "leaked" not in err, err
    interrupted = int(read_mask(store).sum())
    assert f"interrupted: {interrupted} of 12 points are stored" in err
    assert 2 <= interrupted < 12

    # SIGKILL to the coordinator only: worker processes notice and exit by themselves
    process = _start(sweep_file, store, pool)
    try:
        _wait_for_points(process, store, interrupted + 1)
        process.kill()
        process.communicate(timeout=60)
        deadline = time.monotonic() + 10.0
        while _session(process.pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _session(process.pid), "workers outlived their coordinator"
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
    killed = int(read_mask(store).sum())
    assert interrupted < killed < 12

    finished = subprocess.run(_command(sweep_file, store), capture_output=True, text=True,
                              timeout=300)
    assert finished.returncode == 0, finished.stderr
    assert f"12 points: {killed} already stored, {12 - killed} computed" in finished.stdout
    # equal but for the history attribute: when each store was made
    xr.testing.assert_identical(open_sweep(store).assign_attrs(history=""),
                                open_sweep(reference).assign_attrs(history=""))


# --- separation maps -------------------------------------------------------------------------


def test_separation_is_likelier_at_high_speed_and_long_deceleration(tmp_path) -> None:
    """Paper section 3.3 / Fig. 27 on a coarse 3 x 3 grid (runs <= 16 s simulated).

    Measured with fivdisc's (corrected) equations: no point separates at Omega_0 =
    12 rad/s or at t_max = 4 s; at Omega_0 = 16 and 20 rad/s separation starts for
    t_max = 10 and 16 s, at t = 5.50 s and 3.59 s (16 rad/s) and 2.57 s and 2.64 s
    (20 rad/s).
    """
    store, figure = tmp_path / "map.zarr", tmp_path / "map.png"
    result = CliRunner().invoke(
        separation_map,
        [
            *("--x", "12:20:3", "--y", "4:16:3", "-o", str(store), "--figure", str(figure)),
            "--no-progress",
        ],
    )
    assert result.exit_code == 0, result.output
    grid = open_sweep(store)
    assert grid["separated"].dims == ("speed.initial", "speed.duration")
    assert grid["done"].all() and (grid["error"] == "").all()
    separated = grid["separated"].values
    # the fraction of separated points grows with Omega_0 and with t_max ...
    by_speed, by_duration = separated.mean(axis=1), separated.mean(axis=0)
    assert (np.diff(by_speed) >= 0).all() and by_speed[-1] > by_speed[0], separated
    assert (np.diff(by_duration) >= 0).all() and by_duration[-1] > by_duration[0], separated
    # ... and no point loses separation when either grows
    assert (np.diff(separated.astype(int), axis=0) >= 0).all(), separated
    assert (np.diff(separated.astype(int), axis=1) >= 0).all(), separated
    # where both separate, the faster disc separates sooner
    first = grid["first_separation_time"].values
    assert np.isnan(first[~separated]).all()
    both = separated[1] & separated[2]
    assert both.any() and (first[2][both] < first[1][both]).all(), first
    assert figure.stat().st_size > 10_000
    assert f"wrote {figure}" in result.output


def test_separation_map_options_are_checked(tmp_path) -> None:
    result = CliRunner().invoke(separation_map, ["--duration", "5", "-o", str(tmp_path / "m")])
    assert isinstance(result.exception, FivdiscError)
    assert "duration = 5.0 is invalid for a decelerating disc" in str(result.exception)
    result = CliRunner().invoke(separation_map, ["--x", "1:2", "-o", str(tmp_path / "m")])
    assert "axes.'speed.initial' = '1:2' is invalid" in str(result.exception)


def test_accelerating_map_and_figure(tmp_path) -> None:
    from fivdisc.plots import plot_separation_map
    from fivdisc.sweep import separation_sweep

    spec = separation_sweep("accelerating", x=[15.0, 20.0], y=[0.5], duration=3.0)
    assert spec.cases[0].simulation.duration == 3.0
    assert spec.cases[1].speed.rate == 0.5
    report = run_sweep(spec, tmp_path / "acc.zarr", workers=1, progress=False)
    assert report.computed == 2
    fig = plot_separation_map(tmp_path / "acc.zarr", tmp_path / "acc.png")
    ax = fig.axes[0]
    assert ax.get_xlabel() == r"initial disc speed $\Omega_1$ [rad/s]"
    assert ax.get_ylabel() == r"acceleration $c$ [rad/s$^2$]"
    assert (tmp_path / "acc.png").exists()
