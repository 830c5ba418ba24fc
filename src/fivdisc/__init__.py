"""fivdisc: friction-induced vibration of a slider on a spinning elastic disc.

The public API::

    import fivdisc
    case = fivdisc.load_case("mycase.toml")             # or fivdisc.Case(...)
    result = fivdisc.simulate(case)                     # result.dataset is an xarray.Dataset
    print(result.summary())
    result.to_netcdf("run.nc"); fivdisc.open_result("run.nc") == result
    print(fivdisc.linear_stability(case))               # constant-speed cases

Plotting lives in :mod:`fivdisc.plots`, parameter sweeps in :mod:`fivdisc.sweep` and the
paper's cases in :mod:`fivdisc.paper`; they import matplotlib or dask only when used. The
example cases that ship with fivdisc are in :mod:`fivdisc.examples`.
"""

from importlib.metadata import version as _version

from fivdisc.analysis import (
    Equilibrium,
    LinearStability,
    classify,
    dominant_frequency,
    energy_balance,
    find_peaks,
    linear_stability,
    perturbation_test,
    separation_stats,
    sliding_equilibrium,
    spectrum,
    stability_map,
    stft,
)
from fivdisc.case import Case, load_case
from fivdisc.errors import CaseError, FivdiscError, ModeError, SimulationError
from fivdisc.model import Model, build_model
from fivdisc.plate import AnnularPlate, PlateMode
from fivdisc.result import Result, Summary, open_result
from fivdisc.simulate import simulate
from fivdisc.speed import SpeedProfile

__version__ = _version("fivdisc")

__all__ = [
    "AnnularPlate",
    "Case",
    "CaseError",
    "Equilibrium",
    "FivdiscError",
    "LinearStability",
    "ModeError",
    "Model",
    "PlateMode",
    "Result",
    "SimulationError",
    "SpeedProfile",
    "Summary",
    "__version__",
    "build_model",
    "classify",
    "dominant_frequency",
    "energy_balance",
    "find_peaks",
    "linear_stability",
    "load_case",
    "open_result",
    "perturbation_test",
    "separation_stats",
    "simulate",
    "sliding_equilibrium",
    "spectrum",
    "stability_map",
    "stft",
]
