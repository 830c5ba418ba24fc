"""The runs behind the paper's figures: the comparison row, the simulations shared
between figures, and how a figure's runs are stored in its data tree.
"""

from __future__ import annotations

from dataclasses import dataclass
from os import PathLike
from typing import TYPE_CHECKING

import xarray as xr

from fivdisc.case import Case
from fivdisc.engine.selection import select_slider
from fivdisc.engine.simulation import initial_state, simulate
from fivdisc.model.build import build_model
from fivdisc.paper.cases import FIGURES, PaperCase

if TYPE_CHECKING:
    pass

# Result variables a figure may draw, and the event table.
_KEEP = ("phi", "phi_dot", "w", "normal_force", "friction_force", "phase", "disc_speed",
         "event_time", "event_kind", "event_from", "event_slider")
_RUN_ATTRS = ("status", "message", "end_time", "impact", "case", "wall_time")
# The variables of _KEEP that have a slider dimension in a result, and the event table.
_PER_SLIDER = ("phi", "phi_dot", "normal_force", "friction_force", "phase")
_EVENTS = ("phase", "event_time", "event_kind", "event_from", "event_slider")
STFT_SEGMENT = 0.2  # [s]: 5 Hz resolution, fine enough to tell the disc modes apart
FMAX = 1000.0  # [Hz], the Nyquist frequency of the 2 kHz output
WINDOW = 5.0  # [s], windows of the per-stage frequency lists
FREQ_TOL = 1.0  # [Hz], a fivdisc frequency "is" the paper's if this close


@dataclass(frozen=True)
class Row:
    """One comparison of a paper statement with fivdisc.

    Attributes
    ----------
    figure
        Figure number.
    quantity
        What is compared.
    paper
        What the paper says or shows.
    fivdisc
        What fivdisc gives with its model (docs/model.md: skew gyroscopic terms).
    printed
        What fivdisc gives with the printed paper's gyroscopic sign, where measured.
    verdict
        "agrees", "partly", "differs" or "" (a measurement without a paper value).
    """

    figure: int
    quantity: str
    paper: str
    fivdisc: str
    printed: str = ""
    verdict: str = ""


class Runs:
    """The simulations of one process, each (case, start) run once.

    Only the variables figures draw are kept (see ``_KEEP``), to bound memory.

    Parameters
    ----------
    sweep_dir
        Directory of the Zarr stores of Fig. 27's sweeps, which a later call resumes
        or reuses; None: a temporary directory, removed afterwards.
    sweep_workers
        Processes of the sweeps' pool (default: the number of CPUs).
    progress
        Show the sweeps' progress bars.
    """

    def __init__(self, sweep_dir: str | PathLike[str] | None = None,
                 sweep_workers: int | None = None, progress: bool = False) -> None:
        self._done: dict[tuple[Case, int | None], xr.Dataset] = {}
        self.sweep_dir = sweep_dir
        self.sweep_workers = sweep_workers
        self.progress = progress

    def get(self, case: Case, start_from: int | None = None) -> xr.Dataset:
        """The result dataset of `case`.

        Parameters
        ----------
        case
            The case.
        start_from
            Figure whose case's perturbed sliding equilibrium is the initial state;
            None: the case's own ``simulation.initial_state``.
        """
        key = (case, start_from)
        if key not in self._done:
            initial = None
            if start_from is not None:
                initial = initial_state(build_model(FIGURES[start_from].case))
            ds = simulate(case, initial=initial).dataset
            # A deep copy: the kept variables are views of the run's whole state buffer.
            # The paper's cases have one slider: its variables are kept as plain series.
            self._done[key] = select_slider(ds[list(_KEEP)], 0).copy(deep=True)
        return self._done[key]

    def printed(self, case: Case, start_from: int | None = None) -> xr.Dataset:
        """The run of `case` with the printed paper's gyroscopic sign."""
        return self.get(case.replace({"simulation.printed_gyroscopic_sign": True}), start_from)


# --- storing runs ----------------------------------------------------------------------------


def _with_slider(ds: xr.Dataset) -> xr.Dataset:
    """A run kept by :class:`Runs` (slider 0 selected) back in the result layout, with its
    ``slider`` dimension of one."""
    scalars = [c for c in ("slider", "angle", "face", "track_radius") if c in ds.coords]
    out = ds.drop_vars(scalars)
    for name in _PER_SLIDER:
        if name in out:
            out[name] = out[name].expand_dims("slider", axis=-1)
    return out.assign_coords({c: ("slider", [ds[c].item()], ds[c].attrs) for c in scalars})


def pack(pc: PaperCase, runs: dict[str, xr.Dataset], variables: tuple[str, ...]
          ) -> xr.DataTree:
    """Runs as the groups of one tree, each in the result layout (see :func:`compute`)."""
    from fivdisc.engine.conventions import global_attrs

    groups = {}
    for label, ds in runs.items():
        sub = _with_slider(ds[list(dict.fromkeys([*variables, *_EVENTS]))])
        name = f"{pc.stem}{'_' + label if label != 'main' else ''}"
        run = ("" if label == "main" else f" (run {label})")
        sub.attrs = {**global_attrs(f"fivdisc simulation of {name}: Fig. {pc.figure}{run}",
                                    "fivdisc.paper.compute"),
                     "case_name": name, **{key: ds.attrs[key] for key in _RUN_ATTRS}}
        groups[label] = sub
    return xr.DataTree.from_dict(groups)


def unpack(data: xr.DataTree, label: str) -> xr.Dataset:
    """One run of :func:`pack`'s tree, slider 0 selected as :class:`Runs` keeps it."""
    return select_slider(data[label].to_dataset(), 0)


def labels_of(data: xr.DataTree) -> list[str]:
    return list(data.children)


