"""Newton shooting that stalls (issue 36, item 3): within the integration's own accuracy a
converged orbit at that accuracy, after one tightening; ``--tol`` on the command line.
The stall on a discontinuity of the shooting map is tested on the three pads
(``tests/continuation/test_several_pads.py``)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fivdisc.analysis.orbits import periodic_orbit

from support.cases import RIGID, rigid_disc_closed_form
from support.cli import run_cli


@pytest.fixture(scope="module")
def rigid():
    return periodic_orbit(RIGID, transient=4.0)


def test_a_stall_within_the_integration_accuracy_is_tightened_once(rigid):
    """The smallest tolerance allowed (1e-14) is below what rtol 1e-12 can give: Newton
    stalls within ten times the integration's accuracy and is run again, once, at rtol
    1e-13, where it converges. Second route: the period is the closed form's to 1e-10."""
    orbit = periodic_orbit(RIGID, rigid.state, period=rigid.period, phases=rigid.phases,
                           rtol=1e-12, tol=1e-14)
    assert orbit.converged
    assert "solved again at rtol 1e-13" in orbit.note
    assert orbit.period == pytest.approx(rigid_disc_closed_form()[0], rel=1e-10)


def test_an_orbit_at_the_integration_accuracy_says_so(rigid):
    """At rtol 1e-13 the integration's accuracy (~1e-14) is the tolerance's level: the
    orbit is converged at that accuracy, which it reports, and its residual is within ten
    times it (the stall criterion)."""
    orbit = periodic_orbit(RIGID, rigid.state, period=rigid.period, phases=rigid.phases,
                           rtol=1e-13, tol=1e-14)
    assert orbit.converged
    assert np.isfinite(orbit.accuracy) and orbit.residual <= 10 * orbit.accuracy
    assert "converged at the integration's accuracy" in str(orbit)
    assert orbit.period == pytest.approx(rigid_disc_closed_form()[0], rel=1e-10)


def test_orbit_takes_a_tolerance(rigid, tmp_path, case_file):
    path = case_file(RIGID)
    out = tmp_path / "o.nc"
    res = run_cli(["orbit", path, "--transient", 4.0, "--tol", 1e-6, "--json", "-o", out,
                   "--no-progress"])
    assert res.exit_code == 0, res.output
    found = json.loads(res.stdout)
    assert found["residual"] < 1e-6
    assert found["period"] == pytest.approx(rigid_disc_closed_form()[0], rel=1e-7)
    bad = run_cli(["orbit", path, "--tol", 0, "--no-progress"])
    assert bad.exit_code != 0 and "--tol = 0.0 is invalid" in bad.output
