"""Continuation of periodic orbits in one case key, through their bifurcations.

A *problem* (:mod:`~fivdisc.continuation.problem`: the orbit's shooting equations with
the key as one more unknown, and their corrector), its *settings*
(:mod:`~fivdisc.continuation.settings`), the *starts* of a branch
(:mod:`~fivdisc.continuation.starts`: an orbit, a Hopf point, a period doubling), the
*detection* and location of bifurcations between points
(:mod:`~fivdisc.continuation.detection`), the *walk* along the branch
(:mod:`~fivdisc.continuation.walk`) and its result, the *branch*
(:mod:`~fivdisc.continuation.branch`); a bifurcation followed in two keys
(:mod:`~fivdisc.continuation.codim2`) and the bistable region in two keys
(:mod:`~fivdisc.continuation.region`). The names below are imported on first use.
"""

from fivdisc._lazy import public

_API = {
    "fivdisc.continuation.settings": ("ContinuationSettings",),
    "fivdisc.continuation.walk": ("continue_orbit",),
    "fivdisc.continuation.from_hopf": ("hopf_cycles",),
    "fivdisc.continuation.starts": ("doubled_start",),
    "fivdisc.continuation.detection": ("Bifurcation",),
    "fivdisc.analysis.kinds": ("BifurcationKind",),
    "fivdisc.continuation.branch": ("Branch", "open_branch"),
    "fivdisc.continuation.codim2": ("BifurcationCurve", "CONDITIONS", "bifurcation_curve",
                                    "curve_from_branch", "open_curve"),
    "fivdisc.continuation.region": ("REGIONS", "bistable_region"),
}

__all__, __getattr__, __dir__ = public(globals(), _API)
