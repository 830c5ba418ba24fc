"""``fivdisc warmup``: kept for the scripts that call it; there is nothing to compile."""

from __future__ import annotations

import click


@click.command("warmup")
def warmup() -> None:
    """Say that there is nothing to compile.

    fivdisc's integrator is compiled C++, built when fivdisc is installed: every command
    runs at full speed from its first use. The command stays for scripts that call it.
    """
    click.echo("nothing to compile: fivdisc's compiled core was built when fivdisc was "
               "installed")
