"""Sliding equilibrium at constant disc speed (paper section 3.1), for any number of sliders.

Defined in :mod:`fivdisc.start` (the simulation driver starts runs from it); this is its
place among the analyses.
"""

from fivdisc.start import Equilibrium, sliding_equilibrium, slip_phases

__all__ = ["Equilibrium", "sliding_equilibrium", "slip_phases"]
