"""The house reads one way: fivdisc's modules import each other without circles, and
downwards through the layers case -> model -> kernels -> engine -> analysis -> sweep /
paper / cli.

The import graph is read from the sources (every ``import`` statement, those inside
functions and under ``TYPE_CHECKING`` included: a function-level import is a circle
postponed, a type-only one a dependency all the same). Importing ``a.b.c`` also runs the
packages ``a.b`` and ``a`` (unless the importer lives in them), and ``from package import
name`` of a lazily imported name (:mod:`fivdisc._lazy`) imports the module that defines it.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

import fivdisc

SOURCE = Path(fivdisc.__file__).parent

# Layers from the bottom, each a folder (the foundation: a few modules every layer uses);
# a module may import from its own layer and those below.
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("foundation", ("fivdisc.errors", "fivdisc.files", "fivdisc.extras", "fivdisc.limits",
                    "fivdisc._lazy", "fivdisc.examples")),
    # A case's keys and error messages, which its tables use: they import no table.
    ("case messages", ("fivdisc.case.tree", "fivdisc.case.messages")),
    ("case", ("fivdisc.case",)),
    ("model", ("fivdisc.model",)),
    ("core", ("fivdisc.core",)),
    ("engine", ("fivdisc.engine",)),
    ("analysis", ("fivdisc.analysis",)),
    ("continuation", ("fivdisc.continuation",)),
    ("top", ("fivdisc.plots", "fivdisc.sweep", "fivdisc.paper", "fivdisc.cli",
             "fivdisc.__main__", "fivdisc")),
)

# Imports that go up a layer on purpose: a method that hands its object to the layer
# above, imported when called. The circle test still counts them, so the layer above
# cannot import back.
ACCESSORS = {("fivdisc.engine.result", "fivdisc.plots"),  # Result.plot
             ("fivdisc.engine.result", "fivdisc.plots.result")}


def _modules() -> dict[str, tuple[Path, bool]]:
    """Module name -> (source file, is a package)."""
    out = {}
    for path in sorted(SOURCE.rglob("*.py")):
        parts = list(path.relative_to(SOURCE.parent).with_suffix("").parts)
        package = parts[-1] == "__init__"
        out[".".join(parts[:-1] if package else parts)] = (path, package)
    return out


MODULES = _modules()


def _lazy_homes(package: str) -> dict[str, str]:
    return getattr(importlib.import_module(package), "_HOMES", {}) if MODULES[package][1] else {}


def _targets(name: str) -> set[str]:
    """The fivdisc modules that importing module `name` may import."""
    path, package = MODULES[name]
    here = name if package else name.rpartition(".")[0]
    own_lazy = _lazy_homes(name)
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and own_lazy and all(
            own_lazy.get(alias.name) == node.module for alias in node.names
        ):
            continue  # a lazy package naming its own lazy names for type checkers
        if isinstance(node, ast.Import):
            wanted = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                stem = here.split(".")[: len(here.split(".")) - node.level + 1]
                base = ".".join([*stem, base] if base else stem)
            wanted = []
            for alias in node.names:
                full = f"{base}.{alias.name}"
                if full in MODULES:
                    wanted.append(full)
                elif base in MODULES and alias.name in _lazy_homes(base):
                    wanted += [base, _lazy_homes(base)[alias.name]]
                else:
                    wanted.append(base)
        else:
            continue
        for target in wanted:
            parts = target.split(".")
            for i in range(1, len(parts) + 1):
                module = ".".join(parts[:i])
                # The packages around the importer are already being imported.
                if module in MODULES and not (name == module or name.startswith(module + ".")):
                    found.add(module)
    return found


GRAPH = {name: _targets(name) for name in MODULES}


def _layer(module: str) -> int:
    """Index in LAYERS of the most specific prefix naming `module`."""
    best, length = None, -1
    for index, (_, names) in enumerate(LAYERS):
        for prefix in names:
            # The root package names itself only, not every module under it.
            inside = prefix != "fivdisc" and module.startswith(prefix.rstrip(".") + ".")
            matches = module == prefix or inside
            if matches and len(prefix) > length:
                best, length = index, len(prefix)
    assert best is not None, f"{module} is in no layer of LAYERS: place it"
    return best


def _circle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import circle of `graph` (its modules in order, the first repeated), or None."""
    state: dict[str, int] = {}  # 1 on the current path, 2 done
    path: list[str] = []

    def visit(module: str) -> list[str] | None:
        state[module] = 1
        path.append(module)
        for target in sorted(graph[module]):
            if state.get(target) == 1:
                return [*path[path.index(target):], target]
            if target not in state and (found := visit(target)):
                return found
        path.pop()
        state[module] = 2
        return None

    for module in sorted(graph):
        if module not in state and (found := visit(module)):
            return found
    return None


