"""The paper's cases, its stated numbers that fivdisc reproduces, and ``fivdisc reproduce``.

Quick tests run in CI; the ``slow`` ones simulate whole figures (``pytest -m slow``).
Where fivdisc disagrees with the paper, the test asserts what fivdisc measures, and its
docstring gives the paper's claim, the measured value and a pointer to
docs/deviations.md.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from fivdisc import examples, linear_stability, load_case, open_result, simulate, stability_map
from fivdisc.cli.reproduce import reproduce as reproduce_command
from fivdisc.errors import FivdiscError
from fivdisc.model.build import build_model
from fivdisc.paper import (
    FIG3,
    FIG4,
    FIG6,
    FIG8,
    FIG13,
    FIG15,
    FIG18,
    FIG19,
    FIG24,
    FIG27,
    FIG28,
    FIGURES,
    Runs,
    cases,
    compute,
    parse_figures,
    plot,
    reproduce,
    rows,
)
from fivdisc.paper import measure as ms
from fivdisc.paper.cases import FIG10
from fivdisc.paper.fig_separation import separation_grid

from support.cf_check import check_cf
from support.cli import run_cli

EXAMPLES = examples.DIRECTORY


def _short(case, duration, rate=5000.0):
    return case.replace({"simulation.duration": duration, "simulation.output_rate": rate})


# --- the cases ---------------------------------------------------------------------------------


def test_every_figure_3_to_28_has_its_case():
    assert sorted(FIGURES) == list(range(3, 29))
    assert all(pc.figure == n and pc.statements for n, pc in FIGURES.items())


def test_example_files_equal_the_code_cases():
    """The packaged examples figNN.toml are written from fivdisc.paper.cases (write_examples)."""
    expected = cases()
    on_disk = {p.stem for p in EXAMPLES.glob("fig[0-9][0-9]*.toml")} - {"fig27_base"}
    assert on_disk == set(expected)
    for stem, case in expected.items():
        assert load_case(EXAMPLES / f"{stem}.toml") == case, stem
        assert (EXAMPLES / f"{stem}.toml").read_text().startswith("# Fig. ")


def test_captions_parameters():
    """Spot checks of the captions' values against the cases."""
    assert (FIG4.case.slider.normal_damping, FIG4.case.slider.rotational_damping,
            FIG4.case.friction.decay, FIG4.case.speed.value) == (11.0, 1.0, 10.0, 10.0)
    assert (FIG15.case.slider.normal_damping, FIG15.case.slider.rotational_damping,
            FIG15.case.speed.initial, FIG15.case.speed.duration) == (2.0, 0.5, 2 * np.pi, 35.0)
    assert FIG18.case_b.speed.value == pytest.approx(6 * np.pi)
    assert (FIG24.case.speed.initial, FIG24.case.speed.rate) == (2 * np.pi, 0.2)
    assert FIG28.case.simulation.impact and not FIG28.case_b.simulation.impact
    assert FIG28.case.slider.normal_damping == FIG28.case.slider.rotational_damping == 0.0
    for pc in FIGURES.values():
        for case in pc.runs.values():
            # >= 2 kHz: the 442 Hz disc mode and the 823 Hz harmonic of 411 Hz are resolved.
            assert case.simulation.output_rate >= 2000.0 or pc.figure == 27


# --- stated numbers fivdisc reproduces ----------------------------------------------------------


def test_table1_natural_frequencies():
    """Section 3: 1492, 1517, 1517, 1824, 1824, 2774, 2774 rad/s (237, 241, 241, 290,
    290, 442, 442 Hz) for the first seven disc modes."""
    omega = build_model(FIG8.case).omega
    np.testing.assert_allclose(omega, [1492, 1517, 1517, 1824, 1824, 2774, 2774], atol=0.5)
    np.testing.assert_allclose(omega / (2 * np.pi), [237, 241, 241, 290, 290, 442, 442],
                               atol=0.6)


@pytest.mark.parametrize(("pc", "stable"), [(FIG4, True), (FIG6, True), (FIG8, False),
                                            (FIG13, False)], ids=["fig4", "fig6", "fig8",
                                                                  "fig13"])
def test_stability_of_the_sliding_equilibrium(pc, stable):
    """Figs. 4 and 6: stable sliding equilibrium; Figs. 8 and 13 (section 3.2): unstable."""
    assert linear_stability(pc.case).stable is stable


