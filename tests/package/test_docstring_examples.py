"""The docstrings' examples run, and print what they show.

Every function and class that ``import fivdisc`` provides has a numpydoc ``Examples``
section with at least one example that runs (not all marked ``+SKIP``). Its doctests run
here, one test per name (the class's methods' examples with the class), and so do the
examples anywhere else in the package (module docstrings, the sub-packages' names), one
test per module. Each runs in a fresh directory, so that an example may write files, with
the flags ``ELLIPSIS`` and ``NORMALIZE_WHITESPACE``; an example imports what it uses.

The examples are short (simulations of a few milliseconds to 0.05 s, small cases): the
whole module takes well under a minute.
"""

from __future__ import annotations

import ast
import doctest
import importlib
import inspect
import re
from pathlib import Path

import pytest

import fivdisc
from fivdisc import _API

FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
PACKAGE = Path(fivdisc.__file__).resolve().parent

# Top-level name -> the module it lives in, from the API table (no import needed).
HOMES = {name: module for module, names in _API.items() for name in names}
TOP = sorted(HOMES)


def _is_top(module: str, qualname: str) -> bool:
    """Whether `qualname` in `module` is a top-level name or one of its members, whose
    examples test_public_examples_run runs (the API table names the module or a package
    above it that re-exports the name)."""
    home = HOMES.get(qualname.split(".")[0])
    return home is not None and (module == home or module.startswith(home + "."))


def _examples_in(node: ast.AST, module: str, qualname: str = "") -> list[str]:
    """Qualified names of the docstrings under `node` (itself included) that hold a
    doctest and are not the top-level names' or their members'."""
    found = []
    doc = ast.get_docstring(node) if isinstance(
        node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef) else None
    if doc and re.search(r"^\s*>>> ", doc, re.MULTILINE) and not _is_top(module, qualname):
        found.append(f"{module}.{qualname}".rstrip("."))
    for child in getattr(node, "body", ()):
        if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            found += _examples_in(child, module, f"{qualname}.{child.name}".lstrip("."))
    return found


def _modules_with_examples() -> list[str]:
    """Modules of the package with a doctest in a docstring other than the top-level
    names' (and their methods'), found in the source without importing it."""
    modules = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        if _examples_in(ast.parse(path.read_text(encoding="utf-8")), module):
            modules.append(module)
    return modules


def _run(tests: list[doctest.DocTest]) -> None:
    """Run `tests`; fail with doctest's report of every failing example."""
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    report: list[str] = []
    for test in tests:
        runner.run(test, out=report.append)
    failed, attempted = runner.summarize(verbose=False)
    assert attempted, "no examples found"
    assert not failed, "".join(report)


def _public(name: str) -> object:
    return getattr(importlib.import_module(HOMES[name]), name)


def _tests(obj: object, name: str) -> list[doctest.DocTest]:
    """The doctests of `obj` and of the methods defined with it, named after `name`."""
    tests = doctest.DocTestFinder().find(obj, name=f"fivdisc.{name}", globs={})
    return [test for test in tests if test.examples]


@pytest.mark.parametrize("name", TOP)
def test_public_name_has_examples(name):
    """A numpydoc Examples section on the name's own docstring, with an example that
    runs (one marked +SKIP only is no example)."""
    obj = _public(name)
    doc = inspect.getdoc(obj) or ""
    assert re.search(r"^Examples\n--------$", doc, re.MULTILINE), \
        f"fivdisc.{name} has no Examples section"
    examples = doctest.DocTestParser().get_examples(doc)
    running = [e for e in examples if not e.options.get(doctest.SKIP)]
    assert running, f"fivdisc.{name}'s Examples section has no example that runs"


@pytest.mark.parametrize("name", TOP)
def test_public_examples_run(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _run(_tests(_public(name), name))


@pytest.mark.parametrize("module", _modules_with_examples())
def test_other_examples_run(module, tmp_path, monkeypatch):
    """Examples outside the top-level names' docstrings: module docstrings, the
    sub-packages' names."""
    monkeypatch.chdir(tmp_path)
    tests = doctest.DocTestFinder().find(importlib.import_module(module), globs={})
    tests = [test for test in tests if test.examples
             and not _is_top(module, test.name.removeprefix(module).lstrip("."))]
    _run(tests)
