"""The numerical model of a case: modal coordinates, sliders, friction and speed as arrays."""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from fivdisc.case import Case
from fivdisc.model import layout as lay
from fivdisc.model.plate import AnnularPlate, PlateMode
from fivdisc.model.speed import SpeedProfile

# The friction laws by the core's code (KernelModel.opts[O_LAW]).
_LAWS = {lay.LAW_EXPONENTIAL: "exponential", lay.LAW_STRIBECK: "stribeck",
         lay.LAW_TABLE: "table"}


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
        The tuple of arrays the compiled core reads (:mod:`fivdisc.model.layout`).
    speed : SpeedProfile
        Disc speed.
    probe_shapes : ndarray
        ``(n_probe, n)``: ``w(r_p, theta_p) = probe_shapes @ q`` [-].

    Examples
    --------
    The default case keeps the modes (0, 0) to (0, 3): one coordinate for the
    axisymmetric mode, a cosine-sine pair (a doublet) for each of the others.

    >>> import numpy as np
    >>> import fivdisc
    >>> model = fivdisc.build_model(fivdisc.Case())
    >>> model.labels
    ('C00', 'C01', 'D01', 'C02', 'D02', 'C03', 'D03')
    >>> print((model.omega / (2 * np.pi)).round(1))  # [Hz]
    [237.4 241.4 241.4 290.3 290.3 441.5 441.5]
    >>> print(model.shape.round(4))  # R(r) at the slider's track radius, 0.1 m
    [[0.6748 0.6738 0.6738 0.6669 0.6669 0.6493 0.6493]]
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
        return int(self.kernel.slider.shape[1])

    @property
    def state_size(self) -> int:
        """Length of the kernel's state vector without energy accumulators, ``2 (n + 2 S)``."""
        return 2 * (self.n + 2 * self.n_sliders)

    @cached_property
    def kernel_args(self) -> lay.KernelModel:
        """The model tuple the compiled core takes (:func:`fivdisc.core.core_model`), with
        the speed profile of this model."""
        return self.kernel._replace(speed=self.speed.pieces())

    def with_speed(self, speed: SpeedProfile) -> Model:
        """The same model at another disc speed profile."""
        return replace(self, speed=speed)

    def with_sliders(self, **rows: np.ndarray) -> Model:
        """The same model with per-slider quantities replaced (``cz=...``, ``n0=...``;
        names of ``layout.SLIDER_ROWS``).

        The face-signed products follow their plain values.
        """
        slider = self.kernel.slider.copy()
        for name, values in rows.items():
            slider[lay.SLIDER_ROWS[name]] = values
        _sign(slider)
        return replace(self, kernel=self.kernel._replace(slider=slider))

    def with_friction(self, **values: float) -> Model:
        """The same model with friction parameters replaced (``decay=...``; keys of the
        case's ``[friction]`` table in ``layout.FRICTION_SLOTS``)."""
        opts = self.kernel.opts.copy()
        for name, value in values.items():
            opts[lay.FRICTION_SLOTS[name]] = value
        return replace(self, kernel=self.kernel._replace(opts=opts))

    @cached_property
    def slices(self) -> lay.StateSlices:
        """Where ``q``, ``phi``, ``z``, ``q_dot``, ``phi_dot``, ``z_dot`` (and the energy
        accumulators, after them) lie in the state vector."""
        return lay.StateSlices.of(self.n, self.n_sliders, lay.N_ENERGY)

    @cached_property
    def columns(self) -> lay.OutputColumns:
        """The columns of an integration's per-sample output (``out_aux``)."""
        return lay.OutputColumns.of(self.n_sliders)

    def index(self, what: str, j: int = 0) -> int:
        """Position of slider j's ``"phi"``, ``"z"``, ``"phi_dot"`` or ``"z_dot"`` in the
        state vector."""
        return getattr(self.slices, what).start + j

    @property
    def law(self) -> str:
        """The friction law the model holds: ``"exponential"``, ``"stribeck"`` or
        ``"table"``."""
        return _LAWS[int(self.kernel.opts[lay.O_LAW])]

    def friction_value(self, name: str) -> float:
        """A friction parameter the model holds (a key of the case's ``[friction]`` table:
        ``"static"``, ``"decay"``, ``"stribeck_velocity"``, ...), after
        :meth:`with_friction`."""
        return float(self.kernel.opts[lay.FRICTION_SLOTS[name]])

    @property
    def table_knots(self) -> np.ndarray:
        """The relative sliding speeds [m/s] where a tabulated friction law's pieces
        start (empty for the other laws)."""
        if self.law != "table":
            return np.empty(0)
        return np.asarray(self.kernel.table)[:, 0]

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


