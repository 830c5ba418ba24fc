"""Reading inputs and writing outputs safely: the one place every command goes through.

An output path is checked before any work starts (:func:`check_output`): it must not be
one of the command's input files, its directory must exist and be writable, and its
suffix must be one the command knows how to write. Files are then written under a
temporary name in the same directory and renamed into place (:func:`write_atomic`), so an
interrupted or failed write leaves the previous file, or nothing, never half a file.

Every netCDF file fivdisc writes goes through :func:`write_netcdf`, which stores a
checksum of the data in the file (:func:`netcdf_checksum`, as the attribute
``fivdisc_checksum``); :func:`check_netcdf` compares it when the file is read or reused.
"""

from __future__ import annotations

import hashlib
import os
import shutil
from collections.abc import Callable, Iterable, Iterator
from os import PathLike
from pathlib import Path
from typing import Any, Literal

from fivdisc.errors import FivdiscError

__all__ = [
    "CHECKSUM",
    "NETCDF",
    "ZARR",
    "OutputError",
    "check_netcdf",
    "check_output",
    "figure_suffixes",
    "netcdf_checksum",
    "read_text",
    "require_fivdisc_netcdf",
    "write_atomic",
    "write_netcdf",
    "written_by_fivdisc",
]

NETCDF = (".nc",)
ZARR = (".zarr",)
#: Global attribute of a netCDF file of fivdisc holding :func:`netcdf_checksum`.
CHECKSUM = "fivdisc_checksum"


class OutputError(FivdiscError):
    """An output could not be written (a full disk, a file size limit, an I/O error)."""


def figure_suffixes() -> tuple[str, ...]:
    """File suffixes matplotlib can write a figure to, e.g. ``(".png", ".pdf", ...)``."""
    from matplotlib.backend_bases import FigureCanvasBase

    return tuple(f".{name}" for name in sorted(FigureCanvasBase.get_supported_filetypes()))


#: Largest input text file (a case or sweep file) [bytes]: the largest packaged example
#: is a few kilobytes, a sweep listing a million values some megabytes.
MAX_TEXT_BYTES = 16 * 2**20


