"""The first run says it is compiling the kernel, and the wall time says it excludes it
(issue 13, item 2). .ci/check-package sees the notice for real, in a fresh installation."""

from __future__ import annotations

import io
import types

import pytest

from fivdisc.engine import compilation

from support.cli import run_cli


def _dispatcher(signatures=(), index=None, cache_path=None):
    """A stand-in for a numba dispatcher: compiled signatures, what its cache index
    holds (None: no index to read; an exception: one that cannot be read) and its cache
    directory."""

    def load_index():
        if isinstance(index, Exception):
            raise index
        return index or {}

    cache = types.SimpleNamespace(_cache_file=types.SimpleNamespace(_load_index=load_index),
                                  _cache_path=str(cache_path) if cache_path else None)
    return types.SimpleNamespace(signatures=list(signatures), _cache=cache)


@pytest.fixture(autouse=True)
def _fresh_process(monkeypatch):
    """Each test sees a process that has announced nothing yet."""
    monkeypatch.setattr(compilation, "_announced", set())


def test_needs_compiling_only_without_memory_or_fresh_cache():
    assert compilation.needs_compiling(_dispatcher())
    assert not compilation.needs_compiling(_dispatcher(index={"sig": "run.1.nbc"}))
    assert not compilation.needs_compiling(_dispatcher(signatures=["sig"]))
    assert compilation.needs_compiling(_dispatcher(index=EOFError("truncated")))
    assert compilation.needs_compiling(types.SimpleNamespace(signatures=[]))


def test_a_stale_cache_index_needs_compiling(tmp_path):
    """numba's own index of a real function: fresh after a compile, stale once the
    function's source stamp changes (an edited kernel file, another numba)."""
    import numba

    def twice(x):
        return 2 * x

    env = {"NUMBA_CACHE_DIR": str(tmp_path)}
    with pytest.MonkeyPatch.context() as mp:
        for key, value in env.items():
            mp.setenv(key, value)
        mp.setattr(numba.config, "CACHE_DIR", str(tmp_path))
        fresh = numba.njit(cache=True)(twice)
        assert compilation.needs_compiling(fresh)
        fresh(1.0)
        again = numba.njit(cache=True)(twice)
        assert not compilation.needs_compiling(again)
        again._cache._cache_file._source_stamp = "another"
        assert compilation.needs_compiling(again)


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("stream", [io.StringIO, _Terminal])
def test_notice_while_compiling(monkeypatch, stream):
    monkeypatch.setattr(compilation, "_TICK", 0.01)
    out = stream()
    with compilation.compile_notice(_dispatcher(), stream=out):
        import time

        time.sleep(0.1)
    text = out.getvalue()
    # Never measured on this machine: no number is made up.
    expected = "compiling the simulation kernel, once (numba keeps it for later runs)"
    assert text.startswith(expected if stream is io.StringIO else "\r" + expected)
    assert "compiled the simulation kernel in 0 s; later runs load it" in text
    if stream is _Terminal:
        assert text.count("\r") >= 3  # the spinner turned


def test_the_estimate_is_the_last_measured_time(tmp_path, monkeypatch):
    """Issue 27, item 3: the notice's number is the time the same kernel took when it
    last compiled here, kept beside numba's cache; a kernel is announced once per process."""
    clock = iter([100.0, 137.4, 200.0, 205.0])
    monkeypatch.setattr(compilation.time, "perf_counter", lambda: next(clock))
    first = io.StringIO()
    with compilation.compile_notice(_dispatcher(cache_path=tmp_path), stream=first):
        pass
    assert "compiled the simulation kernel in 37 s" in first.getvalue()
    again = io.StringIO()
    with compilation.compile_notice(_dispatcher(cache_path=tmp_path), stream=again):
        pass
    assert again.getvalue() == ""  # announced once in this process
    monkeypatch.setattr(compilation, "_announced", set())  # a later process
    later = io.StringIO()
    with compilation.compile_notice(_dispatcher(cache_path=tmp_path), stream=later):
        pass
    assert later.getvalue().startswith("compiling the simulation kernel, once (it took 37 s "
                                       "when last compiled on this machine)")
    assert "compiled the simulation kernel in 5 s" in later.getvalue()
    assert compilation.measured_seconds(_dispatcher(cache_path=tmp_path),
                                        "simulation kernel") == 5.0


