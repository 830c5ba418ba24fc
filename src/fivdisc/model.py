"""The numerical model of a case: modal coordinates, sliders, friction and speed as arrays."""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from fivdisc._kernels import layout as lay
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
    shape : ndarray
        ``(S, n)``: mode shapes at each slider's track radius [-].
    modal_mass : ndarray
        Modal masses [kg].
    omega : ndarray
        Natural frequencies of the non-rotating disc [rad/s].
    damping : ndarray
        Modal damping ratio per coordinate [-].
    kernel : KernelModel
        The tuple of arrays the compiled kernels read (:mod:`fivdisc._kernels.layout`).
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
    shape: np.ndarray
    modal_mass: np.ndarray
    omega: np.ndarray
    damping: np.ndarray
    kernel: lay.KernelModel
    speed: SpeedProfile
    probe_shapes: np.ndarray

    @property
    def n(self) -> int:
        """Number of modal coordinates."""
        return int(self.l.size)

    @property
    def n_sliders(self) -> int:
        """Number of sliders S."""
        return int(self.kernel.theta.size)

    @property
    def state_size(self) -> int:
        """Length of the kernel's state vector without energy accumulators, ``2 (n + 2 S)``."""
        return 2 * (self.n + 2 * self.n_sliders)

    @cached_property
    def kernel_args(self) -> lay.KernelModel:
        """The model tuple the numba kernels take, with the speed profile of this model."""
        return self.kernel._replace(knots=self.speed.knots, coef=self.speed.coefficients)

    def with_speed(self, speed: SpeedProfile) -> Model:
        """The same model at another disc speed profile."""
        return replace(self, speed=speed)

    def with_sliders(self, **arrays: np.ndarray) -> Model:
        """The same model with per-slider kernel arrays replaced (``cz=...``, ``n0=...``).

        The face-signed products (``smass``, ``skz``, ...) follow their plain values.
        """
        kern = self.kernel._replace(**arrays)
        return replace(self, kernel=kern._replace(**_signed(kern._asdict())))

    def index(self, what: str, j: int = 0) -> int:
        """Position of slider j's ``"phi"``, ``"z"``, ``"phi_dot"`` or ``"z_dot"`` in the
        state vector."""
        n, s = self.n, self.n_sliders
        offset = {"phi": n, "z": n + s, "phi_dot": 2 * n + 2 * s, "z_dot": 2 * n + 3 * s}
        return offset[what] + j

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


def _signed(arrays) -> dict[str, np.ndarray]:
    """The face-signed products of the per-slider arrays (a mapping of kernel fields)."""
    sig = arrays["sigma"]
    return {
        "smass": sig * arrays["mass"],
        "skz": sig * arrays["kz"],
        "scz": sig * arrays["cz"],
        "sn0": sig * arrays["n0"],
        "shh": sig * arrays["hh"],
    }


