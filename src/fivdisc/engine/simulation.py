"""Driver of the non-smooth simulation: ``simulate(case) -> Result``."""

from __future__ import annotations

import math
import time as _time
from collections.abc import Callable

import numpy as np

from fivdisc import core
from fivdisc.case import Case
from fivdisc.engine.conventions import fivdisc_version
from fivdisc.engine.equilibrium import initial_state
from fivdisc.engine.integration import STATUS, Integration, LongRunNotice, check_steps
from fivdisc.engine.progress import SIMULATED_TIME, progress_bar
from fivdisc.engine.result import EVENT_KINDS, PHASE_NAMES, Result, build_dataset
from fivdisc.errors import SimulationError
from fivdisc.limits import check_simulation
from fivdisc.model.build import Model, build_model
from fivdisc.model.speed import SpeedProfile

# Failures in which a state beyond the plate theory's range means the model diverged.
_BLOW_UPS = ("nonfinite", "step_size_underflow")
_CHUNKS = 200


def simulate(
    case: Case,
    *,
    initial=None,
    speed: SpeedProfile | tuple[Callable, Callable] | None = None,
    stop_on: tuple[str, ...] = (),
    progress: bool = False,
    phases=None,
) -> Result:
    """Integrate the slider-on-disc system of ``case``.

    Parameters
    ----------
    case : Case
        The case (disc, slider, friction, speed, simulation settings).
    initial : optional
        Initial state; see :func:`initial_state`.
    speed : SpeedProfile or (callable, callable), optional
        Overrides the case's speed: a profile, or a pair ``Omega(t)`` [rad/s],
        ``Omegadot(t)`` [rad/s^2] of Python callables (represented by a cubic
        Hermite interpolant, see :meth:`SpeedProfile.from_callables`).
    stop_on : tuple of str
        Event kinds (``"separation"``, ``"stick"``, ...) that end the run early;
        the status is then ``"stopped"``.
    progress : bool
        Show a progress bar in simulated time.
    phases : array of int, optional
        Each slider's phase at the start (``layout.SLIP``, ``STICK``, ``SEPARATION``), for
        a state saved mid-run (a result's ``final_phase``): a slider given as separated
        starts flying from its own ``z``, ``zdot``; the others take the phase their state
        allows. Default: all in contact.

    Returns
    -------
    Result
        Its ``dataset`` holds the sampled histories and the event table; a failed
        run keeps what was computed, with ``status`` and ``message`` saying why.

    Raises
    ------
    FivdiscError
        The recorded output would not fit in memory (see :mod:`fivdisc.limits`).
    CaseError
        `speed` is not a profile or a pair of callables, or cannot be represented.

    See Also
    --------
    open_result : A result saved before, read back (``Result.to_netcdf``, ``fivdisc
        simulate -o``).
    fivdisc.sweep.run_sweep : Many simulations over a grid of case values.

    Examples
    --------
    50 ms of the paper's Table 1 case: the slider sticks and slips about every 6 ms.

    >>> import fivdisc
    >>> case = fivdisc.Case(simulation={"duration": 0.05})
    >>> result = fivdisc.simulate(case)
    >>> result
    <fivdisc.Result run: success, 0.05 s simulated, 1 slider(s), 501 samples, 18 events>
    >>> print(result.summary())
    status: success at t = 0.05 s
    time in phase: slip 0.0237 s, stick 0.0263 s, separation 0 s
    switches: 18, separations: 0, impacts: 0
    peak normal force: 668.6... N, largest |w| at probes: 0.00434... m
    note: the disc deflected by up to 4.34 mm, 2.17 times its thickness h = 2 mm; ...
    wall time: ... s (integration only)

    A kick of the first disc mode's velocity makes the slider leave the disc; stop the
    run there:

    >>> kicked = fivdisc.simulate(case, initial={"q_dot": [5.0, 0, 0, 0, 0, 0, 0]},
    ...                           stop_on=("separation",))
    >>> print(kicked.status, f"{1e3 * kicked.events('separation')[0]:.2f} ms")
    stopped 6.45 ms
    """
    if not isinstance(case, Case):
        raise SimulationError(
            f"case = {type(case).__name__} is invalid: must be a fivdisc.Case (Case(...), "
            "Case.model_validate(dict) or load_case(path))"
        )
    sim = case.simulation
    check_simulation(case)
    speed = SpeedProfile.from_override(speed, sim.duration)
    if speed is not None and not speed.end >= sim.duration:
        raise SimulationError(
            f"speed is invalid: the profile ends at t = {speed.end!r} s, before "
            f"simulation.duration = {sim.duration!r} s (it would be extrapolated); give "
            "it over the whole run"
        )
    for kind in stop_on:
        if kind not in EVENT_KINDS:
            raise SimulationError(
                f"stop_on = {kind!r} is invalid: must be one of {', '.join(EVENT_KINDS)}"
            )
    model = build_model(case, speed)
    check_steps(model, sim.duration)
    y0 = initial_state(model, initial)
    limit = Deflection(model)
    if limit.beyond(y0):
        raise SimulationError(
            f"the initial state is invalid: it deflects the disc by {limit.largest:.3g} m, "
            f"more than {limit.DIVERGED:g} times disc.thickness, where the run would end as "
            "diverged"
        )
    if phases is not None:
        phases = np.asarray(phases, dtype=np.int64)
        if phases.shape != (model.n_sliders,):
            raise SimulationError(f"phases has shape {phases.shape}: must be "
                                  f"({model.n_sliders},), one phase per slider")
    run = Integration(model, y0, duration=sim.duration, output_rate=sim.output_rate,
                      stop_on=stop_on, energy=sim.energy_balance, phases=phases)

    # A first call with target 0 only sets up the start (the phases the initial state
    # allows), before the progress bar and the wall time start.
    run.advance(0.0)
    bar = progress_bar(sim.duration, "simulating", "s", show=progress,
                       bar_format=SIMULATED_TIME)
    start = _time.perf_counter()
    status = core.ST_RUNNING
    notice = LongRunNotice(model, sim.duration)
    with Interrupt() as interrupt:
        try:
            # The kernel's step-size controller restarts at each chunk (the saved outputs
            # of the paper's cases follow this grid), so the grid is fixed, not adaptive;
            # within a chunk each call is bounded (Integration.advance), and an interrupt
            # is taken between calls.
            for chunk in range(1, _CHUNKS + 1):
                target = sim.duration * chunk / _CHUNKS
                while not interrupt.requested:
                    status = run.advance(target)
                    notice.update(run)
                    if bar is not None:
                        bar.update(run.t - bar.n)
                    if status != core.ST_RUNNING or run.t >= target:
                        break
                if interrupt.requested or limit.exceeded(run) or status != core.ST_RUNNING:
                    break
        except KeyboardInterrupt:
            interrupt.requested = True
        finally:
            if bar is not None:
                bar.close()
    interrupted = interrupt.requested
    wall = _time.perf_counter() - start

    t_end = run.t
    ph = run.ph
    y = run.y
    phases = _phases(ph)
    name = STATUS.get(status, "unknown")
    if interrupted:
        name, message = "interrupted", f"interrupted at t = {t_end:.9g} s in {phases}"
    elif limit.when is not None or (name in _BLOW_UPS and limit.beyond(y)):
        name, message = "diverged", limit.message(t_end)
    else:
        message = _message(name, t_end, phases, case, run)
    n_done = run.n_samples
    times = np.minimum(np.arange(n_done) / sim.output_rate, sim.duration)
    stats = run.stats
    attrs = {
        "status": name,
        "message": message,
        "end_time": float(t_end),
        "impact": int(sim.impact),
        "case": case.to_toml(),
        "speed_source": "case" if speed is None else
        f"{speed.source} given to simulate (the case's [speed] table is not used)",
        "fivdisc_version": fivdisc_version(),
        "wall_time": wall,
        "n_steps": stats["steps"],
        "n_rejected": stats["rejected"],
        "n_rhs": stats["rhs"],
        "n_rhs_events": stats["rhs_events"],
        "n_switches": stats["switches"],
        "final_phase": ph.copy(),
        "final_state": y.copy(),
    }
    ds = build_dataset(model, run.out_y[:n_done], run.out_aux[:n_done], times, run.events(),
                       attrs)
    ds.attrs["degenerate"] = degenerate(case, ds, limit.largest)
    return Result(ds)


