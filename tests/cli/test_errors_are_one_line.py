"""No tracebacks: bad input of any kind ends in one line naming what to change, or a click
usage error (issue 14, item 6).

The explicit cases are those the issue lists that other test files do not already run
(``test_outputs.py``, ``test_limits.py``, ``test_sweep_store.py``, ``test_sweep_dask.py``).
The property-based tests generate case files and command lines with valid and invalid
values for every key and option, run them in-process through click's runner, and check
the outcome: exit status 0, or 2 with one line on stderr (``error: ...``) or click's usage
message; status 1 only where documented (a failed simulation, a damaged store), with a
one-line ``error:`` too; never a Python exception. CI runs a bounded, derandomised number
of examples; ``pytest -m slow`` runs many more, at random.
"""

from __future__ import annotations

import contextlib
import math
import tempfile
from pathlib import Path
from typing import Any

import hypothesis.strategies as st
import pytest
import tomli_w
from click.testing import Result
from hypothesis import HealthCheck, event, given, settings

from fivdisc import Case, simulate
from fivdisc.cli.plot import KINDS
from fivdisc.sweep import (
    SweepStore,
    load_sweep,
)
from fivdisc.sweep.store.lock import store_lock
from fivdisc.sweep.store.sweep_store import PointOutcome

from support.cli import messages, run_cli

# --- the property ----------------------------------------------------------------------------


def check_outcome(result: Result, args: list[str]) -> None:
    """Exit 0; or 2 with one `error:` line or click's usage error; or a documented 1."""
    shown = f"fivdisc {' '.join(args)}\n{result.output}"
    assert result.exception is None or isinstance(result.exception, SystemExit), (
        f"{shown}\n{type(result.exception).__name__}: {result.exception}"
    )
    assert "Traceback" not in result.output, shown
    err = "\n".join(messages(result.stderr))
    if result.exit_code == 0:
        return
    if result.exit_code == 2 and err.splitlines()[-1].startswith("Error: "):
        return  # click's usage error: usage, a hint, and one line saying what is wrong
    lines = err.splitlines()
    assert result.exit_code in (1, 2), shown
    assert len(lines) == 1 and lines[0].startswith("error: "), shown
    if result.exit_code == 1:
        assert lines[0].startswith(("error: simulation failed: ", "error: ")), shown
        # documented: a failed simulation, a damaged store, an inconclusive exponent, a
        # period shorter than any motion of the model
        assert args[0] in ("simulate", "lyapunov", "orbit") or "--verify" in args, shown


def run(args: list[str]) -> Result:
    result = run_cli(args)
    check_outcome(result, args)
    return result


# --- the cases the issue lists ---------------------------------------------------------------


@pytest.fixture
def binary_file(tmp_path: Path) -> Path:
    path = tmp_path / "binary.toml"
    path.write_bytes(bytes(range(256)) * 4)
    return path


@pytest.mark.parametrize("command", [["modes"], ["simulate"], ["stability"]])
def test_binary_case_file(binary_file: Path, command: list[str]) -> None:
    result = run([*command, str(binary_file)])
    assert result.exit_code == 2
    assert f"{binary_file} is not a text file: byte 0x80 at offset 128 is not UTF-8" in \
        result.stderr


def test_binary_sweep_and_base_files(binary_file: Path, tmp_path: Path) -> None:
    assert "is not a text file" in run(["sweep", str(binary_file)]).stderr
    sweep = tmp_path / "s.toml"
    sweep.write_text(f'base = "{binary_file.name}"\n[axes]\n"slider.mass" = [0.1]\n'
                     '[reduce]\nkeep = ["separated"]\n')
    assert "binary.toml is not a text file" in run(["sweep", str(sweep)]).stderr
    assert "is not a text file" in run(["separation-map", "--base", str(binary_file)]).stderr


