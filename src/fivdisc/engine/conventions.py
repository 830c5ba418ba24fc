"""Metadata every dataset fivdisc writes carries, following the CF conventions.

Global attributes (:func:`global_attrs`): ``Conventions``, ``title``, ``institution``,
``source`` (fivdisc and its version), ``history`` (when and by what the data was made)
and ``references`` (the paper fivdisc implements). Coordinates that are case keys
(stability maps, sweeps) are named after the key and described by :func:`key_attrs`:
its ``units`` and a ``long_name``, with the paper's symbol in ``symbol``.
"""

from __future__ import annotations

import datetime
import functools
from typing import Any

from fivdisc.case import describe_key

__all__ = ["CONVENTIONS", "DOI", "REFERENCES", "axis_label", "fivdisc_version", "global_attrs",
           "key_attrs", "units"]

CONVENTIONS = "CF-1.11"
#: DOI of the paper fivdisc implements.
DOI = "10.1007/s11071-019-05168-x"
REFERENCES = (
    "N. Liu and H. Ouyang, Friction-induced vibration of a slider on an elastic disc "
    f"spinning at variable speeds, Nonlinear Dynamics 98 (2019), https://doi.org/{DOI}"
)


def units(unit: str) -> str:
    """A unit as CF writes it: ``"1"`` for dimensionless (an empty unit)."""
    return unit or "1"


@functools.cache
def fivdisc_version() -> str:
    """The installed fivdisc's version (looked up once per process)."""
    from importlib.metadata import version

    return version("fivdisc")


def global_attrs(title: str, producer: str) -> dict[str, str]:
    """The global attributes of a dataset fivdisc writes.

    Parameters
    ----------
    title
        What the dataset is, e.g. ``"fivdisc simulation of fig10"``.
    producer
        What made it, for ``history``, e.g. ``"fivdisc.simulate"``.
    """
    fivdisc = f"fivdisc {fivdisc_version()}"
    now = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    return {
        "Conventions": CONVENTIONS,
        "title": title,
        "institution": f"computed with {fivdisc} (https://github.com/fivdisc/fivdisc)",
        "source": fivdisc,
        "history": f"{now} {producer} ({fivdisc})",
        "references": REFERENCES,
    }


def key_attrs(key: str) -> dict[str, str]:
    """``units``, ``long_name`` and ``symbol`` of a coordinate named after a case key.

    Parameters
    ----------
    key
        A dotted case key, e.g. ``"slider.normal_damping"`` or ``"sliders.1.preload"``.
    """
    info = describe_key(key)
    attrs = {"units": units(info.unit), "long_name": info.long_name}
    if info.symbol:
        attrs["symbol"] = info.symbol
    return attrs


def axis_label(coord: Any) -> str:
    """Axis label of a coordinate named after a case key: its words, symbol and unit,
    e.g. ``"slider normal damping $c_z$ [N s/m]"`` (matplotlib mathtext).

    Parameters
    ----------
    coord
        A coordinate (an :class:`xarray.DataArray`) with the attributes of
        :func:`key_attrs`.
    """
    attrs = coord.attrs
    symbol = attrs.get("symbol", "")
    text = str(attrs.get("long_name", coord.name)) + (f" ${symbol}$" if symbol else "")
    unit = attrs.get("units", "")
    return f"{text} [{unit}]" if unit and unit != "1" else text
