"""Free transverse vibration of an annular Kirchhoff plate, clamped inside and free outside.

The disc of the model is a thin annular plate of inner radius ``a`` (clamped to the hub)
and outer radius ``b`` (free). Its transverse modes are

    w(r, theta, t) = R_kl(r) [cos(l theta) C_kl(t) + sin(l theta) D_kl(t)],

with ``k`` nodal circles and ``l`` nodal diameters. This module finds the radial functions
``R_kl``, the natural frequencies ``omega_kl`` and the modal masses ``M_kl``.

Notes
-----
For one harmonic ``l`` the radial equation ``(lap^2 - beta^4) R = 0`` with
``lap R = R'' + R'/r - l^2 R / r^2`` has the general solution

    R(r) = A J_l(beta r) + B Y_l(beta r) + C I_l(beta r) e^{-beta b} + D K_l(beta r) e^{beta a}.

The exponential factors make the modified Bessel columns O(1) on ``[a, b]`` (``I_l`` grows
like ``e^{beta r}``, ``K_l`` decays like ``e^{-beta r}``), so the boundary-condition matrix
stays well conditioned for large ``beta``; ``coefficients`` are ``(A, B, C, D)`` of this scaled
form. The boundary conditions are

- clamped at ``r = a``: ``R = 0`` and ``R' = 0``;
- free at ``r = b``: radial moment ``R'' + nu (R'/r - l^2 R / r^2) = 0`` and Kirchhoff shear
  ``(lap R)' - (1 - nu) (l^2 / r^2) (R' - R / r) = 0``.

The frequency parameters ``beta`` are the zeros of the determinant of that 4 x 4 system;
``omega = beta^2 sqrt(D / (rho h))`` with ``D = E h^3 / (12 (1 - nu^2))``. ``beta`` depends only
on ``a``, ``b``, ``nu`` and ``l``, which is the key of the root cache.

The modal mass is ``M_kl = rho h pi int_a^b R_kl^2 r dr`` for ``l >= 1`` and twice that for
``l = 0`` (``int_0^{2 pi} cos^2(l theta) dtheta`` is ``pi`` or ``2 pi``).

Normalisation: ``R`` is scaled so that ``max_{a <= r <= b} |R(r)| = 1`` and ``R(b) > 0``. It
is a convention only: the dynamics depend on ``R(r)^2 / M``, which does not change with it.

References
----------
.. [1] A. W. Leissa, *Vibration of Plates*, NASA SP-160, 1969, ch. 2 (annular plates).
.. [2] The paper the project reproduces (``slider-on-spinning-disc.md``): Eq. (24), Table 1 and
   the natural frequencies quoted after it; the project's ``equations.md``, "Disc modes".
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from fivdisc.errors import ModeError
from fivdisc.model import mode_cache

__all__ = ["AnnularPlate", "PlateMode", "clear_cache"]

#: Highest derivative of R that :meth:`PlateMode.shape` returns (the shear condition needs R''').
MAX_DERIVATIVE = 3

# Consecutive roots of one harmonic are about pi / (b - a) apart in beta (beam limit); 32 grid
# points per spacing leave a wide margin against two roots sharing one grid cell.
_POINTS_PER_SPACING = 32
# Grid points evaluated per vectorised call while scanning for sign changes.
_SCAN_CHUNK = 64
# The determinant of a matrix with unit columns is at most 1 in size (Hadamard) and is
# computed to an absolute error of order 1e-15; below this its sign means nothing. That happens
# as beta -> 0, where J_l and I_l (and Y_l and K_l) become parallel, and where Y_l overflows.
_DETERMINANT_NOISE = 1e-12
# PlateMode.shape keeps its values at up to this many radii in the mode cache (a model's
# sliders and probes); longer arrays (figures, root searches) are computed.
_STORED_RADII = 64
# Slack on the radial range accepted by PlateMode.shape, to let r = a or b computed with
# round-off through.
_RADIUS_SLACK = 1e-12


# Per column (J, Y, I e^{-x_b}, K e^{x_a}): sign of f_{l+1} in f_l' = (l / x) f_l + s f_{l+1}, and
# sigma in the Bessel equation f'' = -f' / x + (sigma + l^2 / x^2) f.
_NEXT_ORDER_SIGN = np.array([-1.0, -1.0, 1.0, -1.0])
_BESSEL_SIGMA = np.array([-1.0, -1.0, 1.0, 1.0])


def _scaled_basis(
    order: int, x: np.ndarray, x_a: np.ndarray | float, x_b: np.ndarray | float, n_max: int
) -> np.ndarray:
    """Derivatives of the four scaled solutions with respect to their argument.

    Parameters
    ----------
    order : int
        Bessel order, the number of nodal diameters l.
    x : ndarray
        Arguments ``beta r`` [-], > 0.
    x_a, x_b : ndarray or float
        ``beta a`` and ``beta b`` [-], broadcastable with ``x``.
    n_max : int
        Highest derivative wanted, 0 to 3.

    Returns
    -------
    ndarray, shape (n_max + 1, *x.shape, 4)
        ``out[n, ..., i]`` is the n-th x-derivative of J_l, Y_l, I_l e^{-x_b}, K_l e^{x_a} for
        ``i = 0..3`` (l = order).

    Notes
    -----
    Only orders l and l + 1 are evaluated (the costly part); then ``f1 = (l / x) f0 + s f_{l+1}``
    and the Bessel equation ``f2 = -f1 / x + q f0`` with ``q = sigma + l^2 / x^2`` give
    ``f3 = -f2 / x + f1 / x^2 + q f1 - (2 l^2 / x^3) f0`` (``fn`` is the n-th derivative). None
    of these steps cancels catastrophically for small or large x. The exponentially scaled
    ``ive``/``kve`` keep I and K finite; the scale factors are constant in r, so they commute
    with the derivatives.
    """
    x = np.asarray(x, dtype=float)
    orders = np.array([order, order + 1], dtype=float).reshape((2,) + (1,) * x.ndim)
    pair = np.empty((2, *x.shape, 4))  # (order l or l + 1, *x.shape, column)
    # Imported here: a model whose radial values are in the mode cache needs no scipy.special
    # (a quarter of a second of every short command).
    from scipy import special

    pair[..., 0] = special.jv(orders, x)
    pair[..., 1] = special.yv(orders, x)
    pair[..., 2] = special.ive(orders, x) * np.exp(x - x_b)
    pair[..., 3] = special.kve(orders, x) * np.exp(x_a - x)
    xe = x[..., None]
    out = np.empty((n_max + 1, *x.shape, 4))
    f0 = out[0] = pair[0]
    if n_max == 0:
        return out
    f1 = out[1] = (order / xe) * f0 + _NEXT_ORDER_SIGN * pair[1]
    if n_max == 1:
        return out
    l2 = float(order * order)
    q = _BESSEL_SIGMA + l2 / xe**2
    f2 = out[2] = -f1 / xe + q * f0
    if n_max == 2:
        return out
    out[3] = -f2 / xe + f1 / xe**2 + q * f1 - (2.0 * l2 / xe**3) * f0
    return out


def _boundary_matrix(order: int, nu: float, a: float, b: float, beta: np.ndarray) -> np.ndarray:
    """Boundary-condition matrices, shape ``(*beta.shape, 4, 4)``.

    Rows: R(a), R'(a), radial moment at b, Kirchhoff shear at b, each divided by the power of
    beta that makes it dimensionless; columns: the four scaled solutions.
    """
    beta = np.asarray(beta, dtype=float)
    x_a = beta * a
    x_b = beta * b
    # One call for both edges halves the number of Bessel-function calls.
    f = _scaled_basis(order, np.stack([x_a, x_b]), x_a, x_b, MAX_DERIVATIVE)
    xb = x_b[..., None]
    l2 = float(order * order)
    matrix = np.empty((*beta.shape, 4, 4))
    matrix[..., 0, :] = f[0, 0]
    matrix[..., 1, :] = f[1, 0]
    matrix[..., 2, :] = f[2, 1] + nu * (f[1, 1] / xb - l2 * f[0, 1] / xb**2)
    matrix[..., 3, :] = (
        f[3, 1]
        + f[2, 1] / xb
        - (1.0 + (2.0 - nu) * l2) * f[1, 1] / xb**2
        + (3.0 - nu) * l2 * f[0, 1] / xb**3
    )
    return matrix


def _determinant(order: int, nu: float, a: float, b: float, beta: np.ndarray) -> np.ndarray:
    """Determinant of the boundary matrix with unit-norm columns.

    For large l, Y_l and K_l are huge at r = a while J_l and I_l are small there; unit columns
    keep every entry O(1). Dividing by positive column norms moves neither the zeros nor the
    sign changes. Where Y_l(beta a) overflows (beta a << l, far below the first root of a
    harmonic l) the value is NaN, which brackets no root.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        matrix = _boundary_matrix(order, nu, a, b, beta)
        return np.linalg.det(matrix / np.linalg.norm(matrix, axis=-2, keepdims=True))