def test_linear_eigenfrequencies_of_fig8_are_f1_and_f2():
    """Fig. 8: f1 = 181 Hz and f2 = 290.5 Hz; fivdisc's linearised modes C01 and D02 at
    2 pi rad/s are at 180.85 Hz and 290.49 Hz."""
    table = linear_stability(FIG8.case).to_dataframe()
    freq = dict(zip(table["coordinate"], table["frequency_hz"], strict=True))
    assert freq["C01"] == pytest.approx(181.0, abs=0.5)
    assert freq["D02"] == pytest.approx(290.5, abs=0.5)


@pytest.mark.parametrize("label", ["a", "b"])
def test_fig3_boundary_exists_with_stable_above(label):
    """Fig. 3: "'stable' refers to the region above the respective curve" (alpha = 0 at
    1 rad/s, alpha = 10 at 10 rad/s, the values of Figs. 6 and 4); coarse grid."""
    case = FIG3.runs[label]
    alpha = 0.0 if label == "a" else 10.0
    ys = np.linspace(0.0, 3.0, 16)
    m = stability_map(case.replace({"friction.decay": alpha}),
                      x=("slider.normal_damping", np.linspace(2.0, 12.0, 6)),
                      y=("slider.rotational_damping", ys))
    bound = m["boundary"].values
    stable = m["stable"].values.astype(bool)
    columns = np.flatnonzero(np.isfinite(bound))
    assert columns.size >= 3
    for i in columns:
        assert stable[ys > bound[i], i].all()
        assert not stable[ys < bound[i], i].any()


@pytest.mark.parametrize("label", ["a", "b"])
def test_fig18_separation_skew_vs_printed_sign(label):
    """Fig. 18: "separation happens in both cases" at 6 pi rad/s. fivdisc (skew
    gyroscopic terms): none in the first 1 s, first separation at 2.91 s (a) and 4.79 s
    (b) on the development machine. With the printed sign (+2 l M Omega dC/dt) it
    separates at 0.85 s and then diverges (docs/deviations.md). The response is chaotic
    (runs at two tolerances part by 2e-2 of the peak within 1 s), so the onset is
    checked by its span, not to the digit."""
    case = _short(FIG18.runs[label], 6.0, 1000.0)
    skew = simulate(case, stop_on=("separation",))
    first = skew.events("separation")
    assert first.size == 1 and 1.0 < first[0] < 6.0
    printed = simulate(case.replace({"simulation.printed_gyroscopic_sign": True,
                                     "simulation.duration": 1.0}), stop_on=("separation",))
    assert printed.events("separation").size == 1 and printed.events("separation")[0] < 1.0


def test_fig28_printed_sign_grows_without_bound():
    """Fig. 28 (c_z = 0, r0^2 c_phi = 0, 50 rad/s): the paper shows bounded responses.
    fivdisc (skew): bounded, no separation in the first 2 s (first at 2.21 s); with the
    printed sign |w| passes 0.1 m within 0.1 s, a speed-proportional negative damping
    (docs/deviations.md)."""
    skew = simulate(_short(FIG28.case, 2.0, 2000.0)).dataset
    assert ms.separation(skew)["count"] == 0
    assert not ms.run_end(skew)[0]
    printed = simulate(_short(FIG28.case, 0.1, 2000.0).replace(
        {"simulation.printed_gyroscopic_sign": True})).dataset
    diverged, text = ms.run_end(printed)
    assert diverged, text


# --- reproduce and its command ------------------------------------------------------------------


def test_parse_figures():
    assert parse_figures("3,8,27") == [3, 8, 27]
    assert parse_figures("8-10, 3") == [3, 8, 9, 10]
    for bad in ("3,99", "2", "x", "10-8"):
        with pytest.raises(FivdiscError, match=r"--figures = .*allowed: 3-28"):
            parse_figures(bad)


@pytest.mark.parametrize("args", [["--figures", "3,99", "-o", "x"], ["-o", "x"],
                                  ["--all", "--figures", "3", "-o", "x"]])
def test_command_rejects_bad_figures(args, tmp_path):
    result = CliRunner().invoke(reproduce_command, [*args[:-1], str(tmp_path / "x")])
    assert isinstance(result.exception, FivdiscError)
    message = str(result.exception)
    assert "\n" not in message and "--figures" in message
    if "99" in args[1]:
        assert "99" in message and "allowed: 3-28" in message


