"""The parameter sets of the paper's Figs. 3-28, as code, named after their figure.

Every case is the paper's Table 1 (the defaults of :class:`fivdisc.Case`) with the
damping, friction decay and disc speed the figure's caption gives. Where the paper
does not state something a simulation needs, the choice is made here and said in
the :class:`PaperCase`'s ``choices``:

* time spans: the 35 s decelerations of Eq. (1) last until the disc stops; the
  constant-speed and accelerating runs that the paper compares with them
  (Figs. 8-9, 13-14, 18, 20-21, 24-26) are simulated over the same 35 s, so that
  "stationary throughout the process" and "no separation at constant speed" are
  checked over the same span. Figs. 4 and 6 (decay to the sliding equilibrium) run
  5 s, Fig. 5 until its disc stops (20 s), Fig. 7 15 s (its growth starts at about
  4 s) and Fig. 28 10 s (separation starts at about 2.2 s);
* output rates: 2 kHz for the long runs (Nyquist 1 kHz, above the 442 Hz disc mode
  and the 823 Hz second harmonic of its 411 Hz neighbour) and 10 kHz for the
  figures that show 0.1 s windows (Figs. 12 and 17);
* probes at (r0, 0) and (r0, 1 rad), the two points the captions name;
* the perturbation of Figs. 4 and 6 (the paper's "small initial perturbation") is
  1e-3 rad of the slider angle, and Figs. 5 and 7 start from the same state (the
  perturbed sliding equilibrium of Figs. 4 and 6, respectively);
* Fig. 3's grid and its values of alpha; Fig. 12's two windows; Fig. 27's grid.

Reference
---------
.. [1] Friction-induced vibration of a slider on an elastic disc spinning at variable
   speeds, Nonlinear Dynamics (2019), received 23 Nov 2018, published online
   16 Aug 2019.
"""

from __future__ import annotations

import json
import math
import textwrap
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

import numpy as np

from fivdisc.case import Case

__all__ = [
    "CITATION",
    "FIGURES",
    "PaperCase",
    "cases",
    "write_examples",
]

CITATION = (
    "Friction-induced vibration of a slider on an elastic disc spinning at variable speeds, "
    "Nonlinear Dynamics (2019), received 23 Nov 2018, published online 16 Aug 2019"
)

TWO_PI = 2.0 * math.pi
SIX_PI = 6.0 * math.pi

LONG_RATE = 2000.0  # [Hz], output rate of the long runs
FINE_RATE = 10000.0  # [Hz], output rate of the figures drawn over 0.1 s windows
PROBES = ((0.1, 0.0), (0.1, 1.0))  # (r0, 0) and (r0, 1 rad) [m, rad]
PROCESS = 35.0  # [s], t_max of the paper's decelerations (Eq. 1)


