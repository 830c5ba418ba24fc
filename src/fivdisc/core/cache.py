"""numba's on-disk cache for the kernels, keyed to the sources of all of them.

numba stamps each cached function with a hash of its own file only. The kernels call
each other across files and numba compiles the callees into the caller, so after an edit
of, say, ``dynamics.py`` the cached ``integrate.run`` would still hold the old
right-hand side. The locators below are numba's own (``__pycache__`` next to the
sources, ``NUMBA_CACHE_DIR``, or the user-wide cache for a read-only install) with one
change: a function of this package stamps its cache entry with the hash of every source
file of ``fivdisc.core`` and of :mod:`fivdisc.model.layout` (whose constants the kernels
compile in), so any edit there recompiles every kernel.

``install`` runs when ``fivdisc.core`` is imported, before any kernel is decorated
(numba picks a function's locator when ``cache=True`` is applied). It hooks into
``numba.core.caching.CacheImpl._locator_classes`` (``_CacheImpl`` before numba 0.61),
the list numba tries in order; the locators decline any function outside this
directory, so other numba code is untouched.
"""

from __future__ import annotations

import functools
import hashlib
from pathlib import Path

from numba.core import caching

KERNELS = Path(__file__).resolve().parent
LAYOUT = KERNELS.parent / "model" / "layout.py"


@functools.cache
def _sources_hash(stamp: tuple[tuple[str, int, int], ...]) -> str:
    digest = hashlib.sha256()
    for name, _, _ in stamp:
        digest.update(name.encode())
        digest.update((KERNELS.parent / name).read_bytes())
    return digest.hexdigest()


def sources_hash() -> str:
    """SHA-256 of the names and contents of all ``*.py`` files of ``fivdisc.core`` and of
    the model's layout.

    Memoised on the files' sizes and modification times, so an edit made while the
    process runs is seen, without re-reading the files at every lookup.
    """
    files = [*sorted(KERNELS.glob("*.py")), LAYOUT]
    return _sources_hash(tuple((str(f.relative_to(KERNELS.parent)), f.stat().st_mtime_ns,
                                f.stat().st_size) for f in files))


def _is_kernel(py_file: str) -> bool:
    return Path(py_file).resolve().parent == KERNELS


class _KernelStamp:
    """Mixin: kernel functions only, stamped with the hash of all kernel sources."""

    def get_source_stamp(self) -> str:
        return sources_hash()

    @classmethod
    def from_function(cls, py_func, py_file):
        if not _is_kernel(py_file):
            return None
        return super().from_function(py_func, py_file)


class UserProvidedLocator(_KernelStamp, caching.UserProvidedCacheLocator):
    """``NUMBA_CACHE_DIR``, when set."""


class InTreeLocator(_KernelStamp, caching.InTreeCacheLocator):
    """``__pycache__`` next to the kernel sources, when writable."""


class UserWideLocator(_KernelStamp, caching.UserWideCacheLocator):
    """The user-wide cache directory (read-only installs)."""


LOCATORS = (UserProvidedLocator, InTreeLocator, UserWideLocator)


def _impl() -> type:
    """numba's class that holds the list of locators."""
    impl = getattr(caching, "CacheImpl", None)
    return impl if impl is not None else caching._CacheImpl


def install() -> None:
    """Put the kernel locators first in numba's list (once)."""
    classes = _impl()._locator_classes
    if classes[: len(LOCATORS)] != list(LOCATORS):
        classes[:0] = LOCATORS
