"""Packages whose public names are imported on first use (PEP 562), from one table.

A package lists its public API once, as a table of modules and the names each gives it;
:func:`public` makes ``__all__``, ``__getattr__`` and ``__dir__`` from it. Such a package
imports none of its modules itself: importing one of them (for example
``fivdisc.analysis.spectra``) then runs no other, the import graph stays one-way
(``tests/package/test_imports.py``), and ``import fivdisc`` starts without scipy, xarray or
matplotlib. No module of such a package is named like a name it gives the package (the
import system would bind the module over it once imported; ``tests/package/test_imports.py``
checks).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from importlib import import_module
from typing import Any

__all__ = ["public"]


def public(namespace: dict[str, Any], table: Mapping[str, Iterable[str]],
           computed: Mapping[str, Callable[[], Any]] | None = None
           ) -> tuple[list[str], Callable[[str], Any], Callable[[], list[str]]]:
    """Make the package whose globals are ``namespace`` lazy, with the public API ``table``
    (module -> the names it gives the package).

    ``computed`` maps further public names to functions that make their values on first
    use (``__version__``). Returns ``__all__`` (sorted), ``__getattr__`` and ``__dir__``;
    ``namespace["_HOMES"]`` is set to the name -> module mapping, which
    ``tests/package/test_imports.py`` reads.
    """
    homes = {name: module for module, names in table.items() for name in names}
    computed = dict(computed or {})
    namespace["_HOMES"] = homes
    names = sorted({*homes, *computed})

    def __getattr__(name: str) -> Any:
        if name in computed:
            value = computed[name]()
        elif name in homes:
            value = getattr(import_module(homes[name]), name)
        else:
            raise AttributeError(f"module {namespace['__name__']!r} has no attribute {name!r}")
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted({*namespace, *names})

    return names, __getattr__, __dir__
