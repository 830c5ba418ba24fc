"""Sliding equilibrium at constant disc speed (paper section 3.1)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivdisc._kernels import dynamics as dyn
from fivdisc.case import Case
from fivdisc.errors import SimulationError
from fivdisc.model import Model, build_model


@dataclass(frozen=True)
class Equilibrium:
    """Steady sliding at constant disc speed.

    Attributes
    ----------
    q : ndarray
        Modal coordinates [m] (per unit mode shape).
    phi : float
        Slider angle [rad].
    normal_force : float
        N [N].
    friction_force : float
        f [N].
    speed : float
        The constant disc speed Omega_c [rad/s].
    state : ndarray
        The kernel state vector at equilibrium (velocities zero).
    """

    q: np.ndarray
    phi: float
    normal_force: float
    friction_force: float
    speed: float
    state: np.ndarray


def _accelerations(model: Model, y: np.ndarray) -> tuple[np.ndarray, float, float]:
    n = model.n
    width = max(model.state_size, int(model.par[dyn.P_LMAX]) + 2)
    work = np.zeros((5, width))
    dy = np.empty(model.state_size)
    nf, f, *_ = dyn.evaluate(0.0, y, dyn.SLIP, 1, True, model.kernel_args, work, dy)
    return dy[n + 2 : 2 * n + 3], nf, f


def sliding_equilibrium(
    case: Case | Model, xtol: float = 1e-13, guess: Equilibrium | None = None
) -> Equilibrium:
    """Solve the slip equations (s = +1) with all velocities and accelerations zero.

    The residual is the vector of generalised forces that remain when the
    kernel's slip accelerations are multiplied by their inertias; it vanishes exactly
    at the equilibrium of Eqs. (33), (34), (36) with the time derivatives set to zero.

    Parameters
    ----------
    case : Case or Model
        A case with a constant speed profile (or a model built from one).
    xtol : float
        Relative tolerance of :func:`scipy.optimize.root` (``hybr``).
    guess : Equilibrium, optional
        Start of the iteration (for example the solution at a neighbouring parameter);
        default: the rigid-disc equilibrium.

    Raises
    ------
    SimulationError
        If the speed is not constant or no equilibrium is found.
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
    n = model.n
    par = model.par
    inertias = np.append(model.modal_mass, par[dyn.P_INERTIA])
    mu = par[dyn.P_MU1] + (par[dyn.P_MU0] - par[dyn.P_MU1]) * np.exp(
        -par[dyn.P_ALPHA] * par[dyn.P_R0] * omega_c
    )
    # Rigid-disc guess: N = N0, friction balanced by the in-plane spring.
    phi0 = par[dyn.P_R0] * mu * par[dyn.P_N0] / par[dyn.P_KPHI]
    stiff = model.modal_mass * (model.omega**2 - model.l**2 * omega_c**2)
    g = np.where(model.sgn > 0, np.cos(model.l * phi0), np.sin(model.l * phi0)) * model.R0
    x0 = np.append(-par[dyn.P_N0] * g / stiff, phi0)
    if guess is not None and guess.q.size == n:
        x0 = np.append(guess.q, guess.phi)

    def state(x: np.ndarray) -> np.ndarray:
        y = np.zeros(model.state_size)
        y[: n + 1] = x
        return y

    def residual(x: np.ndarray) -> np.ndarray:
        acc, *_ = _accelerations(model, state(x))
        return acc * inertias

    def jacobian(x: np.ndarray) -> np.ndarray:
        jac = dyn.complex_step_jacobian(0.0, state(x), dyn.SLIP, 1, model.kernel_args)
        return jac[n + 2 : 2 * n + 3, : n + 1] * inertias[:, None]

    sol = root(residual, x0, jac=jacobian, method="hybr", options={"xtol": xtol})
    # hybr may report "no progress" once it sits at round-off: judge by the residual, in
    # generalised forces [N], against the preload.
    scale = par[dyn.P_N0] + 1.0
    if not np.max(np.abs(sol.fun)) <= 1e-9 * scale:
        raise SimulationError(
            f"no sliding equilibrium found at Omega = {omega_c} rad/s ({sol.message.strip()})"
        )
    y = state(sol.x)
    _, nf, f = _accelerations(model, y)
    if nf <= 0.0:
        raise SimulationError(
            f"no sliding equilibrium at Omega = {omega_c} rad/s: the normal force would be "
            f"{nf:.4g} N (contact lost)"
        )
    return Equilibrium(
        q=sol.x[:n].copy(),
        phi=float(sol.x[n]),
        normal_force=float(nf),
        friction_force=float(f),
        speed=omega_c,
        state=y,
    )
