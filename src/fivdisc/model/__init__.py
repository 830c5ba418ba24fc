"""The numerical model of a case: the annular plate and its modes, speed profiles,
and the arrays the compiled core reads.

The names below are imported on first use.
"""

from fivdisc._lazy import public

_API = {
    "fivdisc.model.build": ("Model", "build_model"),
    "fivdisc.model.layout": ("EventKind", "OutputColumns", "Phase", "StateSlices"),
    "fivdisc.model.plate": ("AnnularPlate", "PlateMode"),
    "fivdisc.model.speed": ("SpeedProfile",),
}

__all__, __getattr__, __dir__ = public(globals(), _API)
