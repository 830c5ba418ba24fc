"""Small cases several tests share, with what is known of them by hand."""

from __future__ import annotations

import numpy as np

from fivdisc.case import Case
from fivdisc.model import layout as lay
from fivdisc.model.build import build_model

MU_S, MU_K, OMEGA = 0.8, 0.5, 1.0
# One axisymmetric disc mode (l = 0): its slope under the slider is zero, so the slider's
# in-plane motion does not act on the disc, and the normal force is constant once the
# disc mode has settled. Constant kinetic friction and no in-plane damping make the
# slider the textbook stick-slip oscillator.
RIGID = Case(
    disc={"modes": [[0, 0]]},
    slider={"rotational_damping": 0.0, "normal_damping": 5.0},
    friction={"static": MU_S, "kinetic_max": MU_K, "kinetic_min": MU_K, "decay": 0.0},
    speed={"value": OMEGA},
)
LIGHT = Case(disc={"density": 720.0, "modes": [[0, 0]]},
             slider={"mass": 1.0, "normal_damping": 20.0}, speed={"value": 1.0})

# Issue 40's study: three identical pads at 0, 120 and 240 degrees on a damped disc
# with Stribeck friction (issue 36's `bist-22-large.toml`, stable sliding at 22 rad/s).
_PAD = {"face": "top", "track_radius": 0.1, "mass": 0.1, "normal_stiffness": 3e4,
        "normal_damping": 0.1, "rotational_stiffness": 2e3, "rotational_damping": 0.1,
        "preload": 500.0}
THREE_PADS = Case(
    disc={"modes": [[0, 0], [0, 1], [0, 2], [0, 3]], "damping_ratio": 0.003,
          "damping_frame": "material"},
    sliders=[{**_PAD, "angle": a} for a in (0.0, 2 * np.pi / 3, 4 * np.pi / 3)],
    friction={"law": "stribeck", "static": 0.8, "kinetic_max": 0.6, "kinetic_min": 0.35,
              "stribeck_velocity": 1.0, "stribeck_exponent": 2.0, "viscous": 0.0},
    speed={"value": 22.0},
    simulation={"duration": 3.0, "initial_state": "equilibrium", "output_rate": 10000.0,
                "perturbation": {"phi": 0.0, "phi_dot": 14.0}},
)


def rigid_disc_closed_form(omega: float = OMEGA):
    """Period of the stick-slip cycle and the disc mode's multipliers, by hand.

    Normal force: N = N0 / (1 + k_z g^2 / K) (disc mode K q = -N g, slider spring
    N = N0 + k_z g q). Stick: phi rises at Omega from phi_k - d to phi_k + d, where
    phi_k = r mu_k N / k_phi is the centre of the slip oscillation and
    d = r (mu_s - mu_k) N / k_phi (slip starts at r mu_s N = k_phi phi); it lasts 2 d / Omega.
    Slip: I phi'' = -k_phi (phi - phi_k), from (phi_k + d, Omega) until phidot = Omega
    again at phi_k - d: with A = sqrt(d^2 + (Omega / w)^2), w = sqrt(k_phi / I), it
    lasts (pi + 2 arcsin(Omega / (A w))) / w. The disc mode obeys
    (M + m g^2) q'' + c_z g^2 q' + (K + k_z g^2) q = -g N0 whatever the slider does.
    """
    model = build_model(RIGID.replace({"speed.value": omega}))
    kern = model.kernel
    g = kern.shape[0, 0]
    mass_modal = 1.0 / kern.disc[lay.D_MINV, 0]
    stiff_modal = kern.disc[lay.D_KD, 0]
    m, kz, cz, n0 = (kern.slider[row, 0] for row in (lay.S_MASS, lay.S_KZ, lay.S_CZ, lay.S_N0))
    inertia, kphi, r = (kern.slider[row, 0] for row in (lay.S_INERTIA, lay.S_KPHI, lay.S_RADIUS))
    normal = n0 / (1.0 + kz * g * g / stiff_modal)
    w = np.sqrt(kphi / inertia)
    d = r * (MU_S - MU_K) * normal / kphi
    amp = np.hypot(d, omega / w)
    period = 2.0 * d / omega + (np.pi + 2.0 * np.arcsin(omega / (amp * w))) / w
    lam = np.roots([mass_modal + m * g * g, cz * g * g, stiff_modal + kz * g * g])
    return period, np.exp(lam * period)


def kick(case: Case, speed: float = 5.0) -> dict:
    """A transverse velocity of the first disc mode [1/s in modal units] strong enough to
    make the sliders fly (an ``initial`` state for :func:`fivdisc.simulate`)."""
    n = build_model(case).n
    return {"q_dot": np.r_[speed, np.zeros(n - 1)]}
