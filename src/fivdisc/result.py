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
        ``(n_time, 2 n + 4)`` sampled states (slider z, zdot already filled in contact).
    out_aux : ndarray
        ``(n_time, 5)``: normal force [N], friction force [N], phase, disc w under the
        slider [m], disc speed [rad/s].
    times : ndarray
        Sample times [s].
    events : (ndarray, ndarray)
        Event times [s] and ``(n_event, 3)`` integer rows (kind, from phase, to phase).
    attrs : dict
        Global attributes (status, message, statistics, case text, ...).
    """
    n = model.n
    q = out_y[:, :n]
    q_dot = out_y[:, n + 2 : 2 * n + 2]
    ev_t, ev_i = events
    probes = np.asarray(model.case.simulation.probes, dtype=float).reshape(-1, 2)
    data = {
        "phi": _var("time", out_y[:, n], "rad", "slider circumferential angle"),
        "phi_dot": _var("time", out_y[:, 2 * n + 2], "rad/s", "slider angular velocity"),
        "disc_speed": _var("time", out_aux[:, 4], "rad/s", "disc spinning speed"),
        "normal_force": _var("time", out_aux[:, 0], "N", "normal contact force"),
        "friction_force": _var(
            "time", out_aux[:, 1], "N", "friction force on the slider (positive along +phi)"
        ),
        "phase": _var(
            "time",
            out_aux[:, 2].astype(np.int8),
            "1",
            "contact phase",
            flag_values=np.array([0, 1, 2], dtype=np.int8),
            flag_meanings=" ".join(PHASE_NAMES),
        ),
        "z": _var("time", out_y[:, n + 1], "m", "slider normal displacement"),
        "z_dot": _var("time", out_y[:, 2 * n + 3], "m/s", "slider normal velocity"),
        "gap": _var(
            "time", out_y[:, n + 1] - out_aux[:, 3], "m", "gap between slider and disc surface"
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
                           flag_values=np.array([0, 1, 2], dtype=np.int8),
                           flag_meanings=" ".join(PHASE_NAMES)),
        "event_to": _var("event", ev_i[:, 2].astype(np.int8), "1", "phase after the switch",
                         flag_values=np.array([0, 1, 2], dtype=np.int8),
                         flag_meanings=" ".join(PHASE_NAMES)),
    }
    coords = {
        "time": _var("time", times, "s", "time"),
        "coordinate": ("coordinate", list(model.labels),
                       {"units": "1", "long_name": "modal coordinate (C/D, k, l)"}),
        "k": _var("coordinate", model.k, "1", "nodal circles"),
        "l": _var("coordinate", model.l, "1", "nodal diameters"),
        "probe": ("probe", np.arange(len(probes)), {"units": "1", "long_name": "probe index"}),
        "probe_r": _var("probe", probes[:, 0], "m", "probe radius"),
        "probe_theta": _var("probe", probes[:, 1], "rad", "probe angle (space-fixed)"),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


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
        """Time in each phase [s], switches, impacts, peak normal force [N], largest |w| [m]."""
        ds = self.dataset
        phase = ds["phase"].values
        dt = np.diff(ds["time"].values)
        spent = {name: float(np.sum(dt[phase[:-1] == i])) for i, name in enumerate(PHASE_NAMES)}
        kinds = ds["event_kind"].values
        impacts = int(np.sum(kinds == "recontact")) if ds.attrs.get("impact", 1) else 0
        return {
            "status": self.status,
            "time_in_phase": spent,
            "switches": int(kinds.size),
            "separations": int(np.sum(kinds == "separation")),
            "impacts": impacts,
            "peak_normal_force": float(np.nanmax(ds["normal_force"].values, initial=np.nan)),
            "max_abs_w": float(np.nanmax(np.abs(ds["w"].values), initial=0.0)),
            "wall_time": float(ds.attrs["wall_time"]),
        }

    def to_netcdf(self, path: str | PathLike[str]) -> None:
        """Write the dataset to a netCDF file atomically (a temporary file is renamed)."""
        from fivdisc.files import write_atomic

        write_atomic(path, self.dataset.to_netcdf)