def test_reproduce_one_figure_and_reuse(tmp_path):
    """Fig. 6 (a 5 s run): files, report, reuse on rerun, recompute on changed parameters."""
    out = tmp_path / "paper"
    first = reproduce([6], out, progress=False, workers=1)
    assert first.computed == (6,) and first.reused == ()
    for name in ("fig06.png", "fig06.nc", "REPORT.md", "REPORT.html"):
        assert (out / name).stat().st_size > 0
    assert not list(out.glob(".*.part"))
    report = (out / "REPORT.md").read_text()
    assert "## Fig. 6:" in report and "![fig06.png](fig06.png)" in report
    assert "| sliding equilibrium | stable |" in report
    html = (out / "REPORT.html").read_text()
    assert "data:image/png;base64," in html and "fig06.png" in html

    stamp = (out / "fig06.nc").stat().st_mtime_ns
    again = reproduce([6], out, progress=False, workers=1)
    assert again.computed == () and again.reused == (6,)
    assert (out / "fig06.nc").stat().st_mtime_ns == stamp

    with xr.open_datatree(out / "fig06.nc") as data:
        stored = data.load()
    assert [r.verdict for r in rows(stored)][:2] == ["agrees", "agrees"]
    assert plot(stored).axes  # drawn from the stored data alone
    # One layout, one reader (issue 13, item 4): each run is a group in the result layout
    check_cf(stored.to_dataset())
    assert list(stored.children) == ["main"]
    check_cf(stored["main"].to_dataset())
    run = open_result(out / "fig06.nc")
    assert run.name == "fig06" and run.dataset["phi_dot"].dims == ("time", "slider")
    assert run.summary().status == "success"
    drawn = run_cli(["plot", str(out / "fig06.nc"), "--kind", "timeseries",
                                     "--var", "phi_dot", "-o", str(tmp_path / "f.png")])
    assert drawn.exit_code == 0, drawn.output
    stored.attrs["parameters"] = "{}"
    stored.to_netcdf(out / "fig06.nc")
    third = reproduce([6], out, progress=False, workers=1)
    assert third.computed == (6,)
    assert reproduce([6], out, force=True, progress=False, workers=1).computed == (6,)


# --- whole figures (slow) -----------------------------------------------------------------------


@pytest.fixture(scope="module")
def runs():
    return Runs()


@pytest.mark.slow
def test_fig8_stationary_only_at_first_and_separates(runs):
    """Fig. 8 (35 s at 2 pi rad/s): the paper says the response is stationary and
    quasi-periodic with f1 = 181 Hz, f2 = 290.5 Hz, and (Fig. 24) that it does not
    separate. fivdisc: quasi-periodic (131.3 and 180.9 Hz) over 1-11 s, but the unstable
    disc modes C02, C03 (growth 0.27 and 0.39 1/s) grow, the strongest line moves to
    ~189 Hz after 10 s and the slider separates late in the run (docs/deviations.md).

    The response is chaotic by then: the first separation moves between 23.9 and 26.6 s
    with the tolerance (tests/data/separation_tolerance_study.py, rtol 1e-5 to 1e-8) and
    was seen at 24.3 s on another machine. So only its occurrence is asserted, in a
    window twice that spread wide on each side, after the quasi-periodic stage."""
    ds = runs.get(FIG8.case)
    assert ms.periodicity(ds, "phi", None, 1.0, 11.0).kind == "quasi-periodic"
    assert ms.dominant(ds, "phi", None, 1.0, 6.0) == pytest.approx(180.9, abs=0.2)
    assert ms.dominant(ds, "phi", None, 10.0, 15.0) == pytest.approx(188.8, abs=1.0)
    separation = ms.separation(ds)
    assert separation["count"] > 0 and 18.0 < separation["first"] < 33.0


@pytest.mark.slow
def test_fig15_segments(runs):
    """Fig. 15: segments 0-10, 10-15, 15-25, 25-28, 28-30, 30-35 s. fivdisc: periodic at
    206 Hz until 13.5 s, then a line gliding down with the disc speed, so the later
    segments differ from each other (medians 150, 104, 82, 40 Hz)."""
    ds = runs.get(FIG15.case)
    times, freqs = ms.ridge(ds, "phi")
    assert 10.0 <= ms.plateau_end(times, freqs) <= 15.0
    medians = [np.median(freqs[(times >= a) & (times <= b)]) for a, b in FIG15.windows]
    assert medians[0] == pytest.approx(206.0, abs=2.0)
    assert np.all(np.diff(medians[1:]) < 0)


