"""Hopf points of the sliding equilibrium along one key.

A Hopf point is where a complex pair of eigenvalues of the linearised slip equations
crosses the imaginary axis: there the equilibrium gains or loses stability and a family
of small periodic orbits is born, with the pair's angular frequency and along its
eigenvector. The crossings are bracketed on the eigenvalue branches of
:func:`~fivdisc.analysis.eigenbranches.eigen_branches` and located with Brent's method on
the real part of the eigenvalue that continues the branch.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import xarray as xr

from fivdisc import core
from fivdisc.analysis.points import ParameterPoints, reduced_indices
from fivdisc.analysis.stability import dominant_coordinates
from fivdisc.case import Case
from fivdisc.engine.equilibrium import Equilibrium, _evaluate, slip_phases
from fivdisc.model.build import Model

# Relative tolerance of the located value of the key (Brent's method; the growth rate is
# smooth in the key, so the root is found to about this, far inside the 1e-8 promised).
KEY_TOLERANCE = 1e-12


@dataclass(frozen=True)
class HopfPoint:
    """A complex pair of eigenvalues of the sliding equilibrium on the imaginary axis.

    Attributes
    ----------
    key : str
        The varied case key.
    value : float
        Its value at the Hopf point.
    omega : float
        Critical angular frequency Im(lambda) [rad/s]; the orbits born here start with
        the period ``2 pi / omega``.
    direction : int
        +1 if the pair's growth rate rises through zero as the key increases (the mode
        becomes unstable), -1 if it falls.
    rate : float
        d Re(lambda) / d key at the point [1/s per unit of the key] (transversality:
        not zero).
    eigenvalue : complex
        The eigenvalue (real part zero to round-off) [1/s].
    state : ndarray
        The sliding equilibrium in the kernel's full dynamic state layout
        ``[q, phi, z, qdot, phidot, zdot]`` (``2 (n + 2 S)`` values; the z, zdot of
        sliders in contact hold the disc's surface under them, as a run's output does).
    eigenvector : ndarray
        Complex right eigenvector in the same layout, of unit 2-norm, phased so that its
        largest component is real and positive. A small orbit starts at
        ``state + eps * Re(eigenvector)``.
    mode : str
        Coordinate with most of the eigenvector's kinetic energy.
    on_boundary : bool
        Whether every other eigenvalue has a negative real part there: the equilibrium
        changes stability at this point (else it stays unstable on both sides).
    equilibrium : Equilibrium
        The sliding equilibrium at the point.
    case : Case
        The base case with the key set to `value`.
    """

    key: str
    value: float
    omega: float
    direction: int
    rate: float
    eigenvalue: complex
    state: np.ndarray
    eigenvector: np.ndarray
    mode: str
    on_boundary: bool
    equilibrium: Equilibrium
    case: Case

    @property
    def frequency(self) -> float:
        """Critical frequency ``omega / 2 pi`` [Hz]."""
        return self.omega / (2.0 * np.pi)

    @property
    def period(self) -> float:
        """``2 pi / omega`` [s], the period of the orbits born here."""
        return 2.0 * np.pi / self.omega

    def __str__(self) -> str:
        turn = "loses" if self.direction > 0 else "gains"
        where = "" if self.on_boundary else " (another mode stays unstable)"
        return (f"Hopf point at {self.key} = {self.value:.10g}: {self.mode} at "
                f"{self.frequency:.6g} Hz ({self.omega:.6g} rad/s) {turn} stability as "
                f"{self.key} increases{where}")


def _full_layout(model: Model, eq: Equilibrium, vector: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Equilibrium and eigenvector (reduced variables) in the kernel's full layout, the
    sliders' z, zdot filled in from the disc under them."""
    ph, sg = slip_phases(model)
    idx = reduced_indices(model)
    full = np.zeros((2, model.state_size))
    full[0, idx], full[1, idx] = vector.real, vector.imag
    full = core.unslaved(core.core_model(model), 0.0, eq.state, ph, sg, full)
    state = eq.state.copy()
    # The slaved rows of the equilibrium itself: z = w under the slider (zdot = 0).
    _, aux = _evaluate(model, state)
    state[model.n + model.n_sliders + np.arange(model.n_sliders)] = aux["w"]
    vec = full[0] + 1j * full[1]
    vec /= np.linalg.norm(vec)
    big = np.argmax(np.abs(vec))
    vec *= np.exp(-1j * np.angle(vec[big]))
    return state, vec