def _sign(slider: np.ndarray) -> None:
    """Fill the face-signed rows of a ``(N_SLIDER, S)`` slider array from the plain ones."""
    for signed, plain in lay.SIGNED_ROWS:
        slider[signed] = slider[lay.S_SIGMA] * slider[plain]


def friction_arrays(friction, opts: np.ndarray) -> np.ndarray:
    """Write a case's ``[friction]`` table into ``opts`` (law and parameters) and return
    the kernel's table of a tabulated law.

    A tabulated law becomes its PCHIP pieces in powers of ``u - x_k`` (rows: start,
    then the four coefficients), with a constant last piece beyond the last point.
    """
    opts[lay.O_MUS] = friction.static
    table = np.zeros((1, 5))
    if friction.law == "exponential":
        opts[lay.O_LAW] = lay.LAW_EXPONENTIAL
        opts[lay.O_MU0] = friction.kinetic_max
        opts[lay.O_MU1] = friction.kinetic_min
        opts[lay.O_ALPHA] = friction.decay
    elif friction.law == "stribeck":
        opts[lay.O_LAW] = lay.LAW_STRIBECK
        opts[lay.O_MU0] = friction.kinetic_max
        opts[lay.O_MU1] = friction.kinetic_min
        opts[lay.O_VS] = friction.stribeck_velocity
        opts[lay.O_DELTA] = friction.stribeck_exponent
        opts[lay.O_MUV] = friction.viscous
    else:
        from scipy.interpolate import PchipInterpolator

        x = np.asarray(friction.speeds, dtype=float)
        v = np.asarray(friction.values, dtype=float)
        pchip = PchipInterpolator(x, v)
        opts[lay.O_LAW] = lay.LAW_TABLE
        table = np.zeros((x.size, 5))
        table[:, 0] = x
        # scipy stores the highest power first.
        table[:-1, 1:] = pchip.c[::-1].T
        table[-1, 1] = v[-1]
    return table


# Per-slider case keys that enter the model only through a row of the kernel's slider
# array, and friction keys that enter only through its options (layout.FRICTION_SLOTS):
# a model at other values of them is the base model patched, without rebuilding the
# plate modes.
_SLIDER_ARRAYS = {
    "normal_damping": "cz",
    "rotational_damping": "cphi",
    "normal_stiffness": "kz",
    "rotational_stiffness": "kphi",
    "preload": "n0",
}


def model_at(base: Model, case: Case, updates: dict[str, float]) -> Model:
    """The model of ``case.replace(updates)``, by patching ``base`` (the model of
    ``case``) where that is exact: the constant disc speed, the sliders' stiffnesses,
    dampings and preloads, the friction law's coefficients; otherwise built afresh.

    The patched model keeps ``base.case``: what it takes from the case beyond the
    patched arrays (tolerances, output) is the same.
    """
    model = base
    rows: dict[str, np.ndarray] = {}
    for key, value in updates.items():
        parts = key.split(".")
        if key == "speed.value" and case.speed.profile == "constant":
            model = model.with_speed(SpeedProfile.constant(value))
        elif (parts[0] in ("slider", "sliders") and parts[-1] in _SLIDER_ARRAYS
              and len(parts) == (2 if parts[0] == "slider" else 3)):
            # slider.KEY and sliders.*.KEY: every slider (the rule of Case.replace)
            j = (slice(None) if parts[0] == "slider" or parts[1] == "*"
                 else int(parts[1]))
            name = _SLIDER_ARRAYS[parts[-1]]
            # One slider patch for all the keys (the face-signed rows follow once).
            rows.setdefault(name, model.kernel.row(name).copy())[j] = value
        elif parts[0] == "friction" and parts[-1] in lay.FRICTION_SLOTS:
            model = model.with_friction(**{parts[-1]: value})
        else:
            return build_model(case.replace(updates))
    return model.with_sliders(**rows) if rows else model


