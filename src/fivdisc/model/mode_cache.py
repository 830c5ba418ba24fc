"""The disc's radial modes, kept on disk from one process to the next.

Finding a mode's frequency parameter and the peak of its shape takes root searches
(:func:`scipy.optimize.brentq`), and its values take Bessel functions
(:mod:`scipy.special`): importing either is a quarter to a third of a second of every
short command. The modes of a geometry, and their values at the radii a model asks for
(its sliders' tracks and probes), are therefore stored once, in
``fivdisc-plate-modes.json`` in ``$FIVDISC_CACHE_DIR`` (else
``~/.cache/fivdisc``), and read back exactly (JSON keeps every bit of a float). The file
is stamped with a hash of :mod:`fivdisc.model.plate`'s source and the numpy and scipy
versions: when one changes, the stored modes are ignored and found again. A file that
cannot be read, or a directory that cannot be written, only costs the root searches.

The modes of every packaged example (their geometries, sliders' tracks and probes) ship
with the package, in ``plate-modes.json`` beside this module, so that even the first
command after an install imports no root finder: they are read before the user's file
and win over it (the same bits on every machine, whatever its scipy). That file is
stamped with the hash of ``plate.py``'s source alone and written by
``tools/seed_modes.py``; a test checks it against modes solved afresh.
"""

from __future__ import annotations

import hashlib
import json
import os
from functools import lru_cache
from pathlib import Path
from typing import Any

__all__ = ["lookup", "lookup_values", "remember", "remember_values", "source_stamp"]

_FILE = "fivdisc-plate-modes.json"
_SEED = Path(__file__).with_name("plate-modes.json")
_modes: dict[str, Any] | None = None


def _path() -> Path:
    directory = os.environ.get("FIVDISC_CACHE_DIR")
    if directory:
        return Path(directory) / _FILE
    home = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(home) / "fivdisc" / _FILE


def _source() -> bytes:
    return Path(__file__).with_name("plate.py").read_bytes()


def source_stamp() -> str:
    """The stamp of the packaged modes: a hash of ``plate.py``'s source."""
    return hashlib.sha256(_source()).hexdigest()[:16]


@lru_cache(maxsize=1)
def _stamp() -> str:
    # The modes are what plate.py computes with these numpy and scipy (their Bessel
    # functions may change in the last bits from one version to the next).
    import numpy
    import scipy

    versions = f"{numpy.__version__} {scipy.__version__}".encode()
    return hashlib.sha256(_source() + versions).hexdigest()[:16]


def _stored(path: Path, stamp: str) -> dict[str, Any]:
    """The modes in the file at `path` if it is stamped `stamp`, else none."""
    try:
        stored = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    if not (isinstance(stored, dict) and stored.get("stamp") == stamp
            and isinstance(stored.get("modes"), dict)):
        return {}
    return stored["modes"]


@lru_cache(maxsize=1)
def _seeded() -> dict[str, Any]:
    """The packaged examples' modes, if stamped by today's ``plate.py``."""
    return _stored(_SEED, source_stamp())


def _with_seed(modes: dict[str, Any]) -> dict[str, Any]:
    """The user's ``modes`` with the packaged ones over them (the values at radii merged
    request by request)."""
    merged = dict(modes)
    for key, value in _seeded().items():
        mine = merged.get(key)
        if key.startswith("values ") and isinstance(mine, dict) and isinstance(value, dict):
            value = {**mine, **value}
        merged[key] = value
    return merged


def _read() -> dict[str, Any]:
    return _stored(_path(), _stamp())


def lookup(key: str) -> Any:
    """The value stored under ``key`` (a mode's ``repr`` of its arguments), or None."""
    global _modes
    seeded = _seeded().get(key)
    if seeded is not None and not key.startswith("values "):
        # A packaged value wins over the user's: the user's cache (its stamp imports
        # scipy) need not be read.
        return seeded
    if _modes is None:
        _modes = _with_seed(_read())
    return _modes.get(key)


def lookup_values(key: str, radii: list[float]) -> list[float] | None:
    """A radial function's values at ``radii`` [m] stored under ``key`` (the mode and the
    derivative), or None. The radii are looked up as one request: numpy's vectorised
    Bessel functions may round a radius differently in another array, and a model must
    read back exactly what it computed."""
    def found_in(stored: Any) -> list[float] | None:
        found = stored.get(repr(radii)) if isinstance(stored, dict) else None
        return found if isinstance(found, list) and len(found) == len(radii) else None

    # The packaged values win (see lookup): the user's are read only for other radii.
    return found_in(_seeded().get(f"values {key}")) or found_in(lookup(f"values {key}"))


def remember_values(key: str, radii: list[float], values: list[float]) -> None:
    """Store a radial function's ``values`` at ``radii`` [m] under ``key``, beside those
    stored for other requests."""
    stored = lookup(f"values {key}")
    merged = dict(stored) if isinstance(stored, dict) else {}
    merged[repr(radii)] = values
    remember(f"values {key}", merged)


def remember(key: str, value: Any) -> None:
    """Store ``value`` (JSON: numbers and lists) under ``key``, merged with what other
    processes stored meanwhile."""
    global _modes
    from fivdisc.files import write_atomic

    modes = _read()
    modes[key] = value
    _modes = _with_seed(modes)
    path = _path()
    text = json.dumps({"stamp": _stamp(), "modes": modes})
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, lambda target: Path(target).write_text(text))
    except OSError:
        pass  # a read-only cache: the modes are found again next time
