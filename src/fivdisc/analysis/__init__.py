"""Analyses of the slider-on-disc system: equilibrium, stability, eigenvalue branches,
Hopf points and boundaries, spectra, trajectories, periodic orbits, Lyapunov exponents."""

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
