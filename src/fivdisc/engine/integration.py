"""One integration of a model, advanced call by call on the compiled core, which keeps its
whole state between calls.

:func:`fivdisc.simulate` drives one to write a :class:`~fivdisc.engine.result.Result`; the
nonlinear-dynamics analyses (:mod:`fivdisc.analysis.orbits`,
:mod:`fivdisc.analysis.exponents`) drive them with tangent vectors.
"""

from __future__ import annotations

import math
import threading

import numpy as np

from fivdisc import core
from fivdisc.engine.result import EVENT_KINDS
from fivdisc.errors import FivdiscError
from fivdisc.model import layout as lay
from fivdisc.model.build import Model
from fivdisc.model.layout import Phase

# Switches closer than this, this many times in a row, are taken as Zeno/chattering.
ZENO_DT = 1e-10
ZENO_COUNT = 1000
# An accumulation of switches that interleaves tiny spacings with longer ones (a cascade
# among many sliders) escapes the test above: ZENO_RATE_COUNT switch events within
# ZENO_RATE_SPAN of simulated time (a mean spacing of 1e-9 s, a thousand times the
# densest switching of the paper's cases) are taken as Zeno too.
ZENO_RATE_COUNT = 10_000
ZENO_RATE_SPAN = 1e-5
# Mean step [s per unit of max(1, t)] of a whole kernel call below which the run is taken
# as stalled (the kernel's own test of a step size underflow: 1e-14 max(1, t)).
_STALLED = 1e-14
# Work [state values x (sliders + 1)] one kernel call may do before it returns to Python,
# about 0.05 s: the bound on how long an interrupt or a step budget waits.
_CALL_WORK = 500_000

# A thread cannot be interrupted (only the main thread receives SIGINT) nor killed: a
# thread that computes a sweep's points is given an event that every kernel call checks
# (stop_thread_when), so that once its sweep stops, its run ends within one call
# (about 0.05 s) instead of running to its end.
_thread = threading.local()


class Stopped(BaseException):
    """A run ended in a thread whose stop event is set (see :func:`stop_thread_when`).

    A BaseException, as KeyboardInterrupt is: the code that computes a point catches
    ``Exception`` to store it as the point's failure, which a stopped point is not.
    """


def stop_thread_when(event: threading.Event | None) -> None:
    """Make every later :meth:`Integration.advance` in the calling thread raise
    :class:`Stopped` once `event` is set (None: never)."""
    _thread.stop = event


STATUS = {
    core.ST_RUNNING: "running",
    core.ST_DONE: "success",
    core.ST_STOPPED: "stopped",
    core.ST_NONFINITE: "nonfinite",
    core.ST_UNDERFLOW: "step_size_underflow",
    core.ST_ZENO: "endless_switching",
    core.ST_MAX_SWITCHES: "max_switches",
    core.ST_TOO_MANY_STEPS: "too_many_steps",
}


# h omega of the tangent step cap: DOPRI5's amplification of an oscillation of frequency
# omega is 1 - (h omega)^6 / 3600 per step, so an exponent is biased by about
# 1e-5 omega [1/s] at 0.5 (0.02 1/s for the paper's fastest mode kept, 2774 rad/s).
_TANGENT_STEP = 0.5


def time_scales(model: Model) -> list[tuple[str, float]]:
    """The rates [1/s] of the model's fast motions, each with the keys that set it: the
    disc's natural frequencies and damping rates, each slider's normal and in-plane
    oscillator (separated) and damping rates. The spin's shift l Omega of a disc frequency
    is small against them for the speeds of brake squeal and left out."""
    kern = model.kernel
    case = model.case
    labels = np.array(model.labels)
    scales = [(f"disc.modes {lab} natural frequency", w) for lab, w in zip(labels, model.omega,
                                                                          strict=True)]
    with np.errstate(all="ignore"):  # an overflow is an infinite rate, refused as such
        scales += [(f"disc.damping_ratio of {lab}", float(2.0 * z * w))
                   for lab, z, w in zip(labels, model.damping, model.omega, strict=True)]
        rows = [("sqrt(normal_stiffness / mass)", np.sqrt(kern.row("kz") / kern.row("mass"))),
                ("sqrt(rotational_stiffness / inertia)",
                 np.sqrt(kern.row("kphi") / kern.row("inertia"))),
                ("normal_damping / mass", kern.row("cz") / kern.row("mass")),
                ("rotational_damping / inertia", kern.row("cphi") / kern.row("inertia"))]
    for what, rates in rows:
        scales += [(f"{case.slider_key(j)}: {what}", float(r)) for j, r in enumerate(rates)]
    return [(what, float(rate)) for what, rate in scales]


