"""Figures and the ``fivdisc plot`` command, on a synthetic result and one short simulation."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from fivdisc import plots
from fivdisc.analysis.spectra import dominant_frequency, find_peaks, spectrum
from fivdisc.cli.plot import plot as plot_command
from fivdisc.errors import FivdiscError
from fivdisc.plots import result as result_plots

from support.cli import run_cli

FS = 10_000.0  # [Hz]
F0 = 206.0  # fundamental of the synthetic slider motion [Hz] (paper Fig. 13)
SEPARATIONS = [(0.1003, 0.1204), (0.3001, 0.3102)]  # exact switch times [s]


def _result(duration: float = 0.4) -> xr.Dataset:
    """A result-like dataset: periodic slider, two disc probes, two separations."""
    t = np.arange(round(duration * FS) + 1) / FS
    phase = np.zeros(t.size, np.int8)
    normal = 500 + 100 * np.sin(2 * np.pi * F0 * t)
    gap = np.zeros(t.size)
    for start, end in SEPARATIONS:
        inside = (t >= start) & (t < end)
        phase[inside], normal[inside], gap[inside] = 2, 0.0, 1e-6
    flags = {"flag_values": np.array([0, 1, 2], np.int8),
             "flag_meanings": "slip stick separation"}

    def var(dims, values, units, long_name, **extra):
        return dims, values, {"units": units, "long_name": long_name, **extra}

    angle = 1e-3 * np.sin(2 * np.pi * F0 * t) + 3e-4 * np.sin(2 * np.pi * 2 * F0 * t)
    data = {
        "phi": var("time", angle, "rad", "slider circumferential angle"),
        "phi_dot": var("time", np.gradient(angle, t), "rad/s", "slider angular velocity"),
        "disc_speed": var("time", np.full(t.size, 2 * np.pi), "rad/s", "disc spinning speed"),
        "normal_force": var("time", normal, "N", "normal contact force"),
        "friction_force": var("time", 0.5 * normal, "N", "friction force on the slider"),
        "phase": var("time", phase, "1", "contact phase", **flags),
        "gap": var("time", gap, "m", "gap between slider and disc surface"),
        "w": var(("time", "probe"),
                 np.column_stack([1e-5 * np.sin(2 * np.pi * 241.0 * t),
                                  2e-5 * np.sin(2 * np.pi * 290.0 * t)]),
                 "m", "disc transverse displacement at the probes"),
        "event_time": var("event", np.ravel(SEPARATIONS), "s", "time of the phase switch"),
        "event_kind": var("event", np.array(["separation", "recontact"] * 2, dtype=object),
                          "1", "kind of switch"),
        "event_from": var("event", np.array([0, 2, 0, 2], np.int8), "1", "before", **flags),
        "event_to": var("event", np.array([2, 0, 2, 0], np.int8), "1", "after", **flags),
    }
    coords = {
        "time": var("time", t, "s", "time"),
        "probe": ("probe", [0, 1], {"long_name": "probe index"}),
        "probe_r": var("probe", [0.1, 0.1], "m", "probe radius"),
        "probe_theta": var("probe", [0.0, 1.0], "rad", "probe angle"),
    }
    return xr.Dataset(data, coords=coords, attrs={"impact": 1})


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


@pytest.fixture(scope="module")
def result_file(tmp_path_factory):
    """The synthetic result, written as fivdisc writes its files (with its checksum:
    fivdisc plot refuses a netCDF file fivdisc did not write)."""
    from fivdisc.files import write_netcdf

    path = tmp_path_factory.mktemp("plots") / "synthetic.nc"
    write_netcdf(path, _result().to_netcdf)
    return path


def test_importing_plots_does_not_import_matplotlib():
    code = "import sys, fivdisc.plots; assert 'matplotlib' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_timeseries_of_a_probe_in_a_window():
    fig = plots.plot_timeseries(_result(), "w", probe=1, window=(0.1, 0.2))
    ax = fig.axes[0]
    assert ax.get_xlabel() == "time [s]"
    # Engineering units (issue 27, item 5): 2e-5 m drawn as 20 µm.
    assert ax.get_ylabel() == "disc transverse displacement at the probes [µm]"
    assert "probe 1" in ax.get_title() and "θ = 1 rad" in ax.get_title()
    x, y = ax.lines[0].get_data()
    np.testing.assert_allclose(x[[0, -1]], [0.1, 0.2])
    assert np.max(np.abs(y)) == pytest.approx(20.0, rel=1e-3)


def test_timeseries_of_phase_names_the_phases():
    ax = plots.plot_timeseries(_result(), "phase").axes[0]
    assert [label.get_text() for label in ax.get_yticklabels()] == ["slip", "stick",
                                                                     "separation"]
    assert ax.get_ylabel() == "contact phase"  # units "1" are not shown


def test_drawing_into_given_axes():
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2)
    assert plots.plot_phase_portrait(_result(), (0.0, 0.01), ax=right) is fig
    assert plots.plot_friction(_result(), None, ax=left) is fig
    # 1e-3 rad drawn in mrad (engineering units)
    assert len(fig.axes) == 2 and right.get_xlabel() == "slider circumferential angle [mrad]"
    assert right.get_ylabel() == "slider angular velocity [rad/s]"
    assert left.get_xlabel() == "relative angular velocity (disc minus slider) [rad/s]"
    assert left.get_ylabel() == "friction force on the slider [N]"


def test_spectrogram_axes_and_colour_scale():
    fig = plots.plot_spectrogram(_result(), "phi", segment=0.05, fmax=1000.0)
    ax, bar = fig.axes
    assert ax.get_xlabel() == "segment centre time [s]"
    assert ax.get_ylabel() == "frequency [Hz]"
    assert bar.get_ylabel() == "magnitude [rad]"
    assert ax.get_title().startswith("spectrogram of slider circumferential angle")
    # Frequencies up to fmax, each drawn as a cell of 20 Hz (1 / segment) centred on it.
    assert ax.get_ylim()[1] == pytest.approx(1010.0)
    # The strongest cell is the 1e-3 rad line at 206 Hz (about 200 Hz on 20 Hz bins).
    mesh = ax.collections[0]
    assert mesh.norm.vmax == pytest.approx(1e-3, rel=0.1)


def test_spectrum_marks_refined_peaks():
    fig = plots.plot_spectrum(_result(), "phi", window=(0.0, 0.4))
    ax = fig.axes[0]
    x, y = ax.lines[1].get_data()
    # Refined to ~1e-4 of the 2.5 Hz bin; amplitudes as synthesised.
    np.testing.assert_allclose(np.sort(x), [F0, 2 * F0], atol=0.01)
    np.testing.assert_allclose(np.sort(y), [3e-4, 1e-3], rtol=1e-2)
    assert "periodic: f0 = 206 Hz" in ax.get_title()
    assert ax.get_title().startswith("spectrum of slider circumferential angle")
    assert ax.get_ylabel() == "amplitude [rad]"
    assert ax.get_xlabel() == "frequency [Hz]"


def test_normal_force_shades_separations():
    ax = plots.plot_normal_force(_result()).axes[0]
    assert ax.get_ylabel() == "normal contact force [N]"
    spans = [patch.get_x() for patch in ax.patches]
    widths = [patch.get_width() for patch in ax.patches]
    np.testing.assert_allclose(spans, [s for s, _ in SEPARATIONS])
    np.testing.assert_allclose(widths, [e - s for s, e in SEPARATIONS])
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["separation"]
    window = plots.plot_normal_force(_result(), (0.2, 0.4)).axes[0]
    assert len(window.patches) == 1


@pytest.mark.parametrize(
    "args",
    [
        ["--kind", "timeseries", "--var", "w", "--probe", "1", "--window", "0.1:0.2"],
        ["--kind", "spectrogram", "--fmax", "1500", "--segment", "0.02"],
        ["--kind", "spectrum", "--window", "0.05:"],
        ["--kind", "phase", "--window", ":0.05"],
        ["--kind", "friction"],
        ["--kind", "normal-force"],
    ],
)
def test_cli_writes_figures(result_file, tmp_path, args):
    out = tmp_path / "fig.png"
    run = CliRunner().invoke(plot_command, [str(result_file), *args, "-o", str(out)])
    assert run.exit_code == 0, run.output
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--var", "psi"], ["--var 'psi'", "must be one of", "phi_dot"]),
        (["--window", "0.1-0.2"], ["--window '0.1-0.2'", "malformed", "T0:T1"]),
        (["--window", "0.3:0.9"], ["--window '0.3:0.9'", "0 <= T0 < T1 <= 0.4"]),
        (["--window", "0.2:0.1"], ["--window '0.2:0.1'"]),
        (["--var", "phi", "--probe", "1"], ["--probe 1", "--var phi"]),
        (["--var", "w", "--probe", "2"], ["--probe 2", "[0, 1]"]),
        (["--kind", "phase", "--var", "w"], ["--var", "--kind phase"]),
        (["--kind", "phase", "--fmax", "100"], ["--fmax", "--kind phase"]),
        (["--kind", "spectrogram", "--segment", "1"], ["segment = 1.0", "0.4001 s"]),
        (["--kind", "spectrum", "--fmax", "6000"], ["--fmax = 6000", "(0, 5000]", "Nyquist"]),
        (["--kind", "spectrogram", "--fmax", "5001"], ["--fmax = 5001", "Nyquist"]),
        (["-o", "figure.unknown"], ["-o", "not supported"]),
    ],
)
def test_cli_bad_input_names_the_option(result_file, tmp_path, monkeypatch, args, words):
    monkeypatch.chdir(tmp_path)
    run = CliRunner().invoke(plot_command, [str(result_file), *args])
    assert isinstance(run.exception, FivdiscError)
    message = str(run.exception)
    assert "\n" not in message
    for word in words:
        assert word in message


def test_simulated_result_end_to_end(tmp_path):
    from fivdisc.case import Case
    from fivdisc.engine.simulation import simulate

    # The paper's first example (Figs. 8-9) for 0.2 s: stick-slip from rest.
    result = simulate(Case(simulation={"duration": 0.2}))
    path = tmp_path / "run.nc"
    result.to_netcdf(path)
    for kind in ("spectrum", "normal-force"):
        run = CliRunner().invoke(plot_command, [str(path), "--kind", kind])
        assert run.exit_code == 0, run.output
        assert (tmp_path / f"run-{kind}.png").stat().st_size > 0
    # Paper: the slider's strongest line is f1 = 181 Hz. The record's 5 Hz bins do not
    # limit the refined estimate; 1 Hz allows for the paper quoting it to 0.5 Hz.
    with xr.open_dataset(path) as stored:
        assert dominant_frequency(stored, "phi", t0=0.05) == pytest.approx(181.0, abs=1.0)


def test_backend_chosen_by_mplbackend_is_kept():
    """Headless, fivdisc picks Agg unless MPLBACKEND chose a backend (Jupyter's inline one)."""
    code = ("import matplotlib; from fivdisc import plots; import numpy as np; "
            "import xarray as xr; t = np.linspace(0, 1, 11); "
            "ds = xr.Dataset({'phi': ('time', t)}, coords={'time': t}); "
            "plots.plot_timeseries(ds, 'phi'); print(matplotlib.get_backend())")
    env = {k: v for k, v in os.environ.items()
           if k not in ("DISPLAY", "WAYLAND_DISPLAY", "MPLBACKEND")}
    chosen = {**env, "MPLBACKEND": "svg"}
    for environment, backend in ((env, "agg"), (chosen, "svg")):
        out = subprocess.run([sys.executable, "-c", code], env=environment, check=True,
                             capture_output=True, text=True)
        assert out.stdout.strip().lower() == backend


# --- what every figure shows -----------------------------------------------------------------


def _text_outside_canvas(fig) -> list[str]:
    """The texts of a figure as drawn (titles, labels, drawn tick labels, legends,
    annotations, colour bars) that are not wholly inside its canvas, after the layout
    engine has run."""
    from matplotlib.text import Text

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    canvas = fig.bbox.padded(0.5)
    drawn = [t for ax in fig.axes for axis in (ax.xaxis, ax.yaxis)
             for tick in axis._update_ticks() for t in (tick.label1, tick.label2)]
    texts = [t for t in fig.findobj(Text) if t.get_visible() and t.get_text()
             and (t in drawn or not any(t is tick for tick in _tick_labels(fig)))]
    return [repr(t.get_text()) for t in texts
            if not canvas.contains(*t.get_window_extent(renderer).min)
            or not canvas.contains(*t.get_window_extent(renderer).max)]


def _tick_labels(fig) -> list:
    return [t for ax in fig.axes for axis in (ax.xaxis, ax.yaxis)
            for tick in (*axis.majorTicks, *axis.minorTicks) for t in (tick.label1, tick.label2)]


@pytest.fixture(scope="module")
def simulated():
    """0.3 s of the paper's first example, named as the command line names a case file."""
    from fivdisc import Case, simulate

    return simulate(Case(simulation={"duration": 0.3})).named("default")


@pytest.mark.parametrize("kind", plots.KINDS)
def test_every_kind_names_case_and_variable_and_keeps_its_text_inside(simulated, kind):
    fig = simulated.plot(kind)
    title = fig.axes[0].get_title()
    assert title.startswith("default: ")
    variable = {"timeseries": "slider circumferential angle",
                "spectrogram": "spectrogram of slider circumferential angle",
                "spectrum": "spectrum of slider circumferential angle",
                "phase": "phase portrait", "friction": "friction force",
                "normal-force": "normal contact force"}[kind]
    assert variable in title.split("\n")[0] + " " + title.split("\n")[1]
    assert "disc at 6.283 rad/s" in title  # the run, on the second line
    assert _text_outside_canvas(fig) == []


def test_result_plot_draws_what_the_command_draws(simulated, tmp_path):
    """Result.plot and fivdisc plot are one function: the same title, labels and lines."""
    path = tmp_path / "run.nc"
    simulated.to_netcdf(path)
    run = CliRunner().invoke(plot_command, [str(path), "--kind", "spectrum", "--window",
                                            "0.1:", "-o", str(tmp_path / "s.svg")])
    assert run.exit_code == 0, run.output
    ax = simulated.plot("spectrum", window=(0.1, None)).axes[0]
    svg = (tmp_path / "s.svg").read_text()
    for text in (ax.get_xlabel(), ax.get_ylabel(), *ax.get_title().split("\n")):
        assert text.replace("&", "&amp;") in svg or text in svg, text


def test_zero_hz_is_never_a_peak():
    """A mean and a slow drift that detrending leaves (a quadratic) give the lobe around
    0 Hz its largest amplitude; it is not reported, the 206 Hz line is."""
    t = np.arange(0.0, 1.0, 1e-4)
    drifting = 5.0 + 20.0 * t**2 + 1e-2 * np.sin(2 * np.pi * F0 * t)
    ds = xr.Dataset({"x": ("time", drifting, {"units": "m", "long_name": "x"})},
                    coords={"time": ("time", t, {"units": "s"})})
    spec = spectrum(ds, "x")
    assert spec.frequencies[np.argmax(spec.amplitude)] < 1.0  # the lobe dominates
    peaks = find_peaks(spec, n=3, min_rel_height=0.5)
    np.testing.assert_allclose(peaks.frequencies, [F0], atol=0.01)
    # A slow line of its own, above the lobe, is still found.
    slow = ds.assign(x=("time", np.sin(2 * np.pi * 3.0 * t), {"units": "m"}))
    assert find_peaks(spectrum(slow, "x"), n=1).frequencies[0] == pytest.approx(
        3.0, abs=0.05)


def test_spectrogram_segment_follows_the_record_and_the_band():
    # 100 segments per record, or bins of 1/50 of the band shown, whichever is longer
    assert result_plots.default_segment(35.0, 1000.0) == 0.35
    assert result_plots.default_segment(1.0, 1000.0) == 0.05
    assert result_plots.default_segment(1.0, 5000.0) == 0.01
    assert result_plots.default_segment(0.1, 100.0) == 0.025  # at most a quarter of the record
    fig = plots.plot_spectrogram(_result(), "phi", fmax=1000.0)
    assert "0.05 s segments (20 Hz bins)" in fig.axes[0].get_title()


def test_fmax_above_nyquist_is_refused():
    for draw in (plots.plot_spectrum, plots.plot_spectrogram):
        with pytest.raises(FivdiscError, match=r"fmax = 5001 \[Hz\] is invalid: must be in "
                           r"\(0, 5000\] Hz, up to the Nyquist frequency"):
            draw(_result(), "phi", fmax=5001.0)


def _map(curves):
    from fivdisc import Case, stability_map

    return stability_map(Case(speed={"value": 1.0}),
                         ("slider.normal_damping", np.linspace(4.0, 14.0, 6)),
                         ("slider.rotational_damping", np.linspace(0.2, 3.0, 12)),
                         curves=curves)


def test_stability_map_shows_every_curve_and_says_which_have_no_boundary():
    ds = _map(("friction.decay", [1.0, 10.0, 50.0]))
    present = [bool(np.isfinite(ds["boundary"].sel({"friction.decay": a})).any())
               for a in (1.0, 10.0, 50.0)]
    assert present[0] and not all(present)  # some curve lies outside this grid
    fig = plots.plot_stability_map(ds)
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    # Every value is in the legend: its boundary, or the state without one.
    for a, p, label in zip((1, 10, 50), present, labels, strict=True):
        assert label.startswith(f"$\\alpha$ = {a:g} s/m: ")
        assert ("boundary" in label) == p
    missing = [a for a, p in zip((1, 10, 50), present, strict=True) if not p]
    assert all(f"$\\alpha$ = {a:g} s/m" in ax.get_title() for a in missing)
    # the stable regions are shaded and each boundary drawn as a contour
    assert len(ax.collections) >= sum(present)
    assert ax.get_xlabel() == "slider normal damping $c_z$ [N s/m]"
    assert ax.get_ylabel() == "slider rotational damping $r_0^2 c_\\phi$ [N m s/rad]"
    assert _text_outside_canvas(fig) == []


def test_map_without_boundary_says_so_on_the_figure():
    from fivdisc import examples, load_case, stability_map

    # Fig. 3a at alpha = 10 s/m: unstable throughout its box.
    ds = stability_map(load_case(examples.path("fig03a")).replace({"friction.decay": 10.0}),
                       ("slider.normal_damping", np.linspace(0.0, 12.0, 4)),
                       ("slider.rotational_damping", np.linspace(0.0, 3.0, 4)))
    assert not np.isfinite(ds["boundary"].values).any()
    ax = plots.plot_stability_map(ds).axes[0]
    assert "no stability boundary in the grid" in [t.get_text() for t in ax.texts]
    # the field is still drawn: the unstable shading
    assert ax.collections


@pytest.mark.parametrize("suffix", [".pdf", ".svg", ".png"])
def test_stability_map_command_writes_any_matplotlib_format(tmp_path, suffix):

    out = tmp_path / f"map{suffix}"
    run = run_cli(["stability", "fig03b", "--x", "normal_damping=4:14:4",
                                   "--y", "rotational_damping=0.2:3:4", "-o", str(out),
                                   "--no-progress"])
    assert run.exit_code == 0, run.output
    assert out.read_bytes()[:4] in (b"%PDF", b"<?xm", b"\x89PNG")


# --- defaults a researcher accepts without flags (issue 27, item 5) ---------------------------


def test_a_long_timeseries_shows_its_last_oscillations_and_says_so():
    """0.4 s of a 206 Hz motion is 82 cycles, a solid block: the default window is the last
    30 or so, and the title says which stretch is shown and how to choose another."""
    ax = plots.plot_kind(_result(), "timeseries", var="phi").axes[0]
    x, y = ax.lines[0].get_data()
    assert x[-1] == pytest.approx(0.4)
    crossings = np.count_nonzero(np.diff(np.sign(y - y.mean())) != 0)
    assert 40 <= crossings <= 90  # about 30 cycles of the 206 Hz line (0.1 s: 41 cycles)
    assert f"the last {0.4 - x[0]:.1g} s of 0.4 s" in ax.get_title()
    assert "--window" in ax.get_title()
    # A short record stays whole, with no note.
    short = plots.plot_kind(_result(0.05), "timeseries", var="phi").axes[0]
    assert short.lines[0].get_data()[0][0] == 0.0 and "the last" not in short.get_title()


def test_the_spectrogram_band_covers_the_content():
    """The synthetic angle has lines at 206 and 412 Hz, nothing above: the default band
    ends above 412 Hz and far below the 5 kHz Nyquist frequency."""
    ax = plots.plot_spectrogram(_result(), "phi").axes[0]
    top = ax.get_ylim()[1]
    assert 412.0 < top <= 1100.0
    assert result_plots.content_band(_result()["phi"], 5000.0) in (500.0, 1000.0)
    assert "0-" in ax.get_title() and " Hz," in ax.get_title()


def test_titles_break_between_phrases_only():
    """A long title wraps after its commas and semicolons, not inside "slider
    circumferential angle" (it used to read "... circumferential / angle")."""
    ds = _result().assign_attrs(case_name="brake-two-pads-stribeck-damped",
                                title="fivdisc simulation of x: 2 sliders, disc at 6.283 "
                                      "rad/s, 0.4 s")
    for kind in ("timeseries", "spectrogram", "spectrum"):
        lines = plots.plot_kind(ds, kind, var="phi").axes[0].get_title().split("\n")
        assert any("slider circumferential angle" in line for line in lines), lines
        assert not any(line.endswith(("circumferential", "slider")) for line in lines)


def test_a_disc_variable_names_no_slider(simulated):
    title = simulated.plot("timeseries", var="w").axes[0].get_title()
    assert "probe 0" in title and not re.search(r"slider \d", title)
    assert "slider 0" in simulated.plot("timeseries", var="phi").axes[0].get_title()




def test_labels_of_close_bifurcations_do_not_overlap():
    """A torus point and a fold 0.002 rad/s apart on a branch spanning 3.5 rad/s (a
    one-slider trial case) had their labels "NS" and "LP" drawn on top of each other.
    Labels of bifurcations that nearly coincide on the figure are stacked instead."""
    import types

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from fivdisc.plots.branch import draw_branch

    p = np.linspace(5.5, 9.0, 50)
    period = 5.9e-3 - 1.4e-4 * (p - 5.5)
    bifs = [{"kind": "torus", "parameter": 5.79686, "point": 4},
            {"kind": "fold", "parameter": 5.79904, "point": 4},
            {"kind": "fold", "parameter": 8.5, "point": 42}]
    branch = types.SimpleNamespace(parameter=p, stable=np.ones(50, bool),
                                   dataset=xr.Dataset({"period": ("point", period)}),
                                   bifurcations=lambda: bifs)
    fig, ax = plt.subplots()
    draw_branch(ax, branch)
    offsets = {t.get_text() + str(i): t.xyann for i, t in enumerate(ax.texts)}
    plt.close(fig)
    assert len(offsets) == 3
    first, second, far = offsets.values()
    assert first != second        # stacked
    assert far == first           # a label with room keeps the usual place


def _s_branch(fold_a: float, fold_b: float):
    """A branch over 5.5 to 9 rad/s that folds back at ``fold_a`` and forward again at
    ``fold_b``: stable, unstable between the folds, stable (the trial's S-shaped stretch,
    folds at 5.79904 and 5.75712)."""
    import types

    up = np.linspace(5.5, fold_a - 1e-3, 12)
    back = np.linspace(fold_a - 2e-3, fold_b + 2e-3, 6)
    on = np.linspace(fold_b + 1e-3, 9.0, 40)
    p = np.r_[up, back, on]
    stable = np.r_[np.ones(up.size, bool), np.zeros(back.size, bool), np.ones(on.size, bool)]
    # The period follows the key, as on the trial's branch, and the three sheets of the S
    # differ a little.
    period = 5.9e-3 - 1.4e-4 * (p - 5.5) + 2e-7 * np.linspace(0.0, 1.0, p.size)
    bifs = [{"kind": "fold", "parameter": fold_a, "point": up.size - 1},
            {"kind": "fold", "parameter": fold_b, "point": up.size + back.size - 1}]
    return types.SimpleNamespace(parameter=p, stable=stable, key="speed.value",
                                 dataset=xr.Dataset({"period": ("point", period),
                                                     "parameter": ("point", p)}),
                                 bifurcations=lambda: bifs)


def test_an_unstable_stretch_too_short_to_show_dashed_is_marked_and_named():
    """An unstable stretch 0.04 rad/s wide between two folds, on a branch 3.5 rad/s wide,
    was invisible on the branch figure (trial s33): shorter than one dash of the unstable
    line. Its points are now marked, and the legend names its range from the located
    folds; a stretch as wide as a third of the figure is left to its dashes."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import rcParams

    from fivdisc.plots.branch import NARROW, narrow_unstable, plot_branch

    narrow = _s_branch(5.79904, 5.75712)
    assert narrow_unstable(narrow) == [(5.79904, 5.75712)]
    fig = plot_branch(narrow)
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("5.75712 to 5.79904" in t for t in labels), labels
    marked = [ln for ln in ax.get_lines()
              if ln.get_marker() == "o" and ln.get_linestyle() == "None"]
    assert len(marked) == 1 and marked[0].get_xdata().size == 6
    # The threshold is about one dash and gap of the unstable line on this figure.
    fig.canvas.draw()
    width_pt = ax.get_window_extent().width * 72.0 / fig.dpi
    dash_pt = sum(rcParams["lines.dashed_pattern"]) * 1.4
    assert 0.5 * NARROW < dash_pt / width_pt < 1.5 * NARROW

    wide = _s_branch(7.5, 6.3)
    assert narrow_unstable(wide) == []
    labels = [t.get_text() for t in plot_branch(wide).axes[0].get_legend().get_texts()]
    assert labels == ["stable", "unstable"]
