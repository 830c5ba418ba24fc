"""fivdisc orbit says when the orbit it found is unstable (the new user's three pads: the
default transient ends near an unstable asymmetric orbit, and the stable orbit of the
pads sticking in turn needs a longer one)."""

from __future__ import annotations

from support.cases import RIGID, THREE_PADS
from support.cli import run_cli


def _largest_modulus(text: str) -> float:
    """The largest multiplier's modulus in the printed table (after the header)."""
    rows = text.split("Floquet multipliers (modulus, real, imag):")[1].splitlines()
    return max(float(row.split()[0]) for row in rows if row.strip()[:1].isdigit())


def test_an_unstable_orbit_found_after_a_transient_is_said_to_be(case_file):
    res = run_cli(["orbit", case_file(THREE_PADS), "--no-progress"])
    assert res.exit_code == 0, res.output
    assert ", unstable," in res.stdout
    assert "note: this orbit is unstable, so a run leaves it" in res.stdout
    # Second route: a multiplier printed lies outside the unit circle.
    assert _largest_modulus(res.stdout) > 1.01


def test_a_stable_orbit_has_no_note(case_file):
    res = run_cli(["orbit", case_file(RIGID), "--transient", 4.0, "--no-progress"])
    assert res.exit_code == 0, res.output
    assert ", stable," in res.stdout and "note: this orbit is unstable" not in res.stdout
    assert _largest_modulus(res.stdout) <= 1.0 + 1e-9