def fastest_time_scale(model: Model) -> tuple[str, float]:
    """The largest of :func:`time_scales` (a nan counts as infinite)."""
    return max(((what, math.inf if math.isnan(r) else r) for what, r in time_scales(model)),
               key=lambda item: item[1], default=("none", 0.0))


def tangent_step(model: Model, h_omega: float = _TANGENT_STEP) -> float:
    """Largest step [s] that resolves the tangent dynamics: ``h_omega`` (default half)
    the shortest time scale of the model (:func:`time_scales`).

    The integrator's steps follow the state alone (so that tangents do not change the
    trajectory); where the state hardly moves (near an equilibrium, a disc mode at rest)
    its steps may be far too long for the tangent dynamics, which then are not merely
    inaccurate but unstable. Analyses that carry tangents cap the step at this.
    """
    return h_omega / fastest_time_scale(model)[1]


# h |lambda| at the edge of DOPRI5's stability region on the negative real axis (3.3) and
# the imaginary axis (3.4).
_STABLE_STEP = 3.3


# h omega of a step that meets the tolerance on an oscillation of frequency omega: the
# local error of DOPRI5 grows as (h omega)^5, so h omega = _ACCURATE rtol^(1/5). The
# paper's cases take about 4 (0.24 at rtol = 1e-6, 11,500 steps per second against their
# fastest mode); 8 makes the estimate about half the steps actually taken.
_ACCURATE = 8.0


def estimate_steps(model: Model, duration: float) -> tuple[float, str, float]:
    """A lower estimate of the steps a run of `duration` [s] takes, with the time scale
    that sets it and its rate [1/s].

    An explicit integrator's step is bounded by its stability region whatever the
    tolerance, ``h <= 3.3 / rate`` for a decay rate (dampers), and on an oscillation of
    frequency omega also by the tolerance, ``h omega <= 8 rtol^(1/5)``; the fastest time
    scale of :func:`time_scales`, or the disc's spin times the largest nodal-diameter
    count, or ``simulation.max_step``, sets the number of steps. Contact and friction
    only add to it.
    """
    rtol = model.case.simulation.rtol
    accurate = min(_STABLE_STEP, _ACCURATE * rtol**0.2)
    oscillating = ("natural frequency", "sqrt(")
    worst = (0.0, "none", 0.0)
    # The spin shifts a disc frequency by l Omega, small against the time scales for the
    # speeds of brake squeal but not for any speed a profile may reach.
    bp = model.speed.breakpoints
    times = np.concatenate([np.linspace(0.0, duration, 1001), bp[bp < duration]])
    with np.errstate(all="ignore"):
        spin = float(np.max(model.l, initial=0) * np.max(np.abs(model.speed.omega(times))))
    scales = [*time_scales(model),
              ("speed: the disc's spin (largest Omega) times the largest l", spin)]
    max_step = model.case.simulation.max_step
    if max_step > 0:
        with np.errstate(all="ignore"):
            scales.append(("1 / simulation.max_step", float(np.float64(1.0) / max_step)))
    for what, rate in scales:
        rate = math.inf if math.isnan(rate) else rate
        step = (accurate if any(word in what for word in oscillating) or what.startswith(
            "speed") else 1.0 if what.endswith("max_step") else _STABLE_STEP)
        steps = duration * rate / step
        if not steps <= worst[0]:
            worst = (steps, what, rate)
    return worst


def check_steps(model: Model, duration: float, span: str = "simulation.duration") -> None:
    """Refuse a run whose estimated steps (:func:`estimate_steps`) exceed
    ``simulation.max_steps``, before it starts.

    ``duration`` [s] is the simulated time the command will integrate; ``span`` names
    what the user set to get it, for the message (e.g. ``"transient + duration"``).

    Raises
    ------
    FivdiscError
        Naming the estimate, the time scale and its keys, and what to change.
    """
    steps, what, rate = estimate_steps(model, duration)
    budget = model.case.simulation.max_steps
    if not steps <= budget:
        raise FivdiscError(
            f"the run needs about {steps:.3g} integrator steps, more than "
            f"simulation.max_steps = {budget}: {what} = {rate:.3g} 1/s limits the step to "
            f"{duration / steps:.3g} s over {span} = {duration!r} s; change "
            "that parameter, shorten the run or raise simulation.max_steps"
        )


