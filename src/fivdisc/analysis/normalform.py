"""The first Lyapunov coefficient of a Hopf point of the sliding equilibrium.

At a Hopf point the slip equations ``x' = F(x)`` (every slider slipping forward, a smooth
flow) have a pair of eigenvalues ``+-i omega`` on the imaginary axis. On the centre
manifold the flow's normal form is, in polar coordinates,

``rho' = rho (Re lambda(p) + omega l1 rho^2 + O(rho^4))``,

and the sign of the first Lyapunov coefficient ``l1`` decides the kind of the point:
``l1 < 0`` supercritical (small stable orbits where the equilibrium is unstable),
``l1 > 0`` subcritical (small unstable orbits where it is stable, around a basin of
stable sliding whose edge they are). ``l1`` comes from the second and third derivatives
of ``F`` at the equilibrium by Kuznetsov's formula; here they are central differences of
the exact (complex-step) Jacobian, extrapolated over a ladder of steps (Romberg), with an
error estimate from the ladder.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivdisc.analysis.points import reduced_indices, slip_jacobian
from fivdisc.model.build import Model

__all__ = ["FirstLyapunov", "first_lyapunov", "lyapunov_coefficient"]

# Largest step of the ladder, as a fraction of the slip-speed scale of the nonlinearity
# (the sliding speed, or the friction law's velocity scale if that is shorter), and the
# number of steps, each half the last. Over the rigid-disc closed forms the extrapolated
# l1 is within 1e-10 from 0.2 down to 0.0125 of the scale; rounding takes over below
# about 0.005 (it grows as 1 / h^2), and the series in h converges slowly above 0.4.
_FIRST_STEP = 0.2
_LEVELS = 5
# Ladders tried, each from a step 8 times shorter, until the error estimate is below
# _ENOUGH of |l1|; the one with the smallest estimate is kept.
_RETRIES = 4
_ENOUGH = 1e-6


@dataclass(frozen=True)
class FirstLyapunov:
    """First Lyapunov coefficient of a Hopf point and what it was computed with.

    Attributes
    ----------
    value : float
        ``l1`` [s^2] (per (rad/s)^2 of slip-speed amplitude): ``rho' = rho (Re lambda +
        omega l1 rho^2)`` with ``rho`` the amplitude of the oscillation of the slip
        speed ``phidot`` [rad/s] of slider `slider`. Negative: supercritical; positive:
        subcritical.
    error : float
        Estimated absolute error of `value` [s^2]: twice the spread of the extrapolated
        values of the step ladder.
    omega : float
        Angular frequency of the pair on the axis [rad/s].
    slider : int
        The slider whose slip-speed oscillation is largest in the critical mode: its
        amplitude is ``rho``.
    coefficient : complex
        ``c1`` [1/s per (rad/s)^2] of the complex normal form ``z' = (lambda) z + c1 z
        |z|^2``; ``l1 = Re c1 / omega``.
    """

    value: float
    error: float
    omega: float
    slider: int
    coefficient: complex

    @property
    def criticality(self) -> str:
        """``"subcritical"`` (``l1 > 0``), ``"supercritical"`` (``l1 < 0``), or
        ``"degenerate"`` where ``|l1|`` is not larger than its error (a Bautin point)."""
        if not np.isfinite(self.value) or abs(self.value) <= self.error:
            return "degenerate"
        return "subcritical" if self.value > 0.0 else "supercritical"


def _velocity_scale(model: Model, state: np.ndarray) -> tuple[float, float]:
    """Slip-speed scale [rad/s] over which the slip equations are far from linear: the
    sliding speed, or shorter the friction law's own scale over the track radius
    (1 / alpha, v_s); and a hard limit [rad/s] the steps must stay inside (a tabulated
    law is a cubic on each piece only: no step may cross a knot; else inf). On a piece
    the law is a cubic, whose differences of the Jacobian are exact: the largest step
    inside the piece is best."""
    radius = model.kernel.row("radius")
    omega_c = float(model.speed.omega(0.0))
    phid = state[model.slices.phi_dot]
    rel = omega_c - phid
    scale = float(np.min(np.abs(rel)))
    limit = np.inf
    law = model.law
    r = float(np.max(radius))
    if law == "exponential" and model.friction_value("decay") > 0.0:
        scale = min(scale, 1.0 / (model.friction_value("decay") * r))
    elif law == "stribeck":
        scale = min(scale, model.friction_value("stribeck_velocity") / r)
    elif law == "table":
        u = radius * rel
        gaps = np.abs(u[:, None] - model.table_knots[None, :]) / radius[:, None]
        limit = float(np.min(gaps))
    return scale, limit


def first_lyapunov(model: Model, state: np.ndarray, omega: float,
                   jacobian: np.ndarray | None = None) -> FirstLyapunov:
    """First Lyapunov coefficient of the slip equations at a Hopf point.

    Parameters
    ----------
    model : Model
        The model at the Hopf point's parameter values.
    state : ndarray
        The sliding equilibrium there, in the kernel's full state layout.
    omega : float
        Angular frequency of the pair on the imaginary axis [rad/s] (the pair nearest
        ``+-i omega`` is taken).
    jacobian : ndarray, optional
        The slip Jacobian at `state` (:func:`~fivdisc.analysis.points.slip_jacobian`),
        if already computed.

    Returns
    -------
    FirstLyapunov
        ``l1`` [s^2], its estimated error and the normal form's ``c1``.

    Notes
    -----
    :func:`lyapunov_coefficient` on the slip equations in the variables
    ``(q, phi, qdot, phidot)``, with the amplitude measured on the slip speed
    ``phidot_j`` of the slider that moves most in the critical mode, and the largest
    step 0.2 of the slip-speed scale of the nonlinearity: the sliding speed, or shorter
    ``1 / (alpha r)`` (exponential law) or ``v_s / r`` (Stribeck law). A tabulated law
    is a cubic on each piece only: no step crosses a knot, and ``l1`` is not defined at
    a knot (nan there).

    Examples
    --------
    A slider on a rigid disc with the exponential law, at its Hopf point in the speed:
    ``l1 = alpha^2 c / (16 m omega) = 0.5 / (16 0.1 1414.2)``, positive: subcritical.

    >>> import numpy as np
    >>> import fivdisc
    >>> from fivdisc.analysis.normalform import first_lyapunov
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> (point,) = fivdisc.hopf_points(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> res = first_lyapunov(fivdisc.build_model(point.case), point.equilibrium.state,
    ...                      point.omega)
    >>> print(f"{res.value:.6e} s^2: {res.criticality}")
    2.209709e-04 s^2: subcritical
    """
    jac = slip_jacobian(model, state) if jacobian is None else jacobian
    idx = reduced_indices(model)
    # The sliders' rates among the reduced unknowns.
    rates = np.flatnonzero(np.isin(idx, np.r_[model.slices.phi_dot]))
    q, _, lam = _critical_vectors(jac, omega)
    slider = int(np.argmax(np.abs(q[rates])))
    scale, limit = _velocity_scale(model, state)

    def jacobian_at(x: np.ndarray) -> np.ndarray:
        full = state.copy()
        full[idx] = x
        return slip_jacobian(model, full)

    # A step h along the critical vector, scaled to a slip-speed amplitude of 1/2,
    # moves the slip speed by at most h / 2.
    step = min(_FIRST_STEP * scale, 1.9 * limit)
    l1, error, c1 = lyapunov_coefficient(jacobian_at, state[idx], omega, int(rates[slider]),
                                         step, jac)
    return FirstLyapunov(l1, error, abs(lam.imag), slider, c1)


def lyapunov_coefficient(jacobian, x: np.ndarray, omega: float, index: int, step: float,
                         jac: np.ndarray | None = None) -> tuple[float, float, complex]:
    """First Lyapunov coefficient of ``x' = F(x)`` at a Hopf point, from its Jacobian.

    Parameters
    ----------
    jacobian : callable
        ``jacobian(x)``: the exact Jacobian of ``F`` at ``x`` (an ``(m, m)`` array).
    x : ndarray
        The equilibrium.
    omega : float
        Angular frequency of the pair on the imaginary axis [rad/s]; the eigenvalue
        nearest ``i omega`` is taken.
    index : int
        The component of ``x`` whose oscillation amplitude is the normal form's
        amplitude ``rho``: the critical eigenvector ``q`` is scaled so that ``q[index]
        = 1/2``, and ``x_eq + z q + conj(z q)`` oscillates in that component with
        amplitude ``|z|``.
    step : float
        The largest step along the real and imaginary parts of that ``q``: about 0.2 of
        the amplitude over which ``F`` is far from cubic (the extrapolation needs the
        series in the step to converge there; the smallest step is 1/16 of it).
    jac : ndarray, optional
        ``jacobian(x)``, if already computed.

    Returns
    -------
    l1 : float
        The first Lyapunov coefficient ``Re c1 / omega`` [1 / (unit of x[index])^2].
    error : float
        Its estimated absolute error.
    c1 : complex
        The normal form's coefficient: ``z' = lambda z + c1 z |z|^2`` [1/s per (unit of
        x[index])^2].

    Notes
    -----
    With ``A = DF(x)``, ``A q = i omega q``, ``A^T p = -i omega p``,
    ``<p, q> = conj(p)^T q = 1`` and the multilinear forms ``B(u, v) = D^2 F(u, v)``,
    ``C(u, v, w) = D^3 F(u, v, w)``, Kuznetsov's projection formula (Elements of Applied
    Bifurcation Theory, 3rd ed., sections 3.5 and 5.4) is

    .. math::

        c_1 = \\tfrac12 \\big[\\langle p, C(q, q, \\bar q)\\rangle
        - 2 \\langle p, B(q, A^{-1} B(q, \\bar q))\\rangle
        + \\langle p, B(\\bar q, (2 i\\omega - A)^{-1} B(q, q))\\rangle\\big],
        \\qquad l_1 = \\mathrm{Re}\\, c_1 / \\omega .

    With ``q = a + i b`` every form needed follows from the derivatives of the Jacobian
    along ``a`` and ``b``, ``K_v = dA/dv`` and ``H_v = d^2A/dv^2``:
    ``B(u, q) = (K_a + i K_b) u``, ``B(u, conj q) = (K_a - i K_b) u`` and
    ``C(q, q, conj q) = (H_a + H_b) q``. ``K_v`` and ``H_v`` are central differences of
    the exact Jacobian at ``x +- h v`` for ``h = step 2^-k``, ``k = 0 .. 4``. Their
    truncation error is a series in ``h^2``: Romberg's extrapolation removes its first
    two terms, leaving three values of ``c1`` with errors ``O(h^6)``, and the last is
    taken. The error estimate is twice the largest difference between those three,
    which also shows rounding (it grows as ``1 / h^2`` and the steps end at
    ``step / 16``). Where it exceeds ``1e-6 |l1|`` (the series in the step converging
    slowly: the nonlinearity shorter than `step` says) the ladder is tried again from
    steps 8, 64 and 512 times shorter, and the result with the smallest estimate kept.

    Examples
    --------
    The planar normal form ``x' = -y - x (x^2 + y^2)``, ``y' = x - y (x^2 + y^2)``:
    ``rho' = -rho^3``, so ``c1 = -1`` and ``l1 = -1`` at ``omega = 1``:

    >>> import numpy as np
    >>> from fivdisc.analysis.normalform import lyapunov_coefficient
    >>> def jacobian(v):
    ...     x, y = v
    ...     return np.array([[-3 * x**2 - y**2, -1 - 2 * x * y],
    ...                      [1 - 2 * x * y, -x**2 - 3 * y**2]])
    >>> l1, error, c1 = lyapunov_coefficient(jacobian, np.zeros(2), 1.0, 0, 0.1)
    >>> print(f"{l1:.10f}, {c1.real:.10f}")
    -1.0000000000, -1.0000000000
    """
    jac = jacobian(x) if jac is None else jac
    q, p, lam = _critical_vectors(jac, omega)
    if lam.imag < 0:
        q, p = q.conj(), p.conj()
    omega = abs(lam.imag)
    if q[index] == 0.0 or not step > 0.0:
        return np.nan, np.nan, complex(np.nan, np.nan)
    q = q * (0.5 / q[index])
    p = p / np.conj(np.vdot(p, q))
    try:
        inv_a = np.linalg.inv(jac)
        resonant = np.linalg.inv(2j * omega * np.eye(jac.shape[0]) - jac)
    except np.linalg.LinAlgError:
        # A zero eigenvalue (zero-Hopf) or a pair at 2 i omega (a 1:2 resonance): the
        # normal form has more critical terms than l1.
        return np.nan, np.nan, complex(np.nan, np.nan)
    best = (np.nan, np.inf, complex(np.nan, np.nan))
    for _ in range(_RETRIES):
        l1, error, c1 = _ladder(jacobian, x, jac, q, p, inv_a, resonant, omega, step)
        if error < best[1]:
            best = (l1, error, c1)
        if error <= _ENOUGH * abs(l1):
            break
        # The series in the step has not converged: the nonlinearity is shorter than
        # the scale given (a disc mode near a critical speed); try shorter steps.
        step /= 8.0
    return best


def _ladder(jacobian, x: np.ndarray, jac: np.ndarray, q: np.ndarray, p: np.ndarray,
            inv_a: np.ndarray, resonant: np.ndarray, omega: float, step: float
            ) -> tuple[float, float, complex]:
    """l1, its error estimate and c1 from the ladder of steps below `step`."""
    a, b = q.real, q.imag
    values = []
    for k in range(_LEVELS):
        h = step * 0.5**k
        ka, ha = _derivatives(jacobian, x, jac, a, h)
        kb, hb = _derivatives(jacobian, x, jac, b, h)
        kq, kqbar = ka + 1j * kb, ka - 1j * kb
        h11 = inv_a @ (kqbar @ q)
        h20 = resonant @ (kq @ q)
        values.append(0.5 * (np.vdot(p, (ha + hb) @ q) - 2.0 * np.vdot(p, kq @ h11)
                             + np.vdot(p, kqbar @ h20)))
    # Romberg's table: the h^2 and h^4 terms eliminated in turn.
    fourth = (4.0 * np.array(values[1:]) - np.array(values[:-1])) / 3.0
    sixth = (16.0 * fourth[1:] - fourth[:-1]) / 15.0
    c1 = complex(sixth[-1])
    error = 2.0 * float(np.max(np.abs(np.diff(sixth.real))))
    return c1.real / omega, error / omega, c1


def _critical_vectors(jac: np.ndarray, omega: float) -> tuple[np.ndarray, np.ndarray,
                                                               complex]:
    """Right and left eigenvectors of the eigenvalue nearest ``i omega``:
    ``A q = lambda q``, ``A^T p = conj(lambda) p``, not yet normalised."""
    from scipy.linalg import eig

    lam, vl, vr = eig(jac, left=True, right=True)
    i = int(np.argmin(np.abs(lam - 1j * omega)))
    return vr[:, i], vl[:, i], complex(lam[i])


def _derivatives(jacobian, x: np.ndarray, jac: np.ndarray, v: np.ndarray, h: float
                 ) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivatives of the Jacobian along ``v``, by central differences
    of step ``h``."""
    plus = jacobian(x + h * v)
    minus = jacobian(x - h * v)
    return (plus - minus) / (2.0 * h), (plus - 2.0 * jac + minus) / (h * h)
