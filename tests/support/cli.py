"""The command line as the tests run it."""

from __future__ import annotations

from typing import Any

from click.testing import CliRunner, Result

from fivdisc.cli import cli


def run_cli(args: list[str], **kwargs: Any) -> Result:
    """Run ``fivdisc ARGS`` in this process (click's runner: stdout and stderr apart);
    ``kwargs`` as :meth:`click.testing.CliRunner.invoke` takes them."""
    return CliRunner().invoke(cli, [str(a) for a in args], **kwargs)


def messages(stderr: str) -> list[str]:
    """The lines of `stderr`."""
    return stderr.strip().splitlines()
