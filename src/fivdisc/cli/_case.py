"""The CASE argument shared by the commands: a TOML file, or a packaged example's name."""

from __future__ import annotations

from pathlib import Path

import click


class CaseFile(click.ParamType):
    """A click parameter type resolved by :func:`fivdisc.examples.resolve` to a file path.

    A missing file or unknown example raises :class:`~fivdisc.errors.FivdiscError`, which
    the command group reports as a one-line error.
    """

    name = "case"

    def convert(self, value, param, ctx) -> Path:
        from fivdisc.examples import resolve

        return resolve(value)


CASE = CaseFile()


def default_output(case_file: Path, suffix: str) -> Path:
    """Where a command writes when no output is given: beside a user's file, or, for a
    packaged example, ``NAME`` + `suffix` in the working directory."""
    from fivdisc.examples import DIRECTORY

    if case_file.resolve().parent == DIRECTORY:
        return Path(case_file.stem + suffix)
    return case_file.with_suffix(suffix)