# Below these a run's response has no physical meaning (a thousandth of a nanometre; a
# nanonewton, a millionth of a gram's weight): a case that stays below them is degenerate.
_NO_DEFLECTION = 1e-12
_NO_FORCE = 1e-9


def degenerate(case: Case, ds, largest_w: float) -> str:
    """Why the run of `case` (its dataset `ds`) says nothing about friction-induced
    vibration, in one line ("" if nothing does): no preload or no friction, no probes,
    or a response that stays below any physical scale (`largest_w` [m]: the largest
    deflection under the sliders and at the probes)."""
    reasons = []
    zero = [f"{case.slider_key(j)}.preload" for j, s in enumerate(case.sliders)
            if s.preload == 0]
    if zero:
        reasons.append(f"{', '.join(zero)} = 0 N (no normal force, so no friction)")
    law = case.friction
    coefficients = [law.static, *(v for _, v in law.kinetic_at_rest()),
                    getattr(law, "kinetic_min", 0.0), *getattr(law, "values", ())]
    if not any(coefficients):
        reasons.append("every friction coefficient is 0 (no friction force)")
    if not case.simulation.probes:
        reasons.append("simulation.probes = [] (no deflection is recorded)")
    if ds.sizes["time"] > 1:
        force = ds["normal_force"].values
        peak = float(np.nanmax(force)) if np.isfinite(force).any() else math.nan
        if len(zero) < len(case.sliders) and peak < _NO_FORCE:
            reasons.append(f"the normal force stays below {_NO_FORCE:g} N (peak {peak:.3g} N)")
        if largest_w < _NO_DEFLECTION:
            reasons.append(f"the disc's deflection stays below {_NO_DEFLECTION:g} m (largest "
                           f"{largest_w:.3g} m): check disc.density, disc.youngs_modulus, "
                           "the preloads")
    return "; ".join(reasons)


