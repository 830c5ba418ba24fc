"""Reading inputs and writing outputs safely: the one place every command goes through.

An output path is checked before any work starts (:func:`check_output`): it must not be
one of the command's input files, its directory must exist and be writable, and its
suffix must be one the command knows how to write. Files are then written under a
temporary name in the same directory and renamed into place (:func:`write_atomic`), so an
interrupted or failed write leaves the previous file, or nothing, never half a file.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from os import PathLike
from pathlib import Path
from typing import Any, Literal

from fivdisc.errors import FivdiscError

__all__ = ["NETCDF", "ZARR", "check_output", "figure_suffixes", "read_text", "write_atomic"]

NETCDF = (".nc",)
ZARR = (".zarr",)


def figure_suffixes() -> tuple[str, ...]:
    """File suffixes matplotlib can write a figure to, e.g. ``(".png", ".pdf", ...)``."""
    from matplotlib.backend_bases import FigureCanvasBase

    return tuple(f".{name}" for name in sorted(FigureCanvasBase.get_supported_filetypes()))


def read_text(path: str | PathLike[str]) -> str:
    """The UTF-8 text of an input file.

    Raises
    ------
    FileNotFoundError
        The file does not exist (the command line reports it on one line).
    FivdiscError
        The path is a directory, cannot be read, or is not UTF-8 text (e.g. a binary file).
    """
    path = Path(path)
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise FivdiscError(
            f"{path} is not a text file: byte {exc.object[exc.start]:#04x} at offset "
            f"{exc.start} is not UTF-8; give a TOML file"
        ) from None
    except IsADirectoryError:
        raise FivdiscError(f"{path} is a directory: give a file") from None
    except PermissionError:
        raise FivdiscError(f"{path} cannot be read: permission denied") from None


def _same_file(a: Path, b: Path) -> bool:
    if a.resolve() == b.resolve():
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist
        return False


def check_output(
    path: str | PathLike[str],
    option: str,
    suffixes: Iterable[str],
    inputs: Iterable[str | PathLike[str] | None] = (),
    kind: Literal["file", "directory"] = "file",
) -> Path:
    """Check that `path` can be written, before the work that produces it starts.

    Parameters
    ----------
    path
        The output path.
    option
        The option that gave it, e.g. ``"-o"``, named in error messages.
    suffixes
        Allowed suffixes, e.g. ``(".nc",)``; empty allows any.
    inputs
        The command's input files (None entries are skipped): the output must be none of them.
    kind
        ``"file"``: a file, replaced if it exists. ``"directory"``: a directory such as a
        Zarr store, reused if it exists.

    Returns
    -------
    Path
        `path` as a Path.

    Raises
    ------
    FivdiscError
        One line naming `option`, the path and what is allowed.
    """
    path = Path(path)
    allowed = tuple(suffixes)
    where = f"{option} {path}"
    if allowed and path.suffix.lower() not in allowed:
        shown = f"'{path.suffix}'" if path.suffix else "no suffix"
        raise FivdiscError(
            f"{where} is invalid: its suffix ({shown}) is not supported; must end in "
            f"{', '.join(allowed)}"
        )
    for source in inputs:
        if source is not None and _same_file(path, Path(source)):
            raise FivdiscError(
                f"{where} is invalid: it is an input of this command; write to another file"
            )
    if kind == "file" and path.is_dir():
        raise FivdiscError(f"{where} is invalid: it is a directory; give a file name")
    if kind == "directory" and path.exists() and not path.is_dir():
        raise FivdiscError(f"{where} is invalid: it is a file; give a directory name")
    parent = path.parent
    if not parent.is_dir():
        raise FivdiscError(
            f"{where} is invalid: the directory {parent} does not exist; create it first"
        )
    target = path if kind == "directory" and path.exists() else parent
    if not os.access(target, os.W_OK | os.X_OK):
        raise FivdiscError(f"{where} is invalid: the directory {target} is not writable")
    return path


def write_atomic(path: str | PathLike[str], write: Callable[[Path], Any]) -> None:
    """Write a file through ``write(temporary_path)`` and rename it to `path`.

    The temporary file lies in the same directory and keeps the suffix (matplotlib picks
    the format from it); it is removed if `write` fails or is interrupted, so `path` is
    either the complete new file or what it was before.

    Parameters
    ----------
    path
        The file to write.
    write
        Writes the content to the path it is given, e.g. ``dataset.to_netcdf``.
    """
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        write(tmp)
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)


def read_dataset(path: str | PathLike[str], option: str):
    """The whole netCDF file at `path` as an :class:`xarray.Dataset`, loaded and closed.

    Raises
    ------
    FivdiscError
        The file cannot be read as netCDF (the message names `option` and the file).
    """
    import xarray as xr

    try:
        with xr.open_dataset(path) as ds:
            return ds.load()
    except (OSError, ValueError) as exc:
        raise FivdiscError(f"{option} {path}: cannot be read as a netCDF file "
                           f"({' '.join(str(exc).split())[:120]})") from None
