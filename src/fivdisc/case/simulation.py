"""The ``[simulation]`` table: how to run, and the ``[simulation.perturbation]`` of a start
from the sliding equilibrium."""

from __future__ import annotations

from typing import ClassVar, Literal

from fivdisc.case.fields import Count, Flag, Probe, Real, Table, field


class Perturbation(Table):
    """Offsets added to the sliding equilibrium when a run starts from it.

    Attributes
    ----------
    phi
        Offset of the slider's angle [rad].
    phi_dot
        Offset of the slider's angular velocity [rad/s].
    """

    _key: ClassVar[tuple[str, ...]] = ("simulation", "perturbation")

    phi: Real = field(1e-3, "rad", r"\Delta\phi", "perturbation of the slider angle")
    phi_dot: Real = field(0.0, "rad/s", r"\Delta\dot\phi",
                          "perturbation of the slider angular velocity")


class Simulation(Table):
    """How to run: time span, output, initial state, options and tolerances.

    Attributes
    ----------
    duration
        Simulated time [s], > 0.
    output_rate
        Output samples per second [Hz], >= 1e-300 (a run shorter than the sample interval
        records its start only).
    impact
        Apply the perfectly plastic impact at re-contact (else velocities are kept).
    initial_state
        "rest" (all displacements and velocities zero) or "equilibrium" (the
        sliding equilibrium plus `perturbation`; constant speed only).
    probes
        (r [m], theta [rad]) points of the disc whose displacement w is recorded;
        each r within [a, b], each theta within +-1e6.
    omega_dot_terms
        Keep the disc's dOmega/dt terms (the paper's printed equations omit them).
    printed_gyroscopic_sign
        Use the printed paper's sign of the gyroscopic term of the D equations
        (+2 l M Omega dC/dt instead of -). That form is not skew: it acts as a
        speed-proportional negative damping. For comparison with the paper only.
    rtol
        Relative tolerance of the integrator, in (0, 0.1].
    atol
        Absolute tolerance of the integrator, > 0.
    max_step
        Largest integrator step [s]; 0 means no limit.
    max_switches
        Phase switches (slip, stick, separation) after which the run stops, >= 1.
    max_steps
        Integrator steps (accepted and rejected) after which the run stops with status
        ``too_many_steps``, keeping what was computed, >= 1; a run estimated to need more
        is refused before it starts. The default is some minutes of work, about a
        hundred times what the longest of the paper's cases takes.
    min_flight_time
        Shortest flight of a slider that is resolved [s], > 0: a landing impact that
        would release another slider for less than this keeps it in contact (it ends
        the ever shorter flights of an impact cascade between several sliders).
    energy_balance
        Integrate the power of every force alongside the state, so that
        :func:`fivdisc.energy_balance` can account for the energy of the run.
    perturbation
        Offsets from the sliding equilibrium used when `initial_state` is "equilibrium"
        (the same offsets for every slider); with "rest" only its defaults are accepted
        (other values would be ignored).
    """

    _key: ClassVar[tuple[str, ...]] = ("simulation",)

    duration: Real = field(1.0, "s", "", "simulated time", gt=0)
    # Its sample interval, 1 / output_rate, must be a number of seconds (5e-324 Hz made it
    # infinite, and the first sample's time 0 * inf a NaN).
    output_rate: Real = field(10000.0, "Hz", ge=1e-300)
    impact: Flag = True
    initial_state: Literal["rest", "equilibrium"] = "rest"
    probes: tuple[Probe, ...] = field(((0.1, 0.0), (0.1, 1.0)))
    omega_dot_terms: Flag = True
    printed_gyroscopic_sign: Flag = False
    # Below these the error test is rounding: a relative tolerance under 1e-15 is below the
    # spacing of doubles, and an absolute one under 1e-30 squares to underflow.
    rtol: Real = field(1e-6, ge=1e-15, le=0.1)
    atol: Real = field(1e-9, ge=1e-30)
    max_step: Real = field(0.0, "s", ge=0)
    max_switches: Count = field(10_000_000, ge=1)
    max_steps: Count = field(100_000_000, ge=1)
    min_flight_time: Real = field(1e-11, "s", gt=0)
    energy_balance: Flag = False
    perturbation: Perturbation = Perturbation()