def _locate(points: ParameterPoints, key: str, lo: float, hi: float, lam_lo: complex,
            lam_hi: complex, guess: Equilibrium) -> HopfPoint:
    from scipy.optimize import brentq

    def eig_near(value: float) -> tuple:
        model, eq, jac = points.linearise((value,), guess)
        lam, vec = np.linalg.eig(jac)
        t = (value - lo) / (hi - lo)
        i = int(np.argmin(np.abs(lam - (lam_lo + t * (lam_hi - lam_lo)))))
        return model, eq, lam, vec, i

    def growth(value: float) -> float:
        _, _, lam, _, i = eig_near(value)
        return float(lam[i].real)

    scale = max(abs(lo), abs(hi), abs(hi - lo))
    root = float(brentq(growth, lo, hi, xtol=KEY_TOLERANCE * scale, rtol=1e-15))
    model, eq, lam, vec, i = eig_near(root)
    step = 1e-6 * abs(hi - lo)
    rate = (growth(root + step) - growth(root - step)) / (2.0 * step)
    pick = i if lam[i].imag > 0 else int(np.argmin(np.abs(lam - np.conj(lam[i]))))
    others = np.delete(lam.real, [i, int(np.argmin(np.abs(lam - np.conj(lam[i]))))])
    state, vector = _full_layout(model, eq, vec[:, pick])
    return HopfPoint(
        key=key, value=root, omega=float(lam[pick].imag),
        direction=1 if (lam_hi.real - lam_lo.real) / (hi - lo) > 0.0 else -1,
        rate=float(rate),
        eigenvalue=complex(lam[pick]), state=state, eigenvector=vector,
        mode=dominant_coordinates(model, vec[:, [pick]])[0],
        on_boundary=bool(np.all(others < 0.0)), equilibrium=eq,
        case=points.case.replace({key: root}),
    )


def hopf_points(case: Case, key: str, values: Sequence[float], option: str = "key",
                branches: xr.Dataset | None = None) -> list[HopfPoint]:
    """Hopf points of the sliding equilibrium along one numeric key.

    Parameters
    ----------
    case : Case
        Base case at constant speed.
    key : str
        Dotted case key, e.g. ``"speed.value"``.
    values : sequence of float
        Values on which the eigenvalue branches are followed; every crossing of a
        complex pair between two neighbours is located. Crossings closer together than
        the spacing of `values` can cancel out unseen: refine the values to find them.
    option : str
        What names `key` in error messages.
    branches : xarray.Dataset, optional
        The branches of :func:`~fivdisc.analysis.eigenbranches.eigen_branches` over the
        same key and values, if already computed.

    Returns
    -------
    list of HopfPoint
        In order of the key's value (of `values`' direction), each located to
        ``KEY_TOLERANCE`` relative.

    Raises
    ------
    CaseError
        As :func:`~fivdisc.analysis.eigenbranches.eigen_branches`.

    Notes
    -----
    At the point the growth rate ``g(p) = Re lambda(p)`` of the branch is zero; it is
    bracketed by a change of sign between neighbouring values and found with
    :func:`scipy.optimize.brentq`, the eigenvalue at each trial value being the one
    nearest to the branch's linear interpolation. A real eigenvalue crossing zero (a
    fold of the equilibrium, not a Hopf point) is not reported.
    """
    from fivdisc.analysis.eigenbranches import eigen_branches

    if branches is None:
        branches = eigen_branches(case, key, values, option=option)
    values = branches[key].values
    lam = branches["growth_rate"].values + 2j * np.pi * branches["frequency"].values
    points = ParameterPoints(case, [key])
    found = []
    for b in range(lam.shape[1]):
        re, im = lam[:, b].real, lam[:, b].imag
        for i in range(values.size - 1):
            both = np.isfinite(re[i]) and np.isfinite(re[i + 1])
            if not both or (re[i] < 0.0) == (re[i + 1] < 0.0) or min(im[i], im[i + 1]) <= 0:
                continue
            guess = points.equilibrium(points.model((values[i],)))
            found.append(_locate(points, key, values[i], values[i + 1], lam[i, b],
                                 lam[i + 1, b], guess))
    ascending = values[-1] > values[0]
    return sorted(found, key=lambda h: h.value, reverse=not ascending)
