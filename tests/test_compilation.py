"""The first run says it is compiling the kernel, and the wall time says it excludes it
(issue 13, item 2). .ci/check-package sees the notice for real, in a fresh installation."""

from __future__ import annotations

import io
import types

import pytest
from click.testing import CliRunner

from fivdisc import compilation
from fivdisc.cli import cli


def _dispatcher(tmp_path, signatures=(), cached=False):
    """A stand-in for a numba dispatcher: compiled signatures and a cache index file."""
    index = tmp_path / "run.nbi"
    if cached:
        index.write_bytes(b"")
    cache = types.SimpleNamespace(_cache_file=types.SimpleNamespace(_index_path=str(index)))
    return types.SimpleNamespace(signatures=list(signatures), _cache=cache)


def test_needs_compiling_only_without_memory_or_cache(tmp_path):
    assert compilation.needs_compiling(_dispatcher(tmp_path))
    assert not compilation.needs_compiling(_dispatcher(tmp_path, cached=True))
    assert not compilation.needs_compiling(_dispatcher(tmp_path, signatures=["sig"]))


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("stream", [io.StringIO, _Terminal])
def test_notice_while_compiling(tmp_path, monkeypatch, stream):
    monkeypatch.setattr(compilation, "_TICK", 0.01)
    out = stream()
    with compilation.compile_notice(_dispatcher(tmp_path), stream=out):
        import time

        time.sleep(0.1)
    text = out.getvalue()
    expected = f"compiling the simulation kernel, once: about {compilation.COMPILE_SECONDS} s"
    assert text.startswith(expected if stream is io.StringIO else "\r" + expected)
    assert "compiled the simulation kernel in 0 s; later runs load it" in text
    if stream is _Terminal:
        assert text.count("\r") >= 3  # the spinner turned


def test_no_notice_when_cached_or_quiet(tmp_path):
    for dispatcher, show in ((_dispatcher(tmp_path, cached=True), True),
                             (_dispatcher(tmp_path), False)):
        out = io.StringIO()
        with compilation.compile_notice(dispatcher, show=show, stream=out):
            pass
        assert out.getvalue() == ""


def test_interrupted_compilation_ends_the_line(tmp_path):
    out = _Terminal()
    with pytest.raises(KeyboardInterrupt), compilation.compile_notice(_dispatcher(tmp_path),
                                                                      stream=out):
        raise KeyboardInterrupt
    assert out.getvalue().endswith("\n") and "compiled" not in out.getvalue()


def test_simulate_command_announces_compilation(tmp_path, monkeypatch):
    """A fresh installation (no kernel in memory or cache): the notice comes first, on
    stderr; the summary's wall time says it leaves the compilation out."""
    monkeypatch.setattr(compilation, "needs_compiling", lambda dispatcher: True)
    case = tmp_path / "c.toml"
    case.write_text("[simulation]\nduration = 0.01\n")
    run = CliRunner().invoke(cli, ["simulate", str(case), "-o", str(tmp_path / "c.nc")])
    assert run.exit_code == 0, run.output
    assert run.stderr.startswith("compiling the simulation kernel, once: about")
    assert "wall time:" in run.stdout and "(integration only, without compiling the kernel)" \
        in run.stdout
