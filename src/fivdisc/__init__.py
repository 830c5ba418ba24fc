"""fivdisc: friction-induced vibration of a slider on a spinning elastic disc.

The public API::

    import fivdisc
    case = fivdisc.load_case("mycase.toml")             # or fivdisc.Case(...)
    result = fivdisc.simulate(case)                     # result.dataset is an xarray.Dataset
    print(result.summary())
    result.to_netcdf("run.nc"); fivdisc.open_result("run.nc") == result
    print(fivdisc.linear_stability(case))               # constant-speed cases
    print(fivdisc.periodic_orbit(case))                 # Floquet multipliers
    print(fivdisc.continue_orbit(case, "speed.value", 4.0))   # a branch of orbits
    print(fivdisc.lyapunov(case, n=3))                  # Lyapunov exponents

Plotting lives in :mod:`fivdisc.plots`, parameter sweeps in :mod:`fivdisc.sweep` and the
paper's cases in :mod:`fivdisc.paper`; they import matplotlib or dask only when used. The
example cases that ship with fivdisc are in :mod:`fivdisc.examples`.

The names of ``__all__`` are imported on first use, so that ``import fivdisc`` and the
command line start without numba, xarray and scipy.
"""

from typing import TYPE_CHECKING, Any

from fivdisc._lazy import homes, lazy_names

if TYPE_CHECKING:
    from fivdisc.analysis.boundary import stability_boundary
    from fivdisc.analysis.branch import Branch, open_branch
    from fivdisc.analysis.continuation import continue_orbit
    from fivdisc.analysis.eigenbranches import eigen_branches
    from fivdisc.analysis.energy import energy_balance
    from fivdisc.analysis.equilibrium import Equilibrium, sliding_equilibrium
    from fivdisc.analysis.hopf import HopfPoint, hopf_points
    from fivdisc.analysis.hopf_cycle import hopf_cycles
    from fivdisc.analysis.lyapunov import LyapunovSpectrum, lyapunov
    from fivdisc.analysis.orbits import PeriodicOrbit, periodic_orbit
    from fivdisc.analysis.spectra import classify, dominant_frequency, find_peaks, spectrum, stft
    from fivdisc.analysis.stability import (
        LinearStability,
        linear_stability,
        perturbation_test,
        stability_map,
    )
    from fivdisc.analysis.trajectories import separation_stats
    from fivdisc.case import Case, load_case
    from fivdisc.errors import (
        AnalysisError,
        CaseError,
        ConvergenceError,
        FivdiscError,
        MissingExtraError,
        ModeError,
        SimulationError,
        SweepError,
    )
    from fivdisc.model import Model, build_model
    from fivdisc.plate import AnnularPlate, PlateMode
    from fivdisc.result import Result, Summary, open_result
    from fivdisc.simulate import simulate
    from fivdisc.speed import SpeedProfile

    __version__: str

__all__ = [
    "AnalysisError",
    "AnnularPlate",
    "Branch",
    "Case",
    "CaseError",
    "ConvergenceError",
    "Equilibrium",
    "FivdiscError",
    "HopfPoint",
    "LinearStability",
    "LyapunovSpectrum",
    "MissingExtraError",
    "ModeError",
    "Model",
    "PeriodicOrbit",
    "PlateMode",
    "Result",
    "SimulationError",
    "SpeedProfile",
    "Summary",
    "SweepError",
    "__version__",
    "build_model",
    "classify",
    "continue_orbit",
    "dominant_frequency",
    "eigen_branches",
    "energy_balance",
    "find_peaks",
    "hopf_cycles",
    "hopf_points",
    "linear_stability",
    "load_case",
    "lyapunov",
    "open_branch",
    "open_result",
    "periodic_orbit",
    "perturbation_test",
    "separation_stats",
    "simulate",
    "sliding_equilibrium",
    "spectrum",
    "stability_boundary",
    "stability_map",
    "stft",
]

# Name of __all__ -> the module that defines it (the imports above, for type checkers).
_HOMES = homes({
    "fivdisc.analysis.boundary": ("stability_boundary",),
    "fivdisc.analysis.branch": ("Branch", "open_branch"),
    "fivdisc.analysis.continuation": ("continue_orbit",),
    "fivdisc.analysis.eigenbranches": ("eigen_branches",),
    "fivdisc.analysis.energy": ("energy_balance",),
    "fivdisc.analysis.equilibrium": ("Equilibrium", "sliding_equilibrium"),
    "fivdisc.analysis.hopf": ("HopfPoint", "hopf_points"),
    "fivdisc.analysis.hopf_cycle": ("hopf_cycles",),
    "fivdisc.analysis.lyapunov": ("LyapunovSpectrum", "lyapunov"),
    "fivdisc.analysis.orbits": ("PeriodicOrbit", "periodic_orbit"),
    "fivdisc.analysis.spectra": (
        "classify", "dominant_frequency", "find_peaks", "spectrum", "stft"
    ),
    "fivdisc.analysis.stability": (
        "LinearStability", "linear_stability", "perturbation_test", "stability_map"
    ),
    "fivdisc.analysis.trajectories": ("separation_stats",),
    "fivdisc.case": ("Case", "load_case"),
    "fivdisc.errors": ("AnalysisError", "CaseError", "ConvergenceError", "FivdiscError",
                       "MissingExtraError", "ModeError", "SimulationError", "SweepError"),
    "fivdisc.model": ("Model", "build_model"),
    "fivdisc.plate": ("AnnularPlate", "PlateMode"),
    "fivdisc.result": ("Result", "Summary", "open_result"),
    "fivdisc.simulate": ("simulate",),
    "fivdisc.speed": ("SpeedProfile",),
})

_getattr, __dir__ = lazy_names(globals(), _HOMES)


def __getattr__(name: str) -> Any:
    """Import a public name on first use and keep it, so later look-ups are plain."""
    if name == "__version__":
        from importlib.metadata import version

        globals()[name] = version("fivdisc")
        return globals()[name]
    return _getattr(name)
