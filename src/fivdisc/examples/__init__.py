"""The example cases and sweeps that ship with fivdisc, and the resolver of CASE arguments.

The TOML files beside this module are package data: ``default.toml`` (the paper's Table 1
with every key written out), ``figNN.toml`` (the paper's figures, written by
:func:`fivdisc.paper.cases.write_examples`), ``fig27_base.toml`` and ``sweep_fig27.toml``
(the separation map of Fig. 27), ``bifurcation-speed.toml`` (a bifurcation diagram over
the disc speed; a sweep file, as every example with an ``[axes]`` table is). Every command
that takes a case accepts an example's bare name (``fivdisc simulate fig10``) where no
file of that name exists:

>>> from fivdisc import examples, load_case
>>> examples.resolve("fig10").name
'fig10.toml'
>>> load_case(examples.path("default")).slider.preload
500.0
"""

from __future__ import annotations

import difflib
from os import PathLike
from pathlib import Path

from fivdisc.errors import FivdiscError

__all__ = ["DIRECTORY", "available", "path", "resolve"]

DIRECTORY = Path(__file__).resolve().parent
"""The directory holding the example files."""


def _names() -> list[str]:
    return sorted(p.stem for p in DIRECTORY.glob("*.toml"))


def _hint(stem: str) -> str:
    """The examples nearest to `stem`, or all of them, for an error message."""
    names = _names()
    close = [name for name in names if name.startswith(stem)] or difflib.get_close_matches(
        stem, names, n=3, cutoff=0.6)
    hint = f"nearest: {', '.join(close)}" if close else f"must be one of {', '.join(names)}"
    return f"{hint} (`fivdisc examples` lists them with their descriptions)"


def _description(file: Path) -> str:
    """The first sentence of the file's leading comment: its lines up to one ending in '.'."""
    words: list[str] = []
    for line in file.read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        text = line.lstrip("#").strip()
        if not text:
            break
        words.append(text)
        if text.endswith("."):
            break
    return " ".join(words)


def available() -> dict[str, str]:
    """Every example, by name, with a one-line description.

    Returns
    -------
    dict of str to str
        Example name (the file name without ``.toml``, e.g. ``"fig10"``) -> the first
        sentence of the file's leading comment, in name order.
    """
    return {name: _description(DIRECTORY / f"{name}.toml") for name in _names()}


def path(name: str) -> Path:
    """The file of the example `name`.

    Parameters
    ----------
    name
        An example's name, with or without ``.toml`` (see :func:`available`).

    Returns
    -------
    Path
        The packaged TOML file.

    Raises
    ------
    FivdiscError
        No example has that name; the message names the nearest ones.
    """
    stem = name.removesuffix(".toml")
    if stem not in _names():
        raise FivdiscError(f"{name!r} is not a packaged example: {_hint(stem)}")
    return DIRECTORY / f"{stem}.toml"


def resolve(case: str | PathLike[str]) -> Path:
    """The file a CASE argument names: an existing file, else a packaged example.

    Parameters
    ----------
    case
        A path to a TOML file, or the bare name of a packaged example (``"fig10"`` or
        ``"fig10.toml"``), used when no file of that name exists in the working
        directory.

    Returns
    -------
    Path
        `case` itself when it exists, else the example's file.

    Raises
    ------
    FivdiscError
        `case` is a directory, or it neither exists nor names an example (a bare name:
        the message names the nearest examples; a path: it says the file is missing).
    """
    given = Path(case)
    if given.is_dir():
        raise FivdiscError(f"{str(case)!r} is a directory: must be a TOML file or the "
                           "name of a packaged example")
    if given.exists():
        return given
    if len(given.parts) != 1:
        raise FivdiscError(f"file not found: {given}")
    stem = given.name.removesuffix(".toml")
    if stem not in _names():
        raise FivdiscError(f"{str(case)!r} is neither a file nor a packaged example: "
                           f"{_hint(stem)}")
    return DIRECTORY / f"{stem}.toml"
