"""Matplotlib figures: simulation results (the paper's Figs. 4-26), stability maps and
boundaries, Hopf curves with their codimension-two points, eigenvalue branches, branches
of periodic orbits, bifurcation diagrams and separation maps of sweeps.

Every function draws into ``ax`` (a new figure when None, where it takes one) and
returns the Figure without showing it. Matplotlib (the ``plot`` extra) is imported only
when a figure is drawn; the names below are imported on first use.
"""

from fivdisc._lazy import public

_API = {
    "fivdisc.plots.kinds": ("KINDS",),
    "fivdisc.plots.result": ("plot_friction", "plot_kind", "plot_normal_force",
                             "plot_phase_portrait", "plot_spectrogram", "plot_spectrum",
                             "plot_timeseries"),
    "fivdisc.plots.stability": ("plot_eigen_branches", "plot_hopf_curves",
                                "plot_stability_boundary", "plot_stability_map"),
    "fivdisc.plots.branch": ("plot_branch",),
    "fivdisc.plots.sweep": ("plot_bifurcation", "plot_separation_map"),
    "fivdisc.plots.region": ("plot_bifurcation_curve", "plot_bistable_region"),
}

__all__, __getattr__, __dir__ = public(globals(), _API)
