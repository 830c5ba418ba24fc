"""The type of a response from its Lyapunov exponents and Floquet multipliers, checked
against the spectral label of :func:`fivdisc.analysis.spectra.classify`.

For a bounded response of an autonomous system (constant disc speed):

- an equilibrium has every exponent negative;
- a periodic orbit has one zero exponent (the flow direction), the rest negative, and
  Floquet multipliers inside the unit circle but for the trivial 1;
- a quasi-periodic response on a k-torus has k zero exponents;
- a chaotic one has a positive exponent.

The paper's disc has no structural damping: every disc mode the slider does not damp is a
neutral oscillator, which adds a zero exponent and a line of its own to the disc's
spectrum. A finite run estimates an exponent with an error of about 1/duration times the
logarithm of how much the tangent's growth fluctuates over the attractor; an exponent is
taken as zero when it lies within three of its standard errors (from the run's blocks)
plus ``zero`` of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fivdisc.analysis.exponents import LyapunovSpectrum
from fivdisc.analysis.orbits import PeriodicOrbit

__all__ = ["Regime", "cross_check", "lyapunov_label"]

# Spectral labels each Lyapunov label agrees with.
_AGREES = {
    "equilibrium": ("none",),
    "periodic": ("periodic",),
    "quasi-periodic": ("quasi-periodic", "periodic"),
    "chaotic": ("irregular",),
}


@dataclass(frozen=True)
class Regime:
    """A response's type by its spectrum and by its exponents (and multipliers).

    Attributes
    ----------
    spectral : str
        The spectral label (``"periodic"``, ``"quasi-periodic"``, ``"irregular"``,
        ``"none"``).
    lyapunov : str
        ``"equilibrium"``, ``"periodic"``, ``"quasi-periodic"`` or ``"chaotic"``
        (``"undecided"`` when the exponents computed cannot tell).
    zero_exponents : int
        How many of the computed exponents are zero within their accuracy.
    largest : float
        The largest exponent [1/s].
    uncertainty : float
        Its standard error [1/s].
    multiplier : float or None
        Largest modulus of the non-trivial Floquet multipliers, if an orbit was given.
    consistent : bool
        Whether the labels agree (a periodic slider with neutral disc modes ringing
        freely is quasi-periodic by its exponents: that counts as agreeing).
    """

    spectral: str
    lyapunov: str
    zero_exponents: int
    largest: float
    uncertainty: float
    multiplier: float | None
    consistent: bool

    @property
    def summary(self) -> str:
        text = (f"largest Lyapunov exponent {self.largest:+.3g} +- {self.uncertainty:.2g} 1/s, "
                f"{self.zero_exponents} zero: {self.lyapunov}")
        if self.multiplier is not None:
            text += f"; largest Floquet multiplier {self.multiplier:.6f}"
        word = "agrees with" if self.consistent else "contradicts"
        return f"{text} ({word} the spectrum: {self.spectral})"


def lyapunov_label(spectrum: LyapunovSpectrum, zero: float = 0.1) -> tuple[str, int]:
    """The response type by its exponents, and how many are zero.

    Parameters
    ----------
    spectrum : LyapunovSpectrum
        At least two exponents tell a periodic orbit from a torus.
    zero : float
        Absolute allowance [1/s] for a zero exponent beyond three uncertainties.
    """
    lam = spectrum.exponents
    slack = 3.0 * np.nan_to_num(spectrum.uncertainty, nan=0.0) + zero
    is_zero = np.abs(lam) <= slack
    count = int(is_zero.sum())
    if lam[0] > slack[0]:
        return "chaotic", count
    if count == 0:
        return "equilibrium", 0
    if count == lam.size and count < 2:
        return "undecided", count
    return ("periodic" if count == 1 else "quasi-periodic"), count


def cross_check(spectral: str, spectrum: LyapunovSpectrum, orbit: PeriodicOrbit | None = None,
                zero: float = 0.1) -> Regime:
    """Check a spectral label against the Lyapunov exponents (and an orbit's multipliers).

    Parameters
    ----------
    spectral : str
        ``Periodicity.kind`` from :func:`~fivdisc.analysis.spectra.classify`.
    spectrum : LyapunovSpectrum
        Exponents of the same response.
    orbit : PeriodicOrbit, optional
        A periodic orbit of the response: a converged, stable orbit confirms
        ``"periodic"``, an unstable or unconverged one contradicts it.
    zero : float
        See :func:`lyapunov_label`.
    """
    label, count = lyapunov_label(spectrum, zero)
    consistent = spectral in _AGREES.get(label, ())
    multiplier = None
    if orbit is not None:
        multiplier = orbit.largest
        if spectral == "periodic":
            consistent = consistent and orbit.verdict == "stable"
    return Regime(spectral, label, count, spectrum.largest,
                  float(spectrum.uncertainty[0]), multiplier, consistent)
