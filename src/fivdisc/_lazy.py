"""Packages whose public names are imported on first use (PEP 562).

Such a package imports none of its modules itself: importing one of them (for example
``fivdisc.analysis.spectra``) then runs no other, and the import graph stays one-way
(``tests/test_imports.py``).
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable, Mapping
from importlib import import_module
from types import ModuleType
from typing import Any

__all__ = ["homes", "lazy_names"]


def homes(modules: Mapping[str, Iterable[str]]) -> dict[str, str]:
    """Public name -> the module that defines it, from module -> names."""
    return {name: module for module, names in modules.items() for name in names}


class _Package(ModuleType):
    """A lazy package's module type: a function keeps its name on the package when the
    module of the same name that defines it is imported.

    The import system binds a submodule, once imported, to the package's attribute of the
    same name; the module ``fivdisc.simulate``, imported by whatever needs it first, would
    then hide the function ``fivdisc.simulate`` that it defines.
    """

    _lazy_homes: Mapping[str, str] = {}

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(value, ModuleType) and self._lazy_homes.get(name) == value.__name__:
            value = getattr(value, name)
        super().__setattr__(name, value)


def lazy_names(namespace: dict[str, Any], names: Mapping[str, str]
               ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """Make the package whose globals are `namespace` lazy: returns its ``__getattr__``
    and ``__dir__``, which import the names `names` (name -> home module) on first use
    and keep them in `namespace`."""
    package = sys.modules[namespace["__name__"]]
    package.__class__ = _Package
    package._lazy_homes = names

    def __getattr__(name: str) -> Any:
        if name not in names:
            raise AttributeError(f"module {namespace['__name__']!r} has no attribute {name!r}")
        value = getattr(import_module(names[name]), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted({*namespace, *names, *namespace.get("__all__", ())})

    return __getattr__, __dir__