@dataclass(frozen=True)
class PaperCase:
    """The parameters of one of the paper's figures.

    Attributes
    ----------
    figure
        Figure number in the paper.
    title
        Short title (what the figure shows).
    case
        The case simulated (panel a when the figure compares two cases); for
        Fig. 3 the base of the stability map of panel a, for Fig. 27 the base of
        the separation sweep.
    caption
        The paper's caption, parameters included.
    statements
        What the paper says about the figure, quoted or closely paraphrased; the
        report compares each with fivdisc.
    case_b
        Panel b's case when the figure compares two cases (Figs. 3, 18, 19, 24, 28).
    start_from
        Figure whose perturbed sliding equilibrium is the initial state (Figs. 5 and
        7 start "from the same initial condition" as Figs. 4 and 6); None: the
        case's own ``simulation.initial_state``.
    windows
        Time windows [s] the figure is about: the panels of Figs. 12 and 17, the
        segments of Fig. 15.
    axes
        Grid axes (dotted case key, values) of a map: x, y and, for Fig. 3, the
        values of alpha of its curves.
    choices
        What the paper leaves open and this module chose, and why.
    """

    figure: int
    title: str
    case: Case
    caption: str
    statements: tuple[str, ...]
    case_b: Case | None = None
    start_from: int | None = None
    windows: tuple[tuple[float, float], ...] = ()
    axes: tuple[tuple[str, tuple[float, ...]], ...] = ()
    choices: str = ""

    @property
    def runs(self) -> dict[str, Case]:
        """Panel label ("" for a one-case figure, else "a" and "b") -> case."""
        return {"": self.case} if self.case_b is None else {"a": self.case, "b": self.case_b}

    @property
    def stem(self) -> str:
        """File name stem, ``figNN``."""
        return f"fig{self.figure:02d}"

    def file_names(self) -> dict[str, str]:
        """Panel label -> name of the example TOML file (``fig08.toml``, ``fig18a.toml``)."""
        return {label: f"{self.stem}{label}.toml" for label in self.runs}

    def parameters(self) -> str:
        """Everything that defines the figure's data, as canonical JSON.

        A rerun of :func:`fivdisc.paper.reproduce` reuses a figure whose stored
        parameters equal these.
        """
        return json.dumps(
            {
                "figure": self.figure,
                "cases": {k: c.model_dump(mode="json") for k, c in self.runs.items()},
                "start_from": self.start_from,
                "windows": [list(w) for w in self.windows],
                "axes": [[k, list(v)] for k, v in self.axes],
            },
            sort_keys=True,
        )

    def toml(self, label: str = "") -> str:
        """The case of panel `label` as a TOML file, led by comment lines naming the figure.

        Parameters
        ----------
        label
            "" for a one-case figure, "a" or "b" for a two-case one.
        """
        text = [f"Fig. {self.figure}{label} of the paper: {self.title}.",
                f"Caption: {self.caption}."]
        if self.start_from is not None:
            text.append(f"Starts from the perturbed sliding equilibrium of Fig. "
                        f"{self.start_from}, which fivdisc.paper passes as the initial state; "
                        "alone, this file starts at rest.")
        text.append(f"To vary it, start from a copy: fivdisc examples {self.stem}{label} > "
                    f"mycase.toml (this file is written from fivdisc.paper.FIG{self.figure}, "
                    "the case fivdisc reproduce runs).")
        lines = [f"# {line}" for part in text for line in textwrap.wrap(part, 88)]
        return "\n".join(lines) + "\n\n" + self.runs[label].to_toml()


def _case(c_z: float, c_phi: float, alpha: float, speed: dict, duration: float,
          rate: float = LONG_RATE, **simulation) -> Case:
    """A Table 1 case with the caption's damping, friction decay and speed.

    Parameters
    ----------
    c_z
        Transverse damping of the slider [N s/m].
    c_phi
        r0^2 c_phi, in-plane damping [N m s/rad].
    alpha
        Decay of the friction coefficient with sliding speed [s/m].
    speed
        The ``[speed]`` table.
    duration
        Simulated time [s].
    rate
        Output rate [Hz].
    **simulation
        Further ``[simulation]`` keys.
    """
    return Case(
        slider={"normal_damping": c_z, "rotational_damping": c_phi},
        friction={"decay": alpha},
        speed=speed,
        simulation={"duration": duration, "output_rate": rate, "probes": PROBES,
                    "initial_state": "rest", **simulation},
    )


def _constant(value: float) -> dict:
    return {"profile": "constant", "value": value}


def _decelerating(initial: float, duration: float = PROCESS) -> dict:
    return {"profile": "decelerating", "initial": initial, "duration": duration}


def _accelerating(initial: float, rate: float) -> dict:
    return {"profile": "accelerating", "initial": initial, "rate": rate}


def _grid(start: float, stop: float, num: int) -> tuple[float, ...]:
    return tuple(float(v) for v in np.linspace(start, stop, num))


