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
from fivdisc.model.build import Model
from fivdisc.model.layout import Phase

__all__ = ["MEASURES", "Cycle", "cyclic_signature", "one_period", "phase_label"]

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
    if phase == Phase.STICK:
        return "stick"
    if phase == Phase.SEPARATION:
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
    events : tuple of (float, str, int)
        Every switch as (time from the orbit's point [s], kind of
        :data:`~fivdisc.engine.result.EVENT_KINDS`, slider).
    period : float
        The period [s].
    dips : tuple of (int, str, float, float)
        Interior minima of the phases' margins, as (slider, ``"stick"`` or ``"slip"``,
        value, time [s]): inside a stick phase the static margin ``(mu_s N - |f|) /
        (mu_s N)``, inside a slip phase the slip speed ``|Omega - phidot| / Omega``
        (parabola through the samples at the minimum). One that reaches zero is where a
        phase appears inside another (a stick phase splits, a slip phase grazes the disc
        speed).
    """

    signature: tuple[str, ...]
    measures: dict[str, np.ndarray]
    switch_times: np.ndarray
    stick_free: np.ndarray
    events: tuple[tuple[float, str, int], ...] = ()
    period: float = np.nan
    dips: tuple[tuple[int, str, float, float], ...] = ()

    def cyclic(self) -> tuple[str, ...]:
        """The signature as a cycle (:func:`cyclic_signature`)."""
        return cyclic_signature(self.signature)


def cyclic_signature(signature: tuple[str, ...]) -> tuple[str, ...]:
    """An event signature as a cycle, independent of where on the orbit it starts: per
    slider, the rotation of its phase sequence (without the repeated first phase) that
    sorts first."""
    out = []
    for sig in signature:
        parts = sig.split(" > ")
        ring = parts[:-1] if len(parts) > 1 and parts[0] == parts[-1] else parts
        out.append(min(" > ".join(ring[i:] + ring[:i]) for i in range(len(ring))))
    return tuple(out)


def one_period(model: Model, x0: np.ndarray, phases: np.ndarray, period: float,
               rtol: float, atol: float, max_step: float | None = None) -> Cycle:
    """Follow the orbit through ``x0`` (phases ``phases``) over one ``period`` [s].

    The run stops at every switch to read each slider's new phase and slip direction,
    so that a phase however short is in the signature. ``max_step`` [s] caps the steps
    as the shooting runs do (:meth:`fivdisc.analysis.orbits.Shooting.cycle`): next to a
    border where switches of different sliders change order, runs with other steps may
    fall on its other side.
    """
    ns = model.n_sliders
    run = Integration(model, x0, duration=period, output_rate=_SAMPLES / period, rtol=rtol,
                      atol=atol, phases=phases, stop_on=EVENT_KINDS, max_step=max_step)
    run.advance(0.0)
    seqs = [[phase_label(run.ph[j], run.sg[j])] for j in range(ns)]
    stick_free = [not np.any(run.ph == Phase.STICK)]
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
        stick_free += [not np.any(run.ph == Phase.STICK)] * (rows.shape[0] - seen)
        seen = rows.shape[0]
        if run.status_name == "success":
            break
    times, rows = run.events()
    events = tuple((float(t), EVENT_KINDS[int(r[0])], int(r[3])) for t, r in zip(times, rows,
                                                                               strict=True))
    y = run.out_y[: run.n_samples]
    aux = run.out_aux[: run.n_samples]
    col = model.columns
    columns = {
        "phi": y[:, model.slices.phi],
        "phi_dot": y[:, model.slices.phi_dot],
        "normal_force": aux[:, col.normal_force],
        "w": aux[:, col.w],
    }
    measures = {}
    for name, values in columns.items():
        measures[f"{name}_max"] = values.max(axis=0)
        measures[f"{name}_min"] = values.min(axis=0)
    dips = _dips(model, y, aux, period / _SAMPLES)
    return Cycle(tuple(" > ".join(s) for s in seqs), measures, times, np.array(stick_free),
                 events, float(period), dips)


def _dips(model: Model, y: np.ndarray, aux: np.ndarray, dt: float
          ) -> tuple[tuple[int, str, float, float], ...]:
    """Interior minima of each phase's margin over the samples (see :class:`Cycle`)."""
    ns, col = model.n_sliders, model.columns
    mus = model.friction_value("static")
    omega = abs(float(model.speed.omega(0.0))) or 1.0
    out = []
    for j in range(ns):
        phase = aux[:, col.phase][:, j]
        normal, force = aux[:, col.normal_force][:, j], aux[:, col.friction_force][:, j]
        rate = y[:, model.index("phi_dot", j)]
        with np.errstate(divide="ignore", invalid="ignore"):
            stick = (mus * normal - np.abs(force)) / (mus * normal)
        slip = np.abs(omega - rate) / omega
        for label, code, values in (("stick", Phase.STICK, stick), ("slip", Phase.SLIP, slip)):
            inside = phase == code
            for i in range(2, phase.size - 2):
                if not (inside[i - 2:i + 3].all() and values[i] <= values[i - 1]
                        and values[i] < values[i + 1]):
                    continue
                a, b, c = values[i - 1], values[i], values[i + 1]
                curve = a - 2 * b + c
                shift = 0.5 * (a - c) / curve if curve > 0 else 0.0
                low = b - 0.25 * (a - c) * shift
                if np.isfinite(low):
                    out.append((j, label, float(low), float((i + shift) * dt)))
    return tuple(out)