class Deflection:
    """The range of linear (Kirchhoff) plate theory: a deflection of more than
    ``DIVERGED`` disc thicknesses ends a run as diverged.

    Linear plate theory holds while |w| is small against the thickness h; the paper's
    own cases reach about 2 h (its 500 N preload on a 2 mm disc), and its runs with the
    printed gyroscopic sign about 17 h before they separate, so the limit is set beyond
    both, where membrane stretching would long dominate: a run that gets there has blown
    up or its parameters leave the model's range. The disc's w is checked
    under every slider and at every probe, at each output sample and at the state where
    each chunk of the run ends.
    """

    DIVERGED = 25.0

    def __init__(self, model: Model) -> None:
        self.model = model
        self.thickness = model.case.disc.thickness * self.DIVERGED
        self.checked = 0
        self.when: float | None = None
        self.largest = 0.0
        self.probes = model.probe_shapes.T if model.probe_shapes.shape[0] else None

    def _w(self, q: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """w [m] under the sliders and at the probes for modal coordinates ``q`` (rows)."""
        model = self.model
        kern = model.kernel
        places = model.shape_matrix(kern.row("radius"), kern.row("theta") + phi)
        return np.concatenate([q @ places.T, q @ model.probe_shapes.T], axis=-1)

    def beyond(self, y: np.ndarray) -> bool:
        """Whether the state ``y`` is non-finite or deflects the disc beyond the limit."""
        model = self.model
        q = y[model.slices.q]
        phi = y[model.slices.phi]
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(phi))):
            self.largest = np.inf
            return True
        # |w| under slider j is at most sum_i |R_i(r_j) q_i| (|cos|, |sin| <= 1): when that
        # bound is within the limit, the mode shapes (Bessel functions, the costly part)
        # need not be evaluated at the sliders' angles.
        bound = np.abs(model.kernel.shape) @ np.abs(q)
        probes = np.abs(model.probe_shapes @ q)
        if max(np.max(bound, initial=0.0), np.max(probes, initial=0.0)) <= self.thickness:
            self.largest = max(self.largest, float(np.max(probes, initial=0.0)))
            return False
        w = np.max(np.abs(self._w(q, phi)), initial=0.0)
        self.largest = max(self.largest, float(w))
        return bool(w > self.thickness)

    def exceeded(self, run: Integration) -> bool:
        """Check the samples ``run`` wrote since the last call (the kernel keeps the
        largest |w| under the sliders), or its current state when there are none (a low
        output rate); remember the first time the limit is passed."""
        done = run.n_samples
        if done > self.checked:
            first, self.checked = self.checked, done
            largest = run.take_peak()
            if self.probes is not None:
                q = run.out_y[first:done, : self.model.n]
                probes = float(np.abs(q @ self.probes).max())
                largest = probes if math.isnan(probes) or probes > largest else largest
            if not math.isfinite(largest):
                self.largest = math.inf
                passed = True
            else:
                self.largest = max(self.largest, largest)
                passed = largest > self.thickness
        else:
            passed = self.beyond(run.y)
        if passed:
            self.when = run.t
        return passed

    def message(self, t: float) -> str:
        return (f"diverged at t = {t:.9g} s: the disc deflection reached {self.largest:.3g} m, "
                f"more than {self.DIVERGED:g} times disc.thickness = "
                f"{self.model.case.disc.thickness:g} m, far beyond linear plate theory; check "
                "the parameters (a preload or speed too large, or "
                "printed_gyroscopic_sign = true)")


