"""Bifurcation diagrams: sections of a run (maxima, switches) in sweeps, their padded
storage, ``largest_lyapunov`` as a reduction and ``fivdisc bifurcation``.

Section values are checked against runs sampled 40 times more finely, with tolerances
from the sampling: the bounds of polynomial interpolation with the derivative they need
estimated from the fine run.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from fivdisc.analysis.exponents import lyapunov
from fivdisc.case import Case
from fivdisc.engine.simulation import simulate
from fivdisc.model.build import build_model
from fivdisc.sweep import (
    LyapunovSettings,
    Section,
    Sweep,
    SweepError,
    SweepStore,
    load_sweep,
    open_sweep,
    run_sweep,
    verify_store,
)
from fivdisc.sweep.reductions import evaluate
from fivdisc.sweep.sections import VARIABLES, section_values
from fivdisc.sweep.store.health import read_mask
from fivdisc.sweep.store.lock import store_lock
from fivdisc.sweep.store.sweep_store import PointOutcome

from support.cli import run_cli

# One axisymmetric disc mode and a heavy slider: a stick-slip cycle of about 20 ms
# (the light case of test_orbits.py).
LIGHT = Case(disc={"density": 720.0, "modes": [[0, 0]]},
             slider={"mass": 1.0, "normal_damping": 20.0}, speed={"value": 1.0})
OMEGA = 1.0  # [rad/s], LIGHT's disc speed
COARSE, FINE = 4000.0, 160_000.0  # output rates [Hz]
H, H_FINE = 1.0 / COARSE, 1.0 / FINE  # sample spacings [s]

# A sweep over the disc speed of LIGHT: 3 short runs.
SWEEP = """
[base.disc]
density = 720.0
modes = [[0, 0]]
[base.slider]
mass = 1.0
normal_damping = 20.0
[base.simulation]
duration = 0.3
output_rate = 4000.0
[axes]
"speed.value" = [0.8, 1.0, 1.2]
[reduce]
keep = ["max_normal_force", "largest_lyapunov", "largest_lyapunov_uncertainty"]
[[reduce.section]]
variable = "phi"
at = "maxima"
after = 0.1
max_points = 4          # fewer than the run has: the first 4
[[reduce.section]]
variable = "phi_dot"
at = "stick"
after = 0.1
max_points = 40         # more than the run has: padded
"""


@pytest.fixture(scope="module")
def runs() -> tuple:
    """LIGHT over 0.5 s, sampled at COARSE and at FINE."""
    case = LIGHT.replace({"simulation.duration": 0.5})
    return (simulate(case.replace({"simulation.output_rate": COARSE})),
            simulate(case.replace({"simulation.output_rate": FINE})))


@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("bifurcation") / "speeds.toml"
    path.write_text(SWEEP, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def diagram(sweep_file, tmp_path_factory) -> tuple[Path, Path, str]:
    """`fivdisc bifurcation` run on a missing store: (store, figure, output)."""
    pytest.importorskip("matplotlib")
    out = tmp_path_factory.mktemp("diagram")
    store, figure = out / "speeds.zarr", out / "speeds.png"
    result = run_cli(["bifurcation", str(sweep_file), "-o", str(figure),
                                      "--store", str(store), "--workers", "1",
                                      "--no-progress"])
    assert result.exit_code == 0, result.output
    return store, figure, result.output


def _differences_bound(t: np.ndarray, y: np.ndarray, order: int, start: float,
                       stop: float, spacing: float) -> float:
    """Largest |d^order y / dt^order| on [start, stop], from differences of samples
    `spacing` apart (coarser than the fine run's, so the integrator's error does not
    dominate them), counted back from `stop`."""
    inside = np.flatnonzero((t >= start) & (t <= stop))
    step = max(1, round(spacing / (t[1] - t[0])))
    picked = y[inside[::-1][::step][::-1]]
    return float(np.max(np.abs(np.diff(picked, order)))) / (step * (t[1] - t[0])) ** order


# --- values at a section against the run ---------------------------------------------------


def test_variables_are_the_time_series_of_a_run() -> None:
    ds = simulate(LIGHT.replace({"simulation.duration": 0.01,
                                 "simulation.energy_balance": True})).dataset
    series = {name: var for name, var in ds.data_vars.items() if var.dims[0] == "time"}
    assert set(series) == set(VARIABLES)
    for name, var in series.items():
        assert var.dims[1:] == ((VARIABLES[name].dim,) if VARIABLES[name].dim else ()), name
        assert var.attrs["units"] == VARIABLES[name].units, name
        assert var.attrs["long_name"].startswith(VARIABLES[name].long_name), name


def test_maxima_are_the_peaks_of_the_finely_sampled_run(runs) -> None:
    """Each refined maximum of the coarse run is a peak of the fine run, its value within
    the parabola's bound 0.064 M3 h^3 plus the fine sample's own shortfall M2 h_f^2 / 8."""
    coarse, fine = runs
    after = 0.1
    times, values = section_values(coarse, Section("phi", at="maxima", after=after))
    t, y = fine.dataset["time"].values, fine.dataset["phi"].values[:, 0]
    peak = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] > y[2:])) + 1
    peak = peak[t[peak] >= after + H]  # where no coarse sample can straddle `after`
    assert times.size == peak.size >= 20
    for when, value, i in zip(times, values, peak, strict=True):
        assert abs(when - t[i]) < H / 4
        m3 = _differences_bound(t, y, 3, when - 1.5 * H, when + 1.5 * H, H / 4)
        m2 = _differences_bound(t, y, 2, when - H, when + H, H_FINE)
        assert abs(value - y[i]) <= 0.064 * m3 * H**3 + m2 * H_FINE**2 / 8


def test_flat_tops_are_one_maximum_each(runs) -> None:
    """phi_dot rises to the disc speed and holds it while the slider sticks: one maximum
    per stick, exactly the disc speed, at the first sample of the stick; the maxima in
    between, while it slips, are below the disc speed."""
    coarse, _ = runs
    times, values = section_values(coarse, Section("phi_dot", at="maxima", after=0.1))
    sticks = coarse.events("stick")
    sticks = sticks[sticks >= 0.1 - H]
    top = values == OMEGA
    assert top.sum() == sticks.size >= 10
    assert np.all((times[top] - sticks > 0) & (times[top] - sticks <= H))
    assert np.all(values[~top] < OMEGA)


def test_values_at_switches_are_the_run_s_left_limits(runs) -> None:
    """At a stick switch phi_dot equals the disc speed, and phi continues the fine run; both
    within the cubic extrapolation's bound M4 h^4 (M4 estimated from differences that
    average over h/4: a factor 2 of margin)."""
    coarse, fine = runs
    t = fine.dataset["time"].values
    for variable in ("phi_dot", "phi"):
        times, values = section_values(coarse, Section(variable, at="stick"))
        np.testing.assert_array_equal(times, coarse.events("stick"))
        y = fine.dataset[variable].values[:, 0]
        rate = fine.dataset["phi_dot"].values[:, 0]
        for when, value in zip(times, values, strict=True):
            last = np.searchsorted(t, when, side="right") - 1
            expected = OMEGA if variable == "phi_dot" else y[last] + rate[last] * (when - t[last])
            m4 = _differences_bound(t, y, 4, when - 5 * H, when, H / 4)
            assert abs(value - expected) <= 2 * m4 * H**4 + 1e-12, (variable, when)


def test_first_switch_matches_the_state_where_a_run_stops(runs) -> None:
    coarse, _ = runs
    stopped = simulate(LIGHT.replace({"simulation.duration": 0.5}), stop_on=("stick",))
    model = build_model(LIGHT)
    state = stopped.dataset.attrs["final_state"]
    times, values = section_values(coarse, Section("phi", at="stick"))
    assert times[0] == stopped.events("stick")[0]
    t, y = coarse.dataset["time"].values, coarse.dataset["phi"].values[:, 0]
    m4 = _differences_bound(t, y, 4, 0.0, times[0], H)
    assert values[0] == pytest.approx(state[model.index("phi")], abs=2 * m4 * H**4)


def test_probes_coordinates_and_sliders_are_chosen(runs) -> None:
    """w by probe, q by coordinate, normal_force by slider: the peaks of that column, each
    refined value between its sample y1 and y1 + max(y1 - y0, y1 - y2) / 8 (the parabola's
    vertex above its middle sample)."""
    result = simulate(Case(sliders=[{"angle": 0.0}, {"angle": 2.0}],
                           simulation={"duration": 0.05, "output_rate": COARSE}))
    ds = result.dataset
    for section, name, y in (
        (Section("w", index=1), "w_maxima_1", ds["w"].values[:, 1]),
        (Section("q", index=2), "q_maxima_2", ds["q"].values[:, 2]),
        (Section("normal_force", slider=1), "normal_force_maxima_1",
         ds["normal_force"].values[:, 1]),
    ):
        assert section.name == name
        times, values = section_values(result, section)
        peak = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] > y[2:])) + 1
        assert times.size == peak.size > 0, name
        assert np.all(np.abs(times - ds["time"].values[peak]) <= H / 2), name
        rise = np.maximum(y[peak] - y[peak - 1], y[peak] - y[peak + 1])
        assert np.all((values >= y[peak]) & (values <= y[peak] + rise / 8)), name


# --- stored in a sweep ------------------------------------------------------------------------


def test_largest_lyapunov_is_the_analysis_over_the_sections_window() -> None:
    case = LIGHT.replace({"simulation.duration": 0.4})
    spec = Sweep(base=case, axes={"speed.value": [1.0]}, keep=["largest_lyapunov"],
                 sections=[{"variable": "phi", "after": 0.1}])
    assert spec.lyapunov == LyapunovSettings(transient=0.1)
    values = evaluate(case, spec.keep, spec.sections, spec.lyapunov)
    assert values["largest_lyapunov"] == lyapunov(case, transient=0.1, duration=0.3).largest
    chosen = LyapunovSettings(transient=0.2, duration=0.1, interval=0.02)
    assert evaluate(case, ["largest_lyapunov"], lyapunov=chosen)["largest_lyapunov"] == (
        lyapunov(case, transient=0.2, duration=0.1, interval=0.02).largest)


def test_store_pads_values_and_counts_them(diagram, sweep_file) -> None:
    store, _, _ = diagram
    spec = load_sweep(sweep_file)
    data = open_sweep(store)
    assert data["done"].all() and (data["error"] == "").all()
    assert data["phi_maxima"].dims == ("speed.value", "phi_maxima_index")
    assert data["phi_maxima"].shape == (3, 4) and data["phi_maxima"].dtype == np.float64
    assert data["phi_dot_stick"].shape == (3, 40)
    assert data["phi_maxima_count"].dims == ("speed.value",)
    assert np.issubdtype(data["phi_dot_stick_count"].dtype, np.integer)
    for name in ("phi_maxima", "phi_dot_stick"):
        attrs = data[name].attrs
        assert attrs["units"] == "rad" if name == "phi_maxima" else "rad/s"
        assert attrs["ancillary_variables"] == f"{name}_count"
        assert data[f"{name}_count"].attrs["units"] == "1"
    for i, case in enumerate(spec.cases):
        result = simulate(case)
        for section in spec.sections:
            _, values = section_values(result, section)
            count = int(data[section.count_name][i])
            row = data[section.name].values[i]
            assert count == min(values.size, section.max_points)
            np.testing.assert_array_equal(row[:count], values[:count])
            assert np.isnan(row[count:]).all()
        assert 0 < int(data["phi_dot_stick_count"][i]) < 40
    assert (data["phi_maxima_count"] == 4).all()
    sections = json.loads(data.attrs["sweep_sections"])
    assert [s["name"] for s in sections] == ["phi_maxima", "phi_dot_stick"]
    assert verify_store(store).healthy


def test_failed_point_has_no_values(tmp_path) -> None:
    spec = Sweep(base=LIGHT.replace({"simulation.duration": 0.05,
                                     "simulation.output_rate": 4000.0}),
                 axes={"simulation.max_switches": [1, 1000]}, keep=[],
                 sections=[{"variable": "phi", "max_points": 3}])
    run_sweep(spec, tmp_path / "s.zarr", workers=1, progress=False)
    data = open_sweep(tmp_path / "s.zarr")
    assert data["error"].values[0].startswith("simulation max_switches")
    assert np.isnan(data["phi_maxima"].values[0]).all()
    assert data["phi_maxima_count"].values.tolist()[0] == 0
    assert data["error"].values[1] == "" and data["phi_maxima_count"].values[1] > 0


def test_interrupted_sweep_keeps_finished_points(diagram, sweep_file, tmp_path,
                                                 monkeypatch) -> None:
    """The coordinator stopped (as by Ctrl-C) after its first write keeps what it wrote;
    the rerun computes only the rest and ends with the uninterrupted sweep's store."""
    reference, _, _ = diagram
    spec = load_sweep(sweep_file)
    store = tmp_path / "resumed.zarr"
    write = SweepStore.write
    calls = []

    def interrupted(self, outcomes):
        write(self, outcomes)
        calls.append(len(outcomes))
        if len(calls) == 1:
            raise KeyboardInterrupt

    monkeypatch.setattr(SweepStore, "write", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_sweep(spec, store, workers=1, progress=False)
    monkeypatch.setattr(SweepStore, "write", write)
    kept = int(read_mask(store).sum())
    assert kept == calls[0] and 1 <= kept < 3
    report = run_sweep(spec, store, workers=1, progress=False)
    assert (report.already_done, report.computed) == (kept, 3 - kept)
    xr.testing.assert_identical(open_sweep(store).assign_attrs(history=""),
                                open_sweep(reference).assign_attrs(history=""))


# --- the store, without simulations ----------------------------------------------------------

STORED = Sweep(base=Case(simulation={"duration": 0.01}),
               axes={"slider.normal_damping": [0.1, 0.2, 0.3]}, keep=["max_normal_force"],
               sections=[{"variable": "phi_dot", "max_points": 5}])


def _outcome(i: int) -> PointOutcome:
    """Point i has i + 1 values."""
    values = np.full(5, np.nan)
    values[: i + 1] = np.arange(i + 1) + 10.0 * i
    return PointOutcome(i, {"max_normal_force": 100.0 + i, "phi_dot_maxima": values,
                            "phi_dot_maxima_count": i + 1})


def test_section_chunks_are_checksummed_and_recomputed(tmp_path) -> None:
    import zarr

    path = tmp_path / "s.zarr"
    with store_lock(path):
        SweepStore.open(path, STORED).write([_outcome(i) for i in range(3)])
    reference = open_sweep(path)
    np.testing.assert_array_equal(reference["phi_dot_maxima_count"], [1, 2, 3])
    np.testing.assert_array_equal(reference["phi_dot_maxima"].values[2, :3], [20, 21, 22])
    # point 1's values lost (read as NaN), its checksum left as it was
    zarr.open_array(path / "phi_dot_maxima", mode="r+")[1] = np.full(5, np.nan)
    np.testing.assert_array_equal(verify_store(path).complete, [True, False, True])
    # the counts' chunk (all three points) damaged
    (path / "phi_dot_maxima_count" / "c" / "0").write_bytes(b"garbage")
    np.testing.assert_array_equal(verify_store(path).complete, [False, False, False])
    with store_lock(path):
        store = SweepStore.open(path, STORED)
        assert not store.completed().any()  # and the damaged chunk removed, to be rewritten
        store.write([_outcome(i) for i in range(3)])
    xr.testing.assert_identical(open_sweep(path), reference)


def test_stores_of_format_3_are_read_not_resumed(tmp_path, monkeypatch) -> None:
    """A store written before sections existed is format 4 without them, one point per
    chunk: read and verified, not resumed."""
    from fivdisc.sweep.store import layout as module

    plain = Sweep(base=STORED.base, axes=STORED.axes, keep=STORED.keep)
    path = tmp_path / "old.zarr"
    monkeypatch.setattr(module, "BLOCK_POINTS", 1)
    with store_lock(path):
        SweepStore.open(path, plain).write(
            [PointOutcome(i, {"max_normal_force": 1.0 + i}) for i in range(2)])
    monkeypatch.undo()
    meta = path / "zarr.json"
    data = json.loads(meta.read_text())
    data["attributes"]["store_format"] = 3
    del data["attributes"]["sweep_sections"]
    meta.write_text(json.dumps(data))
    assert verify_store(path).healthy
    loaded = open_sweep(path)
    assert loaded["done"].values.tolist() == [True, True, False]
    np.testing.assert_array_equal(loaded["max_normal_force"].values[:2], [1.0, 2.0])
    with store_lock(path):
        store = SweepStore.open(path, plain)
        np.testing.assert_array_equal(store.completed(), [True, True, False])
        with pytest.raises(SweepError, match=r"store format 3\); this version reads it but "
                                             r"resumes only"):
            store.write([PointOutcome(2, {"max_normal_force": 3.0})])


# --- sweep files ------------------------------------------------------------------------------


def _sweep(reduce: str, base: str = "") -> str:
    return f"""
[base.simulation]
duration = 0.05
{base}
[axes]
"speed.value" = [1.0, 2.0]
[reduce]
{reduce}
"""


@pytest.mark.parametrize(
    ("reduce", "message"),
    [
        ('[[reduce.section]]\nvariable = "phi_dot"\nsldier = 1',
         r"unknown key 'reduce\.section\[0\]\.sldier'; did you mean "
         r"'reduce\.section\[0\]\.slider'\?"),
        ('[[reduce.section]]\nvariable = "phi_dt"',
         r"reduce\.section\[0\]\.variable = 'phi_dt' is invalid: must be a recorded time "
         r"series of a run \(phi, phi_dot, .*\); did you mean 'phi_dot'\?"),
        ('[[reduce.section]]\nvariable = "phi"\nat = "sitck"',
         r"reduce\.section\[0\]\.at = 'sitck' is invalid: must be 'maxima' or a kind of "
         r"switch \(stick, slip, separation, recontact, reversal\); did you mean 'stick'\?"),
        ('[[reduce.section]]\nat = "stick"', r"reduce\.section\[0\]\.variable is missing"),
        ('[[reduce.section]]\nvariable = "w"\nslider = 1',
         r"reduce\.section\[0\]\.slider = 1 is invalid for variable 'w' at 'maxima': it is "
         r"not a per-slider variable \(choose its probe with index\)"),
        ('[[reduce.section]]\nvariable = "phi"\nindex = 1',
         r"reduce\.section\[0\]\.index = 1 is invalid for variable 'phi'"),
        ('[[reduce.section]]\nvariable = "phi"\nslider = 1',
         r"point 0 \(speed\.value = 1\.0\): reduce\.section\[0\]\.slider = 1 is invalid: "
         r"must be < 1, the number of sliders"),
        ('[[reduce.section]]\nvariable = "w"\nindex = 2',
         r"reduce\.section\[0\]\.index = 2 is invalid: must be < 2, the number of probes"),
        ('[[reduce.section]]\nvariable = "phi"\nafter = 0.05',
         r"reduce\.section\[0\]\.after = 0\.05 is invalid: must be < simulation\.duration "
         r"= 0\.05 s"),
        ('[[reduce.section]]\nvariable = "phi"\nafter = -1.0',
         r"reduce\.section\[0\]\.after = -1\.0 is invalid: must be a number >= 0 \[s\]"),
        ('[[reduce.section]]\nvariable = "phi"\nmax_points = 0',
         r"reduce\.section\[0\]\.max_points = 0 is invalid: must be an integer >= 1"),
        ('[[reduce.section]]\nvariable = "energy_work"',
         r"reduce\.section\[0\]\.variable = 'energy_work' needs "
         r"simulation\.energy_balance = true"),
        ('[[reduce.section]]\nvariable = "phi"\n[[reduce.section]]\nvariable = "phi"',
         r"reduce\.section\[1\] would be stored as 'phi_maxima', as reduce\.section\[0\] "
         r"is: give it another name \(reduce\.section\[1\]\.name\)"),
        ('keep = ["separated"]\n[[reduce.section]]\nvariable = "phi"\nname = "separated"',
         r"would be stored as 'separated', as reduction 'separated' is"),
        ('[reduce.section]\nvariable = "phi"',
         r"reduce\.section is a single table: write it as an array of tables, "
         r"\[\[reduce\.section\]\]"),
        ('keep = ["separated"]\n[reduce.largest_lyapunov]\ntransient = 0.01',
         r"reduce\.largest_lyapunov sets the reduction 'largest_lyapunov', which "
         r"reduce\.keep does not list"),
        ('keep = ["largest_lyapunov"]\n[reduce.largest_lyapunov]\ntransiant = 0.01',
         r"unknown key 'reduce\.largest_lyapunov\.transiant'; did you mean "
         r"'reduce\.largest_lyapunov\.transient'\?"),
        ('keep = ["largest_lyapunov"]\n[reduce.largest_lyapunov]\nduration = -1',
         r"reduce\.largest_lyapunov\.duration = -1 is invalid: must be a number > 0 \[s\]"),
        ('keep = ["largest_lyapunov"]\n[reduce.largest_lyapunov]\ntransient = 0.05',
         r"point 0 \(speed\.value = 1\.0\): reduce\.largest_lyapunov\.transient = 0\.05 is "
         r"invalid: must be < simulation\.duration = 0\.05 s"),
        ("[reduce.sections]", r"unknown key 'reduce\.sections'; did you mean 'reduce\.section'"),
    ],
)
def test_bad_section_and_lyapunov_keys_are_refused(reduce: str, message: str) -> None:
    with pytest.raises(SweepError, match=message) as info:
        Sweep.from_toml(_sweep(reduce), source="s.toml")
    assert str(info.value).startswith("s.toml: ")
    assert "\n" not in str(info.value)


def test_sections_only_and_the_definition() -> None:
    text = _sweep('[[reduce.section]]\nvariable = "phi_dot"\nat = "stick"')
    spec = Sweep.from_toml(text)
    assert spec.keep == () and spec.stop_on == ()
    (section,) = spec.sections
    assert (section.name, section.slider, section.max_points) == ("phi_dot_stick", 0, 100)
    # spelling out a default is the same sweep; another value is another
    same = Sweep.from_toml(text.replace('at = "stick"', 'at = "stick"\nslider = 0'))
    assert same.digest == spec.digest
    assert Sweep.from_toml(text + "after = 0.01\n").digest != spec.digest
    # a sweep without sections keeps its definition (and the hash of stores written before)
    plain = Sweep.from_toml(_sweep('keep = ["separated"]'))
    assert "sections" not in json.loads(plain.definition)


# --- the command ------------------------------------------------------------------------------


def test_command_runs_the_sweep_and_draws_the_diagram(diagram, sweep_file) -> None:
    from fivdisc.plots import plot_bifurcation

    store, figure, output = diagram
    assert "3 points: 0 already stored, 3 computed" in output
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    fig = plot_bifurcation(store, name="speeds")
    top, bottom = fig.axes
    # The other section is named, with how to draw it (issue 27, item 5).
    assert top.get_title().split("\n") == [
        "speeds: phi of slider 0 at its local maxima, t >= 0.1 s",
        "(other sections: phi_dot_stick; pick one with --section NAME)"]
    assert top.get_ylabel() == "slider circumferential angle of slider 0 [rad]"
    assert bottom.get_xlabel() == r"disc speed $\Omega_c$ [rad/s]"
    assert "[1/s]" in bottom.get_ylabel()
    # the dots are the stored values: 4 maxima at each of the 3 speeds
    xs, ys = top.lines[0].get_data()
    assert len(xs) == 12 and set(np.round(xs, 9)) == {0.8, 1.0, 1.2}
    from fivdisc.plots.sweep import _DOT

    assert top.lines[0].get_markersize() > 2 * _DOT  # few values: visible markers
    # The dots have their entry in the key (issue 40, item 2), with a marker to see.
    (entry,) = top.get_legend().legend_handles
    assert top.get_legend().get_texts()[0].get_text() == (
        "phi of slider 0 at the section, one dot per value")
    assert entry.get_marker() == "." and entry.get_markersize() >= 6
    np.testing.assert_array_equal(ys, open_sweep(store)["phi_maxima"].values.ravel())
    # the zero line and the exponents
    assert any(np.all(np.asarray(line.get_ydata()) == 0.0) for line in bottom.lines)
    # Error bars of the exponent: its standard error, that of fivdisc.lyapunov run on the
    # point's case with the sweep's window (issue 27, item 2).
    from matplotlib.collections import LineCollection

    from fivdisc import lyapunov
    from fivdisc.sweep import load_sweep

    spec = load_sweep(sweep_file)
    transient, duration = spec.lyapunov.window(spec.cases[1])
    direct = lyapunov(spec.cases[1], n=1, transient=transient, duration=duration,
                      interval=spec.lyapunov.interval)
    stored = open_sweep(store)
    assert stored["largest_lyapunov"].values[1] == direct.largest
    assert stored["largest_lyapunov_uncertainty"].values[1] == direct.uncertainty[0]
    (bars,) = [c for c in bottom.collections if isinstance(c, LineCollection)]
    lengths = [float(np.ptp(segment[:, 1])) for segment in bars.get_segments()]
    np.testing.assert_allclose(lengths, 2 * stored["largest_lyapunov_uncertainty"].values)
    # Each exponent is stored with whether it is conclusive, as fivdisc.lyapunov says
    # (issue 28, item 3).
    assert bool(stored["largest_lyapunov_inconclusive"].values[1]) == (not direct.conclusive[0])
    # a second run draws the complete store without computing anything
    again = run_cli(["bifurcation", str(sweep_file), "-o", str(figure),
                                     "--store", str(store), "--section", "phi_dot_stick",
                                     "--no-progress"])
    assert again.exit_code == 0, again.output
    assert "3 points: 3 already stored, 0 computed" in again.output


@pytest.mark.parametrize(
    ("axes", "option", "message"),
    [
        ('"speed.value" = [1.0, 2.0]\n"slider.mass" = [0.1, 0.2]', (),
         r"^error: a bifurcation diagram needs a sweep over one key; this one sweeps 2: "
         r"'speed\.value', 'slider\.mass'$"),
        ('"speed.value" = [1.0, 2.0]', ("--section", "phi_maxim"),
         r"^error: section = 'phi_maxim' is invalid: the sweep's sections are phi_maxima; "
         r"did you mean 'phi_maxima'\?$"),
    ],
)
def test_command_refuses_what_it_cannot_draw(tmp_path, axes, option, message) -> None:
    path = tmp_path / "two.toml"
    path.write_text(f'[axes]\n{axes}\n[reduce]\n[[reduce.section]]\nvariable = "phi"\n',
                    encoding="utf-8")
    result = run_cli(["bifurcation", str(path), "-o",
                                      str(tmp_path / "d.png"), *option])
    assert result.exit_code == 2
    assert result.output.count("\n") == 1
    assert re.match(message, result.output.strip())
    assert not (tmp_path / "two.zarr").exists()


def test_diagram_needs_a_section(tmp_path) -> None:
    path = tmp_path / "none.toml"
    path.write_text('[axes]\n"speed.value" = [1.0]\n[reduce]\nkeep = ["separated"]\n',
                    encoding="utf-8")
    result = run_cli(["bifurcation", str(path)])
    assert result.exit_code == 2
    assert "needs a section: add a [[reduce.section]] table" in result.output


def test_inconclusive_exponents_are_ringed_in_the_diagram(diagram) -> None:
    # Issue 28, item 3: a reader of the diagram sees which exponents are not usable.
    from fivdisc.plots import plot_bifurcation

    data = open_sweep(diagram[0])
    flags = np.array([True, False, True])
    data["largest_lyapunov_inconclusive"] = data["largest_lyapunov_inconclusive"].copy(
        data=flags)
    bottom = plot_bifurcation(data).axes[1]
    (ringed,) = [line for line in bottom.lines if line.get_label().startswith("inconclusive")]
    xs, ys = ringed.get_data()
    np.testing.assert_array_equal(xs, data["speed.value"].values[flags])
    np.testing.assert_array_equal(ys, data["largest_lyapunov"].values[flags])
    assert bottom.get_legend() is not None
    data["largest_lyapunov_inconclusive"][:] = False
    bottom = plot_bifurcation(data).axes[1]
    assert not any(line.get_label().startswith("inconclusive") for line in bottom.lines)
