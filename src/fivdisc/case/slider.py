"""The ``[slider]`` table (one of the ``[[sliders]]`` tables): a slider's springs, dampers,
preload, place and face."""

from __future__ import annotations

from typing import ClassVar, Literal

from fivdisc.case.fields import Real, Table, field


class SliderPerturbation(Table):
    """This slider's offsets from the sliding equilibrium when a run starts from it, added
    to the ``[simulation.perturbation]`` every slider takes (identical pads started
    identically stay in step until the integration's round-off parts them: an offset of
    one pad breaks the symmetry on purpose).

    Attributes
    ----------
    phi
        Offset of this slider's angle [rad].
    phi_dot
        Offset of this slider's angular velocity [rad/s].
    """

    _key: ClassVar[tuple[str, ...]] = ("slider", "perturbation")

    phi: Real = field(0.0, "rad", r"\Delta\phi_j", "slider own angle perturbation")
    phi_dot: Real = field(0.0, "rad/s", r"\Delta\dot\phi_j",
                          "slider own angular velocity perturbation")


class Slider(Table):
    """A slider: a mass on a transverse spring-damper and an in-plane one.

    Attributes
    ----------
    track_radius
        r_j, radius of the slider's track [m]; strictly between the disc's radii.
    mass
        m_j [kg]; its moment of inertia about the disc axis is m_j r_j^2.
    normal_stiffness
        k_z [N/m].
    normal_damping
        c_z [N s/m].
    rotational_stiffness
        r_j^2 k_phi [N m/rad].
    rotational_damping
        r_j^2 c_phi [N m s/rad].
    preload
        N0, normal preload [N], pressing the slider onto its face.
    angle
        theta_j, space-fixed angle of the slider's base [rad], within +-1e6; the slider
        sits at theta_j + phi_j. Sliders on one face are at least 1e-6 m apart.
    face
        "top" (the paper's side, on +w, pressed towards -w) or "bottom" (on -w,
        pressed towards +w).
    perturbation
        This slider's own offsets from the sliding equilibrium at the start, added to
        ``simulation.perturbation`` (:class:`SliderPerturbation`).
    """

    _key: ClassVar[tuple[str, ...]] = ("slider",)

    track_radius: Real = field(0.1, "m", "r_0", gt=0)
    mass: Real = field(0.1, "kg", "m", gt=0)
    normal_stiffness: Real = field(3e4, "N/m", "k_z", gt=0)
    normal_damping: Real = field(0.1, "N s/m", "c_z", ge=0)
    rotational_stiffness: Real = field(2e3, "N m/rad", r"r_0^2 k_\phi", gt=0)
    rotational_damping: Real = field(0.1, "N m s/rad", r"r_0^2 c_\phi", ge=0)
    preload: Real = field(500.0, "N", "N_0", ge=0)
    angle: Real = field(0.0, "rad", r"\theta", "slider base angle")
    face: Literal["top", "bottom"] = "top"
    perturbation: SliderPerturbation = SliderPerturbation()

    @property
    def sigma(self) -> float:
        """+1 on the top face, -1 on the bottom face."""
        return 1.0 if self.face == "top" else -1.0
