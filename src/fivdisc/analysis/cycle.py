"""One period of a periodic orbit: its event signature and amplitude measures.

The event signature is, per slider, the sequence of its phases over one period from the
orbit's point: ``slip+`` and ``slip-`` (slipping with the disc faster or slower than the
slider), ``stick`` and ``flight`` (separated), e.g. ``slip+ > stick > slip+``. Two orbits
with the same signature lie on one smooth piece of the flow map; where a branch of orbits
changes its signature, a discontinuity-induced bifurcation happens. The amplitude
measures (largest and smallest angle, angular velocity, normal force and deflection
under each slider over the period) are what a bifurcation diagram of a branch plots.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivdisc.engine.integration import Integration
from fivdisc.engine.result import EVENT_KINDS
from fivdisc.errors import FivdiscError
from fivdisc.model import layout as lay
from fivdisc.model.build import Model

__all__ = ["MEASURES", "Cycle", "one_period", "phase_label"]

#: Amplitude measures per slider: name -> (long name, unit). Each is kept as its
#: largest (``_max``) and smallest (``_min``) value over a period.
MEASURES = {
    "phi": ("slider circumferential angle", "rad"),
    "phi_dot": ("slider circumferential angular velocity", "rad/s"),
    "normal_force": ("normal contact force", "N"),
    "w": ("disc deflection under the slider", "m"),
}
# Samples per period for the measures: the largest of a sinusoid sampled this finely is
# within (pi / 2000)^2 / 2 ~ 1e-6 of its amplitude.
_SAMPLES = 2000


def phase_label(phase: int, sign: int) -> str:
    """``slip+``, ``slip-``, ``stick`` or ``flight``."""
    if phase == lay.STICK:
        return "stick"
    if phase == lay.SEPARATION:
        return "flight"
    return "slip+" if sign > 0 else "slip-"


@dataclass(frozen=True)
class Cycle:
    """What one period of an orbit holds.

    Attributes
    ----------
    signature : tuple of str
        Per slider, its phases over the period from the orbit's point, joined by
        ``" > "``.
    measures : dict of str to ndarray
        ``"phi_max"``, ``"phi_min"``, ... (see :data:`MEASURES`): per slider [units of
        :data:`MEASURES`].
    switch_times : ndarray
        Times of the switches from the orbit's point [s].
    stick_free : ndarray of bool
        Per interval between the start, the switches and the end: whether no slider
        sticks in it.
    """

    signature: tuple[str, ...]
    measures: dict[str, np.ndarray]
    switch_times: np.ndarray
    stick_free: np.ndarray

    def cyclic(self) -> tuple[str, ...]:
        """The signature as a cycle, independent of where on the orbit it starts: per
        slider, the rotation of its phase sequence (without the repeated first phase)
        that sorts first."""
        out = []
        for sig in self.signature:
            parts = sig.split(" > ")
            ring = parts[:-1] if len(parts) > 1 and parts[0] == parts[-1] else parts
            out.append(min(" > ".join(ring[i:] + ring[:i]) for i in range(len(ring))))
        return tuple(out)


def one_period(model: Model, x0: np.ndarray, phases: np.ndarray, period: float,
               rtol: float, atol: float) -> Cycle:
    """Follow the orbit through ``x0`` (phases ``phases``) over one ``period`` [s].

    The run stops at every switch to read each slider's new phase and slip direction,
    so that a phase however short is in the signature.
    """
    ns = model.n_sliders
    run = Integration(model, x0, duration=period, output_rate=_SAMPLES / period, rtol=rtol,
                      atol=atol, phases=phases, stop_on=EVENT_KINDS)
    run.advance(0.0)
    seqs = [[phase_label(run.ph[j], run.sg[j])] for j in range(ns)]
    stick_free = [not np.any(run.ph == lay.STICK)]
    seen = 0
    while run.t < period:
        run.advance(period)
        if run.status_name not in ("stopped", "running", "success"):
            raise FivdiscError(f"the run over one period ({period:.6g} s) ended with "
                               f"{run.status_name} at t = {run.t:.9g} s")
        times, rows = run.events()
        for row in rows[seen:]:
            j = int(row[3])
            label = phase_label(run.ph[j], run.sg[j])
            if seqs[j][-1] != label:
                seqs[j].append(label)
        stick_free += [not np.any(run.ph == lay.STICK)] * (rows.shape[0] - seen)
        seen = rows.shape[0]
        if run.status_name == "success":
            break
    times, _ = run.events()
    y = run.out_y[: run.n_samples]
    aux = run.out_aux[: run.n_samples]
    columns = {
        "phi": y[:, model.index("phi"): model.index("phi") + ns],
        "phi_dot": y[:, model.index("phi_dot"): model.index("phi_dot") + ns],
        "normal_force": aux[:, :ns],
        "w": aux[:, 3 * ns: 4 * ns],
    }
    measures = {}
    for name, values in columns.items():
        measures[f"{name}_max"] = values.max(axis=0)
        measures[f"{name}_min"] = values.min(axis=0)
    return Cycle(tuple(" > ".join(s) for s in seqs), measures, times, np.array(stick_free))
