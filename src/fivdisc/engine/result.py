"""Simulation results: an :class:`xarray.Dataset` with units, events, status and statistics.

A result dataset follows the CF conventions (see :mod:`fivdisc.engine.conventions`): every
variable has ``units`` and ``long_name``, the time coordinate ``standard_name`` and
``axis``, the phases ``flag_values`` and ``flag_meanings``. :func:`open_result` reads a
saved result back, equal to the run that wrote it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from fivdisc.engine.record import Record
from fivdisc.engine.selection import select_slider  # noqa: F401 - its documented path
from fivdisc.errors import FivdiscError
from fivdisc.model.layout import ENERGY_NAMES, EventKind, Phase

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.figure import Figure

    from fivdisc.case import Case
    from fivdisc.model.speed import SpeedProfile

PHASE_NAMES = tuple(p.label for p in Phase)
# Run attributes that are arrays (one entry per slider or state component).
_ARRAY_ATTRS = ("final_phase", "final_state")
EVENT_KINDS = tuple(k.label for k in EventKind)
# Every simulation result keeps some of these (a reproduced figure's runs only what the
# figure draws, and the phases).
_RESULT_VARIABLES = ("phase", "phi", "phi_dot", "q", "w", "normal_force", "friction_force")


def _var(dims, data, units: str, long_name: str, **attrs) -> tuple:
    return dims, data, {"units": units, "long_name": long_name, **attrs}


def build_dataset(model, out_y: np.ndarray, out_aux: np.ndarray, times: np.ndarray,
                  events: tuple[np.ndarray, np.ndarray], attrs: dict) -> Record:
    """Assemble the output of one run, as the :class:`~fivdisc.engine.record.Record` that
    becomes the result's dataset.

    Parameters
    ----------
    model : fivdisc.model.build.Model
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
    sl, col = model.slices, model.columns
    q = out_y[:, sl.q]
    q_dot = out_y[:, sl.q_dot]

    def block(what: str) -> np.ndarray:
        return out_y[:, getattr(sl, what)]

    normal = out_aux[:, col.normal_force]
    friction = out_aux[:, col.friction_force]
    phase = out_aux[:, col.phase]
    w_under = out_aux[:, col.w]
    ev_t, ev_i = events
    probes = np.asarray(model.case.simulation.probes, dtype=float).reshape(-1, 2)
    sliders = model.case.sliders
    per = ("time", "slider")
    flags = {"flag_values": np.array([0, 1, 2], dtype=np.int8),
             "flag_meanings": " ".join(PHASE_NAMES)}
    data = {
        "phi": _var(per, block("phi"), "rad", "slider circumferential angle"),
        "phi_dot": _var(per, block("phi_dot"), "rad/s", "slider angular velocity"),
        "disc_speed": _var("time", out_aux[:, col.disc_speed], "rad/s", "disc spinning speed"),
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
            np.array([EVENT_KINDS[k] for k in ev_i[:, 0]], dtype=str),
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
    if out_y.shape[1] > model.state_size:
        data["energy_work"] = _var(
            ("time", "energy_term"), out_y[:, sl.energy], "J",
            "work done since t = 0 by each kind of force (impact terms: sum of the jumps)",
        )
    coords = {
        "time": _var("time", times, "s", "time", standard_name="time", axis="T"),
        "coordinate": ("coordinate", list(model.labels),
                       {"units": "1", "long_name": "modal coordinate (C/D, k, l)"}),
        "k": _var("coordinate", model.k, "1", "nodal circles"),
        "l": _var("coordinate", model.l, "1", "nodal diameters"),
        "slider": ("slider", np.arange(model.n_sliders),
                   {"units": "1", "long_name": "slider index"}),
        "angle": _var("slider", np.array([s.angle for s in sliders]), "rad",
                      "space-fixed angle of the slider's base"),
        "face": ("slider", np.array([s.face for s in sliders], dtype=str),
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
    from fivdisc.engine.conventions import global_attrs

    title = f"fivdisc simulation: {describe_run(model.case, model.speed)}"
    attrs = {**global_attrs(title, "fivdisc.simulate"), "case_name": "", **attrs}
    return Record(data, coords, attrs)


def describe_run(case: Case, speed: SpeedProfile | None = None) -> str:
    """A short description of a run: sliders, disc speed and duration.

    Parameters
    ----------
    case
        The case.
    speed
        The speed profile the run used, if it overrides the case's.
    """
    from fivdisc.model.speed import SpeedProfile

    table = case.speed
    own = SpeedProfile.from_case(table)
    if speed is not None and not (np.array_equal(speed.knots, own.knots)
                                  and np.array_equal(speed.coefficients, own.coefficients)):
        how = "disc speed given as a function of time"
    elif table.profile == "constant":
        how = f"disc at {table.value:.4g} rad/s"
    elif table.profile == "decelerating":
        how = f"disc slowing from {table.initial:.4g} rad/s to rest in {table.duration:g} s"
    elif table.profile == "accelerating":
        how = f"disc speeding up from {table.initial:.4g} rad/s at {table.rate:g} rad/s^2"
    else:
        how = "disc speed from a table"
    count = len(case.sliders)
    return f"{count} slider{'s' if count > 1 else ''}, {how}, {case.simulation.duration:g} s"


def _disc_thickness(ds: xr.Dataset) -> float:
    """The disc thickness [m] of the case a result was run with (nan if not recorded)."""
    import tomllib

    try:
        return float(tomllib.loads(ds.attrs["case"])["disc"]["thickness"])
    except (KeyError, ValueError, TypeError):
        return float("nan")


@dataclass(frozen=True)
class SliderSummary:
    """What one slider did in a run (see :class:`Summary`).

    Attributes
    ----------
    time_in_phase : dict
        Phase name (slip, stick, separation) -> time spent in it [s], from the output
        samples.
    separations : int
        Times the slider left the disc.
    peak_normal_force : float
        Largest normal contact force [N] (nan if no sample).

    Examples
    --------
    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.05}))
    >>> slider = result.summary().sliders[0]
    >>> {phase: round(t, 4) for phase, t in slider.time_in_phase.items()}  # [s]
    {'slip': 0.0237, 'stick': 0.0263, 'separation': 0.0}
    >>> slider.separations, round(slider.peak_normal_force)
    (0, 669)
    """

    time_in_phase: dict[str, float]
    separations: int
    peak_normal_force: float


@dataclass(frozen=True)
class Summary:
    """The numbers that sum up a run, as :meth:`Result.summary` returns them.

    ``str(summary)`` is what ``fivdisc simulate`` prints; :meth:`to_dataframe` gives one
    row per slider.

    Attributes
    ----------
    status : str
        ``"success"``, ``"stopped"`` or a failure name (see :attr:`Result.status`).
    end_time : float
        Simulated time reached [s].
    sliders : tuple of SliderSummary
        Per slider, in order.
    switches : int
        Switches of the run: instants at which one or more sliders change phase (what
        ``simulation.max_switches`` counts).
    impacts : int
        Plastic impacts at re-contact (0 when ``simulation.impact`` is off).
    max_abs_w : float
        Largest |w| at the probes [m].
    wall_time : float
        Time the integration took [s] (without building the model and the start).
    disc_thickness : float
        The disc's thickness h [m] (nan if the file does not say). Linear plate theory
        assumes |w| small against h: the printed summary notes when ``max_abs_w``
        exceeds it (runs end as diverged beyond 25 h, see ``simulate``).
    phase_changes : int
        Phase changes of all sliders (the rows of the event table; one switch may change
        several sliders' phases); -1 if not known.
    degenerate : str
        Why the case is degenerate (no preload, no friction, no probes, a response below
        any physical scale; see :func:`fivdisc.engine.simulation.degenerate`), "" if it is not.

    Examples
    --------
    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.05}))
    >>> summary = result.summary()
    >>> summary.status, summary.switches, summary.separations, summary.impacts
    ('success', 18, 0, 0)
    >>> print(f"{summary.max_abs_w * 1e3:.2f} mm, {summary.peak_normal_force:.1f} N")
    4.34 mm, 668.6 N
    >>> summary.to_dataframe().columns.tolist()  # one row per slider
    ['slip [s]', 'stick [s]', 'separation [s]', 'separations', 'peak normal force [N]']
    """

    status: str
    end_time: float
    sliders: tuple[SliderSummary, ...]
    switches: int
    impacts: int
    max_abs_w: float
    wall_time: float
    disc_thickness: float = float("nan")
    phase_changes: int = -1
    degenerate: str = ""

    @property
    def separations(self) -> int:
        """Separations of all sliders."""
        return sum(s.separations for s in self.sliders)

    @property
    def peak_normal_force(self) -> float:
        """Largest normal contact force of any slider [N]."""
        return max(s.peak_normal_force for s in self.sliders)

    def to_dict(self) -> dict[str, Any]:
        """The summary as plain Python values (``sliders`` a list of dicts)."""
        return asdict(self)

    def to_dataframe(self) -> pd.DataFrame:
        """One row per slider: time in each phase [s], separations, peak normal force [N]."""
        import pandas as pd

        rows = [{**{f"{k} [s]": v for k, v in s.time_in_phase.items()},
                 "separations": s.separations, "peak normal force [N]": s.peak_normal_force}
                for s in self.sliders]
        return pd.DataFrame(rows, index=pd.RangeIndex(len(rows), name="slider"))

    def lines(self) -> list[str]:
        """The summary as lines of text (what ``str()`` joins)."""
        several = len(self.sliders) > 1
        out = [f"status: {self.status} at t = {self.end_time:.6g} s"]
        for j, s in enumerate(self.sliders):
            spent = ", ".join(f"{k} {v:.4g} s" for k, v in s.time_in_phase.items())
            out.append(f"{f'slider {j} ' if several else ''}time in phase: {spent}")
        changes = (f" ({self.phase_changes} phase changes)"
                   if self.phase_changes not in (-1, self.switches) else "")
        out.append(f"switches: {self.switches}{changes}, separations: {self.separations}, "
                   f"impacts: {self.impacts}")
        peaks = ", ".join(f"{s.peak_normal_force:.6g}" for s in self.sliders)
        at_probes = ("not recorded" if np.isnan(self.max_abs_w)
                     else f"{self.max_abs_w:.6g} m")
        out.append(f"peak normal force: {peaks} N, largest |w| at probes: {at_probes}")
        if self.degenerate:
            out.append(f"warning: degenerate case: {self.degenerate}")
        if self.max_abs_w > self.disc_thickness:
            out.append(f"note: the disc deflected by up to {1e3 * self.max_abs_w:.3g} mm, "
                       f"{self.max_abs_w / self.disc_thickness:.3g} times its thickness "
                       f"h = {1e3 * self.disc_thickness:.3g} mm; linear plate theory assumes "
                       "|w| small against h. The paper's parameters do this too (Table 1's "
                       "500 N preload on a 2 mm disc): see 'Range of validity' in the "
                       "model docs")
        out.append(f"wall time: {self.wall_time:.3g} s (integration only)")
        return out

    def __str__(self) -> str:
        return "\n".join(self.lines())

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:  # IPython, Jupyter
        printer.text(str(self))


class Result:
    """Outcome of :func:`fivdisc.simulate`, or of :func:`open_result` on a saved one.

    Results compare equal, pickle and round-trip through netCDF (:meth:`to_netcdf`,
    :func:`open_result`) unchanged.

    Parameters
    ----------
    dataset : xarray.Dataset or fivdisc.engine.record.Record
        Sampled time histories, the event table and run attributes; a simulation gives a
        record, which becomes a dataset when :attr:`dataset` is first read (the summary
        and :meth:`to_netcdf` do not need it).

    See Also
    --------
    fivdisc.simulate : Makes one.
    open_result : Reads one written by :meth:`to_netcdf`.

    Examples
    --------
    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.05}))
    >>> result.status, result.ok, result.message
    ('success', True, 'reached t = 0.05 s')

    The histories are an :class:`xarray.Dataset`, sampled at ``simulation.output_rate``
    (10 kHz here), with the event table:

    >>> ds = result.dataset
    >>> ds["normal_force"].dims, ds["normal_force"].attrs["units"]
    (('time', 'slider'), 'N')
    >>> print(result.events("stick")[:3].round(4))  # [s]
    [0.0006 0.0065 0.0128]
    >>> print(f"{float(ds['normal_force'].sel(time=0.02, slider=0)):.1f} N")
    598.1 N

    The slider's variables as a table, one row per sample and slider:

    >>> list(result.to_dataframe().columns)
    ['phi', 'phi_dot', 'disc_speed', 'normal_force', 'friction_force', 'phase', 'z', 'z_dot', 'gap']
    """

    __slots__ = ("_data",)

    def __init__(self, dataset: xr.Dataset | Record) -> None:
        self._data = dataset

    @property
    def dataset(self) -> xr.Dataset:
        """Sampled time histories, the event table and run attributes."""
        if isinstance(self._data, Record):
            self._data = self._data.to_xarray()
        return self._data

    def __getstate__(self) -> xr.Dataset | Record:
        return self._data

    def __setstate__(self, state: xr.Dataset | Record) -> None:
        self._data = state

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Result) and self.dataset.identical(other.dataset)

    __hash__ = None  # type: ignore[assignment]  # mutable content

    def __repr__(self) -> str:
        ds = self._data
        name = ds.attrs.get("case_name") or "run"
        return (f"<fivdisc.Result {name}: {self.status}, {ds.attrs.get('end_time', np.nan):.6g}"
                f" s simulated, {ds.sizes.get('slider', 1)} slider(s), {ds.sizes['time']} "
                f"samples, {ds.sizes.get('event', 0)} events>")

    def __str__(self) -> str:
        title = self._data.attrs.get("title", "fivdisc simulation")
        return f"{self!r}\n{title}\n{self.summary()}"

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:  # IPython, Jupyter
        printer.text(str(self))

    @property
    def name(self) -> str:
        """Name of the case (its file or example), "" if not named (see :meth:`named`)."""
        return str(self._data.attrs.get("case_name", ""))

    def named(self, name: str) -> Result:
        """The same result with the case's name (e.g. its file's stem) in its title.

        Parameters
        ----------
        name
            The name, e.g. ``"fig10"``; plots and ``repr`` show it.
        """
        ds = self._data.copy()
        title = str(ds.attrs.get("title", "fivdisc simulation"))
        what = title.split(": ", 1)[-1]
        ds.attrs.update(case_name=name, title=f"fivdisc simulation of {name}: {what}")
        return Result(ds)

    @property
    def status(self) -> str:
        """``"success"``, ``"stopped"`` (early stop requested) or a failure name."""
        return str(self._data.attrs["status"])

    @property
    def message(self) -> str:
        """Human-readable account of how the run ended."""
        return str(self._data.attrs["message"])

    @property
    def ok(self) -> bool:
        """Whether the run ended as requested (finished or stopped early on purpose)."""
        return self.status in ("success", "stopped")

    def events(self, kind: str | None = None) -> np.ndarray:
        """Times [s] of the switches, optionally only those of one ``kind``."""
        ds = self._data
        times = ds["event_time"].values
        if kind is None:
            return times
        if kind not in EVENT_KINDS:
            raise ValueError(f"kind = {kind!r} is invalid: must be one of {EVENT_KINDS}")
        return times[ds["event_kind"].values == kind]

    def summary(self) -> Summary:
        """Time in each phase, switches, separations, impacts, peak normal force, largest
        |w| at the probes and wall time; ``print()`` it, or take its attributes.

        A result that lacks ``normal_force`` or ``w`` (a run of ``fivdisc reproduce`` keeps
        only what its figure draws) has nan for them.
        """
        ds = self._data
        dt = np.diff(ds["time"].values)
        kinds = ds["event_kind"].values
        owners = ds["event_slider"].values
        sliders = []
        for j in range(ds.sizes["slider"]):
            phase = ds["phase"].values[:, j]
            force = ds["normal_force"].values[:, j] if "normal_force" in ds else np.empty(0)
            sliders.append(SliderSummary(
                {name: float(np.sum(dt[phase[:-1] == i])) for i, name in enumerate(PHASE_NAMES)},
                int(np.sum((kinds == "separation") & (owners == j))),
                float(np.nanmax(force)) if np.isfinite(force).any() else np.nan,
            ))
        impacts = int(np.sum(kinds == "recontact")) if ds.attrs.get("impact", 1) else 0
        w = np.abs(ds["w"].values) if "w" in ds else np.full(1, np.nan)
        return Summary(
            status=self.status,
            end_time=float(ds.attrs.get("end_time", ds["time"].values[-1])),
            sliders=tuple(sliders),
            switches=int(ds.attrs.get("n_switches", kinds.size)),
            phase_changes=int(kinds.size),
            degenerate=str(ds.attrs.get("degenerate", "")),
            impacts=impacts,
            max_abs_w=float(np.nanmax(w, initial=0.0) if np.isfinite(w).any() else np.nan),
            wall_time=float(ds.attrs.get("wall_time", np.nan)),
            disc_thickness=_disc_thickness(ds),
        )

    def plot(self, kind: str = "timeseries", **options: Any) -> Figure:
        """Draw the figure ``fivdisc plot --kind KIND`` draws.

        Parameters
        ----------
        kind
            One of :data:`fivdisc.plots.KINDS`.
        **options
            ``var``, ``probe``, ``slider``, ``window`` (t0, t1) [s], ``fmax`` [Hz],
            ``segment`` [s], ``ax``: see :func:`fivdisc.plots.plot_kind`.
        """
        from fivdisc.plots.result import plot_kind

        return plot_kind(self.dataset, kind, **options)

    def to_dataframe(self) -> pd.DataFrame:
        """The per-slider time series as a table: one row per (time, slider), one column
        per variable with a ``slider`` dimension (``phi`` [rad], ``phi_dot`` [rad/s],
        ``normal_force`` [N], ``friction_force`` [N], ``phase`` (0 slip, 1 stick, 2
        separation), ``z`` [m], ``z_dot`` [m/s], ``gap`` [m]) and ``disc_speed``
        [rad/s]. The disc's probes, modal coordinates and events stay in
        :attr:`dataset` (``result.dataset["w"].to_pandas()``, ...).
        """
        ds = self.dataset
        names = [name for name, var in ds.data_vars.items()
                 if var.dims == ("time", "slider") or name == "disc_speed"]
        return ds[names].drop_vars([c for c in ds.coords if c not in ("time", "slider")],
                                   errors="ignore").to_dataframe()

    def to_netcdf(self, path: str | PathLike[str]) -> None:
        """Write the dataset to a netCDF file atomically (a temporary file is renamed), with
        a checksum of its data; :func:`open_result` reads it back and checks it.

        Raises
        ------
        fivdisc.files.OutputError
            The file could not be written (e.g. a full disk); `path` is left as it was.
        """
        from fivdisc.files import write_netcdf

        write_netcdf(path, self._data.to_netcdf)


def open_result(path: str | PathLike[str], run: str | None = None) -> Result:
    """Read a result written by :meth:`Result.to_netcdf`, ``fivdisc simulate`` or
    ``fivdisc reproduce``.

    Parameters
    ----------
    path
        The netCDF file.
    run
        For a file of ``fivdisc reproduce`` that holds several runs (``a``, ``b``,
        ``a_printed``, ...), which one; a file with one run needs none.

    Returns
    -------
    Result
        Equal to the result that was written (a reproduced figure's runs keep only the
        variables the figure draws).

    Raises
    ------
    FivdiscError
        The file is not a fivdisc result, its data do not match the checksum stored in it
        (see :func:`fivdisc.files.check_netcdf`), or `run` is missing or not one of its
        runs; one line naming the file and what it holds.
    FileNotFoundError
        The file does not exist.

    See Also
    --------
    fivdisc.simulate : Computes a result instead.

    Examples
    --------
    A result written and read back compares equal:

    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.01}))
    >>> result.to_netcdf("run.nc")
    >>> again = fivdisc.open_result("run.nc")
    >>> again == result, again.status
    (True, 'success')
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(2, "No such file", str(path))
    try:
        runs = run_groups(path)
        if runs and run is None and len(runs) == 1:
            run = runs[0]
        if runs and run not in runs:
            need = "choose one with run=" if run is None else f"run = {run!r} is not one of them:"
            raise FivdiscError(f"{path} holds the runs {', '.join(runs)}: {need} "
                               f"{', '.join(runs)}")
        if not runs and run is not None:
            raise FivdiscError(f"run = {run!r} is invalid: {path} holds one run; leave run out")
        import xarray as xr

        from fivdisc.files import CHECKSUM, check_netcdf, require_fivdisc_netcdf

        require_fivdisc_netcdf(path, "open_result")
        check_netcdf(path)
        with xr.open_dataset(path, group=run) as stored:
            ds = stored.load()
        ds.attrs.pop(CHECKSUM, None)  # the file's, not the run's
    except (OSError, ValueError) as exc:
        raise FivdiscError(f"cannot read {path} as a fivdisc result: {exc}") from None
    kind = ds.attrs.get("fivdisc_kind", "simulation")
    # One sample is a run: a run of less than one output interval, or one that failed at
    # its start.
    if (kind != "simulation" or "time" not in ds.coords or ds.sizes["time"] < 1
            or not any(name in ds for name in _RESULT_VARIABLES)):
        what = {"stability_map": "a stability map (fivdisc stability)",
                "separation_map": "a separation map"}.get(kind, "not a simulation result")
        if kind == "simulation" and "exponent" in ds:
            what = "Lyapunov exponents (fivdisc lyapunov), not a simulation result"
        raise FivdiscError(f"{path}{f' (run {run})' if run else ''} is {what}: read it with "
                           "xarray.open_dataset, draw it with fivdisc plot")
    for name in _ARRAY_ATTRS:
        # netCDF stores an attribute of one value as a scalar: give the array back.
        if name in ds.attrs:
            ds.attrs[name] = np.atleast_1d(ds.attrs[name])
    return Result(ds)


def run_groups(path: str | PathLike[str]) -> list[str]:
    """The groups of a netCDF file of ``fivdisc reproduce``, one per run (none for a plain
    result or map)."""
    import netCDF4

    with netCDF4.Dataset(path) as root:
        return list(root.groups)
