"""``fivdisc continue --from-hopf`` says which Hopf point it takes and warns when the
orbits born there are all unstable; a branch continued from a Hopf branch's file
restates the point's kind and the bistable range (issue 40, item 1)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fivdisc.analysis.hopf import hopf_points
from fivdisc.analysis.stability import linear_stability
from fivdisc.case import Case
from fivdisc.continuation.branch import open_branch
from fivdisc.continuation.from_hopf import hopf_cycles

from support.cases import THREE_PADS
from support.cli import messages, run_cli

# The rigid-disc oscillator of tests/continuation/test_hopf_cycles.py: one subcritical
# Hopf point at 9.1629 rad/s whose unstable slipping orbits graze at 10.4985 rad/s.
RIGID = Case(disc={"modes": []}, slider={"rotational_damping": 0.5},
             friction={"decay": 1.0}, speed={"value": 1.0})


@pytest.fixture(scope="module")
def three_from_hopf(tmp_path_factory):
    """A branch of three orbits from RIGID's Hopf point: too short to reach the grazing
    that ends the bistable range."""
    home = tmp_path_factory.mktemp("from-hopf")
    case, first = home / "rigid.toml", home / "hopf.nc"
    case.write_text(RIGID.to_toml())
    res = run_cli(["continue", case, "--key", "speed.value", "--to", "30", "--from-hopf",
                   "0.5:30:25", "--points", "3", "--no-progress", "-o", first])
    assert res.exit_code == 0, res.output
    return first


def test_a_branch_continued_from_a_hopf_branch_restates_its_kind_and_range(
        three_from_hopf, tmp_path):
    """Three points from the Hopf point leave the range undetermined; the branch
    continued from that file reaches the grazing and states the range from the Hopf
    point to it, as one continuation from the point does (second route)."""
    first, second = three_from_hopf, tmp_path / "on.nc"
    assert open_branch(first).hopf()["bistable_undetermined"]
    res = run_cli(["continue", "--from", first, "--key", "speed.value", "--to", "30",
                   "--points", "200", "--no-progress", "-o", second, "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)["hopf"]
    assert data["criticality"] == "subcritical" and data["continued"]
    branch = open_branch(second)
    info = branch.hopf()
    (grazing,) = [b for b in branch.bifurcations() if b["kind"] == "grazing"]
    hopf = open_branch(first).hopf()["value"]
    assert info["bistable"] == (hopf, grazing["parameter"]) and info["bistable_open"]
    text = str(branch)
    assert "continues the branch from the Hopf point at speed.value = 9.16290" in text
    assert "(phi): subcritical" in text and "at least" in text
    (point,) = hopf_points(RIGID, "speed.value", np.linspace(0.5, 30.0, 25))
    whole = hopf_cycles(point, 30.0, max_points=200).hopf()
    assert whole["criticality"] == info["criticality"]
    # Each grazing located to about 1e-6 of the key, on branches of different steps.
    assert whole["bistable"][1] == pytest.approx(info["bistable"][1], rel=1e-5)


def test_an_undetermined_range_names_the_farthest_orbit_reached(three_from_hopf, tmp_path):
    """A branch continued from a Hopf branch back towards the Hopf point has not decided
    the range beyond its farthest orbit, which is its start, not its end (the new user's
    branch walked down and said "not determined up to" its last value)."""
    import re

    first, back = three_from_hopf, tmp_path / "back.nc"
    hopf = open_branch(first).hopf()["value"]
    res = run_cli(["continue", "--from", first, "--key", "speed.value", "--to",
                   hopf + 1e-4, "--points", "5", "--no-progress", "-o", back])
    assert res.exit_code == 0, res.output
    branch = open_branch(back)
    assert branch.parameter[-1] < branch.parameter[0]  # it walked back
    (said,) = re.findall(r"not determined up to speed.value = ([0-9.]+)", res.stdout)
    farthest = branch.parameter[np.argmax(np.abs(branch.parameter - hopf))]
    assert float(said) == pytest.approx(farthest, rel=1e-8)


def test_from_hopf_says_which_point_it_takes_and_warns_when_its_orbits_are_unstable(
        tmp_path):
    """Three pads between 0.3 and 5 rad/s: four Hopf points, none where the sliding
    equilibrium changes stability (another mode is unstable at each: second route, its
    eigenvalues there). The command lists them, says it takes the first, and warns that
    its orbits are unstable; the branch's orbits are (their Floquet multipliers)."""
    case = tmp_path / "three.toml"
    case.write_text(THREE_PADS.to_toml())
    res = run_cli(["continue", case, "--key", "speed.value", "--to", "30", "--from-hopf",
                   "0.3:5:20", "--points", "2", "--no-progress", "--json"])
    assert res.exit_code == 0, res.output
    # Under --json the choice goes to stderr: stdout is the JSON alone.
    data = json.loads(res.stdout)
    said = messages(res.stderr)
    assert "4 Hopf points in speed.value between 0.3 and 5:" in said
    (taken,) = [line for line in said if line.startswith("taking")]
    assert taken.startswith("taking [0]: Hopf point at speed.value = 0.41147")
    assert "none changes the equilibrium's stability" in taken
    (warning,) = [line for line in said if line.startswith("warning")]
    assert warning.startswith("warning: at speed.value = 0.41147")
    assert "every orbit born there is unstable" in warning
    assert not data["hopf"]["on_boundary"] and data["hopf"]["unstable_modes"]
    assert not any(p["stable"] for p in data["points"])
    found = hopf_points(THREE_PADS, "speed.value", np.linspace(0.3, 5.0, 20))
    for hp in found:
        lam = linear_stability(hp.case).eigenvalues
        others = lam[np.abs(lam - hp.eigenvalue) > 1e-6 * abs(hp.eigenvalue)]
        others = others[np.abs(others - np.conj(hp.eigenvalue)) > 1e-6 * abs(hp.eigenvalue)]
        assert others.real.max() > 0


def test_identical_pads_have_one_hopf_point_each():
    """Three near-equal pad modes crossing between two values of the scan: each located
    on its own branch (they were the same point three times), each a zero of a real part
    of the plain eigen-solve."""
    found = hopf_points(THREE_PADS, "speed.value", np.linspace(0.3, 5.0, 20))
    pads = [hp for hp in found if hp.mode.startswith("phi")]
    assert sorted(hp.mode for hp in pads) == ["phi~0", "phi~1", "phi~2"]
    assert len({round(hp.value, 6) for hp in pads}) == 3
    for hp in pads:
        lam = linear_stability(hp.case).eigenvalues
        assert np.min(np.abs(lam.real)) < 1e-7 * np.abs(lam).max()