def test_library_calls_are_quiet_unless_the_command_line_asks(monkeypatch):
    monkeypatch.setattr(compilation, "_default_show", False)
    out = io.StringIO()
    with compilation.compile_notice(_dispatcher(), show=None, stream=out):
        pass
    assert out.getvalue() == ""
    compilation.announce_by_default()
    with compilation.compile_notice(_dispatcher(), show=None, stream=out):
        pass
    assert out.getvalue().startswith("compiling the simulation kernel, once")


def test_stability_command_announces_compilation(monkeypatch):
    """Issue 27, item 3: ``fivdisc stability`` compiles the right-hand side and its
    Jacobian in a fresh installation, and says so."""
    monkeypatch.setattr(compilation, "_default_show", False)
    monkeypatch.setattr(compilation, "needs_compiling", lambda dispatcher: True)
    run = run_cli(["stability"])
    assert run.exit_code == 0, run.output
    assert run.stderr.startswith("compiling the right-hand side and its Jacobian, once")
    assert run.stderr.count("compiling") == 1
    assert run.stdout.startswith("sliding equilibrium at Omega")


def test_no_notice_when_cached_or_quiet():
    for dispatcher, show in ((_dispatcher(index={"sig": "run.1.nbc"}), True),
                             (_dispatcher(), False)):
        out = io.StringIO()
        with compilation.compile_notice(dispatcher, show=show, stream=out):
            pass
        assert out.getvalue() == ""


def test_interrupted_compilation_ends_the_line():
    out = _Terminal()
    with pytest.raises(KeyboardInterrupt), compilation.compile_notice(_dispatcher(),
                                                                      stream=out):
        raise KeyboardInterrupt
    assert out.getvalue().endswith("\n") and "compiled" not in out.getvalue()


@pytest.mark.parametrize("quiet", [[], ["--no-progress"]])
def test_simulate_command_announces_compilation(tmp_path, monkeypatch, quiet):
    """A fresh installation (no kernel in memory or cache): the notice comes first, on
    stderr, with or without the progress bar; the summary's wall time says it leaves the
    compilation out."""
    monkeypatch.setattr(compilation, "needs_compiling", lambda dispatcher: True)
    # The kernel is in the cache: no helper process to share a compilation with.
    monkeypatch.setattr("fivdisc.engine.split_compile._cores", lambda: 1)
    case = tmp_path / "c.toml"
    case.write_text("[simulation]\nduration = 0.01\n")
    run = run_cli(["simulate", str(case), "-o", str(tmp_path / "c.nc"),
                                   *quiet])
    assert run.exit_code == 0, run.output
    assert run.stderr.startswith("compiling the simulation kernel, once")
    assert "wall time:" in run.stdout and "(integration only, without compiling the kernel)" \
        in run.stdout


def test_orbit_command_without_progress_announces_the_tangent_kernel(tmp_path, monkeypatch):
    """--no-progress hides the Newton iterations, not the minutes of a first compilation
    (the trial of stop 33 met a silent 4 min 42 s in ``fivdisc continue``)."""
    from support.cases import RIGID

    monkeypatch.setattr(compilation, "needs_compiling", lambda dispatcher: True)
    monkeypatch.setattr("fivdisc.engine.split_compile._cores", lambda: 1)
    case = tmp_path / "rigid.toml"
    case.write_text(RIGID.replace({"simulation.duration": 4.0}).to_toml())
    run = run_cli(["orbit", str(case), "--no-progress", "--json"])
    assert run.exit_code == 0, run.output
    assert "compiling the kernel with tangent vectors, once" in run.stderr
    assert run.stdout.lstrip().startswith("{")