# The two parameter combinations of section 3.2: "first" and "second" example.
_FIRST = {"c_z": 0.1, "c_phi": 0.1, "alpha": 1.0}
_SECOND = {"c_z": 2.0, "c_phi": 0.5, "alpha": 1.0}
_FIRST_TEXT = "c_z = 0.1 N s/m, r0^2 c_phi = 0.1 N m s/rad, alpha = 1"
_SECOND_TEXT = "c_z = 2 N s/m, r0^2 c_phi = 0.5 N m s/rad, alpha = 1"
_SPAN = ("35 s, the span of the paper's decelerations, so that the constant-speed and "
         "accelerating responses are compared with them over the same time")

FIG3 = PaperCase(
    figure=3,
    title="Stable combinations of c_z and r0^2 c_phi for several alpha",
    case=_case(0.1, 0.1, 1.0, _constant(1.0), 1.0),
    case_b=_case(0.1, 0.1, 1.0, _constant(10.0), 1.0),
    caption="Combinations of c_z and r0^2 c_phi corresponding to stable sliding equilibrium "
            "with different values of alpha under two spinning speeds: a Omega_c = 1 rad/s, "
            "b Omega_c = 10 rad/s. 'stable' refers to the region above the respective curve",
    statements=(
        "'stable' refers to the region above the respective curve",
        "(c_z = 11 N s/m, r0^2 c_phi = 1 N m s/rad, alpha = 10, Omega_c = 10 rad/s) lies "
        "in the 'stable' area (Fig. 4)",
        "(c_z = 1 N s/m, r0^2 c_phi = 2 N m s/rad, alpha = 0, Omega_c = 1 rad/s) gives a "
        "stable sliding equilibrium (Fig. 6)",
    ),
    axes=(
        ("slider.normal_damping", _grid(0.0, 12.0, 81)),
        ("slider.rotational_damping", _grid(0.0, 3.0, 61)),
        ("friction.decay", (0.0, 1.0, 5.0, 10.0)),
    ),
    choices="The values of alpha are not legible in our copy: 0, 1 and 10 are the values "
            "the text uses (Figs. 4-17), 5 is added between them. The grid covers the "
            "points of Figs. 4 and 6. Stability is judged by the eigenvalues of the "
            "linearised slip equations (the paper perturbs and simulates; Figs. 4 and 6 "
            "do that for one point each).",
)

FIG4 = PaperCase(
    figure=4,
    title="Decay to the sliding equilibrium at constant speed",
    case=_case(11.0, 1.0, 10.0, _constant(10.0), 5.0, initial_state="equilibrium"),
    caption="The system dynamic responses under the constant disc speed: a the "
            "circumferential velocity of the slider, b the transverse displacement of a "
            "specific point on the disc at r = r0 and theta = 0 (c_z = 11 N s/m, "
            "r0^2 c_phi = 1 N m s/rad, alpha = 10, Omega_c = 10 rad/s)",
    statements=(
        "the parameter combination lies in the 'stable' area of Fig. 3",
        "the amplitudes of dynamic responses of the system decay fast with time until the "
        "sliding equilibrium is reached",
    ),
    choices="5 s from the sliding equilibrium perturbed by 1e-3 rad (the paper's span and "
            "perturbation are not given).",
)

FIG5 = PaperCase(
    figure=5,
    title="Decelerating disc: decay, then growth and stick-slip",
    case=_case(11.0, 1.0, 10.0, _decelerating(10.0, 20.0), 20.0),
    start_from=4,
    caption="The system dynamic responses under the decelerating disc: a the "
            "circumferential velocity of the slider, b the transverse displacement of a "
            "specific point on the disc at r = r0 and theta = 0 (c_z = 11 N s/m, "
            "r0^2 c_phi = 1 N m s/rad, alpha = 10, Omega_0 = 10 rad/s, t_max = 20 s)",
    statements=(
        "the vibration decays in the early stage, similarly to that in the situation of "
        "constant speed, but then grows in the final stage",
        "the stick-slip motion is induced in the final stage",
        "cause: the negative slope of friction against relative velocity at low disc speed",
    ),
    choices="Runs until the disc stops (20 s), from the state Fig. 4 starts from.",
)

