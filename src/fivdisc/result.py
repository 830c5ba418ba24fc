"""Simulation results: an :class:`xarray.Dataset` with units, events, status and statistics."""

from __future__ import annotations

from dataclasses import dataclass
from os import PathLike

import numpy as np
import xarray as xr

PHASE_NAMES = ("slip", "stick", "separation")
EVENT_KINDS = ("stick", "slip", "reversal", "separation", "recontact")


def _var(dims, data, units: str, long_name: str, **attrs) -> xr.Variable:
    return xr.Variable(dims, data, attrs={"units": units, "long_name": long_name, **attrs})


def build_dataset(model, out_y: np.ndarray, out_aux: np.ndarray, times: np.ndarray,
                  events: tuple[np.ndarray, np.ndarray], attrs: dict) -> xr.Dataset:
    """Assemble the output dataset of one run.

    Parameters
    ----------
    model : fivdisc.model.Model
        The model that was integrated.
    out_y : ndarray
        ``(n_time, 2 (n + 2 S) [+ K])`` sampled states (the sliders' z, zdot already
        filled in contact), with the K energy accumulators last when recorded.
    out_aux : ndarray
        ``(n_time, 4 S + 1)``: per slider the normal force [N], friction force [N],
        phase and the disc's w under it [m]; then the disc speed [rad/s].
    times : ndarray
        Sample times [s].
    events : (ndarray, ndarray)
        Event times [s] and ``(n_event, 4)`` integer rows (kind, from phase, to phase,
        slider).
    attrs : dict
        Global attributes (status, message, statistics, case text, ...).
    """
    n, ns = model.n, model.n_sliders
    q = out_y[:, :n]
    q_dot = out_y[:, n + 2 * ns : 2 * n + 2 * ns]

    def block(what: str) -> np.ndarray:
        start = model.index(what)
        return out_y[:, start : start + ns]

    normal = out_aux[:, :ns]
    friction = out_aux[:, ns : 2 * ns]
    phase = out_aux[:, 2 * ns : 3 * ns]
    w_under = out_aux[:, 3 * ns : 4 * ns]
    ev_t, ev_i = events
    probes = np.asarray(model.case.simulation.probes, dtype=float).reshape(-1, 2)
    sliders = model.case.sliders
    per = ("time", "slider")
    flags = {"flag_values": np.array([0, 1, 2], dtype=np.int8),
             "flag_meanings": " ".join(PHASE_NAMES)}
    data = {
        "phi": _var(per, block("phi"), "rad", "slider circumferential angle"),
        "phi_dot": _var(per, block("phi_dot"), "rad/s", "slider angular velocity"),
        "disc_speed": _var("time", out_aux[:, 4 * ns], "rad/s", "disc spinning speed"),
        "normal_force": _var(per, normal, "N", "normal contact force"),
        "friction_force": _var(
            per, friction, "N", "friction force on the slider (positive along +phi)"
        ),
        "phase": _var(per, phase.astype(np.int8), "1", "contact phase", **flags),
        "z": _var(per, block("z"), "m", "slider normal displacement"),
        "z_dot": _var(per, block("z_dot"), "m/s", "slider normal velocity"),
        "gap": _var(
            per,
            model.kernel.row("sigma") * (block("z") - w_under),
            "m",
            "gap between slider and disc surface (positive when apart)",
        ),
        # einsum: numpy's BLAS matmul on this tall strided array is ~6x slower.
        "w": _var(("time", "probe"), np.einsum("tj,pj->tp", q, model.probe_shapes), "m",
                  "disc transverse displacement at the probes"),
        "q": _var(("time", "coordinate"), q, "m", "modal coordinates"),
        "q_dot": _var(("time", "coordinate"), q_dot, "m/s", "modal velocities"),
        "event_time": _var("event", ev_t, "s", "time of the phase switch"),
        "event_kind": _var(
            "event",
            np.array([EVENT_KINDS[k] for k in ev_i[:, 0]], dtype=object),
            "1",
            "kind of switch (" + ", ".join(EVENT_KINDS) + ")",
        ),
        "event_from": _var("event", ev_i[:, 1].astype(np.int8), "1", "phase before the switch",
                           **flags),
        "event_to": _var("event", ev_i[:, 2].astype(np.int8), "1", "phase after the switch",
                         **flags),
        "event_slider": _var("event", ev_i[:, 3].astype(np.int16), "1",
                             "slider that switched"),
    }
    n_dyn = model.state_size
    if out_y.shape[1] > n_dyn:
        from fivdisc._kernels.layout import ENERGY_NAMES

        data["energy_work"] = _var(
            ("time", "energy_term"), out_y[:, n_dyn:], "J",
            "work done since t = 0 by each kind of force (impact terms: sum of the jumps)",
        )
    coords = {
        "time": _var("time", times, "s", "time"),
        "coordinate": ("coordinate", list(model.labels),
                       {"units": "1", "long_name": "modal coordinate (C/D, k, l)"}),
        "k": _var("coordinate", model.k, "1", "nodal circles"),
        "l": _var("coordinate", model.l, "1", "nodal diameters"),
        "slider": ("slider", np.arange(ns), {"units": "1", "long_name": "slider index"}),
        "angle": _var("slider", np.array([s.angle for s in sliders]), "rad",
                      "space-fixed angle of the slider's base"),
        "face": ("slider", np.array([s.face for s in sliders], dtype=object),
                 {"units": "1", "long_name": "face of the disc the slider presses on"}),
        "track_radius": _var("slider", np.array([s.track_radius for s in sliders]), "m",
                             "radius of the slider's track"),
        "probe": ("probe", np.arange(len(probes)), {"units": "1", "long_name": "probe index"}),
        "probe_r": _var("probe", probes[:, 0], "m", "probe radius"),
        "probe_theta": _var("probe", probes[:, 1], "rad", "probe angle (space-fixed)"),
    }
    if "energy_work" in data:
        coords["energy_term"] = ("energy_term", list(ENERGY_NAMES),
                                 {"units": "1", "long_name": "kind of force"})
    return xr.Dataset(data, coords=coords, attrs=attrs)


