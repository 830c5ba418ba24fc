"""The ``fivdisc`` command line.

Each sub-command lives in its own module of this package and is registered here; a
:class:`~fivdisc.errors.FivdiscError` raised by any of them, an operating-system error
(a full disk) or running out of memory ends the program with a one-line message and
exit status 2 instead of a traceback.
"""

from __future__ import annotations

import gc
import sys
import warnings

import click

from fivdisc.errors import FivdiscError, FivdiscWarning

# Allocations between young collections, young collections per middle one, middle per
# full one (Python's defaults: 700, 10, 10).
_GC_THRESHOLDS = (50_000, 20, 20)


def _fail(message: str) -> None:
    """End the program with `message` on one line of stderr and exit status 2."""
    click.echo(f"error: {' '.join(message.split())}", err=True)
    sys.exit(2)


class _Warnings:
    """How a command shows warnings: fivdisc's at once, as one line ``warning: ...`` on
    stderr; numerical RuntimeWarnings (numpy's overflow and the like, on the way to a
    value a check then refuses) held until the command ends, and dropped if it ends
    with an error, whose one line says what went wrong; any other as Python shows it."""

    def __init__(self) -> None:
        self.held: list[tuple] = []
        self.python = warnings.showwarning

    def show(self, message, category, filename, lineno, file=None, line=None) -> None:
        if issubclass(category, FivdiscWarning):
            click.echo(f"warning: {' '.join(str(message).split())}", err=True)
        elif issubclass(category, RuntimeWarning):
            self.held.append((message, category, filename, lineno, file, line))
        else:
            self.python(message, category, filename, lineno, file, line)

    def release(self) -> None:
        for held in self.held:
            self.python(*held)
        self.held = []


# Each sub-command: its module in this package and the function defining it. A command is
# imported when it is named, so that a short command loads only its own module (all of
# them for the group's help).
_COMMANDS = {
    "bifurcation": ("sweep", "bifurcation"),
    "bistable": ("bistable", "bistable"),
    "continue": ("continuation", "continuation"),
    "examples": ("examples", "examples"),
    "lyapunov": ("dynamics", "lyapunov"),
    "modes": ("modes", "modes"),
    "orbit": ("dynamics", "orbit"),
    "plot": ("plot", "plot"),
    "reproduce": ("reproduce", "reproduce"),
    "separation-map": ("sweep", "separation_map"),
    "simulate": ("simulate", "simulate"),
    "stability": ("stability", "stability"),
    "sweep": ("sweep", "sweep"),
    "warmup": ("warmup", "warmup"),
}


class _Group(click.Group):
    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted({*self.commands, *_COMMANDS})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in self.commands and cmd_name in _COMMANDS:
            from importlib import import_module

            module, name = _COMMANDS[cmd_name]
            self.add_command(getattr(import_module(f"fivdisc.cli.{module}"), name), cmd_name)
        return super().get_command(ctx, cmd_name)

    def invoke(self, ctx: click.Context):
        shown = _Warnings()
        with warnings.catch_warnings():
            warnings.showwarning = shown.show
            warnings.simplefilter("always", FivdiscWarning)
            try:
                result = self._invoke(ctx)
            except SystemExit as exc:
                if exc.code in (0, None):
                    shown.release()
                raise
            shown.release()
            return result

    def _invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except FivdiscError as exc:
            _fail(str(exc))
        except FileNotFoundError as exc:
            _fail(f"file not found: {exc.filename}")
        except OSError as exc:  # e.g. a full disk while writing an output
            _fail(f"{exc.filename}: {exc.strerror}" if exc.filename else str(exc))
        except MemoryError as exc:  # an estimate in fivdisc.limits fell short
            _fail(f"out of memory ({exc or 'no details'}); ask for less (shorter runs, "
                  "lower output rates, smaller grids)")


@click.group(cls=_Group)
@click.version_option(package_name="fivdisc")
def cli() -> None:
    """fivdisc: friction-induced vibration of a slider on a spinning elastic disc."""


def main() -> None:
    """Console-script entry point."""
    # A command imports scipy, xarray and the netCDF engine as it goes: with the default
    # thresholds the collector runs hundreds of times over their objects meanwhile, a
    # noticeable part of a short command (``benchmarks/bench_startup.py`` times both).
    # Rarer collections still bound what cycles a long sweep leaves behind.
    gc.set_threshold(*_GC_THRESHOLDS)
    try:
        cli(prog_name="fivdisc")
    finally:
        # Every output is written and closed by now. The interpreter's shutdown then
        # collects garbage across all the imported libraries' objects, a noticeable part
        # of a short command; frozen, they are left to the exit, which frees them anyway.
        gc.freeze()