#: What each event kind is called in words.
EVENT_WORDS = {"stick": "stick", "slip": "release", "reversal": "reversal",
               "separation": "separation", "recontact": "re-contact"}
# Events of different sliders closer than this fraction of the period are simultaneous:
# the integration makes the switches of one instant at one time, to the last bit, and two
# switches a picosecond apart near a border are in order, not together.
SIMULTANEOUS = 1e-13


def _matched(events: tuple[tuple[float, str, int], ...]) -> dict[tuple[str, int, int], float]:
    """Each event keyed by (kind, slider, its count among that slider's events of that
    kind)."""
    seen: dict[tuple[str, int], int] = {}
    out = {}
    for t, kind, j in events:
        i = seen.get((kind, j), 0)
        seen[(kind, j)] = i + 1
        out[(kind, j, i)] = t
    return out


def order_changes(before: Cycle, after: Cycle, limit: int = 3) -> list[str]:
    """The pairs of events of different sliders whose order (or simultaneity) differs
    between two runs over (nearly) the same period, in words, nearest pairs first: e.g.
    ``"pad 2's release: together with pad 0's release -> 171 ns after it"``."""
    a, b = _matched(before.events), _matched(after.events)
    common = [key for key in a if key in b]
    period = before.period if np.isfinite(before.period) else 1.0
    tol = SIMULTANEOUS * period

    def rel(dt: float) -> float:
        # the signed time from the first to the second, the nearer way round the cycle
        return (dt + 0.5 * period) % period - 0.5 * period

    def words(dt: float, first: tuple[str, int, int]) -> str:
        what = f"pad {first[1]}'s {EVENT_WORDS[first[0]]}"
        if abs(dt) <= tol:
            return f"together with {what}"
        return f"{abs(dt) * 1e9:.3g} ns {'after' if dt > 0 else 'before'} {what}"

    found = []
    for i, one in enumerate(common):
        for two in common[i + 1:]:
            if one[1] == two[1]:
                continue
            da, db = rel(a[two] - a[one]), rel(b[two] - b[one])
            same_a, same_b = abs(da) <= tol, abs(db) <= tol
            if same_a != same_b or (not same_a and np.sign(da) != np.sign(db)):
                found.append((min(abs(da), abs(db)),
                              f"pad {two[1]}'s {EVENT_WORDS[two[0]]}: {words(da, one)} -> "
                              f"{words(db, one)}"))
    missing = [k for k in a if k not in b] + [k for k in b if k not in a]
    lines = [text for _, text in sorted(found)[:limit]]
    if missing:
        lines.append("events " + ", ".join(f"pad {k[1]}'s {EVENT_WORDS[k[0]]}"
                                           for k in missing[:limit])
                     + " appear or vanish")
    return lines