def _count_bucket(count: int) -> int:
    """Round a root count up to a power of two (at least 4).

    The first n roots do not depend on how many are asked for, so asking for a few more lets
    requests for k = 0..3 (and later 4..7, ...) share one cache entry.
    """
    return max(4, 1 << max(count - 1, 0).bit_length())


@lru_cache(maxsize=512)
def _roots(a: float, b: float, nu: float, order: int, count: int) -> tuple[float, ...]:
    """The first ``count`` frequency parameters beta [1/m] of harmonic ``order``, ascending."""
    spacing = math.pi / (b - a)
    step = spacing / _POINTS_PER_SPACING
    # Generous upper bound: the k-th root lies near (k + 1) pi / (b - a) plus an l-dependent
    # offset below about l / b; missing it means the scan is broken, not that it is far away.
    beta_cap = 4.0 * ((count + 2) * spacing + (order + 2) / a)

    from scipy.optimize import brentq

    def det(beta: float) -> float:
        return float(_determinant(order, nu, a, b, np.array([beta]))[0])

    roots: list[float] = []
    # Last grid point whose determinant has a trustworthy sign; a bracket runs from it to the
    # next such point, so cells with an untrustworthy sign are merged into their neighbours'.
    last_beta, last_value = math.nan, math.nan
    start = 0.5 * step
    while len(roots) < count:
        if start > beta_cap:
            raise ModeError(
                f"found only {len(roots)} of {count} frequency parameters for l = {order} below "
                f"beta = {beta_cap:.4g} 1/m; the plate geometry may be degenerate"
            )
        grid = start + step * np.arange(_SCAN_CHUNK)
        values = _determinant(order, nu, a, b, grid)
        for beta, value in zip(grid.tolist(), values.tolist(), strict=True):
            if not abs(value) > _DETERMINANT_NOISE:  # also skips NaN
                continue
            if value * last_value < 0.0:
                roots.append(brentq(det, last_beta, beta, xtol=1e-14, rtol=1e-15))
            last_beta, last_value = beta, value
        start = float(grid[-1]) + step
    return tuple(roots[:count])