def test_a_directory_as_case_file(tmp_path: Path) -> None:
    result = run(["modes", str(tmp_path)])
    assert result.exit_code == 2


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--x", "decay=0:1:3", "--y", "friction.decay=0:2:3"],
         ["--y friction.decay is invalid: --x varies the same key"]),
        (["--x", "decay=0:1:3", "--y", "normal_damping=0:2:3", "--curves", "decay=1,2"],
         ["--curves friction.decay is invalid: --x varies the same key"]),
        (["--curves", "decay=0,1"], ["--curves is used only by a stability map"]),
        (["-o", "map.nc"], ["-o is used only by a scan"]),
        (["--x", "decay=0:1:3", "--curves", "decay=1,2"], ["--curves is used only by a map"]),
        (["--y", "decay=0:1:3"], ["--y needs --x too"]),
    ],
)
def test_meaningless_stability_options(tmp_path: Path, monkeypatch, args, words) -> None:
    monkeypatch.chdir(tmp_path)
    result = run(["stability", *args, "--no-progress"])
    assert result.exit_code == 2
    for word in words:
        assert word in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_model_validate_is_one_line() -> None:
    from fivdisc.errors import CaseError

    with pytest.raises(CaseError) as info:
        Case.model_validate({"disc": {"modes": [[0, "x"]], "thickness": -1}, "nope": 1})
    assert "\n" not in str(info.value)


# --- generated case files --------------------------------------------------------------------