def build_model(case: Case, speed: SpeedProfile | None = None) -> Model:
    """Assemble the kernel arrays of ``case``.

    Parameters
    ----------
    case : Case
        The case.
    speed : SpeedProfile, optional
        Overrides the case's ``[speed]`` table (for example a profile from callables).

    Returns
    -------
    Model
        The modes, the sliders' and the probes' mode shapes, and the arrays the compiled
        kernels read.

    Examples
    --------
    The modal masses [kg] and the radial mode shapes at the slider's track radius [-],
    for two modes:

    >>> import fivdisc
    >>> model = fivdisc.build_model(fivdisc.Case(disc={"modes": [[0, 0], [0, 2]]}))
    >>> model.labels, model.n, model.n_sliders
    (('C00', 'C02', 'D02'), 3, 1)
    >>> print(model.modal_mass.round(4), model.shape.round(4))
    [0.1953 0.0963 0.0963] [[0.6748 0.6669 0.6669]]
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
    disc_rows = np.zeros((lay.N_DISC, n))
    # Extreme values (a damping ratio of 1e300) overflow to inf here, silently: the rates
    # of the model are checked before any run or analysis uses them, and refused in one
    # line (fivdisc.engine.integration.check_steps, fivdisc.analysis.points.check_rates).
    with np.errstate(over="ignore", invalid="ignore"):
        cdamp = 2.0 * zeta_a * omega_a * mass_a
        disc_rows[lay.D_SGN] = sgn_a
        disc_rows[lay.D_L] = l_a
        disc_rows[lay.D_PARTNER] = partner
        disc_rows[lay.D_MINV] = 1.0 / mass_a
        disc_rows[lay.D_KD] = mass_a * omega_a**2
        disc_rows[lay.D_ML2] = mass_a * l_a**2
        disc_rows[lay.D_GYR] = gyro_sign * l_a * mass_a
        disc_rows[lay.D_OMD_FIX] = sgn_a * gyro_sign
        disc_rows[lay.D_CDAMP] = cdamp
        if disc.damping_frame == "material":
            disc_rows[lay.D_CDAMP_OM] = sgn_a * l_a * cdamp
    shape = np.array(cols).T.copy() if n else np.zeros((len(sliders), 0))
    slider_rows = np.zeros((lay.N_SLIDER, len(sliders)))
    slider_mass = np.array([s.mass for s in sliders])
    for row, values in (
        (lay.S_THETA, [s.angle for s in sliders]),
        (lay.S_SIGMA, [s.sigma for s in sliders]),
        (lay.S_MASS, slider_mass),
        (lay.S_INERTIA, slider_mass * radii**2),
        (lay.S_KZ, [s.normal_stiffness for s in sliders]),
        (lay.S_CZ, [s.normal_damping for s in sliders]),
        (lay.S_KPHI, [s.rotational_stiffness for s in sliders]),
        (lay.S_CPHI, [s.rotational_damping for s in sliders]),
        (lay.S_N0, [s.preload for s in sliders]),
        (lay.S_RADIUS, radii),
        (lay.S_HH, disc.thickness / (2.0 * radii)),
    ):
        slider_rows[row] = values
    _sign(slider_rows)
    opts = np.zeros(lay.N_OPTS)
    table = friction_arrays(case.friction, opts)
    opts[lay.O_OMDOT] = 1.0 if sim.omega_dot_terms else 0.0
    opts[lay.O_IMPACT] = 1.0 if sim.impact else 0.0
    opts[lay.O_LMAX] = max(ls, default=0)
    opts[lay.O_DAMPED] = 1.0 if np.any(zeta_a > 0.0) else 0.0
    opts[lay.O_MIN_FLIGHT] = sim.min_flight_time
    speed = speed if speed is not None else SpeedProfile.from_case(case.speed)
    kern = lay.KernelModel(disc=disc_rows, slider=slider_rows, shape=shape, table=table,
                           speed=speed.pieces(), opts=opts)

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