class Interrupt:
    """While active (a ``with`` block in the main thread), the first SIGINT (Ctrl-C) sets
    :attr:`requested` instead of raising, so that a run stops between two kernel calls
    and keeps what it computed; a second one interrupts at once."""

    def __init__(self) -> None:
        self.requested = False
        self._previous = None

    def _handle(self, signum, frame) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self) -> Interrupt:
        import signal
        import threading

        # Only over Python's own handler: a process that ignores SIGINT (a sweep's
        # worker, which its coordinator stops) keeps ignoring it.
        if (threading.current_thread() is threading.main_thread()
                and signal.getsignal(signal.SIGINT) is signal.default_int_handler):
            self._previous = signal.signal(signal.SIGINT, self._handle)
        return self

    def __exit__(self, *exc) -> None:
        if self._previous is not None:
            import signal

            signal.signal(signal.SIGINT, self._previous)


def _phases(ph: np.ndarray) -> str:
    """The sliders' phases in a message: each one's, or how many are in each."""
    if ph.size <= 8:
        return ", ".join(PHASE_NAMES[p] for p in ph)
    return ", ".join(f"{np.sum(ph == i)} sliders in {name}"
                     for i, name in enumerate(PHASE_NAMES) if np.any(ph == i))


def _sliders(case: Case, sliders: tuple[int, ...]) -> str:
    names = [case.slider_key(j) for j in sliders]
    if len(names) > 8:
        names = [*names[:8], f"... ({len(names)} sliders)"]
    return ", ".join(names)


def _message(name: str, t: float, phase: str, case: Case, run: Integration) -> str:
    sim = case.simulation
    where = f"at t = {t:.9g} s in {phase}"
    if name == "endless_switching":
        return (f"endless switching (Zeno/chattering) {where}: switches accumulate among "
                f"{_sliders(case, run.zeno_sliders)} ({run.zeno_count} switches "
                f"within {run.zeno_span:.3g} s); check the parameters of these sliders "
                "(an impact cascade between sliders close together, a stiff contact)")
    return {
        "success": f"reached t = {sim.duration} s",
        "stopped": f"stopped early on request at t = {t:.9g} s",
        "nonfinite": f"state became non-finite {where}; try smaller simulation.rtol/atol "
        "or check the parameters",
        "step_size_underflow": f"step size underflow {where}; try looser simulation.rtol/atol",
        "max_switches": f"simulation.max_switches = {sim.max_switches} reached {where} "
        f"after {run.stats['switches']} switches",
        "too_many_steps": f"simulation.max_steps = {sim.max_steps} steps tried {where} "
        f"(mean step {t / max(run.steps_tried, 1):.3g} s); raise simulation.max_steps, "
        "loosen simulation.rtol/atol or check the parameters (a stiff spring or damper)",
    }.get(name, f"ended {where}")