def test_the_graph_sees_function_level_and_type_only_imports():
    # Both kinds exist in the sources; a graph without them would miss circles.
    assert "fivdisc.plots.result" in GRAPH["fivdisc.engine.result"]  # inside Result.plot
    assert "fivdisc.sweep.sections" in GRAPH["fivdisc.sweep.reductions"]  # TYPE_CHECKING
    assert "fivdisc.analysis.stability" in GRAPH["fivdisc.paper.fig_stability"]  # a lazy name


def test_the_circle_finder_finds_a_circle():
    assert _circle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert _circle({"a": {"b"}, "b": set()}) is None


def test_no_import_circles():
    circle = _circle(GRAPH)
    assert circle is None, "import circle: " + " -> ".join(circle or [])


def test_imports_go_down_the_layers():
    upward = sorted(
        f"{module} ({LAYERS[_layer(module)][0]}) imports {target} ({LAYERS[_layer(target)][0]})"
        for module, targets in GRAPH.items() for target in targets
        if _layer(target) > _layer(module) and (module, target) not in ACCESSORS
    )
    assert not upward, "\n".join(upward)


@pytest.mark.parametrize("module", ["fivdisc.engine.simulation", "fivdisc.engine.conventions"])
def test_the_engine_does_not_import_the_package_root(module):
    # The root's names import the analyses; the engine below them must not use it.
    assert "fivdisc" not in GRAPH[module]


def test_no_module_is_named_like_a_public_name_of_its_package():
    # Importing fivdisc.analysis.exponents binds the module to fivdisc.analysis.exponents;
    # were it named lyapunov, it would hide the function fivdisc.analysis.lyapunov.
    clashes = []
    for package, (_, is_package) in MODULES.items():
        if not is_package:
            continue
        for name, home in _lazy_homes(package).items():
            if f"{package}.{name}" in MODULES:
                clashes.append(f"{package}.{name} is a module and a name from {home}")
    assert not clashes, "\n".join(clashes)


def _from_imports(module: str) -> list[ast.ImportFrom]:
    path = MODULES[module][0]
    return [node for node in ast.walk(ast.parse(path.read_text(), str(path)))
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module]


def _reaches_core(node: ast.ImportFrom) -> bool:
    return node.module.startswith("fivdisc.core") or (
        node.module == "fivdisc" and any(a.name == "core" for a in node.names))


def test_above_the_engine_nothing_reaches_the_core():
    # The analyses and everything above them use the core through the engine's face
    # (fivdisc.engine.integration, fivdisc.engine.evaluation).
    engine = _layer("fivdisc.engine")
    reaching = sorted(f"{module} imports the core"
                      for module in MODULES if _layer(module) > engine
                      for node in _from_imports(module) if _reaches_core(node))
    assert not reaching, "\n".join(reaching)
    # the check sees the engine's own import of it
    assert any(_reaches_core(node) for node in _from_imports("fivdisc.engine.evaluation"))


def test_no_private_name_crosses_a_layer():
    crossing = sorted(
        f"{module} imports {alias.name} from {node.module}"
        for module in MODULES
        for node in _from_imports(module)
        if node.module in MODULES and _layer(node.module) != _layer(module)
        for alias in node.names if alias.name.startswith("_")
    )
    assert not crossing, "\n".join(crossing)