FIG6 = PaperCase(
    figure=6,
    title="Decay to the sliding equilibrium at constant speed (alpha = 0)",
    case=_case(1.0, 2.0, 0.0, _constant(1.0), 5.0, initial_state="equilibrium"),
    caption="The system dynamic responses under the constant disc speed: a the "
            "circumferential velocity of the slider, b the transverse displacement of a "
            "specific point on the disc at r = r0 and theta = 0 (c_z = 1 N s/m, "
            "r0^2 c_phi = 2 N m s/rad, alpha = 0, Omega_c = 1 rad/s)",
    statements=(
        "the parameter combination leads to a stable sliding equilibrium",
        "the vibration decays fast until the sliding equilibrium is reached",
    ),
    choices="5 s from the sliding equilibrium perturbed by 1e-3 rad (as Fig. 4).",
)

FIG7 = PaperCase(
    figure=7,
    title="Accelerating disc: decay, then growth",
    case=_case(1.0, 2.0, 0.0, _accelerating(1.0, 3.0), 15.0),
    start_from=6,
    caption="The system dynamic responses under the accelerating disc: a the "
            "circumferential velocity of the slider, b the transverse displacement of a "
            "specific point on the disc at r = r0 and theta = 0 (c_z = 1 N s/m, "
            "r0^2 c_phi = 2 N m s/rad, alpha = 0, Omega_1 = 1 rad/s, c = 3 rad/s^2)",
    statements=(
        "the vibration decays at first but starts to grow at a time point later due to "
        "the increase of disc speed",
        "cause: the moving load, which causes speed-dependent instability",
    ),
    choices="15 s (the paper's span is not given; the growth starts at about 4 s), from "
            "the state Fig. 6 starts from.",
)

_FIG8_CASE = _case(**_FIRST, speed=_constant(TWO_PI), duration=PROCESS)
_FIG8_CAPTION = ("The time history of the circumferential angular velocity of the slider and "
                 "time-frequency plot of the circumferential angular displacement of the "
                 f"slider under the constant disc speed ({_FIRST_TEXT}, Omega_c = 2 pi rad/s)")
FIG8 = PaperCase(
    figure=8,
    title="Slider, constant speed 2 pi rad/s, first example",
    case=_FIG8_CASE,
    caption=_FIG8_CAPTION,
    statements=(
        "the sliding equilibrium is unstable (section 3.2 considers unstable cases)",
        "the frequency compositions of the responses remain unchanged throughout the whole "
        "process (stationary responses)",
        "the spectra of the in-plane motion and of the disc's transverse vibration have two "
        "common incommensurate frequencies f1 = 181 Hz and f2 = 290.5 Hz: quasi-periodic",
    ),
    choices=f"{_SPAN}; starts at rest (section 3.2).",
)

FIG9 = PaperCase(
    figure=9,
    title="Disc at (r0, 1 rad), constant speed 2 pi rad/s, first example",
    case=_FIG8_CASE,
    caption="The time history and time-frequency plot of the transverse displacement of the "
            "disc at r = r0 and theta = 1 rad under the constant disc speed: a the time "
            "history, b the frequency spectrum plot (parameters of Fig. 8)",
    statements=FIG8.statements[1:],
    choices=FIG8.choices,
)

_FIG10_CASE = _case(**_FIRST, speed=_decelerating(TWO_PI), duration=PROCESS)
FIG10 = PaperCase(
    figure=10,
    title="Slider, decelerating disc from 2 pi rad/s, first example",
    case=_FIG10_CASE,
    caption="The time history of the circumferential angular velocity of the slider and "
            "time-frequency plot of the circumferential angular displacement of the slider "
            f"under the decelerating disc ({_FIRST_TEXT}, Omega_0 = 2 pi rad/s, "
            "t_max = 35 s)",
    statements=(
        "the frequency spectra are time-variant, especially the in-plane motion of the slider",
        "in the early stage the spectra are similar to those at constant speed (Fig. 8)",
        "lower-frequency components arise towards the end of the process",
        "the spectrum of the in-plane motion gets very fuzzy and dense in the final stage",
    ),
    choices="The whole deceleration (35 s), from rest.",
)