def _num(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


# Values no numeric key accepts, and values of the wrong type for any key.
NOT_FINITE = st.sampled_from([math.nan, math.inf, -math.inf])
WRONG_TYPE = st.one_of(
    st.text(max_size=4),
    st.booleans(),
    st.lists(st.integers(-2, 2), max_size=2),
    st.dictionaries(st.sampled_from(["a", "value"]), st.integers(0, 2), max_size=1),
)


def _bad(*numbers: float) -> st.SearchStrategy[Any]:
    """Invalid values of a numeric key: out of its range, not finite, or another type."""
    return st.one_of(st.sampled_from(numbers), NOT_FINITE, WRONG_TYPE) if numbers else \
        st.one_of(NOT_FINITE, WRONG_TYPE)


MODES_VALID = st.lists(st.tuples(st.integers(0, 2), st.integers(0, 4)), max_size=4,
                       unique=True).map(lambda ms: [list(m) for m in ms])
MODES_BAD = st.one_of(
    st.sampled_from([[[0, 100000]], [[0, 500]], [[16, 0]], [[-1, 0]], [[0]], [[0, 1, 2]],
                     [[0, 1], [0, 1]], [["a", 1]], [[0.5, 1]], [[0, l] for l in range(33)]]),
    WRONG_TYPE,
)
PROBES_VALID = st.lists(st.tuples(_num(0.06, 0.1), _num(-7.0, 7.0)), max_size=3).map(
    lambda ps: [list(p) for p in ps])
PROBES_BAD = st.one_of(st.sampled_from([[[0.5, 0.0]], [[0.1]], [[0.01, 1.0]], [0.1, 0.0]]),
                       WRONG_TYPE)

# Per key: (valid values, invalid values). Valid ranges keep the disc, the slider and the
# run near Table 1 so that a valid case runs in well under a second; the invalid ones cover
# each key's rule (range, type, finiteness) and its neighbours' (e.g. a hub larger than
# the disc, static friction below kinetic).
KEYS: dict[str, tuple[st.SearchStrategy[Any], st.SearchStrategy[Any]]] = {
    "disc.inner_radius": (_num(0.03, 0.05), _bad(0.0, -0.04, 0.2, 1e-9)),
    "disc.outer_radius": (_num(0.11, 0.13), _bad(0.0, -1.0, 0.04)),
    "disc.thickness": (_num(0.0015, 0.003), _bad(0.0, -0.002)),
    "disc.density": (_num(5000.0, 9000.0), _bad(0.0, -7200.0)),
    "disc.youngs_modulus": (_num(1e11, 2e11), _bad(0.0, -1.0)),
    "disc.poisson_ratio": (_num(0.0, 0.45), _bad(0.5, -1.0, 2.0)),
    "disc.modes": (MODES_VALID, MODES_BAD),
    "slider.track_radius": (_num(0.06, 0.1), _bad(0.0, 0.2, 0.01)),
    "slider.mass": (_num(0.05, 0.2), _bad(0.0, -0.1)),
    "slider.normal_stiffness": (_num(1e4, 5e4), _bad(0.0, -1.0)),
    "slider.normal_damping": (_num(0.0, 12.0), _bad(-0.1)),
    "slider.rotational_stiffness": (_num(1e3, 3e3), _bad(0.0, -1.0)),
    "slider.rotational_damping": (_num(0.0, 2.0), _bad(-0.1)),
    "slider.preload": (_num(0.0, 1e6), _bad(-1.0)),
    "friction.static": (_num(0.8, 1.0), _bad(-0.1, 0.1)),
    "friction.kinetic_max": (_num(0.3, 0.7), _bad(-0.6, 2.0)),
    "friction.kinetic_min": (_num(0.2, 0.5), _bad(-0.35, 2.0)),
    "friction.decay": (_num(0.0, 10.0), _bad(-1.0)),
    "simulation.duration": (_num(1e-4, 0.02), _bad(0.0, -1.0, 1e9)),
    "simulation.output_rate": (_num(100.0, 1e4), _bad(0.0, -1.0, 1e12)),
    "simulation.impact": (st.booleans(), st.one_of(st.text(max_size=4), st.integers(0, 1))),
    "simulation.initial_state": (st.sampled_from(["rest", "equilibrium"]),
                                 st.one_of(st.text(max_size=5), st.integers(0, 1))),
    "simulation.probes": (PROBES_VALID, PROBES_BAD),
    "simulation.omega_dot_terms": (st.booleans(), st.sampled_from([0, "yes"])),
    "simulation.printed_gyroscopic_sign": (st.booleans(), st.sampled_from([1, "no"])),
    "simulation.rtol": (_num(1e-8, 1e-3), _bad(0.0, 0.5, -1e-6)),
    "simulation.atol": (_num(1e-12, 1e-6), _bad(0.0, -1e-9)),
    "simulation.max_step": (st.one_of(st.just(0.0), _num(1e-4, 1e-2)), _bad(-1e-3)),
    "simulation.max_switches": (st.integers(1, 10_000_000), _bad(0, -5, 1.5)),
    "simulation.perturbation.phi": (_num(-0.01, 0.01), _bad()),
    "simulation.perturbation.phi_dot": (_num(-1.0, 1.0), _bad()),
}
SPEEDS: dict[str, dict[str, tuple[st.SearchStrategy[Any], st.SearchStrategy[Any]]]] = {
    "constant": {"value": (_num(0.0, 30.0), _bad(-1.0))},
    "decelerating": {"initial": (_num(0.0, 30.0), _bad(-1.0)),
                     "duration": (_num(0.5, 50.0), _bad(0.0, -35.0))},
    "accelerating": {"initial": (_num(0.0, 20.0), _bad(-1.0)),
                     "rate": (_num(0.0, 5.0), _bad(-0.2))},
    "table": {
        "times": (st.lists(_num(0.001, 0.01), min_size=1, max_size=3).map(
            lambda steps: [0.0, *(sum(steps[: i + 1]) for i in range(len(steps)))]),
            st.sampled_from([[0.5, 1.5], [0.0, 1.0, 1.0], [0.0], [], [1.0, 0.0]])),
        "values": (st.lists(_num(0.0, 20.0), min_size=2, max_size=4),
                   st.sampled_from([[1.0, -2.0], [1.0], [], ["a", 1.0]])),
    },
}


def _set(tables: dict[str, Any], key: str, value: Any) -> None:
    *path, name = key.split(".")
    for part in path:
        tables = tables.setdefault(part, {})
    tables[name] = value


@st.composite
def case_texts(draw: st.DrawFn) -> bytes:
    """The bytes of a case file: mostly TOML with any keys set to valid or invalid values,
    sometimes unknown keys, broken TOML or binary data."""
    kind = draw(st.sampled_from(["toml"] * 8 + ["binary", "text"]))
    if kind == "binary":
        return draw(st.binary(max_size=64))
    if kind == "text":
        return draw(st.text(max_size=40)).encode("utf-8", "surrogatepass")
    tables: dict[str, Any] = {}
    # Short runs: a valid case always gets a short duration unless one is drawn.
    _set(tables, "simulation.duration", 0.005)
    _set(tables, "simulation.output_rate", 1000.0)
    bad_share = draw(st.sampled_from([0.0, 0.1, 0.3]))
    for key, (valid, invalid) in KEYS.items():
        if draw(st.booleans()):
            bad = draw(st.floats(0, 1)) < bad_share
            _set(tables, key, draw(invalid if bad else valid))
    profile = draw(st.sampled_from([*SPEEDS, "constant", "sideways", None]))
    if profile is not None:
        speed: dict[str, Any] = {"profile": profile}
        for name, (valid, invalid) in SPEEDS.get(profile, {}).items():
            if draw(st.booleans()):
                speed[name] = draw(invalid if draw(st.floats(0, 1)) < bad_share else valid)
        if draw(st.integers(0, 9)) == 0:  # a key of another profile
            speed[draw(st.sampled_from(["value", "initial", "rate", "times"]))] = 1.0
        tables["speed"] = speed
    if draw(st.integers(0, 9)) == 0:
        _set(tables, draw(st.sampled_from(["slider.mas", "disk.modes", "simulation.rtoll",
                                           "friction"])), 1.0)
    text = tomli_w.dumps(tables)
    if draw(st.integers(0, 19)) == 0:
        text = text[: draw(st.integers(0, len(text)))]  # cut short
    return text.encode()


def _case_file_property(content: bytes) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "case.toml"
        path.write_bytes(content)
        for args in (["modes", str(path), "--json"], ["stability", str(path)],
                     ["simulate", str(path), "-o", str(Path(tmp) / "out.nc"), "--no-progress"]):
            event(f"{args[0]}: exit status {run(args).exit_code}")


def _profile(examples: int, derandomize: bool) -> settings:
    return settings(max_examples=examples, deadline=None, derandomize=derandomize,
                    database=None, suppress_health_check=[HealthCheck.too_slow])


test_generated_case_files = _profile(60, True)(given(case_texts())(_case_file_property))
test_generated_case_files_long = pytest.mark.slow(
    _profile(1000, False)(given(case_texts())(_case_file_property)))


# --- generated command lines -----------------------------------------------------------------


SWEEP = """
[base.simulation]
duration = 0.005
output_rate = 1000.0
[axes]
"slider.normal_damping" = [0.1, 0.2]
[reduce]
keep = ["separated", "max_normal_force"]
"""


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """Inputs the command lines pick from: valid ones, and ones of the wrong kind."""
    root = tmp_path_factory.mktemp("inputs")
    case = Case(simulation={"duration": 0.01, "output_rate": 1000.0})
    case.save(root / "case.toml")
    simulate(case).to_netcdf(root / "result.nc")
    (root / "sweep.toml").write_text(SWEEP)
    spec = load_sweep(root / "sweep.toml")
    with store_lock(root / "sweep.zarr"):  # complete, so that valid sweeps run nothing
        SweepStore.open(root / "sweep.zarr", spec).write(
            [PointOutcome(i, {"separated": False, "max_normal_force": 500.0})
             for i in range(spec.n_points)])
    (root / "binary.toml").write_bytes(bytes(range(256)))
    (root / "bad.toml").write_text("[slider]\nmass = -1\n")
    (root / "empty.toml").write_text("")
    (root / "dir.zarr").mkdir()
    return {p.name: p for p in root.iterdir()} | {"missing.toml": root / "missing.toml"}


def _paths(*names: str) -> st.SearchStrategy[str]:
    return st.sampled_from(names)


OUT_FIGURES = ["{out}/f.png", "{out}/f.svg", "{out}/f", "{out}/f.xyz", "{out}/no/f.png",
               "result.nc", "case.toml", "dir.zarr"]
OUT_STORES = ["sweep.zarr", "{out}/new.toml", "{out}/no/s.zarr", "dir.zarr", "case.toml"]
FLOATS = st.one_of(st.sampled_from(["0", "-1", "nan", "inf", "1e300", "x", ""]),
                   _num(-10.0, 2000.0).map(repr))
INTS = st.one_of(st.sampled_from(["0", "-1", "1", "2", "x", "1e3", "100000"]),
                 st.integers(-3, 300).map(str))
RANGES = st.sampled_from([
    "normal_damping=0:1:2", "slider.preload=100:200:2", "decay=0,1", "speed.value=1:2:2",
    "rotational_damping=0.1,0.2", "x", "decay=", "decay=1:2", "nokey=0:1:2", "decay=0:1:-1",
    "decay=nan:1:2", "decay=0:1:100000000000", "disc.modes=0:1:2", "speed.duration=1:2:2",
    "mass=a,b", "=1:2:3", "decay=0:1:1",
])
SEPARATION_RANGES = st.sampled_from(["2:4:2", "3:3:1", "1:2", "a:b:c", "2:1:0", "-1:2:2",
                                     "0:1:10000000000"])


def _option(name: str, values: st.SearchStrategy[str]) -> st.SearchStrategy[list[str]]:
    return st.one_of(st.just([]), values.map(lambda v: [name, v]))


def _command(name: str, *parts: st.SearchStrategy[list[str]]) -> st.SearchStrategy[list[str]]:
    return st.tuples(*parts).map(lambda chunks: [name, *(a for c in chunks for a in c)])


# Options that always fail validation, added to commands whose valid form would start
# long work (a sweep of simulations, the paper's figures).
SEPARATION_INVALID = st.sampled_from([
    ["--x", "1:2"], ["--y", "a:b:c"], ["--profile", "sideways"], ["--workers", "0"],
    ["--figure", "{out}/f.xyz"], ["-o", "{out}/s.nc"], ["--base", "bad.toml"],
    ["--profile", "decelerating", "--duration", "5"], ["--scheduler", "not-an-address"],
    ["-o", "{out}/no/s.zarr"], ["--pool", "fork"],
])
REPRODUCE_INVALID = st.sampled_from([
    ["--figures", "2"], ["--figures", "3-"], ["--figures", "x"], ["--all", "--figures", "3"],
    ["--workers", "0"], ["-o", "{out}/no/dir"],
])

COMMANDS = st.one_of(
    _command("modes", _paths("case.toml", "binary.toml", "bad.toml", "missing.toml",
                             "result.nc").map(lambda p: [p]), _option("--json", st.just("")).map(
        lambda o: o[:1])),
    _command("simulate", _paths("case.toml", "binary.toml", "bad.toml", "missing.toml",
                                "empty.toml", "dir.zarr").map(lambda p: [p]),
             _option("-o", st.sampled_from(["{out}/r.nc", "{out}/r", "case.toml", "{out}/no/r.nc",
                                            "dir.zarr"])),
             st.just(["--no-progress"])),
    _command("plot", _paths("result.nc", "case.toml", "missing.toml", "binary.toml").map(
        lambda p: [p]),
             _option("--kind", st.sampled_from([*KINDS, "bar"])),
             _option("--var", st.sampled_from(["phi", "w", "phase", "q", "", "nope", "time"])),
             _option("--probe", INTS),
             _option("--window", st.sampled_from(["0:0.005", ":", "0.002:", ":0.004", "a:b",
                                                  "1:2", "0.005:0.001", "", "0:0:0"])),
             _option("--fmax", FLOATS), _option("--segment", FLOATS),
             _option("-o", st.sampled_from(OUT_FIGURES)), _option("--dpi", INTS)),
    _command("stability", st.one_of(st.just([]), _paths("case.toml", "bad.toml",
                                                         "binary.toml").map(lambda p: [p])),
             _option("--x", RANGES), _option("--y", RANGES), _option("--curves", RANGES),
             _option("-o", st.sampled_from(["{out}/m.nc", "{out}/m.png", "{out}/m.pdf",
                                            "{out}/no/m.nc", "case.toml"])),
             st.just(["--no-progress"])),
    _command("sweep", st.one_of(st.just([]), _paths("sweep.toml", "case.toml", "binary.toml",
                                                    "missing.toml").map(lambda p: [p])),
             _option("-o", st.sampled_from(OUT_STORES)),
             _option("--verify", st.sampled_from(["sweep.zarr", "dir.zarr", "case.toml",
                                                  "{out}/none.zarr"])),
             _option("--workers", INTS),
             _option("--pool", st.sampled_from(["thread", "fork", ""])),
             _option("--scheduler", st.sampled_from(["", "not-an-address", "foo://x:1"])),
             st.just(["--no-progress"])),
    # the invalid option last, so that no valid one given after it overrides it
    _command("separation-map",
             _option("--profile", st.sampled_from(["decelerating", "accelerating"])),
             _option("--x", SEPARATION_RANGES), _option("--y", SEPARATION_RANGES),
             _option("--base", _paths("case.toml", "bad.toml", "missing.toml")),
             _option("--duration", FLOATS),
             _option("--figure", st.sampled_from(OUT_FIGURES)),
             st.just(["--no-progress"]), SEPARATION_INVALID),
    _command("reproduce",
             _option("--figures", st.sampled_from(["3", "8-12", "29", "3,,4", "4-3"])),
             _option("-o", st.sampled_from(["{out}/figs", "case.toml"])),
             st.just(["--no-progress"]), REPRODUCE_INVALID),
    # anything at all after a command name (not separation-map, which would run the
    # default 40 x 40 map)
    st.tuples(st.sampled_from(["modes", "simulate", "plot", "stability", "sweep", "reproduce",
                               "nope"]),
              st.lists(st.sampled_from(["--bogus", "-x", "a", "--json", "--", "-o"]),
                       max_size=3)).map(lambda t: [t[0], *t[1]]),
)


def _command_line_property(files: dict[str, Path], args: list[str]) -> None:
    # In a directory of its own: outputs by default go to the working directory.
    with tempfile.TemporaryDirectory() as out, contextlib.chdir(out):
        resolved = [str(files[a]) if a in files else a.format(out=out) for a in args]
        event(f"{args[0]}: exit status {run(resolved).exit_code}")


test_generated_command_lines = _profile(150, True)(given(args=COMMANDS)(_command_line_property))
test_generated_command_lines_long = pytest.mark.slow(
    _profile(2000, False)(given(args=COMMANDS)(_command_line_property)))


# --- extreme values for every numeric key and option (issue 28, item 7) ----------------------

# Tiny (subnormal, the smallest normal, just above), huge, zero, negative zero, infinite and
# integers beyond any double's exact range or a TOML integer's.
EXTREME = st.sampled_from([5e-324, 2.2250738585072014e-308, 1e-300, 1e-30, 1e30, 1e300,
                           1.7976931348623157e308, 0.0, -0.0, math.inf, -math.inf, -1e308,
                           9223372036854775807, -9223372036854775807, 10**30])
# Every numeric key of a case; a speed key also sets its profile.
NUMERIC_KEYS = [key for key in KEYS if key not in (
    "disc.modes", "simulation.impact", "simulation.initial_state", "simulation.probes",
    "simulation.omega_dot_terms", "simulation.printed_gyroscopic_sign")] + [
    "slider.angle", "disc.damping_ratio", "simulation.min_flight_time", "simulation.max_steps",
    "speed.value", "speed.initial", "speed.rate", "speed.duration"]
_PROFILE_OF = {"value": "constant", "rate": "accelerating", "duration": "decelerating",
               "initial": "decelerating"}
# The extreme values an option of a command line may take.
EXTREME_TEXT = EXTREME.map(lambda v: repr(v) if isinstance(v, float) else str(v))


@st.composite
def extreme_cases(draw: st.DrawFn) -> dict[str, Any]:
    """A short case with one to three numeric keys at extreme values."""
    tables: dict[str, Any] = {}
    _set(tables, "simulation.duration", 0.005)
    _set(tables, "simulation.output_rate", 1000.0)
    for key in draw(st.lists(st.sampled_from(NUMERIC_KEYS), min_size=1, max_size=3,
                             unique=True)):
        if key.startswith("speed."):
            tables["speed"] = {"profile": _PROFILE_OF[key.split(".")[1]]}
        _set(tables, key, draw(EXTREME))
    if draw(st.booleans()):
        _set(tables, "simulation.initial_state", "equilibrium")
    return tables


# Per example: generous against a loaded machine, far below an unbounded run.
_EXTREME_BOUND = 60.0


def _extreme_case_property(tables: dict[str, Any]) -> None:
    import time

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "case.toml"
        path.write_text(tomli_w.dumps(tables))
        start = time.perf_counter()
        result = run(["simulate", str(path), "-o", str(Path(tmp) / "out.nc"), "--no-progress"])
        assert time.perf_counter() - start < _EXTREME_BOUND, tables
        event(f"simulate: exit status {result.exit_code}")


EXTREME_COMMANDS = st.one_of(
    st.tuples(st.sampled_from(["--period", "--window", "--rtol"]), EXTREME_TEXT).map(
        lambda o: ["orbit", "short.toml", *o]),
    st.tuples(st.sampled_from(["--transient", "--duration", "--interval", "--n"]),
              EXTREME_TEXT).map(lambda o: ["lyapunov", "short.toml", *o, "--no-progress"]),
    st.tuples(st.sampled_from(["--fmax", "--segment", "--probe", "--dpi"]),
              EXTREME_TEXT).map(lambda o: ["plot", "result.nc", *o, "-o", "{out}/f.png"]),
)


def _extreme_option_property(files: dict[str, Path], args: list[str]) -> None:
    import time

    with tempfile.TemporaryDirectory() as out, contextlib.chdir(out):
        short = Path(out) / "short.toml"
        Case(simulation={"duration": 0.005, "output_rate": 1000.0}).save(short)
        resolved = [str(short) if a == "short.toml" else
                    str(files[a]) if a in files else a.format(out=out) for a in args]
        start = time.perf_counter()
        result = run(resolved)
        assert time.perf_counter() - start < _EXTREME_BOUND, args
        event(f"{args[0]}: exit status {result.exit_code}")


# About a minute of CI together (most values are refused before any work).
test_extreme_case_values = _profile(40, True)(given(extreme_cases())(_extreme_case_property))
test_extreme_option_values = _profile(30, True)(
    given(args=EXTREME_COMMANDS)(_extreme_option_property))
test_extreme_case_values_long = pytest.mark.slow(
    _profile(500, False)(given(extreme_cases())(_extreme_case_property)))


# --- issue 40, item 7: no numpy warning before a one-line error ------------------------------


@pytest.mark.parametrize("command", [["simulate"], ["stability", "--json"]])
def test_no_numpy_warning_before_a_one_line_error(tmp_path: Path, command: list[str]) -> None:
    """disc.damping_ratio = 1e300 overflowed in the model's arrays: numpy's "overflow
    encountered in multiply" (with its file and line) came before the one-line refusal of
    the infinite rate."""
    import warnings

    path = tmp_path / "c.toml"
    Case(disc={"damping_ratio": 1e300}).save(path)
    with warnings.catch_warnings():
        warnings.simplefilter("always")  # not once per place: every warning shows
        result = run([command[0], str(path), *command[1:]])
    assert result.exit_code == 2
    lines = messages(result.stderr)
    assert len(lines) == 1 and "disc.damping_ratio" in lines[0], result.stderr


def test_numerical_warnings_are_dropped_when_a_command_fails(monkeypatch) -> None:
    """Whatever numpy warns on the way to a refusal is not shown before the refusal's one
    line (the command line holds numerical warnings until it knows how it ends)."""
    import warnings

    import numpy as np

    from fivdisc.analysis import stability
    from fivdisc.errors import AnalysisError

    def overflowing(case):
        np.float64(1e308) * 10.0
        raise AnalysisError("refused")

    monkeypatch.setattr(stability, "linear_stability", overflowing)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        result = run_cli(["stability"])
    assert result.exit_code == 2 and messages(result.stderr) == ["error: refused"]


def test_an_error_of_a_fresh_process_is_one_line_to_its_exit(tmp_path: Path) -> None:
    """After the compiled core: an error whose traceback held the core's model in a
    reference cycle ended with nanobind's report of it as leaked at the exit (some twenty
    lines after the one-line error; the command line freezes the collector at exit)."""
    import subprocess
    import sys

    path = tmp_path / "c.toml"
    Case(slider={"preload": 1e12}).save(path)  # no sliding equilibrium is found
    done = subprocess.run([sys.executable, "-m", "fivdisc", "stability", str(path), "--json"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    lines = messages(done.stderr)
    assert len(lines) == 1 and lines[0].startswith("error: no sliding equilibrium"), done.stderr


def test_a_command_on_three_pads_ends_quietly(tmp_path: Path) -> None:
    """A successful command of a fresh process writes nothing after its output: the
    command line freezes the collector at exit, so the runs and models of three pads left
    in reference cycles are alive at the core's teardown, which nanobind reported as
    leaks (some twenty lines on stderr after each such command)."""
    import subprocess
    import sys

    from support.cases import THREE_PADS

    path = tmp_path / "three.toml"
    THREE_PADS.replace({"simulation.duration": 0.05}).save(path)
    for command in (["simulate", str(path), "-o", str(tmp_path / "r.nc")],
                    ["stability", str(path)]):
        done = subprocess.run([sys.executable, "-m", "fivdisc", *command],
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        assert "nanobind" not in done.stderr and "leaked" not in done.stderr, done.stderr
