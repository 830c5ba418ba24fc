"""Stability commands on cases the linearisation cannot answer, and scans it cannot make
(issue 40, items 3, 4, 5 and 7): one line naming the parameter, its value and what is
allowed, before any work; never a traceback, a numpy warning or an answer of round-off.

Each test is one reproduction of the issue, named by what must happen.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fivdisc import Case
from fivdisc.analysis.stability import linear_stability

from support.cli import messages, run_cli


def _case(tmp_path: Path, **tables) -> Path:
    path = tmp_path / "case.toml"
    Case(**tables).save(path)
    return path


def _refused(args: list, *words: str) -> str:
    """Exit status 2 and one line, ``error: ...``, naming `words`; nothing else on stderr
    (no traceback, no numpy warning before it), nothing on stdout."""
    result = run_cli(args)
    assert result.exception is None or isinstance(result.exception, SystemExit), result.output
    assert result.exit_code == 2, result.output
    lines = messages(result.stderr)
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    for word in words:
        assert word in lines[0], lines[0]
    assert result.stdout == ""
    return lines[0]


# --- item 3: tracebacks become one-line errors -----------------------------------------------


def test_stability_of_a_normal_damper_beyond_resolution_is_refused(tmp_path: Path) -> None:
    """LinAlgError before: the damper's rate overflowed the Jacobian."""
    _refused(["stability", _case(tmp_path, slider={"normal_damping": 1e308}), "--json"],
             "slider: normal_damping / mass = inf 1/s", "slider.normal_damping = 1e+308",
             "must be <= 1e+12 1/s")


def test_stability_of_a_rotational_damper_beyond_resolution_is_refused(tmp_path: Path) -> None:
    _refused(["stability", _case(tmp_path, slider={"rotational_damping": 1e308}), "--json"],
             "slider: rotational_damping / inertia = inf 1/s",
             "slider.rotational_damping = 1e+308", "must be <= 1e+12 1/s")


def test_stability_with_a_friction_slope_out_of_range_is_refused(tmp_path: Path) -> None:
    """A Stribeck velocity of 1e-308 m/s: the law's slope is not a double (LinAlgError)."""
    path = _case(tmp_path, friction={"law": "stribeck", "stribeck_velocity": 1e-308})
    _refused(["stability", path, "--json"],
             "the linearised slip equations are not finite",
             "the slope of the friction law (stribeck)", "friction.stribeck_velocity = 1e-308")


def test_stability_at_a_speed_beyond_resolution_is_refused(tmp_path: Path) -> None:
    """OverflowError before, in the equilibrium's guess (Omega squared)."""
    _refused(["stability", _case(tmp_path, speed={"value": 1e308}), "--json"],
             "the disc's spin", "speed.value = 1e+308 rad/s", "must be <= 1e+12 1/s")


def test_stability_of_a_slider_of_subnormal_mass_is_refused(tmp_path: Path) -> None:
    """ZeroDivisionError before, in the right-hand side."""
    _refused(["stability", _case(tmp_path, slider={"mass": 5e-324}), "--json"],
             "sqrt(normal_stiffness / mass) = inf 1/s", "slider.mass = 5e-324")


def test_hopf_points_across_decades_of_the_key_are_located(tmp_path: Path) -> None:
    """kinetic_min = 0 and decay from 0 to 1.6e10 in 7 values: Brent's method tried values
    where the equilibrium from the bracket's lower end did not converge (TypeError), and
    the slope below the key's lowest value (decay < 0). Now each crossing is located with
    the equilibrium of the nearer end; the points are on the imaginary axis."""
    path = _case(tmp_path, friction={"kinetic_min": 0.0})
    result = run_cli(["stability", path, "--x", "friction.decay=0:15535335780:7",
                      "-o", tmp_path / "b.nc", "--no-progress"])
    assert result.exit_code == 0, result.output
    lines = [line for line in result.stdout.splitlines() if line.startswith("Hopf point at")]
    assert lines, result.stdout
    for line in lines:
        value = float(line.split("= ")[1].split(":")[0])
        at = linear_stability(Case(friction={"kinetic_min": 0.0, "decay": value}))
        growth = at.eigenvalues.real
        assert abs(growth).min() < 1e-6, (line, growth)


def test_round_off_growth_rates_make_no_hopf_point(tmp_path: Path) -> None:
    """Constant friction at 1e-12 rad/s: the D modes are undamped, their growth rates
    +-5e-13 at random. A sign change there was a "crossing" Brent's method could not
    bracket (ValueError: f(a) and f(b) must have different signs)."""
    path = _case(tmp_path, friction={"decay": 0.0}, slider={"rotational_damping": 4.1966},
                 speed={"value": 1e-12})
    result = run_cli(["stability", path, "--x", "friction.decay=0:1:7", "-o", tmp_path / "b.nc",
                      "--no-progress"])
    assert result.exit_code == 0, result.output
    assert "no Hopf point between friction.decay = 0 and 1" in result.stdout


def test_continue_on_a_rigid_disc_is_refused_as_orbit_refuses_it(tmp_path: Path) -> None:
    """modes = []: ValueError (a maximum of no modes) in the orbit search."""
    path = _case(tmp_path, disc={"modes": []})
    words = "disc.modes = [] is invalid for a periodic orbit"
    _refused(["orbit", path], words)
    _refused(["continue", path, "--key", "speed.value", "--to", "7", "--no-progress"], words)


# --- item 4: wrong answers refused -----------------------------------------------------------