FIG11 = PaperCase(
    figure=11,
    title="Disc at (r0, 1 rad), decelerating disc from 2 pi rad/s, first example",
    case=_FIG10_CASE,
    caption="The time history and time-frequency plot of the transverse displacement of the "
            "disc at r = r0 and theta = 1 rad under the decelerating disc: a the time "
            "history, b the frequency spectrum plot (parameters of Fig. 10)",
    statements=(
        "the spectra are time-variant; early ones are similar to those at constant speed "
        "(Fig. 9)",
    ),
    choices=FIG10.choices,
)

FIG12 = PaperCase(
    figure=12,
    title="Short time spans, early and late, decelerating disc, first example",
    case=_FIG10_CASE.replace({"simulation.output_rate": FINE_RATE}),
    caption="The short-term time histories during two different time spans under the "
            "decelerating disc: a, b the circumferential angular velocity of the slider, "
            "c, d the friction force (parameters of Fig. 10)",
    statements=(
        "the variation of the frequencies of the response during the process can also be "
        "observed from the time histories in the early and late stages",
    ),
    windows=((5.0, 5.1), (30.0, 30.1)),
    choices="The two spans are not given in our copy: 5-5.1 s and 30-30.1 s, 0.1 s long "
            "like those of Fig. 17, are early and late. Output at 10 kHz (50 samples per "
            "period of the 200 Hz motion).",
)

_FIG13_CASE = _case(**_SECOND, speed=_constant(TWO_PI), duration=PROCESS)
FIG13 = PaperCase(
    figure=13,
    title="Slider, constant speed 2 pi rad/s, second example",
    case=_FIG13_CASE,
    caption="The time history of the circumferential angular velocity of the slider and "
            "time-frequency plot of the circumferential angular displacement of the slider "
            f"under the constant disc speed ({_SECOND_TEXT}, Omega_c = 2 pi rad/s)",
    statements=(
        "the sliding equilibrium is unstable (section 3.2 considers unstable cases)",
        "the frequency compositions of the responses remain unchanged",
        "the spectra of the in-plane motion and of the disc consist of the fundamental "
        "frequency f0 = 206 Hz and its superharmonics: periodic at the same frequency",
    ),
    choices=f"{_SPAN}; starts at rest.",
)

FIG14 = PaperCase(
    figure=14,
    title="Disc at (r0, 1 rad), constant speed 2 pi rad/s, second example",
    case=_FIG13_CASE,
    caption="The time history and time-frequency plot of the transverse displacement of the "
            "disc at r = r0 and theta = 1 rad under the constant disc speed: a the time "
            "history, b the frequency spectrum plot (parameters of Fig. 13)",
    statements=FIG13.statements[1:],
    choices=FIG13.choices,
)

_FIG15_CASE = _case(**_SECOND, speed=_decelerating(TWO_PI), duration=PROCESS)
_FIG15_SEGMENTS = ((0.0, 10.0), (10.0, 15.0), (15.0, 25.0), (25.0, 28.0), (28.0, 30.0),
                   (30.0, 35.0))
FIG15 = PaperCase(
    figure=15,
    title="Slider, decelerating disc from 2 pi rad/s, second example",
    case=_FIG15_CASE,
    caption="The time history of the circumferential angular velocity of the slider and "
            "time-frequency plot of the circumferential angular displacement of the slider "
            f"under the decelerating disc ({_SECOND_TEXT}, Omega_0 = 2 pi rad/s, "
            "t_max = 35 s)",
    statements=(
        "at least six segments with distinct frequency compositions, in 0-10, 10-15, "
        "15-25, 25-28, 28-30 and 30-35 s, can be identified by visual inspection",
    ),
    windows=_FIG15_SEGMENTS,
    choices="The whole deceleration (35 s), from rest.",
)

