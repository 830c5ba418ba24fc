"""Analyses of the slider-on-disc system: equilibrium, stability, spectra, trajectories."""

from fivdisc.analysis.energy import energy_balance
from fivdisc.analysis.equilibrium import Equilibrium, sliding_equilibrium
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
    "LinearStability",
    "Periodicity",
    "PerturbationTest",
    "Spectrum",
    "classify",
    "dominant_frequency",
    "energy_balance",
    "find_peaks",
    "friction_trajectory",
    "linear_stability",
    "perturbation_test",
    "phase_portrait",
    "separation_intervals",
    "separation_stats",
    "sliding_equilibrium",
    "spectrum",
    "stability_map",
    "stft",
]
