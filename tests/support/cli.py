"""The command line as the tests run it."""

from __future__ import annotations

from typing import Any

from click.testing import Result


def run_cli(args: list[str], **kwargs: Any) -> Result:
    """Run ``fivdisc ARGS`` in this process (click's runner: stdout and stderr apart);
    ``kwargs`` as :meth:`click.testing.CliRunner.invoke` takes them."""
    return run_cli([str(a) for a in args], **kwargs)


def messages(stderr: str) -> list[str]:
    """The lines of `stderr` but the notices of a kernel's first compilation, which every
    command prints when it compiles one (with or without --progress)."""
    return [line for line in stderr.strip().splitlines()
            if not line.startswith(("compiling the ", "compiled the "))]
