"""What the model fills and the compiled core reads: the model tuple, the state layout,
phase and event codes.

State vector ``y`` for ``n`` modal coordinates and ``S`` sliders::

    y = [q_0 .. q_{n-1}, phi_1 .. phi_S, z_1 .. z_S,
         qdot_0 .. qdot_{n-1}, phidot_1 .. phidot_S, zdot_1 .. zdot_S,
         E_0 .. E_{K-1}]

``z_j``, ``zdot_j`` are slider j's own normal displacement and velocity; they are
integrated only while it flies (in contact the slider follows the disc and they are
held). ``E`` are the optional energy accumulators (``K = N_ENERGY`` or 0): integrals of
the power of each kind of force, carried along but kept out of the error norm and the
events, so they never change the step sequence. For one slider the layout is the
paper's ``[q, phi, z, qdot, phidot, zdot]``.

The model is a tuple of a few two-dimensional arrays whose rows are named below; the
compiled core (:func:`fivdisc.core.core_model`) checks them once and holds them as named
fields (``src/fivdisc/core/src/model.hpp``).
"""

from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple

import numpy as np


class Phase(IntEnum):
    """A slider's contact phase, as the state's phase codes, the ``phase`` variable of a
    result and the event table hold it (an ``int``: arrays of phases are integer arrays).

    Examples
    --------
    >>> from fivdisc import Phase
    >>> Phase.STICK.label, Phase(2)
    ('stick', <Phase.SEPARATION: 2>)
    """

    SLIP = 0
    STICK = 1
    SEPARATION = 2

    @property
    def label(self) -> str:
        """The name results and messages use (``"slip"``, ``"stick"``, ``"separation"``)."""
        return self.name.lower()


class EventKind(IntEnum):
    """The kind of a switch, as the first column of the event table holds it.

    ``STICK``: the slip speed reaches zero and the static margin holds; ``SLIP``: a
    stuck slider's friction reaches its static limit; ``REVERSAL``: the slip speed
    changes sign without sticking; ``SEPARATION``: the normal force reaches zero;
    ``RECONTACT``: the gap closes.

    Examples
    --------
    >>> from fivdisc import EventKind
    >>> EventKind(4).label
    'recontact'
    """

    STICK = 0
    SLIP = 1
    REVERSAL = 2
    SEPARATION = 3
    RECONTACT = 4

    @property
    def label(self) -> str:
        """The name results and ``stop_on`` use (``"stick"``, ``"slip"``, ...)."""
        return self.name.lower()


class StateSlices(NamedTuple):
    """Where each block of the state vector ``y`` lies (the layout above), for ``n``
    modal coordinates and ``S`` sliders: ``y[slices.phi_dot]`` are the sliders' rates.

    Examples
    --------
    >>> from fivdisc.model.layout import StateSlices
    >>> StateSlices.of(n=2, sliders=1).phi_dot
    slice(6, 7, None)
    """

    q: slice
    phi: slice
    z: slice
    q_dot: slice
    phi_dot: slice
    z_dot: slice
    energy: slice

    @classmethod
    def of(cls, n: int, sliders: int, energy: int = 0) -> StateSlices:
        """The slices for ``n`` modal coordinates, ``sliders`` sliders and ``energy``
        accumulators."""
        sizes = (n, sliders, sliders, n, sliders, sliders, energy)
        ends = np.cumsum(sizes).tolist()
        return cls(*(slice(e - k, e) for e, k in zip(ends, sizes, strict=True)))


class OutputColumns(NamedTuple):
    """The columns of an integration's per-sample output ``out_aux`` for ``S`` sliders:
    per slider the normal force [N], the friction force [N], the phase and the disc's
    deflection under it [m] (slices of ``S`` columns), then the disc speed [rad/s] (one
    column).

    Examples
    --------
    >>> from fivdisc.model.layout import OutputColumns
    >>> OutputColumns.of(2).phase, OutputColumns.of(2).disc_speed
    (slice(4, 6, None), 8)
    """

    normal_force: slice
    friction_force: slice
    phase: slice
    w: slice
    disc_speed: int

    @classmethod
    def of(cls, sliders: int) -> OutputColumns:
        s = sliders
        return cls(slice(0, s), slice(s, 2 * s), slice(2 * s, 3 * s), slice(3 * s, 4 * s),
                   4 * s)


# Rows of KernelModel.disc (one column per modal coordinate).
D_SGN = 0  # +1 for a cosine (C) coordinate, -1 for a sine (D) coordinate
D_L = 1  # nodal diameters l
D_PARTNER = 2  # index of the other member of a doublet, -1 for l = 0
D_MINV = 3  # 1 / M
D_KD = 4  # M omega^2
D_ML2 = 5  # M l^2
D_GYR = 6  # the 2 Omega gyroscopic factor, sgn l M (or the printed paper's sign)
D_OMD_FIX = 7  # turns D_GYR into the dOmega/dt term's factor (1, or -1 for D when printed)
D_CDAMP = 8  # 2 zeta omega M
D_CDAMP_OM = 9  # its material-frame Omega q_partner coefficient, sgn l cdamp (0: space)
N_DISC = 10

