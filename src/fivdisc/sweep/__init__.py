"""Parameter sweeps: many simulations, reduced to a few numbers each, stored resumably.

>>> from fivdisc import examples
>>> from fivdisc.sweep import load_sweep, run_sweep, open_sweep
>>> spec = load_sweep(examples.path("sweep_fig27"))
>>> spec.shape, spec.n_points
((40, 40), 1600)
>>> report = run_sweep(spec, "fig27.zarr")  # doctest: +SKIP
>>> open_sweep("fig27.zarr")["separated"]  # on the grid's axes  # doctest: +SKIP

See the documentation's page "Sweep files" (and :mod:`fivdisc.sweep.spec`) for the sweep
file format and the store's layout (:mod:`fivdisc.sweep.store`),
:mod:`fivdisc.sweep.sections` for the values at a section (Poincare-type reductions),
:mod:`fivdisc.sweep.separation` for the paper's separation maps (Fig. 27); the figures
of a sweep are in :mod:`fivdisc.plots`.
"""

from fivdisc._lazy import public

_API = {
    "fivdisc.errors": ("SweepError",),
    "fivdisc.sweep.spec": ("Sweep", "load_sweep"),
    "fivdisc.sweep.reductions": ("BUILTIN", "LyapunovSettings", "Reduction", "RunFailed"),
    "fivdisc.sweep.sections": ("Section",),
    "fivdisc.sweep.run": ("SweepReport", "run_sweep"),
    "fivdisc.sweep.separation": ("separation_sweep",),
    "fivdisc.sweep.store.sweep_store": ("SweepStore", "open_sweep"),
    "fivdisc.sweep.store.health": ("StoreHealth", "verify_store"),
}

__all__, __getattr__, __dir__ = public(globals(), _API)