def read_text(path: str | PathLike[str]) -> str:
    """The UTF-8 text of an input file, of at most :data:`MAX_TEXT_BYTES`.

    Raises
    ------
    FileNotFoundError
        The file does not exist (the command line reports it on one line).
    FivdiscError
        The path is a directory or a device, is larger than :data:`MAX_TEXT_BYTES`,
        cannot be read, or is not UTF-8 text (e.g. a binary file). A device (``/dev/zero``)
        or a file too large is refused before it is read; a pipe is read up to the limit.
    """
    import stat

    path = Path(path)
    limit = f"{MAX_TEXT_BYTES // 2**20} MiB"
    try:
        status = path.stat()
        if stat.S_ISCHR(status.st_mode) or stat.S_ISBLK(status.st_mode):
            raise FivdiscError(f"{path} is a device, not a file: give a TOML file")
        if stat.S_ISREG(status.st_mode) and status.st_size > MAX_TEXT_BYTES:
            raise FivdiscError(f"{path} is {status.st_size / 2**20:.3g} MiB: an input text "
                               f"file must be at most {limit}; give a TOML file")
        with path.open("rb") as f:  # a pipe: read up to the limit
            data = f.read(MAX_TEXT_BYTES + 1)
        if len(data) > MAX_TEXT_BYTES:
            raise FivdiscError(f"{path} holds more than {limit}: an input text file must be "
                               f"at most {limit}; give a TOML file")
        # Newlines as a text file reads them (universal newlines).
        return data.decode("utf-8").replace("\r\n", "\n").replace("\r", "\n")
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
    either the complete new file or what it was before. One that a killed process left
    (SIGKILL, a power cut) is removed by the next write of `path`.

    Parameters
    ----------
    path
        The file to write.
    write
        Writes the content to the path it is given, e.g. ``dataset.to_netcdf``.
    """
    path = Path(path)
    _remove_stale(path)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        write(tmp)
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)


def _remove_stale(path: Path) -> None:
    """Remove the temporary files of :func:`write_atomic` for `path` that a killed
    process left (``.STEM.PID.tmpSUFFIX`` of a process that no longer runs)."""
    prefix, suffix = f".{path.stem}.", f".tmp{path.suffix}"
    try:
        names = os.listdir(path.parent)
    except OSError:
        return
    for name in names:
        pid = name[len(prefix):len(name) - len(suffix)]
        if not (name.startswith(prefix) and name.endswith(suffix) and pid.isdigit()):
            continue
        try:
            os.kill(int(pid), 0)
            continue  # still running: its write may be under way
        except ProcessLookupError:
            pass
        except (PermissionError, OverflowError, ValueError):
            continue  # another user's process, or not a process id
        (path.parent / name).unlink(missing_ok=True)


def _groups(group: Any) -> Iterator[Any]:
    """A netCDF group and all its subgroups, in a fixed order."""
    yield group
    for name in sorted(group.groups):
        yield from _groups(group.groups[name])


def _token(value: Any) -> tuple[bytes, Any]:
    """An attribute or variable value as (a header with its type and shape, its bytes):
    the header and a buffer over the values, so that a large variable is hashed without
    a copy."""
    import numpy as np

    if isinstance(value, str):
        return b"s", value.encode()
    array = np.asarray(value)
    if array.dtype.kind in "OUS":  # text: one item at a time, each with its length
        items = [str(v).encode() for v in array.ravel()]
        body = b"".join(len(i).to_bytes(8, "little") + i for i in items)
        return f"t{array.shape}".encode(), body
    return (f"{array.dtype.str}{array.shape}".encode(),
            np.ascontiguousarray(array).reshape(-1).view(np.uint8))


def netcdf_checksum(path: str | PathLike[str]) -> str:
    """SHA-256 (hex) of what a netCDF file stores: every group's attributes and variables
    (name, type, shape, stored values, attributes), except the attribute holding the
    checksum itself.

    Values are hashed as stored (no scaling, masking or decoding), so that the checksum
    does not depend on how a reader decodes them.

    Raises
    ------
    OSError, RuntimeError
        The file cannot be read (netCDF4 raises RuntimeError for damaged HDF5 data).
    """
    import netCDF4

    digest = hashlib.sha256()

    def update(name: str, value: Any) -> None:
        # The token is framed by its length: header and body are one token.
        header, body = _token(value)
        digest.update(len(name).to_bytes(8, "little") + name.encode())
        digest.update((len(header) + len(body)).to_bytes(8, "little") + header)
        digest.update(body)

    with netCDF4.Dataset(path) as root:
        for group in _groups(root):
            update("group", group.path)
            for name in sorted(group.ncattrs()):
                if not (group is root and name == CHECKSUM):
                    update(f"attribute {name}", group.getncattr(name))
            for name in sorted(group.variables):
                var = group.variables[name]
                var.set_auto_maskandscale(False)
                var.set_auto_chartostring(False)
                update(f"variable {name}", var[...])
                for key in sorted(var.ncattrs()):
                    update(f"attribute {name}.{key}", var.getncattr(key))
    return digest.hexdigest()


def check_netcdf(path: str | PathLike[str]) -> bool:
    """Check a netCDF file of fivdisc against the checksum stored in it.

    Returns
    -------
    bool
        True if the file holds a checksum and its data match it; False if it holds none
        (a file of another program, or of a fivdisc before checksums).

    Raises
    ------
    FivdiscError
        The data do not match the checksum, or cannot be read; one line naming the file.
    """
    import netCDF4

    path = Path(path)
    try:
        with netCDF4.Dataset(path) as root:
            stored = root.getncattr(CHECKSUM) if CHECKSUM in root.ncattrs() else None
        if stored is None:
            return False
        actual = netcdf_checksum(path)
    except Exception as exc:
        # A damaged file makes the netCDF library fail in many ways: OSError, RuntimeError,
        # ValueError, and AttributeError for a damaged attribute ("Can't open HDF5
        # attribute"), among others.
        raise FivdiscError(f"{path} is damaged: it cannot be read ({_brief(exc)}); write it "
                           "again") from None
    if actual != stored:
        raise FivdiscError(f"{path} is damaged: its data do not match the checksum stored in "
                           f"it ({CHECKSUM}); write it again")
    return True


def written_by_fivdisc(path: str | PathLike[str]) -> bool:
    """Whether a netCDF file says fivdisc wrote it: it holds fivdisc's checksum
    (:data:`CHECKSUM`), or, from a fivdisc before checksums, a ``source`` attribute
    naming fivdisc, a ``fivdisc_kind`` or a branch's ``content`` (at the root, or in
    each of its groups: runs gathered into one file).

    Raises
    ------
    FivdiscError
        The file cannot be read as netCDF; one line naming it.
    """
    import netCDF4

    def ours(group: Any) -> bool:
        attrs = {name: group.getncattr(name) for name in group.ncattrs()}
        return (CHECKSUM in attrs or str(attrs.get("source", "")).startswith("fivdisc")
                or "fivdisc_kind" in attrs or attrs.get("content") == "continuation branch")

    try:
        with netCDF4.Dataset(path) as root:
            groups = list(root.groups.values())
            return ours(root) or (bool(groups) and all(ours(g) for g in groups))
    except (OSError, RuntimeError, ValueError) as exc:
        raise FivdiscError(f"{path} cannot be read as a netCDF file "
                           f"({' '.join(str(exc).split())[:120]})") from None


def require_fivdisc_netcdf(path: str | PathLike[str], what: str) -> None:
    """Refuse a netCDF file that fivdisc did not write (:func:`written_by_fivdisc`):
    its variables may share a result's names without meaning what fivdisc's do.

    Parameters
    ----------
    path
        The file.
    what
        What reads it, for the message (``"fivdisc plot"``, ``"open_result"``).

    Raises
    ------
    FivdiscError
        One line naming the file and what it lacks.
    """
    if not written_by_fivdisc(path):
        raise FivdiscError(f"{path} was not written by fivdisc (it holds no fivdisc checksum "
                           f"or source attribute): {what} reads the netCDF files fivdisc "
                           "writes (-o of its commands); read this one with "
                           "xarray.open_dataset")


def write_netcdf(path: str | PathLike[str], write: Callable[[Path], Any]) -> None:
    """Write a netCDF file through ``write(temporary_path)`` (e.g. ``dataset.to_netcdf``),
    store its checksum in it (see :func:`netcdf_checksum`) and rename it to `path`; see
    :func:`write_atomic`.

    Raises
    ------
    OutputError
        The file could not be written (a full disk, a file size limit, an I/O error: the
        netCDF library reports them as ``NetCDF: HDF error``); one line with the reason
        and the space left. `path` is left as it was.
    """
    import netCDF4

    def stamped(tmp: Path) -> None:
        write(tmp)
        digest = netcdf_checksum(tmp)
        with netCDF4.Dataset(tmp, "a") as root:
            root.setncattr(CHECKSUM, digest)

    path = Path(path)
    try:
        write_atomic(path, stamped)
    except (OSError, RuntimeError) as exc:
        if isinstance(exc, RuntimeError) and not str(exc).startswith("NetCDF"):
            raise
        reason = (exc.strerror if isinstance(exc, OSError) and exc.strerror
                  else " ".join(str(exc).split()))
        try:
            free = f"; {shutil.disk_usage(path.parent).free / 1e6:.3g} MB free there"
        except OSError:
            free = ""
        raise OutputError(f"cannot write {path}: {reason}{free}") from exc


def read_dataset(path: str | PathLike[str], option: str):
    """The whole netCDF file at `path` as an :class:`xarray.Dataset`, loaded and closed,
    after checking it against its checksum (:func:`check_netcdf`).

    Raises
    ------
    FivdiscError
        The file cannot be read as netCDF, or is damaged (the message names `option` and
        the file).
    """
    import xarray as xr

    try:
        with open(path, "rb") as f:
            magic = f.read(4)
    except OSError as exc:
        raise FivdiscError(f"{option} {path}: cannot be read ({exc.strerror})") from None
    # netCDF classic files start with "CDF", netCDF-4 files with HDF5's signature.
    if not (magic[:3] == b"CDF" or magic == b"\x89HDF"):
        raise FivdiscError(f"{option} {path}: is not a netCDF file: give one that fivdisc "
                           "wrote with -o (a case file goes where a command takes CASE_FILE)")
    check_netcdf(path)
    try:
        with xr.open_dataset(path) as ds:
            return ds.load()
    except Exception as exc:  # as in check_netcdf: the types vary
        raise FivdiscError(f"{option} {path}: cannot be read as a netCDF file "
                           f"({_brief(exc)})") from None


def _brief(exc: BaseException) -> str:
    """An exception of a reader as one short line (its type if it says nothing)."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text[:120]
