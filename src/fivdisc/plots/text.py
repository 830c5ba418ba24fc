"""What every figure shares: the check for matplotlib, new axes, axis labels with
engineering units, titles fitted to the axes' width."""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, ParamSpec, TypeVar

import numpy as np
import xarray as xr

from fivdisc.analysis.spectra import (
    AnalysisError,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


Window = tuple[float | None, float | None] | None


P = ParamSpec("P")


R = TypeVar("R")


# Average width of a character of the default font, in units of its size (for wrapping).
_CHAR_WIDTH = 0.6


def drawing(function: Callable[P, R]) -> Callable[P, R]:
    """A function that draws: it checks for matplotlib (the plot extra) before any work."""

    @functools.wraps(function)
    def checked(*args: P.args, **kwargs: P.kwargs) -> R:
        from fivdisc.extras import require

        require("plot", "fivdisc.plots")
        return function(*args, **kwargs)

    return checked


def new_axes(ax: Axes | None, figsize: tuple[float, float] | None = None
             ) -> tuple[Figure, Axes]:
    """`ax` and its figure, or new ones (`figsize` [in], default matplotlib's)."""
    if ax is not None:
        return ax.figure, ax
    import matplotlib

    headless = sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    )
    if headless and not os.environ.get("MPLBACKEND") and "matplotlib.pyplot" not in sys.modules:
        # An interactive backend chosen by the user's config would fail without a display;
        # one chosen for this process (MPLBACKEND, e.g. Jupyter's inline backend) stays.
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, new_ax = plt.subplots(layout="constrained", figsize=figsize)
    return fig, new_ax


def label_of(da: xr.DataArray, fallback: str, prefix: str = "") -> str:
    name = da.attrs.get("long_name", fallback)
    units = da.attrs.get("units", "")
    return f"{name} [{prefix}{units}]" if units and units != "1" else name


# SI prefixes for axis values, so that ticks read 0.1 [mm] rather than 0.0001 [m].
_PREFIXES = {-9: "n", -6: "µ", -3: "m", 0: "", 3: "k", 6: "M"}


_SCALED_UNITS = ("m", "m/s", "rad", "rad/s", "N", "J")


def engineering_scale(da: xr.DataArray) -> tuple[float, str]:
    """(factor, prefix) that bring the largest |value| of `da` into [1, 1000) with an SI
    prefix of its unit; (1, "") for units not scaled (or rad/s, N beyond their ranges)."""
    units = da.attrs.get("units", "")
    values = np.abs(np.asarray(da.values, dtype=float))
    top = float(np.nanmax(values)) if values.size and np.isfinite(values).any() else 0.0
    if units not in _SCALED_UNITS or not top > 0:
        return 1.0, ""
    power = int(np.clip(3 * np.floor(np.log10(top) / 3), min(_PREFIXES), max(_PREFIXES)))
    if units == "rad" and power > 0:  # kilo-radians read worse than radians
        power = 0
    return 10.0 ** -power, _PREFIXES[power]


def lone_coords(data: xr.DataArray | xr.Dataset) -> dict[str, str]:
    """Line options that show a record of one sample (a line through one point draws
    nothing): a marker."""
    return {"marker": "o"} if data.sizes.get("time") == 1 else {}


def window_bounds(window: Window) -> tuple[float | None, float | None]:
    if window is None:
        return None, None
    try:
        t0, t1 = window
    except (TypeError, ValueError):
        raise AnalysisError(f"window = {window!r} is invalid: must be a pair (t0, t1) [s] "
                            "or None") from None
    return t0, t1


def where_text(da: xr.DataArray | xr.Dataset) -> str:
    """Which slider, probe or modal coordinate a series was taken at, for titles."""
    parts = []
    if "slider" in da.coords and da["slider"].ndim == 0:
        parts.append(f"slider {int(da['slider'])}")
    if "probe" in da.coords and da["probe"].ndim == 0:
        probe = f"probe {int(da['probe'])}"
        if "probe_r" in da.coords and "probe_theta" in da.coords:
            probe += f" (r = {float(da['probe_r']):g} m, θ = {float(da['probe_theta']):g} rad)"
        parts.append(probe)
    if "coordinate" in da.coords and da["coordinate"].ndim == 0:
        parts.append(f"coordinate {da['coordinate'].item()}")
    return ", ".join(parts)