@pytest.mark.slow
def test_fig19_separation_throughout_a_and_not_late_b(runs):
    """Fig. 19: a separates throughout the deceleration, b not in the late stage.
    fivdisc: a from 2.57 s to 32.99 s, b from 5.05 s to 15.33 s; the printed sign
    diverges at ~1.3 s in both (docs/deviations.md)."""
    a, b = (ms.separation(runs.get(c)) for c in FIG19.runs.values())
    assert a["first"] < 5.0 and a["last"] > 30.0
    assert 0 < b["count"] and b["last"] < 20.0
    for case in FIG19.runs.values():
        printed = runs.printed(case)
        diverged, text = ms.run_end(printed)
        assert diverged and printed.attrs["end_time"] < 2.0, text


@pytest.mark.slow
def test_fig24_separation_accelerating_and_constant(runs):
    """Fig. 24: separation as the disc speeds up, none at constant speed. fivdisc: b
    separates from 14.3 s (Omega = 9.1 rad/s) and not at constant 2 pi; a separates
    from 26.5 s, but so does its constant-speed counterpart (Fig. 8, late in the run),
    which the paper says does not separate (docs/deviations.md). Unlike Fig. 8's, these
    onsets hardly move with the tolerance (a: 26.50-26.51 s, b: 14.27-14.41 s for rtol
    1e-5 to 1e-8, tests/data/separation_tolerance_study.py), so they are checked to
    several times that spread."""
    a, b = (ms.separation(runs.get(c)) for c in FIG24.runs.values())
    assert b["first"] == pytest.approx(14.3, abs=0.5)
    assert a["first"] == pytest.approx(26.5, abs=1.0)
    assert ms.separation(runs.get(FIG13.case))["count"] == 0
    assert ms.separation(runs.get(FIG8.case))["count"] > 0


@pytest.mark.slow
def test_fig28_impact_weakens_the_vibration(runs):
    """Fig. 28: "the transverse vibration with impact considered is much weaker". fivdisc:
    max |w| after the first separation 4.5 mm with impact, 7.5 mm without."""
    peaks = []
    for case in FIG28.runs.values():
        ds = runs.get(case)
        after = ds["time"].values >= ms.separation(ds)["first"]
        peaks.append(np.max(np.abs(ds["w"].values[after, 0])))
    assert peaks[1] > 1.5 * peaks[0]


@pytest.mark.slow
def test_omega_dot_terms_change_little(runs):
    """The printed equations omit the dOmega/dt terms; for the paper's 2 pi rad/s
    decelerations the slider angle moves by < 1e-4 of its peak in the first 1 s and the
    stick count by < 1 % over 35 s (docs/deviations.md)."""
    for case in (FIG10.case, FIG15.case):
        on = runs.get(case)
        off = runs.get(case.replace({"simulation.omega_dot_terms": False}))
        first = on["time"].values <= 1.0
        diff = np.max(np.abs(on["phi"].values[first] - off["phi"].values[first]))
        assert diff < 1e-4 * np.max(np.abs(on["phi"].values[first]))
        sticks = [int(np.sum(d["event_kind"].values == "stick")) for d in (on, off)]
        assert abs(sticks[0] - sticks[1]) < 0.01 * sticks[0]


@pytest.mark.slow
def test_fig27_region_grows_with_speed_and_duration(tmp_path):
    """Fig. 27: separation more likely at high Omega_0 and long t_max. fivdisc: the
    separated region is closed towards both (coarse 5 x 4 grid here)."""
    small = replace(FIG27, axes=(("speed.initial", (4.0, 8.0, 12.0, 16.0, 20.0)),
                                 ("speed.duration", (10.0, 20.0, 30.0, 40.0))))
    grid = separation_grid(small, tmp_path, printed=False, workers=1)
    sep = grid["separated"].values.astype(bool)
    assert sep.any() and not sep.all()
    assert np.all(~sep[:-1] | sep[1:]) and np.all(~sep[:, :-1] | sep[:, 1:])


@pytest.mark.slow
@pytest.mark.parametrize("figure", sorted(set(FIGURES) - {27}))
def test_every_figure_computes_and_plots(figure, runs):
    data = compute(figure, runs)
    assert rows(data)
    assert plot(data).axes