#: A run projected to take longer than this [s] says so (a
#: :class:`~fivdisc.errors.FivdiscWarning` with its estimate) ...
LONG_RUN = 60.0
# ... once it has run for this long [s], so that the projection rests on measured steps.
_TIMED_AFTER = 0.2


class LongRunNotice:
    """Warn once, early in a run, if it will take longer than :data:`LONG_RUN`: the
    steps estimated (:func:`estimate_steps`, or as many as the run's pace so far needs,
    whichever is more) at the time a step has taken so far.

    Call :meth:`update` after each call of :meth:`Integration.advance`.
    """

    def __init__(self, model: Model, duration: float, what: str = "the run",
                 stop: str = "Ctrl-C stops it and keeps what was computed") -> None:
        import time

        self.duration = duration
        self.what, self.stop = what, stop
        self.estimate = estimate_steps(model, duration)
        self.start = time.perf_counter()
        self.done = False

    def update(self, run: Integration) -> None:
        import time
        import warnings

        from fivdisc.errors import FivdiscWarning
        from fivdisc.limits import duration_words

        elapsed = time.perf_counter() - self.start
        if self.done or elapsed < _TIMED_AFTER:
            return
        self.done = True
        tried = run.steps_tried
        if tried == 0 or not run.t > 0.0:
            return
        per_step = elapsed / tried
        steps = max(self.estimate[0], tried * self.duration / run.t)
        total = steps * per_step
        if total > LONG_RUN:
            _, what, rate = self.estimate
            warnings.warn(
                f"{self.what} will take about {duration_words(total)}: about {steps:.2g} "
                f"integrator steps at {1.0 / per_step:.2g} a second, measured ({what} = "
                f"{rate:.3g} 1/s limits the step to {self.duration / self.estimate[0]:.3g} "
                f"s); {self.stop}", FivdiscWarning, stacklevel=3)


