"""Where a run starts: the sliding equilibrium at constant disc speed (paper section 3.1),
for any number of sliders, and the initial state of a simulation.

Both sit below the simulation driver, so that the driver and the analyses can share them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from fivdisc import core
from fivdisc.case import Case
from fivdisc.engine.evaluation import evaluate
from fivdisc.errors import SimulationError
from fivdisc.model import layout as lay
from fivdisc.model.build import Model, build_model
from fivdisc.model.layout import Phase


@dataclass(frozen=True)
class Equilibrium:
    """Steady sliding at constant disc speed: every slider slips forward, nothing moves.

    Attributes
    ----------
    q : ndarray
        Modal coordinates [m] (per unit mode shape).
    phi : ndarray
        Slider angles [rad], one per slider.
    normal_force : ndarray
        N [N], one per slider.
    friction_force : ndarray
        f [N], one per slider.
    speed : float
        The constant disc speed Omega_c [rad/s].
    state : ndarray
        The kernel state vector at equilibrium (velocities zero).

    See Also
    --------
    sliding_equilibrium : Makes it.

    Examples
    --------
    The preload presses the slider into the disc, which deflects under it; friction
    turns the slider forward until its spring holds it:

    >>> import fivdisc
    >>> equilibrium = fivdisc.sliding_equilibrium(fivdisc.Case())
    >>> print(f"phi = {equilibrium.phi[0]:.6f} rad, N = {equilibrium.normal_force[0]:.3f} N, "
    ...       f"f = {equilibrium.friction_force[0]:.3f} N")
    phi = 0.010495 rad, N = 434.226 N, f = 209.893 N
    >>> print((equilibrium.q * 1e3).round(3))  # modal coordinates [mm]
    [-0.674 -1.304 -0.007 -0.904 -0.01  -0.395 -0.007]
    """

    q: np.ndarray
    phi: np.ndarray
    normal_force: np.ndarray
    friction_force: np.ndarray
    speed: float
    state: np.ndarray


def slip_phases(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """Phase and sign arrays of every slider slipping forward (``v = Omega - phidot > 0``)."""
    ns = model.n_sliders
    return np.full(ns, Phase.SLIP, dtype=np.int64), np.ones(ns, dtype=np.int64)


def slip_evaluation(model: Model, y: np.ndarray) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The slip equations' right-hand side at ``y`` and the per-slider quantities of
    :func:`fivdisc.engine.evaluation.evaluate` (``normal_force``, ``friction_force``,
    ``w``, ...), every slider slipping with the disc faster."""
    return evaluate(model, y, *slip_phases(model))