FIG16 = PaperCase(
    figure=16,
    title="Disc at (r0, 1 rad), decelerating disc from 2 pi rad/s, second example",
    case=_FIG15_CASE,
    caption="The time history and time-frequency plot of the transverse displacement of the "
            "disc at r = r0 and theta = 1 rad under the decelerating disc: a the time "
            "history, b the frequency spectrum plot (parameters of Fig. 15)",
    statements=(
        "the frequency spectra under the decelerating disc are more time-variant than "
        "under constant speed (Fig. 14)",
    ),
    choices=FIG15.choices,
)

FIG17 = PaperCase(
    figure=17,
    title="Phase portraits and friction trajectories in the six segments of Fig. 15",
    case=_FIG15_CASE.replace({"simulation.output_rate": FINE_RATE}),
    caption="The phase portraits of the circumferential motion of the slider and "
            "trajectories of friction force during short-term time spans within six "
            "different time segments under the decelerating disc: a, b 5 < t < 5.1 s, "
            "c, d 12 < t < 12.1 s, e, f 20 < t < 20.1 s, g, h 26 < t < 26.1 s, "
            "i, j 29 < t < 29.1 s, k, l 33 < t < 35 s",
    statements=(
        "stick-slip vibration with different periods in the six time intervals can be "
        "identified for the in-plane motion of the slider",
    ),
    windows=((5.0, 5.1), (12.0, 12.1), (20.0, 20.1), (26.0, 26.1), (29.0, 29.1),
             (33.0, 35.0)),
    choices="Output at 10 kHz for smooth portraits over 0.1 s windows.",
)

_SIX_A = _case(**_FIRST, speed=_constant(SIX_PI), duration=PROCESS)
_SIX_B = _case(**_SECOND, speed=_constant(SIX_PI), duration=PROCESS)
_SEPARATION_NOTE = ("The printed paper's sign of the D-equation gyroscopic term is also run "
                    "(docs/deviations.md).")
FIG18 = PaperCase(
    figure=18,
    title="Normal force at constant speed 6 pi rad/s, both examples",
    case=_SIX_A,
    case_b=_SIX_B,
    caption="The variation of normal force with time in the situation of constant speed in "
            f"the two cases: a {_FIRST_TEXT}, Omega_c = 6 pi rad/s, b {_SECOND_TEXT}, "
            "Omega_c = 6 pi rad/s",
    statements=(
        "separation happens in both cases; the normal contact force is zero during "
        "separation",
    ),
    choices=f"{_SPAN}. {_SEPARATION_NOTE}",
)

_DEC6_A = _case(**_FIRST, speed=_decelerating(SIX_PI), duration=PROCESS)
_DEC6_B = _case(**_SECOND, speed=_decelerating(SIX_PI), duration=PROCESS)
FIG19 = PaperCase(
    figure=19,
    title="Normal force, decelerating disc from 6 pi rad/s, both examples",
    case=_DEC6_A,
    case_b=_DEC6_B,
    caption="The variation of normal force with time in the situation of deceleration in "
            f"the two cases: a {_FIRST_TEXT}, Omega_0 = 6 pi rad/s, t_max = 35 s, "
            f"b {_SECOND_TEXT}, Omega_0 = 6 pi rad/s, t_max = 35 s",
    statements=(
        "in the first case, separation and re-contact occur throughout the whole "
        "decelerative process",
        "in the second case, there is no separation in the late stage of the decelerative "
        "process",
    ),
    choices=f"The whole deceleration (35 s). {_SEPARATION_NOTE}",
)

