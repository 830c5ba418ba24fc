"""The kernels compile once per signature (issue 11, item 4).

numba types a Python int or bool passed to a compiled function as a literal and compiles
the callee again for each value (before the fix, 90 compiles instead of 74 for a first
simulation, ``_switch`` four times, ``evaluate`` twice). The kernels pass numpy scalars
instead (``dynamics.RIGHT``, ``switch.MODE_START``, ...). This test reads the kernel
sources and fails on any call of a separately compiled kernel function with a Python
int or bool constant, written out or named by a module constant. Functions inlined into
their callers (``inline="always"``) compile no library of their own and are exempt,
except where they hand the constant on to a compiled function: ``tangent.jvp`` given a
literal ``right`` compiled ``evaluate`` (with ``speed_at``, ``_piece`` and
``linearised_one``) twice more for the kernel with tangent vectors.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import fivdisc.core as kernels

SOURCES = sorted(Path(kernels.__file__).parent.glob("*.py"))


def _is_njit(decorator: ast.expr) -> tuple[bool, bool]:
    """(compiled, inlined) of one decorator."""
    call = decorator if isinstance(decorator, ast.Call) else None
    target = call.func if call else decorator
    if not (isinstance(target, ast.Name) and target.id == "njit"):
        return False, False
    inlined = any(k.arg == "inline" and isinstance(k.value, ast.Constant)
                  and k.value.value == "always" for k in (call.keywords if call else []))
    return True, inlined


def _compiled_functions() -> set[str]:
    """Names of kernel functions compiled into libraries of their own."""
    names = set()
    for path in SOURCES:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef):
                flags = [_is_njit(d) for d in node.decorator_list]
                if any(c and not i for c, i in flags):
                    names.add(node.name)
    return names


def _called_name(node: ast.Call) -> str:
    func = node.func
    return func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")


def _passed_on(compiled: set[str]) -> dict[str, set[int]]:
    """Inlined kernel function -> the positions of its parameters that it hands on, as
    they are, to a compiled kernel function (or to such a position of another inlined
    one): a literal given there reaches the compiled function as a literal."""
    inlined = {}
    for path in SOURCES:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef) and any(
                    c and i for c, i in map(_is_njit, node.decorator_list)):
                inlined[node.name] = node
    passed: dict[str, set[int]] = {name: set() for name in inlined}
    changed = True
    while changed:
        changed = False
        for name, node in inlined.items():
            params = [a.arg for a in node.args.args]
            for call in ast.walk(node):
                if not isinstance(call, ast.Call):
                    continue
                callee = _called_name(call)
                for position, arg in enumerate(call.args):
                    if not (isinstance(arg, ast.Name) and arg.id in params):
                        continue
                    if callee in compiled or position in passed.get(callee, ()):
                        index = params.index(arg.id)
                        if index not in passed[name]:
                            passed[name].add(index)
                            changed = True
    return passed


def _python_constant(node: ast.expr, module) -> object | None:
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        node = node.operand
    if isinstance(node, ast.Constant) and isinstance(node.value, int | bool):
        return node.value
    if isinstance(node, ast.Name):
        value = getattr(module, node.id, None)
        if type(value) in (int, bool):
            return value
    return None


def test_no_compiled_kernel_receives_a_python_literal():
    compiled = _compiled_functions()
    assert {"evaluate", "run", "_switch", "choose_phase"} <= compiled
    passed = _passed_on(compiled)
    # tangent.jvp hands its `right` on to evaluate: a literal there compiled evaluate
    # twice more (issue 29, item 1).
    assert 5 in passed["jvp"]
    found = []
    for path in SOURCES:
        module = importlib.import_module(f"fivdisc.core.{path.stem}")
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Call):
                continue
            name = _called_name(node)
            if name not in compiled and not passed.get(name):
                continue
            for position, arg in enumerate(node.args):
                if name not in compiled and position not in passed[name]:
                    continue
                if _python_constant(arg, module) is not None:
                    found.append(f"{path.name}:{node.lineno} {name}({ast.unparse(arg)}, ...)")
    assert not found, "Python literals passed to compiled kernels:\n" + "\n".join(found)
