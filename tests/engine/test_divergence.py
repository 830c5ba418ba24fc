"""Runs that leave the range of linear plate theory end as diverged, never as success."""

from __future__ import annotations

import numpy as np

from fivdisc.case import Case
from fivdisc.engine.integration import Integration
from fivdisc.engine.simulation import Deflection, initial_state, simulate
from fivdisc.model.build import build_model

from support.cli import messages, run_cli


def test_absurd_preload_diverges():
    """1e6 N on a 2 mm disc deflects it by metres in milliseconds."""
    res = simulate(Case(slider={"preload": 1e6}, simulation={"duration": 0.2}))
    assert res.status == "diverged" and not res.ok
    assert "disc.thickness" in res.message
    # The data up to the divergence are kept; the run stopped soon after the limit.
    w = np.abs(res.dataset["w"].values)
    assert res.dataset.attrs["end_time"] < 0.2
    assert np.max(w) > Deflection.DIVERGED * 0.002


def test_the_kernel_keeps_the_largest_deflection_under_the_sliders():
    """The check reads the largest |w| under the sliders that the kernel keeps while it
    writes the samples: it must be the largest of the written samples, call by call,
    over both of two sliders in stick-slip."""
    case = Case(sliders=[{"track_radius": 0.1, "angle": 0.0},
                         {"track_radius": 0.11, "angle": 2.0, "face": "bottom"}],
                speed={"value": 20.0}, simulation={"duration": 0.05})
    model = build_model(case)
    run = Integration(model, initial_state(model), duration=0.05, output_rate=20000.0)
    done = 0
    for target in (0.01, 0.02, 0.05):
        run.run_to(target)
        under = run.out_aux[done : run.n_samples, 6:8]  # w under each of the 2 sliders
        done = run.n_samples
        assert run.take_peak() == np.max(np.abs(under))
    assert run.take_peak() == 0.0


def test_printed_sign_blow_up_diverges():
    """The printed (non-skew) gyroscopic sign acts as negative damping growing with the
    speed: at 200 rad/s the state grows without bound."""
    case = Case(speed={"value": 200.0},
                simulation={"duration": 1.0, "printed_gyroscopic_sign": True})
    res = simulate(case)
    assert res.status == "diverged"


def test_paper_case_stays_within_the_limit():
    """The paper's Table 1 case deflects the disc by about two thicknesses: no verdict."""
    res = simulate(Case(simulation={"duration": 0.3}))
    assert res.status == "success"
    assert 0.002 < np.max(np.abs(res.dataset["w"].values)) < Deflection.DIVERGED * 0.002
    # ... but the summary notes, once and in words, that linear plate theory is
    # stretched, relative to what, and that the paper's parameters do it (issue 27, item 11).
    summary = res.summary()
    assert summary.disc_thickness == 0.002
    ratio = summary.max_abs_w / 0.002
    text = str(summary)
    assert "warning" not in text
    assert text.count("note: ") == 1
    assert (f"note: the disc deflected by up to {1e3 * summary.max_abs_w:.3g} mm, "
            f"{ratio:.3g} times its thickness h = 2 mm") in text
    assert "The paper's parameters do this too" in text and "Range of validity" in text


def test_small_deflections_get_no_warning():
    """Two equal pads on opposite faces keep the disc flat: |w| far below h."""
    pad = {"track_radius": 0.1, "angle": 0.0}
    res = simulate(Case(sliders=[{**pad, "face": "top"}, {**pad, "face": "bottom"}],
                        simulation={"duration": 0.05}))
    summary = res.summary()
    assert summary.max_abs_w < 0.1 * summary.disc_thickness
    assert "note:" not in str(summary)


def test_cli_reports_divergence_in_one_line(tmp_path):
    case = tmp_path / "big.toml"
    case.write_text("[slider]\npreload = 1e6\n[simulation]\nduration = 0.05\n")
    out = run_cli(["simulate", str(case), "-o", str(tmp_path / "big.nc"),
                                  "--no-progress"])
    assert out.exit_code == 1
    (line,) = messages(out.stderr)
    assert "diverged" in line
