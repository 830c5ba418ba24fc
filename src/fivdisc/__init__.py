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

Plotting lives in :mod:`fivdisc.plots`, parameter sweeps in :mod:`fivdisc.sweep`, the
analyses and continuation in :mod:`fivdisc.analysis` and :mod:`fivdisc.continuation`
(which hold more than is listed here) and the paper's cases in :mod:`fivdisc.paper`;
they import matplotlib or dask only when used. The example cases that ship with fivdisc
are in :mod:`fivdisc.examples`.

The names below are imported on first use, so that ``import fivdisc`` and the command
line start without scipy, xarray or matplotlib. The API is listed once, in ``_API``:
each module with the names it gives ``fivdisc``.
"""

from fivdisc._lazy import public

_API = {
    "fivdisc.errors": ("AnalysisError", "CaseError", "ConvergenceError", "FivdiscError",
                       "FivdiscWarning", "MissingExtraError", "ModeError", "SimulationError",
                       "SweepError"),
    "fivdisc.case": ("Case", "load_case"),
    "fivdisc.model.plate": ("AnnularPlate", "PlateMode"),
    "fivdisc.model.speed": ("SpeedProfile",),
    "fivdisc.model.build": ("Model", "build_model"),
    "fivdisc.model.layout": ("EventKind", "Phase"),
    "fivdisc.engine.simulation": ("simulate",),
    "fivdisc.engine.result": ("Result", "SliderSummary", "Summary", "open_result"),
    "fivdisc.engine.equilibrium": ("Equilibrium", "sliding_equilibrium"),
    "fivdisc.analysis.stability": ("LinearStability", "PerturbationTest", "linear_stability",
                                   "perturbation_test", "stability_map"),
    "fivdisc.analysis.boundary": ("stability_boundary",),
    "fivdisc.analysis.codimension": ("hopf_curves",),
    "fivdisc.analysis.eigenbranches": ("eigen_branches",),
    "fivdisc.analysis.hopf": ("HopfPoint", "hopf_points"),
    "fivdisc.analysis.spectra": ("Peaks", "Periodicity", "Spectrum", "classify",
                                 "dominant_frequency", "find_peaks", "spectrum", "stft"),
    "fivdisc.analysis.trajectories": ("separation_stats",),
    "fivdisc.analysis.energy": ("energy_balance",),
    "fivdisc.analysis.orbits": ("PeriodicOrbit", "periodic_orbit"),
    "fivdisc.analysis.kinds": ("BifurcationKind",),
    "fivdisc.analysis.exponents": ("LyapunovSpectrum", "lyapunov"),
    "fivdisc.continuation.settings": ("ContinuationSettings",),
    "fivdisc.continuation.walk": ("continue_orbit",),
    "fivdisc.continuation.from_hopf": ("hopf_cycles",),
    "fivdisc.continuation.branch": ("Branch", "open_branch"),
    "fivdisc.continuation.codim2": ("BifurcationCurve", "bifurcation_curve",
                                    "curve_from_branch", "open_curve"),
    "fivdisc.continuation.region": ("bistable_region",),
}


def _version() -> str:
    from importlib.metadata import version

    return version("fivdisc")


__all__, __getattr__, __dir__ = public(globals(), _API, computed={"__version__": _version})
