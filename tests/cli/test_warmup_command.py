"""``fivdisc warmup`` stays for the scripts that call it and says there is nothing to
compile: the core is compiled C++, built when fivdisc is installed (issue 37)."""

from __future__ import annotations

from support.cli import run_cli


def test_warmup_says_there_is_nothing_to_compile():
    result = run_cli(["warmup"])
    assert result.exit_code == 0, result.output
    assert result.output.startswith("nothing to compile")
    assert result.output.count("\n") == 1
