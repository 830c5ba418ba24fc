"""Every number the documentation states about fivdisc's output is produced by a script of
the repository and checked here (issue 13, item 3).

- README, "Accuracy and speed": the errors of the default tolerances, which
  ``benchmarks/bench_accuracy.py`` prints, measured again.
- docs/deviations.md: its numbers are those of ``fivdisc reproduce --all`` (REPORT.md), or,
  for the chaotic runs, the spreads over tolerances that
  ``tests/data/separation_tolerance_study.py`` measured (its output is kept beside it).
  The fast test checks the spreads against that output; the slow one reproduces every
  figure (or reads the REPORT.md named by ``FIVDISC_REPORT``) and checks the rest.

The tutorials state no number of their own: they print what they compute when the site is
built.
"""

from __future__ import annotations

import importlib.util
import os
import re
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
DEVIATIONS = ROOT / "docs" / "deviations.md"
STUDY = ROOT / "tests" / "data" / "separation_tolerance_study.txt"
_NUMBER = r"\d+(?:\.\d+)?(?:e[-+]?\d+)?"
# A spread from the study, as deviations.md writes it (two decimals): "23.87-26.59 s"; and
# a spread of separation counts: "7536-7683 separations".
_SPREAD = re.compile(r"(?<![\w.])(?:\d+\.\d\d-\d+\.\d\d(?= s\b)|\d+-\d+(?= separations))")

pytestmark = pytest.mark.skipif(not DEVIATIONS.is_file(), reason="needs the repository")


