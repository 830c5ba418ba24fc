"""Commands that need an optional extra say so in one line, in the README's install form,
before any work (issue 13, item 1).

The environment without the extra is made by hiding its modules: ``sys.modules[name] =
None`` makes both the import system and fivdisc's look-up report the module missing, so
the commands run in this process as they would in an installation without the extra.
.ci/check-package runs ``fivdisc plot`` from a wheel installed without extras too.
"""

from __future__ import annotations

import importlib
import sys

import pytest
from click.testing import CliRunner

from fivdisc.cli import cli
from fivdisc.extras import EXTRAS, MissingExtraError, require

from support.cli import run_cli


@pytest.fixture
def without(monkeypatch):
    """Hide the modules of an extra (and their submodules already imported)."""

    def hide(extra: str) -> None:
        for module in EXTRAS[extra]:
            for name in [n for n in sys.modules if n == module or n.startswith(module + ".")]:
                monkeypatch.setitem(sys.modules, name, None)
            monkeypatch.setitem(sys.modules, module, None)

    return hide


@pytest.fixture
def no_work(monkeypatch):
    """Every computation a command could start fails the test."""

    def never(*args, **kwargs):
        raise AssertionError("the command started working before saying what it needs")

    for module, name in [("fivdisc.engine.simulation", "simulate"),
                         ("fivdisc.paper.reproduce", "reproduce"),
                         ("fivdisc.analysis.stability", "stability_map"),
                         ("fivdisc.sweep.run", "run_sweep"), ("fivdisc.sweep.spec", "load_sweep")]:
        monkeypatch.setattr(importlib.import_module(module), name, never)


COMMANDS = [
    ("plot", ["plot", "result.nc", "--kind", "spectrum"]),
    ("plot", ["stability", "--x", "normal_damping=0:1:2", "--y", "decay=0:1:2", "-o", "m.pdf"]),
    ("plot", ["reproduce", "--figures", "8", "-o", "{tmp}"]),
    ("plot", ["separation-map", "-o", "{tmp}/m.zarr"]),
    ("distributed", ["sweep", "sweep_fig27", "-o", "{tmp}/s.zarr"]),
    ("distributed", ["sweep", "--verify", "{tmp}/s.zarr"]),
    ("distributed", ["separation-map", "-o", "{tmp}/m.zarr"]),
    ("distributed", ["reproduce", "--all", "-o", "{tmp}"]),
    ("plot", ["bifurcation", "bifurcation-speed", "-o", "{tmp}/d.png"]),
    ("distributed", ["bifurcation", "bifurcation-speed", "-o", "{tmp}/d.png"]),
]


@pytest.mark.parametrize(("extra", "args"), COMMANDS, ids=[" ".join(a[:2]) for _, a in COMMANDS])
def test_command_without_its_extra_says_how_to_install_it(extra, args, without, no_work,
                                                          tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    without(extra)
    result = run_cli([a.format(tmp=tmp_path) for a in args])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith(f"error: fivdisc {args[0]}")
    assert f'pip install "fivdisc[{extra}]"' in line
    assert f'pip install ".[{extra}]"' in line  # the README's form, from a clone
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_commands_without_the_plot_extra_need_none(without, tmp_path, monkeypatch):
    """simulate, modes, examples and stability (without a figure) run without matplotlib.
    (.ci/check-package runs them from a wheel installed without any extra.)"""
    monkeypatch.chdir(tmp_path)
    without("plot")
    runner = CliRunner()
    assert runner.invoke(cli, ["modes"]).exit_code == 0
    assert runner.invoke(cli, ["examples"]).exit_code == 0
    assert runner.invoke(cli, ["stability"]).exit_code == 0
    case = tmp_path / "c.toml"
    case.write_text("[simulation]\nduration = 0.01\n")
    run = runner.invoke(cli, ["simulate", str(case), "--no-progress"])
    assert run.exit_code == 0, run.output


def test_python_plots_without_matplotlib(without):
    from fivdisc import plots

    without("plot")
    with pytest.raises(MissingExtraError, match=r'fivdisc.plots needs matplotlib, which is not '
                       r'installed: install the plot extra with pip install "fivdisc\[plot\]"'):
        plots.plot_timeseries(None, "phi")
    assert isinstance(MissingExtraError("x"), ImportError)


def test_require_passes_when_installed():
    require("plot", "this test")
    require("distributed", "this test")