def contact_forces(model: Model, y: np.ndarray, phases: np.ndarray, signs: np.ndarray,
                   t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Each slider's normal force and friction force (on the slider, along +phi) [N] at
    state ``y`` in the given phases and slip signs, as they are: no phase is chosen
    again (a stuck slider beyond its static limit stays stuck, its friction force the
    reaction that would hold it)."""
    _, aux = evaluate(model, np.asarray(y, dtype=float)[: model.state_size].copy(), phases,
                      signs, t)
    return (np.asarray(aux["normal_force"], dtype=float).copy(),
            np.asarray(aux["friction_force"], dtype=float).copy())


def _unknowns(model: Model) -> np.ndarray:
    """State indices of the equilibrium's unknowns (q, phi)."""
    return np.r_[model.slices.q, model.slices.phi]


def sliding_equilibrium(
    case: Case | Model, xtol: float = 1e-13, guess: Equilibrium | None = None,
    contact: bool = True,
) -> Equilibrium:
    """Solve the slip equations (s = +1 for every slider) with all velocities and
    accelerations zero.

    The residual is the vector of generalised forces that remain when the kernel's
    slip accelerations are multiplied by their inertias; it vanishes exactly at the
    equilibrium of the equations of motion with the time derivatives set to zero (the
    material-frame disc damping leaves its ``l Omega`` terms in it).

    Parameters
    ----------
    case : Case or Model
        A case with a constant speed profile (or a model built from one).
    xtol : float
        Relative tolerance of :func:`scipy.optimize.root` (``hybr``).
    guess : Equilibrium, optional
        Start of the iteration (for example the solution at a neighbouring parameter);
        default: each slider on a rigid disc, the disc deflected statically by the
        preloads.

    contact : bool
        Require every normal force to be positive (an equilibrium with a slider pulling
        on the disc does not exist). ``False`` returns the solution of the slip
        equations anyway, so that the limit of existence (a normal force reaching zero)
        can be located by a root finder.

    Returns
    -------
    Equilibrium
        The modal coordinates, the sliders' angles and their contact forces.

    Raises
    ------
    SimulationError
        If the speed is not constant or no equilibrium is found (with `contact`: or a
        normal force is not positive).

    See Also
    --------
    fivdisc.linear_stability : The eigenvalues of the slip equations about it.

    Examples
    --------
    While it slides, the slider's friction coefficient is the kinetic one at the sliding
    speed ``u = r Omega``: ``mu_1 + (mu_0 - mu_1) exp(-alpha u)`` for the exponential law
    of the paper's Table 1 case.

    >>> import numpy as np
    >>> import fivdisc
    >>> case = fivdisc.Case()
    >>> equilibrium = fivdisc.sliding_equilibrium(case)
    >>> u = case.slider.track_radius * case.speed.value  # [m/s]
    >>> mu = case.friction
    >>> print(f"{equilibrium.friction_force[0] / equilibrium.normal_force[0]:.10f}")
    0.4833720228
    >>> print(f"{mu.kinetic_min + (mu.kinetic_max - mu.kinetic_min) * np.exp(-mu.decay * u):.10f}")
    0.4833720228
    """
    from scipy.optimize import root

    model = case if isinstance(case, Model) else build_model(case)
    if not model.speed.is_constant():
        raise SimulationError(
            "a sliding equilibrium exists only at constant disc speed; "
            "use [speed] profile = \"constant\""
        )
    omega_c = float(model.speed.omega(0.0))
    if omega_c <= 0.0:
        raise SimulationError(
            f"speed.value = {omega_c} has no sliding equilibrium: the disc must spin (> 0 rad/s)"
        )
    n, ns = model.n, model.n_sliders
    kern = model.kernel_args
    unknowns = _unknowns(model)
    acc_index = np.r_[model.slices.q_dot, model.slices.phi_dot]
    radius, n0 = kern.row("radius"), kern.row("n0")
    inertias = np.append(model.modal_mass, kern.row("inertia"))
    # Rigid-disc guess: N = N0, friction balanced by the in-plane spring; the disc
    # deflected statically by the preloads.
    cm = core.core_model(model)
    mu = np.array([core.kinetic_friction(cm, radius[j], 1, omega_c) for j in range(ns)])
    with np.errstate(all="ignore"):
        phi0 = radius * mu * n0 / kern.row("kphi")
        stiff = model.modal_mass * (model.omega**2 - model.l**2 * omega_c**2)
        q0 = np.zeros(n)
        for j in range(ns):
            psi = kern.row("theta")[j] + phi0[j]
            g = (np.where(model.sgn > 0, np.cos(model.l * psi), np.sin(model.l * psi))
                 * model.shape[j])
            q0 -= kern.slider[lay.S_SN0, j] * g / stiff
    x0 = np.append(q0, phi0)
    if not np.all(np.isfinite(x0)):
        # Parameters out of range (a preload or friction torque against a vanishing
        # spring): the static deflection is not representable.
        raise SimulationError(
            f"no sliding equilibrium at Omega = {omega_c} rad/s: the static deflection "
            "by the preloads is out of floating-point range (check slider.preload, "
            "slider.rotational_stiffness, the friction coefficients)"
        )
    if guess is not None and guess.q.size == n and np.size(guess.phi) == ns:
        x0 = np.append(guess.q, guess.phi)

    def state(x: np.ndarray) -> np.ndarray:
        y = np.zeros(model.state_size)
        y[unknowns] = x
        return y

    ph, sg = slip_phases(model)

    def residual(x: np.ndarray) -> np.ndarray:
        return core.rhs(cm, 0.0, state(x), ph, sg)[acc_index] * inertias

    def jacobian(x: np.ndarray) -> np.ndarray:
        jac = core.jacobian(cm, 0.0, state(x), ph, sg)
        return jac[np.ix_(acc_index, unknowns)] * inertias[:, None]

    sol = root(residual, x0, jac=jacobian, method="hybr", options={"xtol": xtol})
    # hybr may report "no progress" once it sits at round-off: judge by the residual, in
    # generalised forces [N], against the preload.
    scale = float(np.max(n0)) + 1.0
    if not np.max(np.abs(sol.fun)) <= 1e-9 * scale:
        raise SimulationError(
            f"no sliding equilibrium found at Omega = {omega_c} rad/s ({sol.message.strip()})"
        )
    y = state(sol.x)
    _, aux = slip_evaluation(model, y)
    nf = aux["normal_force"]
    if contact and np.any(nf <= 0.0):
        j = int(np.argmin(nf))
        raise SimulationError(
            f"no sliding equilibrium at Omega = {omega_c} rad/s: the normal force of slider {j} "
            f"would be {nf[j]:.4g} N (contact lost)"
        )
    return Equilibrium(
        q=sol.x[:n].copy(),
        phi=sol.x[n:].copy(),
        normal_force=nf,
        friction_force=aux["friction_force"],
        speed=omega_c,
        state=y,
    )


def initial_state(model: Model, initial=None) -> np.ndarray:
    """Kernel state at t = 0 (without energy accumulators).

    Parameters
    ----------
    model : Model
        The model.
    initial : None, "rest", "equilibrium", mapping or array
        ``None`` takes the case's ``simulation.initial_state``. A mapping may give
        ``q`` [m] and ``q_dot`` [m/s] (one per modal coordinate), ``phi`` [rad] and
        ``phi_dot`` [rad/s] (one per slider, or one number for all); missing ones are
        zero. An array is a full state of length ``2 (n + 2 S)``.
    """
    sim = model.case.simulation
    if initial is None:
        initial = sim.initial_state
    n, ns = model.n, model.n_sliders
    y = np.zeros(model.state_size)
    phi, phi_dot = model.slices.phi, model.slices.phi_dot
    if isinstance(initial, str):
        if initial == "rest":
            return y
        if initial == "equilibrium":
            y = sliding_equilibrium(model).state.copy()
            own = model.case.sliders
            y[phi] += sim.perturbation.phi + np.array([s.perturbation.phi for s in own])
            y[phi_dot] += (sim.perturbation.phi_dot
                           + np.array([s.perturbation.phi_dot for s in own]))
            return _checked(y, phi)
        raise SimulationError(
            f"initial = {initial!r} is invalid: must be 'rest', 'equilibrium', a mapping "
            "or a state array"
        )
    if isinstance(initial, Mapping):
        allowed = {"q", "q_dot", "phi", "phi_dot"}
        unknown = set(initial) - allowed
        if unknown:
            raise SimulationError(
                f"initial has unknown keys {sorted(unknown)}: allowed are {sorted(allowed)}"
            )
        blocks = (("q", model.slices.q, n, "modal coordinate"),
                  ("q_dot", model.slices.q_dot, n, "modal coordinate"),
                  ("phi", phi, ns, "slider"), ("phi_dot", phi_dot, ns, "slider"))
        for key, sl, size, what in blocks:
            if key not in initial:
                continue
            val = np.asarray(initial[key], dtype=float)
            if what == "slider" and val.ndim == 0:
                val = np.full(ns, float(val))
            if val.shape != (size,):
                raise SimulationError(
                    f"initial[{key!r}] has shape {val.shape}: must be ({size},), one per {what}"
                )
            y[sl] = val
    else:
        y = np.array(initial, dtype=float)
        if y.shape != (model.state_size,):
            raise SimulationError(
                f"initial state has shape {y.shape}: must be ({model.state_size},) = "
                "2 (n + 2 S)"
            )
    return _checked(y, phi)


#: Largest initial rotation of a slider [rad].
MAX_PHI = 1e6


def _checked(y: np.ndarray, phi: slice) -> np.ndarray:
    """``y``, refused unless finite with slider rotations within :data:`MAX_PHI`."""
    if not np.all(np.isfinite(y)):
        raise SimulationError("initial state is invalid: all values must be finite")
    largest = float(np.max(np.abs(y[phi]), initial=0.0))
    if largest > MAX_PHI:
        raise SimulationError(
            f"initial phi = {largest:g} rad is invalid: must be within +-{MAX_PHI:g} rad "
            "(further out a double resolves the slider's angle to no better than 1e-10 rad)"
        )
    return y
