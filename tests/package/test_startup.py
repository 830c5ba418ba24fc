"""``import fivdisc`` and the command line's help start light (issue 11, item 3): the
public names are imported on first use, the commands import their machinery when they run.

Each check runs in a fresh process, where nothing else has imported the heavy modules yet.
How long the start takes is measured by ``benchmarks/bench_startup.py``.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import pytest

import fivdisc

HEAVY = ("scipy.optimize", "xarray", "matplotlib", "dask")

# Runs CODE (which may end the process, as click does after --help), then prints which
# of HEAVY were imported, as the last line of stdout.
_PROBE = """
import json, sys
try:
{code}
finally:
    print(json.dumps([m for m in {heavy!r} if m in sys.modules]))
"""
# What the console script `fivdisc` runs.
_CLI = "    from fivdisc.cli import main\n    main()"


def _run(code: str, *args: str) -> subprocess.CompletedProcess:
    """A fresh interpreter running `code` with `args`, on the fivdisc under test."""
    source = str(Path(fivdisc.__file__).parents[1])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [source, *filter(None, [os.environ.get("PYTHONPATH")])])}
    return subprocess.run([sys.executable, "-c", code, *args], env=env, capture_output=True,
                          text=True, timeout=120)


@pytest.mark.parametrize(("code", "args", "shows"), [
    ("    import fivdisc", (), ""),
    (_CLI, ("--help",), "Usage: fivdisc [OPTIONS] COMMAND"),
    (_CLI, ("simulate", "--help"), "Usage: fivdisc simulate [OPTIONS] [CASE_FILE]"),
], ids=["import fivdisc", "fivdisc --help", "fivdisc simulate --help"])
def test_start_imports_no_heavy_module(code, args, shows):
    out = _run(_PROBE.format(code=code, heavy=HEAVY), *args)
    assert out.returncode == 0, out.stderr
    assert shows in out.stdout
    assert json.loads(out.stdout.splitlines()[-1]) == []


@pytest.mark.parametrize("name", sorted(set(fivdisc.__all__) - {"__version__"}))
def test_public_name_is_the_object_of_its_home_module(name):
    obj = getattr(fivdisc, name)
    assert obj is getattr(importlib.import_module(obj.__module__), name)
    assert name in dir(fivdisc)


def test_version_is_the_installed_one():
    assert "__version__" in dir(fivdisc)
    assert fivdisc.__version__ == version("fivdisc")


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="module 'fivdisc' has no attribute 'simulation'"):
        fivdisc.simulation  # noqa: B018
    assert not hasattr(fivdisc, "__wrapped__")


def test_the_simulator_leaves_the_netcdf_library_to_the_warm_up():
    """Importing the simulator imports no netCDF library: ``fivdisc simulate`` imports it in
    a thread while its kernel integrates (fivdisc.engine.preload), and the waiter it gets returns
    only once it is imported."""
    code = (
        "import sys\n"
        "import fivdisc.engine.simulation\n"
        "print(sorted(m for m in ('xarray', 'netCDF4') if m in sys.modules))\n"
        "from fivdisc.engine.preload import warm_up\n"
        "wait = warm_up('netcdf')\n"
        "wait()\n"
        "print(sorted(m for m in ('xarray', 'netCDF4') if m in sys.modules))\n"
    )
    out = _run(code)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == ["[]", "['netCDF4']"]


def test_simulate_writes_its_file_without_xarray(tmp_path):
    """``fivdisc simulate`` writes its netCDF file from the run's record (fivdisc.engine.record):
    xarray, with pandas and the array libraries it probes for, was over a second of
    processor time of a short run's process (issue 29, item 2)."""
    case = tmp_path / "short.toml"
    case.write_text("[simulation]\nduration = 0.01\n")
    heavy = ("xarray", "pandas", "dask", "distributed", "matplotlib")
    out = _run(_PROBE.format(code=_CLI, heavy=heavy), "simulate", str(case), "-o",
               str(tmp_path / "short.nc"), "--no-progress")
    assert out.returncode == 0, out.stderr
    assert "wrote" in out.stdout
    assert json.loads(out.stdout.splitlines()[-1]) == []
    assert fivdisc.open_result(tmp_path / "short.nc").ok


def test_the_simulators_model_imports_no_root_finder(tmp_path, monkeypatch):
    """Building a model (the disc's modes: Bessel roots and the peaks of their shapes, and
    their values under the sliders and probes) imports neither scipy.optimize nor
    scipy.special, a quarter to a third of a second of every short run each, once an
    earlier process stored the geometry's modes (fivdisc.model.mode_cache;
    tests/model/test_plate.py checks they are the solved ones). A track no packaged
    example has (tests/model/test_mode_seed.py covers those), so the first solves."""
    monkeypatch.setenv("FIVDISC_CACHE_DIR", str(tmp_path))
    code = (
        "import sys, tomllib\n"
        "from fivdisc import examples\n"
        "from fivdisc.case import Case\n"
        "from fivdisc.model.build import build_model\n"
        "from fivdisc.engine.equilibrium import initial_state\n"
        "data = tomllib.loads(examples.path('fig10').read_text())\n"
        "data['slider']['track_radius'] = 0.0987\n"
        "model = build_model(Case(**data))\n"
        "initial_state(model)\n"
        "print(sorted(m for m in ('scipy.optimize', 'scipy.special', 'scipy.linalg', "
        "'matplotlib', 'dask', 'xarray') if m in sys.modules))\n"
    )
    first = _run(code)
    assert first.returncode == 0, first.stderr
    assert "scipy.special" in first.stdout  # the values on the new track solved, and stored
    out = _run(code)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines()[-1] == "[]"
