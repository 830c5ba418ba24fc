"""Parameter sweeps: many simulations, reduced to a few numbers each, stored resumably.

>>> from fivdisc import examples
>>> from fivdisc.sweep import load_sweep, run_sweep, open_sweep
>>> spec = load_sweep(examples.path("sweep_fig27"))
>>> report = run_sweep(spec, "fig27.zarr")  # doctest: +SKIP
>>> open_sweep("fig27.zarr")["separated"]  # doctest: +SKIP  (on the grid's axes)

See the documentation's page "Sweep files" (and :mod:`fivdisc.sweep.spec`) for the sweep
file format, :mod:`fivdisc.sweep.store` for the store layout,
:mod:`fivdisc.sweep.sections` for the values at a section (Poincare-type reductions),
:mod:`fivdisc.sweep.separation` for the paper's separation maps (Fig. 27) and
:mod:`fivdisc.sweep.bifurcation` for bifurcation diagrams.
"""

from fivdisc.sweep.bifurcation import plot_bifurcation
from fivdisc.sweep.reductions import (
    BUILTIN,
    LyapunovSettings,
    Reduction,
    RunFailed,
    SweepError,
)
from fivdisc.sweep.run import SweepReport, run_sweep, warm_kernel
from fivdisc.sweep.sections import Section
from fivdisc.sweep.separation import plot_separation_map, separation_sweep
from fivdisc.sweep.spec import Sweep, load_sweep, parse_range
from fivdisc.sweep.store import (
    StoreHealth,
    SweepStore,
    open_sweep,
    read_mask,
    store_lock,
    verify_store,
)

__all__ = [
    "BUILTIN",
    "LyapunovSettings",
    "Reduction",
    "RunFailed",
    "Section",
    "StoreHealth",
    "Sweep",
    "SweepError",
    "SweepReport",
    "SweepStore",
    "load_sweep",
    "open_sweep",
    "parse_range",
    "plot_bifurcation",
    "plot_separation_map",
    "read_mask",
    "run_sweep",
    "separation_sweep",
    "store_lock",
    "verify_store",
    "warm_kernel",
]
