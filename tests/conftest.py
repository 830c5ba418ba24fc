"""Fixtures every folder of tests may use.

Plain helpers that test modules import by name are in ``tests/support/`` (small cases,
the command line, the CF checks) and the slow reference model in ``tests/reference/``;
both are on the path (``pythonpath`` in ``pyproject.toml``).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from fivdisc.case import Case


@pytest.fixture
def case_file(tmp_path: Path) -> Callable[[Case, str], Path]:
    """Write a case to a TOML file in the test's directory: ``case_file(case, name)``."""

    def write(case: Case, name: str = "case.toml") -> Path:
        path = tmp_path / name
        path.write_text(case.to_toml(), encoding="utf-8")
        return path

    return write
