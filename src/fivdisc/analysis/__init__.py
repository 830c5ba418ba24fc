"""Analyses of the slider-on-disc system: equilibrium, stability, spectra, trajectories,
periodic orbits, Lyapunov exponents.

The names below are imported on first use, so that importing one analysis module (say
:mod:`fivdisc.analysis.spectra`) does not import the others.
"""

from typing import TYPE_CHECKING

from fivdisc._lazy import homes, lazy_names

if TYPE_CHECKING:
    from fivdisc.analysis.boundary import stability_boundary
    from fivdisc.analysis.eigenbranches import eigen_branches
    from fivdisc.analysis.energy import energy_balance
    from fivdisc.analysis.equilibrium import Equilibrium, sliding_equilibrium
    from fivdisc.analysis.hopf import HopfPoint, hopf_points
    from fivdisc.analysis.lyapunov import LyapunovSpectrum, lyapunov
    from fivdisc.analysis.orbits import PeriodicOrbit, periodic_orbit
    from fivdisc.analysis.regimes import Regime, cross_check
    from fivdisc.analysis.spectra import (
        Periodicity,
        Spectrum,
        classify,
        dominant_frequency,
        find_peaks,
        spectrum,
        stft,
    )
    from fivdisc.analysis.stability import (
        LinearStability,
        PerturbationTest,
        linear_stability,
        perturbation_test,
        stability_map,
    )
    from fivdisc.analysis.trajectories import (
        friction_trajectory,
        phase_portrait,
        separation_intervals,
        separation_stats,
    )

_HOMES = homes({
    "fivdisc.analysis.boundary": ("stability_boundary",),
    "fivdisc.analysis.eigenbranches": ("eigen_branches",),
    "fivdisc.analysis.energy": ("energy_balance",),
    "fivdisc.analysis.hopf": ("HopfPoint", "hopf_points"),
    "fivdisc.analysis.equilibrium": ("Equilibrium", "sliding_equilibrium"),
    "fivdisc.analysis.lyapunov": ("LyapunovSpectrum", "lyapunov"),
    "fivdisc.analysis.orbits": ("PeriodicOrbit", "periodic_orbit"),
    "fivdisc.analysis.regimes": ("Regime", "cross_check"),
    "fivdisc.analysis.spectra": ("Periodicity", "Spectrum", "classify", "dominant_frequency",
                                 "find_peaks", "spectrum", "stft"),
    "fivdisc.analysis.stability": ("LinearStability", "PerturbationTest", "linear_stability",
                                   "perturbation_test", "stability_map"),
    "fivdisc.analysis.trajectories": ("friction_trajectory", "phase_portrait",
                                      "separation_intervals", "separation_stats"),
})

__all__ = [
    "Equilibrium",
    "HopfPoint",
    "LinearStability",
    "LyapunovSpectrum",
    "PeriodicOrbit",
    "Periodicity",
    "PerturbationTest",
    "Regime",
    "Spectrum",
    "classify",
    "cross_check",
    "dominant_frequency",
    "eigen_branches",
    "energy_balance",
    "find_peaks",
    "friction_trajectory",
    "hopf_points",
    "linear_stability",
    "lyapunov",
    "periodic_orbit",
    "perturbation_test",
    "phase_portrait",
    "separation_intervals",
    "separation_stats",
    "sliding_equilibrium",
    "spectrum",
    "stability_boundary",
    "stability_map",
    "stft",
]

__getattr__, __dir__ = lazy_names(globals(), _HOMES)