def set_title(ax: Axes, ds: xr.Dataset, what: str, where: str = "", detail: str = "") -> None:
    """Title: the case's name and what is drawn; the run and where; a detail."""
    name = str(ds.attrs.get("case_name", ""))
    title = str(ds.attrs.get("title", ""))
    run = title.split(": ", 1)[1] if ": " in title else ""
    lines = [f"{name}: {what}" if name else what, "; ".join(p for p in (run, where) if p),
             detail]
    ax.set_title(fit_text(ax, "\n".join(line for line in lines if line), "medium"),
                 fontsize="medium")


# Font sizes a two-line title may take, largest first [pt].
_TITLE_SIZES = (10.0, 9.0, 8.0, 7.0)


def set_two_line_title(ax: Axes, ds: xr.Dataset, what: str, where: str = "",
                       detail: str = "") -> None:
    """Title of at most two lines: the case's name, what is drawn and where; the run
    and a detail. The font shrinks (down to 7 pt) until both lines fit the axes' width
    as laid out; a line still too long loses its end to an ellipsis."""
    name = str(ds.attrs.get("case_name", ""))
    title = str(ds.attrs.get("title", ""))
    run = title.split(": ", 1)[1] if ": " in title else ""
    first = ", ".join(p for p in (f"{name}: {what}" if name else what, where) if p)
    lines = [first, "; ".join(p for p in (run, detail) if p)]
    lines = [line for line in lines if line]
    fig = ax.figure
    fig.draw_without_rendering()  # the layout (a colour bar takes its share) first
    width = ax.get_position().width * fig.get_figwidth() * 72.0  # [pt]
    for size in _TITLE_SIZES:
        chars = int(width / (_CHAR_WIDTH * size))
        if all(len(line) <= chars for line in lines):
            break
    lines = [line if len(line) <= chars else line[: max(chars - 1, 1)].rstrip() + "…"
             for line in lines]
    ax.set_title("\n".join(lines), fontsize=size)


def disc_speed_axis(ax: Axes, ds: xr.Dataset) -> None:
    """A second time axis on top, in disc speed, where the disc's speed changes
    monotonically over the record (a braking or accelerating run): each time read
    as the speed the disc had then."""
    if "disc_speed" not in ds or "time" not in ds["disc_speed"].dims:
        return
    time = np.asarray(ds["time"].values, dtype=float)
    speed = np.asarray(ds["disc_speed"].values, dtype=float)
    if time.size < 2 or not np.all(np.isfinite(speed)):
        return
    step = np.diff(speed)
    scale = float(np.max(np.abs(speed))) or 1.0
    if not (np.all(step < 0) or np.all(step > 0)) or np.ptp(speed) < 1e-6 * scale:
        return
    # np.interp wants increasing abscissae: a braking run's speeds are reversed.
    order = np.argsort(speed)

    def to_speed(t):
        return np.interp(t, time, speed)

    def to_time(v):
        return np.interp(v, speed[order], time[order])

    top = ax.secondary_xaxis("top", functions=(to_speed, to_time))
    units = ds["disc_speed"].attrs.get("units", "rad/s")
    top.set_xlabel(f"disc speed [{units}]")


def fit_text(ax: Axes, text: str, size: str) -> str:
    """`text` wrapped to the width of `ax` (at font `size`), never inside $math$."""
    from matplotlib.font_manager import FontProperties

    points = FontProperties(size=size).get_size_in_points()
    width = ax.get_position().width * ax.figure.get_figwidth() * 72.0  # [pt]
    chars = max(20, int(width / (_CHAR_WIDTH * points)))
    # Spaces inside $...$ are kept from the line breaks.
    parts = text.split("$")
    parts[1::2] = [part.replace(" ", "\0") for part in parts[1::2]]
    wrapped = "\n".join(_fill_phrases(line, chars)
                         for line in "$".join(parts).split("\n"))
    return wrapped.replace("\0", " ")


def _fill_phrases(line: str, chars: int) -> str:
    """`line` broken only after ", " or "; " outside parentheses (never inside a phrase
    such as "slider circumferential angle"), at most about `chars` characters a line; a
    phrase longer than a line and a half is itself broken between words."""
    import textwrap

    phrases, start, depth = [], 0, 0
    for i, char in enumerate(line):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if char in ",;" and depth == 0 and line[i + 1:i + 2] == " ":
            phrases.append(line[start:i + 1])
            start = i + 2
    phrases.append(line[start:])
    out: list[str] = []
    for phrase in phrases:
        if len(phrase) > 1.5 * chars:
            pieces = textwrap.wrap(phrase, chars, break_on_hyphens=False)
        else:
            pieces = [phrase]
        for piece in pieces:
            if out and len(out[-1]) + 1 + len(piece) <= chars:
                out[-1] += " " + piece
            else:
                out.append(piece)
    return "\n".join(out)
