"""The ``fivdisc`` command line.

Each sub-command lives in its own module of this package and is registered here; a
:class:`~fivdisc.errors.FivdiscError` raised by any of them ends the program with a
one-line message and exit status 2 instead of a traceback.
"""

from __future__ import annotations

import sys

import click

from fivdisc.errors import FivdiscError


class _Group(click.Group):
    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except FivdiscError as exc:
            click.echo(f"error: {exc}", err=True)
            sys.exit(2)
        except FileNotFoundError as exc:
            click.echo(f"error: file not found: {exc.filename}", err=True)
            sys.exit(2)


@click.group(cls=_Group)
@click.version_option(package_name="fivdisc")
def cli() -> None:
    """fivdisc: friction-induced vibration of a slider on a spinning elastic disc."""


def _register() -> None:
    from fivdisc.cli import examples, modes, plot, reproduce, simulate, stability, sweep

    cli.add_command(modes.modes)
    cli.add_command(simulate.simulate)
    cli.add_command(plot.plot)
    cli.add_command(stability.stability)
    cli.add_command(sweep.sweep)
    cli.add_command(sweep.separation_map)
    cli.add_command(reproduce.reproduce)
    cli.add_command(examples.examples)


_register()


def main() -> None:
    """Console-script entry point."""
    cli(prog_name="fivdisc")