def friction_arrays(friction) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(fric, ftab_x, ftab_c)`` kernel arrays of a case's ``[friction]`` table.

    A tabulated law becomes its PCHIP pieces in powers of ``u - x_k``, with a constant
    last piece beyond the last point.
    """
    fric = np.zeros(lay.N_FRIC)
    fric[lay.F_MUS] = friction.static
    tab_x = np.zeros(1)
    tab_c = np.zeros((1, 4))
    if friction.law == "exponential":
        fric[lay.F_LAW] = lay.LAW_EXPONENTIAL
        fric[lay.F_MU0] = friction.kinetic_max
        fric[lay.F_MU1] = friction.kinetic_min
        fric[lay.F_ALPHA] = friction.decay
    elif friction.law == "stribeck":
        fric[lay.F_LAW] = lay.LAW_STRIBECK
        fric[lay.F_MU0] = friction.kinetic_max
        fric[lay.F_MU1] = friction.kinetic_min
        fric[lay.F_VS] = friction.stribeck_velocity
        fric[lay.F_DELTA] = friction.stribeck_exponent
        fric[lay.F_MUV] = friction.viscous
    else:
        from scipy.interpolate import PchipInterpolator

        x = np.asarray(friction.speeds, dtype=float)
        v = np.asarray(friction.values, dtype=float)
        pchip = PchipInterpolator(x, v)
        fric[lay.F_LAW] = lay.LAW_TABLE
        tab_x = x.copy()
        tab_c = np.zeros((x.size, 4))
        # scipy stores the highest power first.
        tab_c[:-1] = pchip.c[::-1].T
        tab_c[-1, 0] = v[-1]
    return fric, tab_x, tab_c


def build_model(case: Case, speed: SpeedProfile | None = None) -> Model:
    """Assemble the kernel arrays of ``case``.

    Parameters
    ----------
    case : Case
        The case.
    speed : SpeedProfile, optional
        Overrides the case's ``[speed]`` table (for example a profile from callables).
    """
    disc, sliders, sim = case.disc, case.sliders, case.simulation
    plate = AnnularPlate.from_disc(disc)
    modes = tuple(plate.mode(int(k), int(l)) for k, l in disc.modes)
    labels, ks, ls, sgn, partner, mass, omega, zeta, cols = [], [], [], [], [], [], [], [], []
    radii = np.array([s.track_radius for s in sliders])
    for mode, ratio in zip(modes, disc.mode_damping(), strict=True):
        kinds = ("C", "D") if mode.l > 0 else ("C",)
        base = len(labels)
        radial = np.asarray(mode.shape(radii), dtype=float)
        for j, kind in enumerate(kinds):
            labels.append(f"{kind}{mode.k}{mode.l}")
            ks.append(mode.k)
            ls.append(mode.l)
            sgn.append(1.0 if kind == "C" else -1.0)
            partner.append(base + 1 - j if mode.l > 0 else -1)
            cols.append(radial)
            mass.append(mode.modal_mass)
            omega.append(mode.omega)
            zeta.append(ratio)
    n = len(labels)
    sgn_a = np.array(sgn)
    l_a = np.array(ls, dtype=np.int64)
    mass_a = np.array(mass)
    omega_a = np.array(omega)
    zeta_a = np.array(zeta)
    printed = sim.printed_gyroscopic_sign
    # The printed paper flips the sign of 2 l M Omega dC/dt in the D equations only; the
    # l M dOmega/dt C term keeps its sign, so its factor undoes the flip there.
    gyro_sign = np.ones(n) if printed else sgn_a
    omd_fix = sgn_a * gyro_sign
    cdamp = 2.0 * zeta_a * omega_a * mass_a
    material = disc.damping_frame == "material"
    shape = np.array(cols).T.copy() if n else np.zeros((len(sliders), 0))
    sigma = np.array([s.sigma for s in sliders])
    slider_mass = np.array([s.mass for s in sliders])
    fric, tab_x, tab_c = friction_arrays(case.friction)
    opts = np.zeros(lay.N_OPTS)
    opts[lay.O_OMDOT] = 1.0 if sim.omega_dot_terms else 0.0
    opts[lay.O_IMPACT] = 1.0 if sim.impact else 0.0
    opts[lay.O_LMAX] = max(ls, default=0)
    opts[lay.O_DAMPED] = 1.0 if np.any(zeta_a > 0.0) else 0.0
    opts[lay.O_MIN_FLIGHT] = sim.min_flight_time
    speed = speed if speed is not None else SpeedProfile.from_case(case.speed)
    fields = dict(
        l=l_a,
        sgn=sgn_a,
        partner=np.array(partner, dtype=np.int64),
        minv=1.0 / mass_a,
        kd=mass_a * omega_a**2,
        ml2=mass_a * l_a**2,
        gyr=gyro_sign * l_a * mass_a,
        omd_fix=omd_fix,
        cdamp=cdamp,
        cdamp_om=sgn_a * l_a * cdamp if material else np.zeros(n),
        shape=shape,
        theta=np.array([s.angle for s in sliders]),
        sigma=sigma,
        mass=slider_mass,
        inertia=slider_mass * radii**2,
        kz=np.array([s.normal_stiffness for s in sliders]),
        cz=np.array([s.normal_damping for s in sliders]),
        kphi=np.array([s.rotational_stiffness for s in sliders]),
        cphi=np.array([s.rotational_damping for s in sliders]),
        n0=np.array([s.preload for s in sliders]),
        radius=radii,
        hh=disc.thickness / (2.0 * radii),
        fric=fric,
        ftab_x=tab_x,
        ftab_c=tab_c,
        knots=speed.knots,
        coef=speed.coefficients,
        opts=opts,
    )
    kern = lay.KernelModel(**fields, **_signed(fields))

    probes = np.asarray(sim.probes, dtype=float).reshape(-1, 2)
    return Model(
        case=case,
        modes=modes,
        labels=tuple(labels),
        k=np.array(ks, dtype=np.int64),
        l=l_a,
        sgn=sgn_a,
        partner=np.array(partner, dtype=np.int64),
        shape=shape,
        modal_mass=mass_a,
        omega=omega_a,
        damping=zeta_a,
        kernel=kern,
        speed=speed,
        probe_shapes=shape_matrix(modes, probes[:, 0], probes[:, 1]),
    )
