"""``fivdisc continue``'s arguments checked before any orbit is searched, its messages, and
its branch kept through a second Ctrl-C (issue 40, items 5 and 7). Each test is one
reproduction of the issue."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import pytest

from fivdisc.continuation.branch import open_branch

from support.cases import RIGID
from support.cli import messages, run_cli


def _refused(args: list, *words: str, bound: float = 20.0) -> str:
    start = time.perf_counter()
    result = run_cli(args)
    assert result.exit_code == 2, result.output
    lines = messages(result.stderr)
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    for word in words:
        assert word in lines[0], lines[0]
    assert time.perf_counter() - start < bound
    return lines[0]


def test_continue_refuses_a_period_too_long_to_integrate() -> None:
    """--period 1e6 ran the search until the machine's patience ran out."""
    _refused(["continue", "default", "--key", "speed.value", "--to", "7", "--period", "1e6",
              "--no-progress"], "more than simulation.max_steps",
             "over simulation.duration + the search window + --period = 1000002.0 s")


def test_continue_refuses_a_transient_too_long_to_integrate() -> None:
    """--transient 1e12 integrated for minutes, to end with too_many_steps."""
    _refused(["continue", "default", "--key", "speed.value", "--to", "7", "--transient",
              "1e12", "--no-progress"], "more than simulation.max_steps",
             "over --transient + the search window = 1000000000001.0 s")


def test_continue_takes_a_keys_last_part_as_stability_does() -> None:
    """--key normal_damping was "unknown key 'normal_damping'; did you mean 'disc'?"; it is
    slider.normal_damping, as for fivdisc stability (here refused for its target only)."""
    _refused(["continue", "default", "--key", "normal_damping", "--to", "-1", "--no-progress"],
             "--to -1.0 is invalid for slider.normal_damping")
    _refused(["continue", "default", "--key", "dampin", "--to", "1", "--no-progress"],
             "--key: unknown case key 'dampin'")


def test_from_hopf_names_its_range_when_an_end_is_invalid() -> None:
    """--from-hopf 500:-100:13 was refused as "--to -100.0 is invalid" (--to was 1)."""
    line = _refused(["continue", "default", "--key", "speed.value", "--to", "1", "--from-hopf",
                     "500:-100:13", "--no-progress"],
                    "--from-hopf = '500:-100:13' is invalid: its end -100 is not a value of "
                    "speed.value", "must be >= 0")
    assert "--to" not in line


@pytest.fixture(scope="module")
def rigid_orbit_file(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("rigid")
    case, orbit = folder / "rigid.toml", folder / "orbit.nc"
    case.write_text(RIGID.replace({"simulation.duration": 4.0}).to_toml())
    result = run_cli(["orbit", case, "--no-progress", "-o", orbit])
    assert result.exit_code == 0, result.output
    return orbit


def test_a_second_ctrl_c_during_continue_still_writes_the_branch(rigid_orbit_file: Path,
                                                                  tmp_path: Path,
                                                                  monkeypatch) -> None:
    """The first Ctrl-C stops the walk, which keeps its points; a second one while the
    branch is written lost it (KeyboardInterrupt in the writer). Now it is refused with a
    note, the branch is written and the command exits 130."""
    from fivdisc.continuation.branch import Branch
    from fivdisc.continuation.problem import OrbitProblem

    step_from, write = OrbitProblem.step_from, Branch.to_netcdf
    calls = {"n": 0}

    def interrupted_later(self, a, s, deadline):
        calls["n"] += 1
        if calls["n"] == 4:
            os.kill(os.getpid(), signal.SIGINT)  # the first Ctrl-C
            time.sleep(1.0)  # delivered meanwhile
        return step_from(self, a, s, deadline)

    def interrupted_again(self, path):
        os.kill(os.getpid(), signal.SIGINT)  # the second, while the branch is written
        time.sleep(0.5)
        return write(self, path)

    monkeypatch.setattr(OrbitProblem, "step_from", interrupted_later)
    monkeypatch.setattr(Branch, "to_netcdf", interrupted_again)
    out = tmp_path / "b.nc"
    result = run_cli(["continue", "--from", rigid_orbit_file, "--key", "speed.value", "--to",
                      "3", "--no-progress", "-o", out])
    assert result.exit_code == 130, result.output
    assert "interrupted again: the branch so far is being written" in result.stderr
    assert len(open_branch(out)) == 4
    # The handler is the one before the command again.
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_an_orbit_of_a_preload_below_any_physical_force_is_refused(tmp_path: Path) -> None:
    """Found by the fuzz (item 3): a preload of 2.2e-308 N let the shooting run into
    subnormal states, where the kernel divided by zero (ZeroDivisionError). As for a
    preload of 0, nothing drives the disc: refused, for orbit and continue alike."""
    from fivdisc import Case

    path = tmp_path / "c.toml"
    Case(slider={"preload": 2.2250738585072014e-308}).save(path)
    words = ("slider.preload = 2.22507e-308 is invalid for a periodic orbit: must be > 1e-09 N "
             "for some slider")
    _refused(["orbit", path, "--no-progress", "--transient", "0.01"], words)
    _refused(["continue", path, "--key", "speed.value", "--to", "7", "--no-progress",
              "--transient", "0.01"], words)