def select_slider(ds: xr.Dataset, slider: int = 0) -> xr.Dataset:
    """The dataset as seen by one slider: per-slider variables at ``slider`` (the
    ``slider`` dimension dropped) and only that slider's events.

    Parameters
    ----------
    ds : xarray.Dataset
        A simulation dataset (a dataset without a ``slider`` dimension is returned as is).
    slider : int
        Slider index, from 0.

    Raises
    ------
    ValueError
        If ``slider`` is not an index of the dataset's sliders.
    """
    if "slider" not in ds.dims:
        return ds
    count = ds.sizes["slider"]
    if isinstance(slider, bool) or not isinstance(slider, int | np.integer) or not (
        0 <= slider < count
    ):
        raise ValueError(f"slider = {slider!r} is invalid: must be an index in [0, {count - 1}]"
                         f" (the run has {count} slider{'s' if count > 1 else ''})")
    out = ds.isel(slider=int(slider))
    if "event_slider" in ds and "event" in ds.dims:
        out = out.isel(event=np.flatnonzero(ds["event_slider"].values == slider))
    return out


@dataclass(frozen=True)
class Result:
    """Outcome of :func:`fivdisc.simulate`.

    Attributes
    ----------
    dataset : xarray.Dataset
        Sampled time histories, the event table and run attributes.
    """

    dataset: xr.Dataset

    @property
    def status(self) -> str:
        """``"success"``, ``"stopped"`` (early stop requested) or a failure name."""
        return str(self.dataset.attrs["status"])

    @property
    def message(self) -> str:
        """Human-readable account of how the run ended."""
        return str(self.dataset.attrs["message"])

    @property
    def ok(self) -> bool:
        """Whether the run ended as requested (finished or stopped early on purpose)."""
        return self.status in ("success", "stopped")

    def events(self, kind: str | None = None) -> np.ndarray:
        """Times [s] of the switches, optionally only those of one ``kind``."""
        ds = self.dataset
        times = ds["event_time"].values
        if kind is None:
            return times
        if kind not in EVENT_KINDS:
            raise ValueError(f"kind = {kind!r} is invalid: must be one of {EVENT_KINDS}")
        return times[ds["event_kind"].values == kind]

    def summary(self) -> dict:
        """Time in each phase [s], switches, separations, impacts, peak normal force [N],
        largest |w| at the probes [m], wall time [s].

        With several sliders the per-slider entries (time in each phase, separations,
        peak normal force) are lists, one item per slider.
        """
        ds = self.dataset
        dt = np.diff(ds["time"].values)
        kinds = ds["event_kind"].values
        sliders = ds["event_slider"].values
        count = ds.sizes["slider"]
        per: dict[str, list] = {"time_in_phase": [], "separations": [], "peak_normal_force": []}
        for j in range(count):
            phase = ds["phase"].values[:, j]
            per["time_in_phase"].append(
                {name: float(np.sum(dt[phase[:-1] == i])) for i, name in enumerate(PHASE_NAMES)}
            )
            per["separations"].append(int(np.sum((kinds == "separation") & (sliders == j))))
            force = ds["normal_force"].values[:, j]
            per["peak_normal_force"].append(float(np.nanmax(force, initial=np.nan)))
        one = {k: v[0] for k, v in per.items()} if count == 1 else per
        impacts = int(np.sum(kinds == "recontact")) if ds.attrs.get("impact", 1) else 0
        return {
            "status": self.status,
            "time_in_phase": one["time_in_phase"],
            "switches": int(kinds.size),
            "separations": one["separations"],
            "impacts": impacts,
            "peak_normal_force": one["peak_normal_force"],
            "max_abs_w": float(np.nanmax(np.abs(ds["w"].values), initial=0.0)),
            "wall_time": float(ds.attrs["wall_time"]),
        }

    def to_netcdf(self, path: str | PathLike[str]) -> None:
        """Write the dataset to a netCDF file atomically (a temporary file is renamed)."""
        from fivdisc.files import write_atomic

        write_atomic(path, self.dataset.to_netcdf)