def _radial_values(
    order: int, beta: float, a: float, b: float, coefficients: np.ndarray, r: np.ndarray, d: int
) -> np.ndarray:
    """R^(d)(r) [1/m^d] for the scaled combination with the given coefficients."""
    return beta**d * (_scaled_basis(order, beta * r, beta * a, beta * b, d)[d] @ coefficients)


@lru_cache(maxsize=64)
def _leggauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    # numpy's rule, cached: scipy's roots_legendre is cheaper but differs in the last bits,
    # which changes every modal mass and so breaks bit-for-bit reproducibility of runs.
    return np.polynomial.legendre.leggauss(n)


def _gauss_legendre(a: float, b: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = _leggauss(n)
    half = 0.5 * (b - a)
    return a + half * (x + 1.0), half * w


@lru_cache(maxsize=2048)
def _radial_mode(
    a: float, b: float, nu: float, k: int, order: int
) -> tuple[float, tuple[float, float, float, float], float]:
    """beta [1/m], normalised coefficients and ``int_a^b R^2 r dr`` [m^2] of mode (k, l = order),
    as stored by an earlier process (:mod:`fivdisc.model.mode_cache`) or solved."""
    key = repr((a, b, nu, k, order))
    stored = mode_cache.lookup(key)
    if stored is not None:
        beta, coefficients, norm = stored
        return float(beta), tuple(float(c) for c in coefficients), float(norm)
    mode = _solved_radial_mode(a, b, nu, k, order)
    mode_cache.remember(key, [mode[0], list(mode[1]), mode[2]])
    return mode


def _solved_radial_mode(
    a: float, b: float, nu: float, k: int, order: int
) -> tuple[float, tuple[float, float, float, float], float]:
    from scipy.optimize import brentq

    beta = _roots(a, b, nu, order, _count_bucket(k + 1))[k]
    matrix = _boundary_matrix(order, nu, a, b, np.array(beta))
    # Null vector of the unit-column matrix (as in _determinant), mapped back to the columns.
    norms = np.linalg.norm(matrix, axis=0)
    _, _, vt = np.linalg.svd(matrix / norms)
    coefficients = vt[-1] / norms

    # R^2 r is analytic on [a, b] with about beta (b - a) / pi half waves (plus boundary layers
    # like e^{-2 beta |r - edge|}); Gauss-Legendre converges exponentially once the number of
    # nodes exceeds that several times. Rounding to a multiple of 16 lets modes share the
    # cached nodes.
    n_nodes = 16 * math.ceil((48 + 4 * beta * (b - a)) / 16)
    nodes, weights = _gauss_legendre(a, b, n_nodes)
    # The nodes are also at least 8 per half wave, dense enough to bracket the peak of |R|.
    samples = np.concatenate([[a], nodes, [b]])
    values = _radial_values(order, beta, a, b, coefficients, samples, 0)
    integral = float(np.sum(weights * values[1:-1] ** 2 * nodes))

    i = int(np.argmax(np.abs(values)))
    lo, hi = samples[max(i - 1, 0)], samples[min(i + 1, samples.size - 1)]
    candidates = [float(samples[i])]
    d_lo, d_hi = np.sign(values[i]) * _radial_values(
        order, beta, a, b, coefficients, np.array([lo, hi]), 1
    )
    if d_lo > 0.0 > d_hi:  # |R| peaks strictly inside (lo, hi): refine on R' = 0
        candidates.append(
            brentq(
                lambda s: float(_radial_values(order, beta, a, b, coefficients, np.array(s), 1)),
                lo,
                hi,
                xtol=1e-15,
            )
        )
    peak = float(
        np.max(np.abs(_radial_values(order, beta, a, b, coefficients, np.array(candidates), 0)))
    )
    sign = np.sign(values[-1]) if values[-1] != 0.0 else np.sign(values[i])
    coefficients = coefficients * (sign / peak)
    c0, c1, c2, c3 = (float(c) for c in coefficients)
    return beta, (c0, c1, c2, c3), integral / peak**2


def clear_cache() -> None:
    """Forget every cached root list, mode and quadrature rule (for timing a cold start)."""
    _roots.cache_clear()
    _radial_mode.cache_clear()
    _leggauss.cache_clear()


def _check_positive(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ModeError(f"{name} = {value!r} is not a number; allowed: a real number > 0")
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise ModeError(f"{name} = {value!r} is out of range; allowed: finite and > 0")
    return value


def _check_index(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ModeError(f"{name} = {value!r} is not an integer; allowed: integer >= 0")
    if value < 0:
        raise ModeError(f"{name} = {value!r} is out of range; allowed: integer >= 0")
    return int(value)


@dataclass(frozen=True)
class AnnularPlate:
    """Thin annular Kirchhoff plate, clamped at the inner radius and free at the outer one.

    Parameters
    ----------
    inner_radius : float
        Clamped radius ``a`` [m], > 0.
    outer_radius : float
        Free radius ``b`` [m], > ``a``.
    thickness : float
        Thickness ``h`` [m], > 0.
    density : float
        Mass density ``rho`` [kg/m^3], > 0.
    youngs_modulus : float
        Young's modulus ``E`` [Pa], > 0.
    poisson_ratio : float
        Poisson's ratio ``nu`` [-], -1 < nu < 0.5.

    Raises
    ------
    ModeError
        If a parameter is out of its range; the message names it.

    See Also
    --------
    PlateMode : One mode of the plate.
    fivdisc.build_model : The modes a case asks for, at its sliders and probes.

    Examples
    --------
    The paper's Table 1 disc and its first modes [Hz], ``(k, l)`` = (nodal circles, nodal
    diameters):

    >>> import fivdisc
    >>> plate = fivdisc.AnnularPlate(0.044, 0.12, 0.002, 7200.0, 150e9, 0.211)
    >>> round(plate.mode(0, 2).omega)
    1824
    >>> for mode in plate.modes([(0, 0), (0, 1), (0, 2), (0, 3), (1, 0)]):
    ...     print(mode.k, mode.l, round(mode.frequency_hz, 1))
    0 0 237.4
    0 1 241.4
    0 2 290.3
    0 3 441.5
    1 0 1551.5
    """

    inner_radius: float
    outer_radius: float
    thickness: float
    density: float
    youngs_modulus: float
    poisson_ratio: float

    def __post_init__(self) -> None:
        for name in ("inner_radius", "outer_radius", "thickness", "density", "youngs_modulus"):
            object.__setattr__(self, name, _check_positive(name, getattr(self, name)))
        if self.outer_radius <= self.inner_radius:
            raise ModeError(
                f"outer_radius = {self.outer_radius!r} is out of range; allowed: "
                f"> inner_radius = {self.inner_radius!r}"
            )
        nu = self.poisson_ratio
        if isinstance(nu, bool) or not isinstance(nu, numbers.Real):
            raise ModeError(
                f"poisson_ratio = {nu!r} is not a number; allowed: a real number in (-1, 0.5)"
            )
        # -1 < nu < 0.5 keeps the isotropic elastic energy positive definite.
        if not -1.0 < float(nu) < 0.5:
            raise ModeError(f"poisson_ratio = {nu!r} is out of range; allowed: -1 < nu < 0.5")
        object.__setattr__(self, "poisson_ratio", float(nu))

    @classmethod
    def from_disc(cls, disc: Any) -> AnnularPlate:
        """Build the plate from any object with the six attributes of this class.

        Parameters
        ----------
        disc : object
            For example ``Case().disc``; needs ``inner_radius``, ``outer_radius``,
            ``thickness``, ``density``, ``youngs_modulus`` and ``poisson_ratio`` (SI units).

        Returns
        -------
        AnnularPlate
        """
        names = (
            "inner_radius",
            "outer_radius",
            "thickness",
            "density",
            "youngs_modulus",
            "poisson_ratio",
        )
        missing = [name for name in names if not hasattr(disc, name)]
        if missing:
            raise ModeError(f"disc description lacks {', '.join(missing)}")
        return cls(**{name: getattr(disc, name) for name in names})

    @property
    def flexural_rigidity(self) -> float:
        """Flexural rigidity ``D = E h^3 / (12 (1 - nu^2))`` [N m]."""
        return self.youngs_modulus * self.thickness**3 / (12.0 * (1.0 - self.poisson_ratio**2))

    def frequency_parameters(self, l: int, count: int) -> np.ndarray:
        """The first ``count`` frequency parameters of harmonic ``l``.

        Parameters
        ----------
        l : int
            Number of nodal diameters, >= 0.
        count : int
            How many roots, >= 0.

        Returns
        -------
        ndarray, shape (count,)
            ``beta`` [1/m], strictly ascending; entry ``k`` belongs to the mode with ``k`` nodal
            circles.
        """
        order = _check_index("l", l)
        count = _check_index("count", count)
        if count == 0:
            return np.empty(0)
        roots = _roots(
            self.inner_radius, self.outer_radius, self.poisson_ratio, order, _count_bucket(count)
        )
        return np.array(roots[:count])

    def mode(self, k: int, l: int) -> PlateMode:
        """Mode with ``k`` nodal circles and ``l`` nodal diameters.

        Parameters
        ----------
        k : int
            Nodal circles (root index), >= 0.
        l : int
            Nodal diameters, >= 0.

        Returns
        -------
        PlateMode
        """
        k = _check_index("k", k)
        order = _check_index("l", l)
        beta, coefficients, integral = _radial_mode(
            self.inner_radius, self.outer_radius, self.poisson_ratio, k, order
        )
        rho_h = self.density * self.thickness
        # int_0^{2 pi} cos^2(l theta) dtheta is 2 pi for l = 0 and pi otherwise.
        modal_mass = rho_h * math.pi * integral * (2.0 if order == 0 else 1.0)
        return PlateMode(
            k=k,
            l=order,
            beta=beta,
            omega=beta**2 * math.sqrt(self.flexural_rigidity / rho_h),
            modal_mass=modal_mass,
            coefficients=coefficients,
            plate=self,
        )

    def modes(self, pairs: Iterable[tuple[int, int]]) -> list[PlateMode]:
        """Modes for a sequence of ``(k, l)`` pairs, in the given order.

        Parameters
        ----------
        pairs : iterable of (int, int)
            ``(nodal circles, nodal diameters)``.

        Returns
        -------
        list of PlateMode
        """
        result = []
        for pair in pairs:
            try:
                k, order = pair
            except (TypeError, ValueError):
                raise ModeError(
                    f"mode {pair!r} is not a (k, l) pair; allowed: two integers >= 0"
                ) from None
            result.append(self.mode(k, order))
        return result


@dataclass(frozen=True)
class PlateMode:
    """One transverse mode ``R(r) cos(l theta)`` (and its ``sin`` twin for ``l >= 1``).

    Attributes
    ----------
    k : int
        Nodal circles.
    l : int
        Nodal diameters.
    beta : float
        Frequency parameter [1/m].
    omega : float
        Natural frequency ``beta^2 sqrt(D / (rho h))`` [rad/s].
    modal_mass : float
        ``rho h pi int_a^b R^2 r dr`` for ``l >= 1``, twice that for ``l = 0`` [kg], with the
        dimensionless ``R`` of :meth:`shape`.
    coefficients : tuple of 4 floats
        ``(A, B, C, D)`` of ``A J_l(beta r) + B Y_l(beta r) + C I_l(beta r) e^{-beta b}
        + D K_l(beta r) e^{beta a}`` [-].
    plate : AnnularPlate
        The plate the mode belongs to.

    Notes
    -----
    ``R`` is normalised so that ``max |R| = 1`` on ``[a, b]`` and ``R(b) > 0``; only
    ``R^2 / modal_mass`` enters the dynamics, and it does not depend on that choice.

    Examples
    --------
    The two-nodal-diameter mode of the paper's Table 1 disc, clamped (``R = 0``) at the
    inner radius 0.044 m and largest at the free outer one, 0.12 m:

    >>> import fivdisc
    >>> plate = fivdisc.AnnularPlate(0.044, 0.12, 0.002, 7200.0, 150e9, 0.211)
    >>> mode = plate.mode(0, 2)
    >>> mode.k, mode.l, round(mode.frequency_hz, 2), round(mode.modal_mass, 4)
    (0, 2, 290.28, 0.0963)
    >>> [round(mode.shape(r), 4) + 0.0 for r in (0.044, 0.1, 0.12)]
    [0.0, 0.6669, 1.0]
    """

    k: int
    l: int
    beta: float
    omega: float
    modal_mass: float
    coefficients: tuple[float, float, float, float]
    plate: AnnularPlate

    @property
    def frequency_hz(self) -> float:
        """Natural frequency [Hz]."""
        return self.omega / (2.0 * math.pi)

    def shape(self, r: float | np.ndarray, derivative: int = 0) -> np.ndarray | float:
        """Radial function or one of its derivatives.

        Parameters
        ----------
        r : float or array_like
            Radii [m], within ``[a, b]``.
        derivative : int
            Order ``d`` of the derivative, 0 to 3.

        Returns
        -------
        float or ndarray
            ``d^d R / dr^d`` [1/m^d], a float for scalar ``r``, else an array of ``r``'s shape.
        """
        if (
            isinstance(derivative, bool)
            or not isinstance(derivative, numbers.Integral)
            or not 0 <= derivative <= MAX_DERIVATIVE
        ):
            raise ModeError(
                f"derivative = {derivative!r} is out of range; allowed: integer 0 to "
                f"{MAX_DERIVATIVE}"
            )
        a, b = self.plate.inner_radius, self.plate.outer_radius
        radii = np.asarray(r, dtype=float)
        slack = _RADIUS_SLACK * b
        if radii.size and not (np.all(radii >= a - slack) and np.all(radii <= b + slack)):
            bad = radii[(radii < a - slack) | (radii > b + slack) | np.isnan(radii)].flat[0]
            raise ModeError(f"r = {float(bad)!r} is out of range; allowed: {a} <= r <= {b} [m]")
        if radii.size <= _STORED_RADII:
            values = self._stored_values(radii, int(derivative))
        else:
            values = _radial_values(
                self.l, self.beta, a, b, np.asarray(self.coefficients), radii, int(derivative)
            )
        return float(values) if radii.ndim == 0 else values

    def _stored_values(self, radii: np.ndarray, derivative: int) -> np.ndarray:
        """:meth:`shape` at a few radii (sliders' tracks, probes), kept in the mode cache
        from one process to the next: the values computed once, read back exactly."""
        plate = self.plate
        key = repr((plate.inner_radius, plate.outer_radius, plate.poisson_ratio, self.k,
                    self.l, derivative))
        stored = mode_cache.lookup_values(key, radii.ravel().tolist())
        if stored is None:
            values = _radial_values(self.l, self.beta, plate.inner_radius, plate.outer_radius,
                                    np.asarray(self.coefficients), radii, derivative)
            mode_cache.remember_values(key, radii.ravel().tolist(),
                                       np.ravel(values).tolist())
            return values
        return np.reshape(np.array(stored, dtype=float), radii.shape)