FIG20 = PaperCase(
    figure=20,
    title="Responses at constant speed 6 pi rad/s, first example",
    case=_SIX_A,
    caption="The time histories and time-frequency plots of the dynamic responses under the "
            "constant speed: a, b the in-plane motion of the slider, c, d the transverse "
            f"motion of the disc ({_FIRST_TEXT}, Omega_c = 6 pi rad/s)",
    statements=(
        "separation happens (Fig. 18a)",
        "the spectra at constant speed are less time-variant than under the decelerating "
        "disc (Fig. 22)",
    ),
    choices=FIG18.choices,
)

FIG21 = PaperCase(
    figure=21,
    title="Responses at constant speed 6 pi rad/s, second example",
    case=_SIX_B,
    caption="The time histories and time-frequency plots of the dynamic responses under the "
            "constant speed: a, b the in-plane motion of the slider, c, d the transverse "
            f"motion of the disc ({_SECOND_TEXT}, Omega_c = 6 pi rad/s)",
    statements=(
        "separation happens (Fig. 18b)",
        "the spectra at constant speed are less time-variant than under the decelerating "
        "disc (Fig. 23)",
    ),
    choices=FIG18.choices,
)

FIG22 = PaperCase(
    figure=22,
    title="Responses, decelerating disc from 6 pi rad/s, first example",
    case=_DEC6_A,
    caption="The time histories and time-frequency plots of the dynamic responses under the "
            "decelerating disc: a, b the in-plane motion of the slider, c, d the transverse "
            f"motion of the disc ({_FIRST_TEXT}, Omega_0 = 6 pi rad/s, t_max = 35 s)",
    statements=(
        "the spectra are more time-variant than at constant speed (Fig. 20)",
        "the lower-frequency, fuzzy and dense final stage of Fig. 23b is not seen in "
        "Fig. 22b, because separation and re-contact occur throughout this process",
    ),
    choices=FIG19.choices,
)

FIG23 = PaperCase(
    figure=23,
    title="Responses, decelerating disc from 6 pi rad/s, second example",
    case=_DEC6_B,
    caption="The time histories and time-frequency plots of the dynamic responses under the "
            "decelerating disc: a, b the in-plane motion of the slider, c, d the transverse "
            f"motion of the disc ({_SECOND_TEXT}, Omega_0 = 6 pi rad/s, t_max = 35 s)",
    statements=(
        "the spectra are more time-variant than at constant speed (Fig. 21)",
        "lower-frequency components arise and the spectra get fuzzy and dense towards the "
        "end of the process, because there is no separation in the late stage",
    ),
    choices=FIG19.choices,
)

_ACC_A = _case(**_FIRST, speed=_accelerating(TWO_PI, 0.2), duration=PROCESS)
_ACC_B = _case(**_SECOND, speed=_accelerating(TWO_PI, 0.2), duration=PROCESS)
FIG24 = PaperCase(
    figure=24,
    title="Normal force, accelerating disc from 2 pi rad/s, both examples",
    case=_ACC_A,
    case_b=_ACC_B,
    caption="The variation of normal force with time in the situation of accelerating disc "
            f"in the two cases: a {_FIRST_TEXT}, Omega_1 = 2 pi rad/s, c = 0.2 rad/s^2, "
            f"b {_SECOND_TEXT}, Omega_1 = 2 pi rad/s, c = 0.2 rad/s^2",
    statements=(
        "separation happens with the increase of disc speed in the process",
        "there is no separation for the corresponding system at constant disc speed "
        "(Figs. 8 and 13)",
    ),
    choices=f"{_SPAN}. {_SEPARATION_NOTE}",
)

FIG25 = PaperCase(
    figure=25,
    title="Responses, accelerating disc from 2 pi rad/s, first example",
    case=_ACC_A,
    caption="The time histories and time-frequency plots of the dynamic responses under the "
            "accelerating disc: a, b the in-plane motion of the slider, c, d the transverse "
            f"motion of the disc ({_FIRST_TEXT}, Omega_1 = 2 pi rad/s, c = 0.2 rad/s^2)",
    statements=("separation happening in the process leads to shift of frequency spectra",),
    choices=FIG24.choices,
)