class Integration:
    """The integrator of ``model`` from state ``y0`` at t = 0 to ``duration``: a thin
    wrapper of the compiled core's :class:`fivdisc.core.Integrator`, which keeps the whole
    state between calls; this class adds the step budget, the accumulation test of
    switches and the event table.

    Parameters
    ----------
    model : Model
        The model (its case gives tolerances, step and switch limits).
    y0 : ndarray
        Initial state, ``2 (n + 2 S)`` values.
    duration : float
        End time [s]; the last step lands on it exactly.
    output_rate : float
        Output samples per second [Hz]; 0 records none.
    stop_on : tuple of str
        Event kinds that end the run early.
    energy : bool
        Integrate the energy accumulators too.
    rtol, atol : float, optional
        Override the case's tolerances.
    max_step : float, optional
        Override the case's largest step [s] (0: none).
    phases : array of int, optional
        Phase of each slider at the start (``layout.SLIP``, ``STICK``, ``SEPARATION``);
        a slider in contact takes the phase its state allows, one given as separated
        starts flying from its own ``z``, ``zdot``. Default: all in contact.
    """

    def __init__(self, model: Model, y0: np.ndarray, *, duration: float,
                 output_rate: float = 0.0, stop_on: tuple[str, ...] = (),
                 energy: bool = False, rtol: float | None = None,
                 atol: float | None = None, max_step: float | None = None,
                 phases: np.ndarray | None = None) -> None:
        sim = model.case.simulation
        self.model = model
        self.duration = duration
        n_acc = lay.N_ENERGY if energy else 0
        y = np.concatenate([np.asarray(y0, dtype=float), np.zeros(n_acc)])
        n_sl = model.n_sliders
        n_out = int(np.floor(duration * output_rate + 1e-9)) + 1 if output_rate > 0 else 0
        ph = np.full(n_sl, Phase.SLIP, dtype=np.int64)
        if phases is not None:
            ph[:] = phases
        bp = model.speed.breakpoints
        # Not np.unique: numpy 2.4's imports numpy.ma (15 ms), before the kernel starts.
        self.breaks = np.array(sorted(set(bp[bp < duration].tolist())), dtype=float)
        self.core = core.Integrator(
            core.core_model(model), y, ph, t_final=float(duration),
            rtol=float(sim.rtol if rtol is None else rtol),
            atol=float(sim.atol if atol is None else atol),
            max_step=float(sim.max_step if max_step is None else max_step),
            out_dt=1.0 / output_rate if output_rate > 0 else np.inf, n_out=n_out,
            max_switches=float(sim.max_switches), zeno_dt=ZENO_DT,
            zeno_count=float(ZENO_COUNT),
            stop_mask=sum(1 << EVENT_KINDS.index(k) for k in set(stop_on)),
            breaks=self.breaks)
        self.max_steps = sim.max_steps
        self.call_steps = max(20, _CALL_WORK // (y.size * (n_sl + 1)))
        self.zeno_sliders: tuple[int, ...] = ()
        self.zeno_span = 0.0
        self.zeno_count = 0
        self.ev_times: list[np.ndarray] = []
        self.ev_rows: list[np.ndarray] = []
        self.status = core.ST_RUNNING

    @property
    def t(self) -> float:
        """Time reached [s]."""
        return float(self.core.t)

    @property
    def y(self) -> np.ndarray:
        """A copy of the state reached, with the energy accumulators if any (slaved
        coordinates as the core holds them)."""
        return self.core.y

    @property
    def state(self) -> np.ndarray:
        """The dynamic state reached (without energy accumulators), slaved coordinates as
        the core holds them."""
        return self.core.y[: self.model.state_size]

    @property
    def ph(self) -> np.ndarray:
        """Every slider's phase (a copy)."""
        return self.core.ph

    @property
    def sg(self) -> np.ndarray:
        """Every slider's slip sign (a copy)."""
        return self.core.sg

    @property
    def out_y(self) -> np.ndarray:
        """The state samples (rows; those past :attr:`n_samples` are not written)."""
        return self.core.out_y

    @property
    def out_aux(self) -> np.ndarray:
        """Per sample, each slider's normal force, friction force, phase and w under it,
        then Omega (rows as :attr:`out_y`)."""
        return self.core.out_aux

    @property
    def stats(self) -> dict[str, int]:
        """Accepted (``steps``) and rejected steps, right-hand sides (``rhs``; those to
        locate events ``rhs_events``), ``switches`` and ``samples``."""
        return dict(self.core.stats)

    @property
    def status_name(self) -> str:
        return STATUS.get(self.status, "unknown")

    @property
    def n_samples(self) -> int:
        return int(self.core.n_samples)

    def take_peak(self) -> float:
        """The largest |w| [m] under the sliders at the samples written since the last
        call (nan if any was not finite), and start again."""
        return float(self.core.take_peak())

    @property
    def steps_tried(self) -> int:
        """Steps tried so far, accepted and rejected."""
        return int(self.core.steps_tried)

    def advance(self, target: float) -> int:
        """Integrate until ``t >= target`` (or the end, a failure, a full event log, the
        call's step budget); returns the status. The first call (any target) also chooses
        the phases at the start.

        A call tries at most a bounded number of steps (about 0.05 s of work), so that
        the caller regains control often: a run that cannot make progress is seen to, and
        an interrupt is handled, within a fraction of a second. Splitting a run into calls
        changes none of its steps. The run ends as ``too_many_steps`` once
        ``simulation.max_steps`` steps were tried, and as ``endless_switching`` when its
        switches accumulate (:data:`ZENO_RATE_COUNT` within :data:`ZENO_RATE_SPAN`).
        The core releases the GIL while it integrates.

        Raises
        ------
        Stopped
            The calling thread's stop event (:func:`stop_thread_when`) is set.
        """
        stop = getattr(_thread, "stop", None)
        if stop is not None and stop.is_set():
            raise Stopped(f"stopped at t = {self.t:.9g} s")
        left = self.max_steps - self.steps_tried
        if left <= 0 and self.core.started:
            self.status = core.ST_TOO_MANY_STEPS
            return self.status
        tried, t0 = self.steps_tried, self.t
        status = self.core.advance(target, max(1, min(self.call_steps, left)))
        times, rows = self.core.take_events()
        n_ev = times.size
        if n_ev:
            self.ev_times.append(times)
            self.ev_rows.append(rows)
        if status == core.ST_ZENO:
            self._name_zeno(ZENO_COUNT)
        elif status == core.ST_RUNNING and n_ev and self._accumulating():
            status = core.ST_ZENO
        elif (status == core.ST_RUNNING and self.t < self.duration
              and self.steps_tried >= self.max_steps):
            status = core.ST_TOO_MANY_STEPS
        elif (status == core.ST_RUNNING and self.steps_tried - tried >= self.call_steps
              and self.t - t0 < (self.steps_tried - tried) * _STALLED * max(1.0, self.t)):
            # A whole call's steps that do not add up to the round-off of t: the
            # step size has underflowed although each step is accepted.
            status = core.ST_UNDERFLOW
        self.status = status
        return status

    def _recent(self, count: int) -> tuple[np.ndarray, np.ndarray]:
        """Times and rows of the last ``count`` events (fewer if there are fewer)."""
        times, rows, have = [], [], 0
        for t, r in zip(reversed(self.ev_times), reversed(self.ev_rows), strict=True):
            times.append(t[-(count - have):])
            rows.append(r[-(count - have):])
            have += times[-1].size
            if have >= count:
                break
        if not times:
            return np.empty(0), np.empty((0, core.N_EVI), dtype=np.int64)
        return np.concatenate(times[::-1]), np.concatenate(rows[::-1])

    def _name_zeno(self, count: int) -> None:
        """Keep the sliders of the last ``count`` events, their number and the time they
        span."""
        times, rows = self._recent(count)
        if times.size:
            self.zeno_sliders = tuple(int(j) for j in np.unique(rows[:, core.EVI_SLIDER]))
            self.zeno_span = float(times[-1] - times[0])
            self.zeno_count = int(times.size)

    def _accumulating(self) -> bool:
        """Whether :data:`ZENO_RATE_COUNT` consecutive events among the latest fall within
        :data:`ZENO_RATE_SPAN` of simulated time."""
        new = self.ev_times[-1].size
        # A window that holds a new event lies after the first new event's time less the
        # span: count the events there first (most calls stop here, having looked at the
        # last few chunks only).
        cutoff = self.ev_times[-1][0] - ZENO_RATE_SPAN
        near = 0
        for chunk in reversed(self.ev_times):
            near += chunk.size - int(np.searchsorted(chunk, cutoff))
            if chunk[0] < cutoff or near >= ZENO_RATE_COUNT:
                break
        if near < ZENO_RATE_COUNT:
            return False
        times, rows = self._recent(new + ZENO_RATE_COUNT - 1)
        if times.size < ZENO_RATE_COUNT:
            return False
        spans = times[ZENO_RATE_COUNT - 1:] - times[: times.size - ZENO_RATE_COUNT + 1]
        dense = np.flatnonzero(spans < ZENO_RATE_SPAN)
        if not dense.size:
            return False
        first = int(dense[0])
        window = rows[first:first + ZENO_RATE_COUNT]
        self.zeno_sliders = tuple(int(j) for j in np.unique(window[:, core.EVI_SLIDER]))
        self.zeno_span = float(spans[first])
        self.zeno_count = ZENO_RATE_COUNT
        return True

    def run_to(self, target: float, deadline: float | None = None,
               notice: LongRunNotice | None = None) -> int:
        """Advance until ``target`` is reached or the run ends, or (the status still
        running) a ``deadline`` of :func:`time.monotonic` passes; ``notice`` is told after
        each call."""
        import time

        while True:
            status = self.advance(target)
            if notice is not None:
                notice.update(self)
            if status != core.ST_RUNNING or self.t >= target:
                return status
            if deadline is not None and time.monotonic() > deadline:
                return status

    def events(self) -> tuple[np.ndarray, np.ndarray]:
        """Times and integer rows (kind, from, to, slider) of the switches so far."""
        if not self.ev_times:
            return np.empty(0), np.empty((0, core.N_EVI), dtype=np.int64)
        return np.concatenate(self.ev_times), np.concatenate(self.ev_rows)

    def set_tangents(self, vectors: np.ndarray) -> None:
        """Carry tangent vectors (rows, over the dynamic state) from the current state on.

        Rows of coordinates that are not free in the current phases (``z``, ``zdot`` of a
        slider in contact, ``phidot`` of a sticking one) are ignored. Given before the
        first :meth:`advance`, they are carried across the start's choice of phases.
        """
        vectors = np.atleast_2d(np.asarray(vectors, dtype=float))
        nd = self.model.state_size
        if vectors.ndim != 2 or vectors.shape[1] != nd:
            raise ValueError(
                f"tangent vectors have shape {vectors.shape}: must be (k, {nd}), rows over "
                "the dynamic state"
            )
        self.core.set_tangents(vectors)

    def tangents(self, slaved: bool = True) -> np.ndarray:
        """Current tangent vectors (rows); with ``slaved``, the rows of coordinates that
        follow the contact (``z``, ``zdot`` in contact) are filled in as the output
        carries them, else they are zero as integrated."""
        if not self.core.has_tangents:
            raise RuntimeError("no tangent vectors are carried: call set_tangents first")
        return self.core.tangents(slaved)

    def free(self) -> np.ndarray:
        """Mask of the coordinates that are free in the current phases."""
        return core.free_mask(core.core_model(self.model), self.core.ph)

    def rhs(self) -> np.ndarray:
        """The current phases' right-hand side at the current state (dynamic part)."""
        return self.core.rhs()
