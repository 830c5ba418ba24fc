"""Analyses of the slider-on-disc system: equilibrium, stability, Hopf points and their
first Lyapunov coefficients, spectra, trajectories, energy, periodic orbits and their
symmetry, Lyapunov exponents.

The names below are imported on first use, so that importing one analysis module (say
:mod:`fivdisc.analysis.spectra`) does not import the others.
"""

from fivdisc._lazy import public

_API = {
    "fivdisc.engine.equilibrium": ("Equilibrium", "sliding_equilibrium", "slip_phases"),
    "fivdisc.analysis.stability": ("LinearStability", "PerturbationTest", "linear_stability",
                                   "perturbation_test", "stability_map"),
    "fivdisc.analysis.boundary": ("stability_boundary",),
    "fivdisc.analysis.codimension": ("hopf_curve_lines", "hopf_curves"),
    "fivdisc.analysis.eigenbranches": ("eigen_branches",),
    "fivdisc.analysis.hopf": ("HopfPoint", "hopf_points"),
    "fivdisc.analysis.normalform": ("FirstLyapunov", "first_lyapunov", "lyapunov_coefficient"),
    "fivdisc.analysis.spectra": ("Peaks", "Periodicity", "Spectrum", "classify",
                                 "dominant_frequency", "find_peaks", "spectrum", "stft"),
    "fivdisc.analysis.trajectories": ("friction_trajectory", "phase_portrait",
                                      "separation_intervals", "separation_stats"),
    "fivdisc.analysis.energy": ("energy_balance",),
    "fivdisc.analysis.orbits": ("PeriodicOrbit", "periodic_orbit", "orbit_symmetry"),
    "fivdisc.analysis.symmetry": ("CaseSymmetry", "OrbitSymmetry", "case_symmetry"),
    "fivdisc.analysis.cycle": ("Cycle", "one_period"),
    "fivdisc.analysis.kinds": ("BifurcationKind",),
    "fivdisc.analysis.exponents": ("LyapunovSpectrum", "lyapunov"),
    "fivdisc.analysis.regimes": ("Regime", "cross_check"),
}

__all__, __getattr__, __dir__ = public(globals(), _API)
