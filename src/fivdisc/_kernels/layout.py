"""What the compiled kernels share: the model tuple, the state layout, phase and event codes.

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
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

SLIP = 0
STICK = 1
SEPARATION = 2

# Event kinds (columns of the event table).
EV_STICK = 0
EV_SLIP = 1
EV_REVERSAL = 2
EV_SEPARATION = 3
EV_RECONTACT = 4

# Friction laws (KernelModel.fric[F_LAW]).
LAW_EXPONENTIAL = 0
LAW_STRIBECK = 1
LAW_TABLE = 2

# KernelModel.fric slots.
F_LAW = 0
F_MUS = 1
F_MU0 = 2
F_MU1 = 3
F_ALPHA = 4
F_VS = 5
F_DELTA = 6
F_MUV = 7
N_FRIC = 8

# KernelModel.opts slots.
O_OMDOT = 0
O_IMPACT = 1
O_LMAX = 2
O_DAMPED = 3
O_MIN_FLIGHT = 4
N_OPTS = 5

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

# Rows of the per-slider scratch ``aux`` (filled by ``evaluate``).
A_N = 0  # normal force [N]
A_F = 1  # friction force on the slider, positive along +phi [N]
A_WC = 2  # the disc's w under the slider [m]
A_WCD = 3  # its rate following the slider [m/s]
A_V = 4  # relative speed Omega - phidot [rad/s]
A_GPQ = 5  # g'.q
A_GPQD = 6  # g'.qdot
A_L2GQ = 7  # sum l^2 g q
A_SGF = 8  # g M^-1 F_q
A_SGG = 9  # g M^-1 g
A_SGGP = 10  # g M^-1 g'
A_PHID = 11  # phidot (Omega in stick)
A_SMU = 12  # s mu in slip
A_FPHI = 13  # in-plane spring and damper force
A_KNOWN = 14  # the part of N that does not depend on the accelerations
N_AUX = 15


class KernelModel(NamedTuple):
    """Arrays the kernels read, built by :func:`fivdisc.model.build_model`.

    Per modal coordinate ``i`` (length n): ``l`` nodal diameters, ``sgn`` +1 for a cosine
    (C) and -1 for a sine (D) coordinate, ``partner`` the other member of a doublet (-1
    for l = 0), ``minv = 1/M``, ``kd = M omega^2``, ``ml2 = M l^2``, ``gyr`` the
    gyroscopic factor ``sgn l M`` of the ``2 Omega`` term, ``omd_fix`` the factor that
    turns ``gyr`` into the ``dOmega/dt`` term's (1, or -1 for D with the printed sign),
    ``cdamp = 2 zeta omega M`` and ``cdamp_om`` its material-frame ``Omega q_partner``
    coefficient (``sgn l cdamp``; 0 in the space frame).

    Per slider ``j`` (length S): ``shape[j]`` the mode shapes at its track radius, base
    angle ``theta``, face ``sigma`` (+1 top, -1 bottom), ``mass``, ``inertia = m r^2``,
    ``kz``, ``cz``, ``kphi`` (``r^2 k_phi``), ``cphi``, ``n0``, ``radius``,
    ``hh = h / (2 r)``, and the face-signed products ``smass``, ``skz``, ``scz``,
    ``sn0``, ``shh`` (sigma times the plain value).

    ``fric`` holds the friction law (``F_*`` slots), ``ftab_x``/``ftab_c`` the pieces of
    a tabulated law, ``knots``/``coef`` the piecewise-cubic speed profile and ``opts``
    the switches (``O_*`` slots).
    """

    l: np.ndarray
    sgn: np.ndarray
    partner: np.ndarray
    minv: np.ndarray
    kd: np.ndarray
    ml2: np.ndarray
    gyr: np.ndarray
    omd_fix: np.ndarray
    cdamp: np.ndarray
    cdamp_om: np.ndarray
    shape: np.ndarray
    theta: np.ndarray
    sigma: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray
    kz: np.ndarray
    cz: np.ndarray
    kphi: np.ndarray
    cphi: np.ndarray
    n0: np.ndarray
    radius: np.ndarray
    hh: np.ndarray
    smass: np.ndarray
    skz: np.ndarray
    scz: np.ndarray
    sn0: np.ndarray
    shh: np.ndarray
    fric: np.ndarray
    ftab_x: np.ndarray
    ftab_c: np.ndarray
    knots: np.ndarray
    coef: np.ndarray
    opts: np.ndarray


@njit(cache=True, inline="always")
def sizes(mdl):
    """``(n, S, half)``: modal coordinates, sliders, and the offset of the velocities."""
    n = mdl.l.shape[0]
    s = mdl.theta.shape[0]
    return n, s, n + 2 * s


@njit(cache=True, inline="always")
def n_dynamic(mdl):
    """Length of the state without the energy accumulators, ``2 (n + 2 S)``."""
    return 2 * (mdl.l.shape[0] + 2 * mdl.theta.shape[0])