def test_continue_refuses_a_period_shorter_than_any_motion() -> None:
    """--period 1e-300 gave a branch of T = 8e-302 s and exit status 0."""
    _refused(["continue", "default", "--key", "speed.value", "--to", "7", "--period", "1e-300",
              "--no-progress"], "--period = 1e-300 s is invalid: must be >=")


def test_a_boundary_not_found_says_at_which_resolution(tmp_path: Path) -> None:
    """A box of 1e8 on both dampers has no boundary on its seed grid, but a box of 12 by 2
    inside it has one: not "stable or unstable throughout"."""
    small = run_cli(["stability", "--boundary", "normal_damping=0:12", "rotational_damping=0:2",
                     "-o", tmp_path / "small.nc"])
    assert small.exit_code == 0 and "boundary curve 0" in small.stdout, small.output
    large = run_cli(["stability", "--boundary", "normal_damping=0:1e8",
                     "rotational_damping=0:1e8", "-o", tmp_path / "large.nc"])
    assert large.exit_code == 0, large.output
    assert "throughout" not in large.stdout
    assert ("no stability boundary found at this resolution: the sliding equilibrium is "
            "unstable at all 144 of the 12 x 12 points of the seed grid (spacing 9.09e+06 in "
            "slider.normal_damping, 9.09e+06 in slider.rotational_damping)") in large.stdout
    assert "trace a smaller box" in large.stdout


def test_a_scan_to_rates_beyond_round_off_is_refused(tmp_path: Path) -> None:
    """--x rotational_damping=0:1e300:5 found "Hopf points" at 4e299, "C00 at 0 Hz"."""
    _refused(["stability", "--x", "rotational_damping=0:1e300:5", "-o", tmp_path / "b.nc",
              "--no-progress"],
             "at --x slider.rotational_damping = 1e+300: slider: rotational_damping / inertia "
             "= 1e+303 1/s", "must be <= 1e+12 1/s")
    assert not (tmp_path / "b.nc").exists()


@pytest.mark.parametrize("option", ["--x", "--y"])
def test_a_scan_of_a_simulation_setting_is_refused(tmp_path: Path, option: str) -> None:
    """The simulation settings do not change the linearisation (continue refused them)."""
    axes = {"--x": "speed.value=1:5:3", "--y": "normal_damping=0:1:3"}
    axes[option] = "simulation.rtol=1e-8:1e-6:3"
    given = ["--x", axes["--x"]] + (["--y", axes["--y"]] if option == "--y" else [])
    _refused(["stability", *given, "-o", tmp_path / "m.nc", "--no-progress"],
             f"{option[2:]} = simulation.rtol is invalid: the simulation settings do not change "
             "the sliding equilibrium")


def test_more_curves_than_a_figure_tells_apart_are_refused(tmp_path: Path) -> None:
    """2000 --curves drew 2000 shades and a legend running off the figure (in 4 minutes)."""
    args = ["stability", "--x", "normal_damping=0:12:3", "--y", "rotational_damping=0:2:3",
            "--curves", "decay=0:10:2000", "--no-progress"]
    start = time.perf_counter()
    _refused([*args, "-o", tmp_path / "m.png"],
             "--curves = friction.decay with 2000 values is invalid for a figure: must have at "
             "most 10", "write the map to a .nc file")
    assert time.perf_counter() - start < 30
    assert not (tmp_path / "m.png").exists()


# --- item 5: nothing unbounded ---------------------------------------------------------------


@pytest.mark.parametrize("spec", ["speed.value=1:2:1000000000", "speed.value=1:2:100000000"])
def test_a_scan_too_large_for_memory_is_refused_before_its_values_are_made(
        tmp_path: Path, spec: str) -> None:
    """1e9 values of --x allocated 8 GB (and ignored Ctrl-C meanwhile) before the map's
    check; eigenvalue branches need 16 numbers a value and branch."""
    start = time.perf_counter()
    _refused(["stability", "--x", spec, "-o", tmp_path / "b.nc", "--no-progress"],
             "--x with N = ", "of memory", "lower N")
    _refused(["stability", "--x", spec, "--y", "normal_damping=0:1:3", "-o", tmp_path / "m.nc",
              "--no-progress"], "a stability map of ", "use fewer points per axis")
    assert time.perf_counter() - start < 20


def test_a_from_hopf_scan_too_large_for_memory_is_refused_before_its_values_are_made() -> None:
    start = time.perf_counter()
    _refused(["continue", "--key", "speed.value", "--to", "7", "--from-hopf", "1:2:1000000000",
              "--no-progress"], "--from-hopf with N = 1000000000 values needs about",
             "lower N")
    assert time.perf_counter() - start < 20


def test_a_long_map_warns_with_its_estimate_up_front(tmp_path: Path) -> None:
    """A 3000 x 3000 map ran for a day without a word. Its first line on stderr now
    estimates the time, measured on one point, before the map starts (the process is
    stopped there)."""
    process = subprocess.Popen(
        [sys.executable, "-m", "fivdisc", "stability", "--x", "normal_damping=0:12:3000",
         "--y", "rotational_damping=0:2:3000", "-o", str(tmp_path / "m.nc"), "--no-progress"],
        stderr=subprocess.PIPE, text=True)
    try:
        lines = []
        deadline = time.monotonic() + 300
        for line in process.stderr:
            lines.append(line)
            if line.startswith("warning: ") or time.monotonic() > deadline:
                break
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=60)
    warning = messages("".join(lines))[-1]
    assert warning.startswith("warning: a stability map of 3000 x 3000 (9,000,000 points) "
                              "will take about "), lines
    assert "ms a point, measured on its first); fewer points per axis take less" in warning
