"""The numerical model of a case: modal coordinates, parameters and speed as arrays."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from fivdisc._kernels import dynamics as dyn
from fivdisc.case import Case
from fivdisc.plate import AnnularPlate, PlateMode
from fivdisc.speed import SpeedProfile


@dataclass(frozen=True, eq=False)
class Model:
    """Arrays the kernel works on, built from a :class:`~fivdisc.case.Case`.

    Modal coordinates are ordered as the case's ``disc.modes``: ``C_kl``, then
    ``D_kl`` when ``l >= 1``.

    Attributes
    ----------
    case : Case
        The case the model was built from.
    modes : tuple of PlateMode
        One plate mode per requested (k, l).
    labels : tuple of str
        Coordinate names, e.g. ``"C01"``, ``"D01"``.
    k, l : ndarray of int
        Nodal circles and diameters per coordinate.
    sgn : ndarray
        +1 for a cosine (C) coordinate, -1 for a sine (D) coordinate.
    partner : ndarray of int
        Index of the doublet partner (-1 for l = 0).
    R0 : ndarray
        Mode shape at the slider's track radius [-].
    modal_mass : ndarray
        Modal masses [kg].
    omega : ndarray
        Natural frequencies of the non-rotating disc [rad/s].
    par : ndarray
        Scalar parameters indexed by the ``P_*`` constants of ``_kernels.dynamics``.
    speed : SpeedProfile
        Disc speed.
    probe_shapes : ndarray
        ``(n_probe, n)``: ``w(r_p, theta_p) = probe_shapes @ q`` [-].
    """

    case: Case
    modes: tuple[PlateMode, ...]
    labels: tuple[str, ...]
    k: np.ndarray
    l: np.ndarray
    sgn: np.ndarray
    partner: np.ndarray
    R0: np.ndarray
    modal_mass: np.ndarray
    omega: np.ndarray
    par: np.ndarray
    speed: SpeedProfile
    probe_shapes: np.ndarray

    @property
    def n(self) -> int:
        """Number of modal coordinates."""
        return int(self.l.size)

    @property
    def state_size(self) -> int:
        """Length of the kernel's state vector, ``2 n + 4``."""
        return 2 * self.n + 4

    @cached_property
    def kernel_args(self) -> tuple:
        """The model tuple the numba kernels take."""
        mass = self.modal_mass
        gyro_sign = (
            np.ones_like(self.sgn) if self.case.simulation.printed_gyroscopic_sign else self.sgn
        )
        return (
            self.par,
            self.l,
            self.R0,
            1.0 / mass,
            mass * self.omega**2,
            mass * self.l**2,
            gyro_sign * self.l * mass,
            self.sgn,
            self.partner,
            self.speed.knots,
            self.speed.coefficients,
        )

    def shape_matrix(self, r, theta) -> np.ndarray:
        """``(len(r), n)`` matrix mapping q to the disc's w at points (r [m], theta [rad])."""
        return shape_matrix(self.modes, r, theta)


def shape_matrix(modes, r, theta) -> np.ndarray:
    """``(len(r), n)`` matrix mapping modal coordinates to w at (r [m], theta [rad])."""
    r = np.atleast_1d(np.asarray(r, dtype=float))
    theta = np.atleast_1d(np.asarray(theta, dtype=float))
    cols = []
    for mode in modes:
        radial = np.asarray(mode.shape(r), dtype=float)
        cols.append(radial * np.cos(mode.l * theta))
        if mode.l > 0:
            cols.append(radial * np.sin(mode.l * theta))
    return np.stack(cols, axis=1) if cols else np.empty((r.size, 0))


def build_model(case: Case, speed: SpeedProfile | None = None) -> Model:
    """Assemble the kernel arrays of ``case``.

    Parameters
    ----------
    case : Case
        The case.
    speed : SpeedProfile, optional
        Overrides the case's ``[speed]`` table (for example a profile from callables).
    """
    disc, slider, fr, sim = case.disc, case.slider, case.friction, case.simulation
    plate = AnnularPlate.from_disc(disc)
    modes = tuple(plate.mode(int(k), int(l)) for k, l in disc.modes)
    labels, ks, ls, sgn, partner, R0, mass, omega = [], [], [], [], [], [], [], []
    r0 = slider.track_radius
    for mode in modes:
        kinds = ("C", "D") if mode.l > 0 else ("C",)
        base = len(labels)
        for j, kind in enumerate(kinds):
            labels.append(f"{kind}{mode.k}{mode.l}")
            ks.append(mode.k)
            ls.append(mode.l)
            sgn.append(1.0 if kind == "C" else -1.0)
            partner.append(base + 1 - j if mode.l > 0 else -1)
            R0.append(float(mode.shape(r0)))
            mass.append(mode.modal_mass)
            omega.append(mode.omega)

    par = np.zeros(dyn.N_PAR)
    par[dyn.P_MASS] = slider.mass
    par[dyn.P_INERTIA] = slider.mass * r0**2
    par[dyn.P_KZ] = slider.normal_stiffness
    par[dyn.P_CZ] = slider.normal_damping
    par[dyn.P_KPHI] = slider.rotational_stiffness
    par[dyn.P_CPHI] = slider.rotational_damping
    par[dyn.P_N0] = slider.preload
    par[dyn.P_R0] = r0
    par[dyn.P_HALF_H_OVER_R0] = disc.thickness / (2.0 * r0)
    par[dyn.P_MUS] = fr.static
    par[dyn.P_MU0] = fr.kinetic_max
    par[dyn.P_MU1] = fr.kinetic_min
    par[dyn.P_ALPHA] = fr.decay
    par[dyn.P_OMDOT] = 1.0 if sim.omega_dot_terms else 0.0
    par[dyn.P_IMPACT] = 1.0 if sim.impact else 0.0
    par[dyn.P_LMAX] = max(ls, default=0)

    probes = np.asarray(sim.probes, dtype=float).reshape(-1, 2)
    return Model(
        case=case,
        modes=modes,
        labels=tuple(labels),
        k=np.array(ks, dtype=np.int64),
        l=np.array(ls, dtype=np.int64),
        sgn=np.array(sgn),
        partner=np.array(partner, dtype=np.int64),
        R0=np.array(R0),
        modal_mass=np.array(mass),
        omega=np.array(omega),
        par=par,
        speed=speed if speed is not None else SpeedProfile.from_case(case.speed),
        probe_shapes=shape_matrix(modes, probes[:, 0], probes[:, 1]),
    )