# Rows of KernelModel.slider (one column per slider); "signed" rows are sigma times
# the plain value.
S_THETA = 0  # base angle [rad]
S_SIGMA = 1  # face, +1 top, -1 bottom
S_MASS = 2
S_INERTIA = 3  # m r^2
S_KZ = 4
S_CZ = 5
S_KPHI = 6  # r^2 k_phi
S_CPHI = 7  # r^2 c_phi
S_N0 = 8
S_RADIUS = 9
S_HH = 10  # h / (2 r)
S_SMASS = 11
S_SKZ = 12
S_SCZ = 13
S_SN0 = 14
S_SHH = 15
N_SLIDER = 16
SLIDER_ROWS = {"theta": S_THETA, "sigma": S_SIGMA, "mass": S_MASS, "inertia": S_INERTIA,
               "kz": S_KZ, "cz": S_CZ, "kphi": S_KPHI, "cphi": S_CPHI, "n0": S_N0,
               "radius": S_RADIUS, "hh": S_HH}
SIGNED_ROWS = ((S_SMASS, S_MASS), (S_SKZ, S_KZ), (S_SCZ, S_CZ), (S_SN0, S_N0),
               (S_SHH, S_HH))

# Friction laws (KernelModel.opts[O_LAW]).
LAW_EXPONENTIAL = 0
LAW_STRIBECK = 1
LAW_TABLE = 2

# KernelModel.opts slots.
O_LAW = 0
O_MUS = 1
O_MU0 = 2
O_MU1 = 3
O_ALPHA = 4
O_VS = 5
O_DELTA = 6
O_MUV = 7
O_OMDOT = 8  # 1 keeps the dOmega/dt terms
O_IMPACT = 9  # 1 applies the plastic impact at re-contact
O_LMAX = 10  # largest l
O_DAMPED = 11  # 1 if any modal damping
O_MIN_FLIGHT = 12  # shortest flight resolved [s]
N_OPTS = 13
FRICTION_SLOTS = {"static": O_MUS, "kinetic_max": O_MU0, "kinetic_min": O_MU1,
                  "decay": O_ALPHA, "stribeck_velocity": O_VS, "stribeck_exponent": O_DELTA,
                  "viscous": O_MUV}

# Energy accumulators: integrated power [W] of each kind of force, and impact jumps [J].
E_FRICTION = 0  # friction at the contacts, f r (phidot - Omega): dissipation while slipping
E_DRIVE = 1  # what keeps the disc at Omega(t): f r Omega, gyroscopic and dOmega/dt terms
E_MOMENT = 2  # the friction's bending moment on the disc, sigma (h / 2 r) f g'.qdot
E_SLOPE = 3  # the normal force on the disc's sloped surface, sigma N phidot g'.q
E_SLIDER_DAMPING = 4  # -c_z zdot^2 - r^2 c_phi phidot^2
E_DISC_DAMPING = 5  # modal damping of the disc
E_IMPACT = 6  # kinetic energy lost in the plastic impacts, -1/2 |du|_W^2
E_SURFACE = 7  # work of the moving, sloped surface during impacts, lambda.b
N_ENERGY = 8
ENERGY_NAMES = ("friction", "drive", "friction_moment", "normal_slope", "slider_damping",
                "disc_damping", "impact_loss", "impact_surface")

# Per-slider rows of the work array's auxiliary block (filled by ``evaluate``).
A_N = 0  # normal force [N]
A_F = 1  # friction force on the slider, positive along +phi [N]
A_WC = 2  # the disc's w under the slider [m]
A_WCD = 3  # its rate following the slider [m/s]
A_V = 4  # relative speed Omega - phidot [rad/s]
A_GPQ = 5  # g'.q
A_GPQD = 6  # g'.qdot
A_L2GQ = 7  # sum l^2 g q
A_SGGP = 8  # g M^-1 g'
A_PHID = 9  # phidot (Omega in stick)
A_SMU = 10  # s mu in slip
A_FPHI = 11  # in-plane spring and damper force
A_KNOWN = 12  # the part of N that does not depend on the accelerations
A_DEN = 13  # one slider in contact: the divisor of its N in closed form
A_OM = 14  # column 0: the disc's speed Omega [rad/s] at the evaluation (one per evaluation)
A_OMD = 15  # column 0: its rate dOmega/dt [rad/s^2]
N_AUX = 16


class KernelModel(NamedTuple):
    """Arrays the kernels read, built by :func:`fivdisc.model.build.build_model`.

    ``disc`` is ``(N_DISC, n)`` with rows ``D_*``; ``slider`` is ``(N_SLIDER, S)`` with
    rows ``S_*``; ``shape[j]`` the mode shapes at slider j's track radius; ``table`` the
    pieces of a tabulated friction law (start, then cubic coefficients in powers of the
    distance from it; a constant last piece); ``speed`` the pieces of the speed profile
    (knot, cubic coefficients); ``opts`` the friction law and the switches (``O_*``).
    """

    disc: np.ndarray
    slider: np.ndarray
    shape: np.ndarray
    table: np.ndarray
    speed: np.ndarray
    opts: np.ndarray

    def row(self, name: str) -> np.ndarray:
        """A per-slider quantity by name (``"inertia"``, ``"kz"``, ... of
        ``SLIDER_ROWS``), one value per slider."""
        return self.slider[SLIDER_ROWS[name]]