FIG26 = PaperCase(
    figure=26,
    title="Responses, accelerating disc from 2 pi rad/s, second example",
    case=_ACC_B,
    caption="The time histories and time-frequency plots of the dynamic responses under the "
            "accelerating disc: a, b the in-plane motion of the slider, c, d the transverse "
            f"motion of the disc ({_SECOND_TEXT}, Omega_1 = 2 pi rad/s, c = 0.2 rad/s^2)",
    statements=FIG25.statements,
    choices=FIG24.choices,
)

FIG27 = PaperCase(
    figure=27,
    title="Separation region over Omega_0 and t_max, decelerating disc",
    case=_case(**_FIRST, speed=_decelerating(10.0, 20.0), duration=20.0, rate=100.0),
    caption="The separation region (SR) with respect to Omega_0 and t_max in the situation "
            f"of decelerating disc ({_FIRST_TEXT})",
    statements=(
        "separation is more likely to happen in the case of high initial speed and long "
        "decelerative process",
        "the initial displacements and velocities are zero",
    ),
    axes=(
        ("speed.initial", _grid(2.0, 20.0, 13)),
        ("speed.duration", _grid(4.0, 40.0, 10)),
    ),
    choices="The paper's axis ranges are not legible in our copy: Omega_0 from 2 to 20 rad/s "
            "(1.5 rad/s apart) and t_max from 4 to 40 s (4 s apart), the region where "
            "fivdisc's boundary lies. Each run lasts until the disc stops or ends at its "
            "first separation (only whether and when it separates is kept), so 100 Hz "
            f"output is enough. {_SEPARATION_NOTE}",
)

_FIG28 = _case(0.0, 0.0, 1.0, _constant(50.0), 10.0)
FIG28 = PaperCase(
    figure=28,
    title="Transverse displacement at (r0, 0), with and without impact, 50 rad/s",
    case=_FIG28,
    case_b=_FIG28.replace({"simulation.impact": False}),
    caption="The time histories of the transverse displacement in the situation of constant "
            "disc speed under two conditions: a with impact, b without impact (c_z = 0, "
            "r0^2 c_phi = 0, alpha = 1, Omega_c = 50 rad/s)",
    statements=(
        "separation and re-contact occur (the comparison is about the impact at re-contact)",
        "the transverse vibration with impact considered is much weaker than without impact "
        "(the perfectly plastic impact dissipates energy)",
    ),
    choices="10 s (separation starts at about 2.2 s; the paper's span is not given). "
            f"{_SEPARATION_NOTE}",
)

FIGURES: dict[int, PaperCase] = {
    pc.figure: pc
    for pc in (FIG3, FIG4, FIG5, FIG6, FIG7, FIG8, FIG9, FIG10, FIG11, FIG12, FIG13, FIG14,
               FIG15, FIG16, FIG17, FIG18, FIG19, FIG20, FIG21, FIG22, FIG23, FIG24, FIG25,
               FIG26, FIG27, FIG28)
}
"""Figure number -> its parameters, for Figs. 3-28."""


def cases() -> dict[str, Case]:
    """Every case of the paper, by example file stem (``"fig08"``, ``"fig18a"``, ...)."""
    return {
        name.removesuffix(".toml"): pc.runs[label]
        for pc in FIGURES.values()
        for label, name in pc.file_names().items()
    }



def write_examples(directory: str | PathLike[str]) -> list[Path]:
    """Write every case as a TOML file (``fig08.toml``, ``fig18a.toml``, ...).

    Parameters
    ----------
    directory
        Where to write (the repository's ``src/fivdisc/examples``, which ships them as
        package data: :mod:`fivdisc.examples`).

    Returns
    -------
    list of Path
        The files written.
    """
    written = []
    for pc in FIGURES.values():
        for label, name in pc.file_names().items():
            path = Path(directory) / name
            path.write_text(pc.toml(label), encoding="utf-8")
            written.append(path)
    return written