def _bench_accuracy():
    spec = importlib.util.spec_from_file_location("bench_accuracy",
                                                  ROOT / "benchmarks" / "bench_accuracy.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_readme_accuracy_numbers():
    """'a slider angle within about A of its peak and switch times within about B s of a
    rtol = 1e-12 run, both shrinking tenfold with each tenfold tighter rtol'."""
    text = " ".join(README.read_text().split())
    found = re.search(rf"slider angle within about ({_NUMBER}) of its peak and switch times "
                      rf"within about ({_NUMBER}) s of a `rtol = 1e-12` run, both shrinking "
                      "tenfold with each tenfold tighter `rtol`", text)
    assert found, "the README's accuracy sentence changed: update this test"
    angle, switch = map(float, found.groups())
    rows = _bench_accuracy().tolerance_errors((1e-6, 1e-7))
    (_, angle_6, switch_6), (_, angle_7, switch_7) = rows
    # "about": within a factor of 2 either way
    assert angle / 2 < angle_6 < angle * 2, angle_6
    assert switch / 2 < switch_6 < switch * 2, switch_6
    assert 5 < angle_6 / angle_7 < 20 and 5 < switch_6 / switch_7 < 20


def _study() -> dict[tuple[str, str, str], tuple[str, str]]:
    rows = {}
    for line in STUDY.read_text().splitlines():
        if line and not line.startswith("#"):
            case, sign, quantity, low, high = line.split()
            rows[case, sign, quantity] = (low, high)
    return rows


def test_deviations_spreads_are_the_study_s():
    """Every spread "A-B s" in docs/deviations.md is a (min, max) the tolerance study
    measured, and the study's output covers what the doc cites."""
    spreads = {tuple(s.split("-")) for s in _SPREAD.findall(DEVIATIONS.read_text())}
    measured = set(_study().values())
    assert spreads, "docs/deviations.md states no spread"
    assert spreads <= measured, sorted(spreads - measured)


# Numbers of docs/deviations.md that are not fivdisc's output: the paper's equation
# numbers, and the bound on the squared natural frequencies (the smallest, 1492 rad/s, is
# checked by test_paper.py::test_table1_natural_frequencies). Every other number is
# checked: small integers too, though figure numbers may match a report value by chance.
_NOT_OUTPUT = {"33", "34", "37", "38", "40", "41", "45", "46", "2e6"}


def _numbers(text: str) -> list[str]:
    text = _SPREAD.sub(" ", text)  # spreads are checked against the study
    return re.findall(rf"(?<![\w.]){_NUMBER}", text)


def _matches(token: str, values: np.ndarray) -> bool:
    """Whether a report value rounds to `token` at the token's own precision."""
    value = float(token)
    mantissa = token.split("e")[0]
    digits = len(mantissa.split(".")[1]) if "." in mantissa else 0
    scale = 10.0 ** (int(token.split("e")[1]) if "e" in token else 0)
    half = 0.5 * 10.0 ** -digits * scale
    return bool(np.any(np.abs(np.abs(values) - value) <= half * (1 + 1e-9)))


@pytest.mark.slow
def test_deviations_numbers_are_the_report_s(tmp_path):
    """Every other number of docs/deviations.md is one of REPORT.md's (or a rounded value
    of the study), to the doc's precision (all figures reproduced: about 15 minutes on 2
    cores)."""
    report = os.environ.get("FIVDISC_REPORT")
    if report is None:
        from fivdisc.paper import reproduce

        reproduce(outdir=tmp_path, progress=False)
        report = tmp_path / "REPORT.md"
    text = Path(report).read_text()
    # the study's values too: a doc number may round one of them ("after 2.5 to 5.1 s")
    study = [v for pair in _study().values() for v in pair if v != "nan"]
    values = np.array([float(t) for t in [*re.findall(_NUMBER, text), *study]])
    missing = [t for t in dict.fromkeys(_numbers(DEVIATIONS.read_text()))
               if t not in _NOT_OUTPUT | _EIGEN_TOKENS and not _matches(t, values)]
    assert not missing, f"not in REPORT.md: {missing}"


def _eigen_rows():
    from fivdisc.paper import FIG4, FIG6, FIG8, FIG13, FIG18, FIG28

    # (case, printed sign, coordinate, growth rate [1/s] as docs/deviations.md writes it)
    return [
        (FIG4.case, False, "C00", "-0.0033"), (FIG4.case, True, "D03", "+0.96"),
        (FIG6.case, False, "C00", "-0.00039"), (FIG6.case, True, "D03", "+0.16"),
        (FIG8.case, False, "phi", "240"), (FIG8.case, True, "D03", "+0.74"),
        (FIG8.case, False, "C03", "0.39"), (FIG8.case, False, "C02", "0.27"),
        (FIG13.case, False, "phi", "39.9"), (FIG13.case, True, "D03", "+0.72"),
        (FIG18.runs["a"], False, "phi", "+33.2"), (FIG18.runs["a"], False, "C02", "+0.98"),
        (FIG18.runs["b"], False, "C02", "+0.58"),
        (FIG18.runs["a"], True, "C00", "+6.6"), (FIG18.runs["b"], True, "C00", "+7.5"),
        (FIG28.case, False, "phi", "+5.75"), (FIG28.case, False, "C03", "+1.44"),
        (FIG28.case, True, "D03", "+98"), (FIG28.case, True, "C02", "+66"),
    ]


# The growth rates docs/deviations.md states, checked by the next test.
_EIGEN_TOKENS = {"0.0033", "0.00039", "0.96", "0.16", "240", "0.74", "0.39", "0.27", "39.9",
                 "0.72", "33.2", "0.98", "0.58", "6.6", "7.5", "5.75", "1.44", "98", "66",
                 "238.5", "238.8", "0.0004"}


def test_deviations_growth_rates():
    """The linear stability numbers of docs/deviations.md (section 1's table, section 3)."""
    from fivdisc import linear_stability

    text = DEVIATIONS.read_text()
    for case, printed, coordinate, written in _eigen_rows():
        assert written.lstrip("+") in text, written
        table = linear_stability(case.replace(
            {"simulation.printed_gyroscopic_sign": printed})).to_dataframe()
        rate = float(table.loc[table["coordinate"] == coordinate, "growth_rate"].iloc[0])
        assert _matches(written.lstrip("+-"), np.array([abs(rate)])), (coordinate, rate)
        assert (rate > 0) == (not written.startswith("-")), (coordinate, rate)
    # section 4: the least damped disc mode of Figs. 4 and 6, its frequency and decay
    for case, frequency, decay in ((_eigen_rows()[0][0], "238.5", "0.0033"),
                                   (_eigen_rows()[2][0], "238.8", "0.0004")):
        table = linear_stability(case).to_dataframe()
        c00 = table[table["coordinate"] == "C00"].iloc[0]
        assert _matches(frequency, np.array([c00["frequency_hz"]]))
        assert _matches(decay, np.array([abs(c00["growth_rate"])]))
    assert "(C00, at 238.5 and 238.8 Hz) decays at 0.0033 and 0.0004 1/s" in " ".join(
        text.split())
