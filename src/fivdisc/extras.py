"""Optional extras: what needs matplotlib (``plot``) or zarr and dask (``distributed``).

Commands and functions that need an extra call :func:`require` before any work, so
that a missing package ends them at once with one line saying how to install it, rather
than with an import traceback after minutes of computing. The check looks the modules
up without importing them.
"""

from __future__ import annotations

import importlib.util

from fivdisc.errors import MissingExtraError

__all__ = ["EXTRAS", "MissingExtraError", "require"]

#: Extra name -> modules it installs.
EXTRAS: dict[str, tuple[str, ...]] = {
    "plot": ("matplotlib",),
    "distributed": ("zarr", "dask", "distributed"),
}


def _installed(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # a broken parent package, or a module without spec
        return False


def require(extra: str, what: str) -> None:
    """Check that the modules of an extra can be imported, without importing them.

    Parameters
    ----------
    extra
        A key of :data:`EXTRAS`.
    what
        What needs it, named in the message, e.g. ``"fivdisc plot"``.

    Raises
    ------
    MissingExtraError
        One line naming `what`, the missing modules and the install command.
    """
    missing = [module for module in EXTRAS[extra] if not _installed(module)]
    if missing:
        raise MissingExtraError(
            f"{what} needs {' and '.join(missing)}, which {'is' if len(missing) == 1 else 'are'}"
            f' not installed: install the {extra} extra with pip install "fivdisc[{extra}]"'
            f' (from a clone: pip install ".[{extra}]")'
        )
