"""The names of the bifurcations a branch of periodic orbits meets, one per event."""

from __future__ import annotations

from enum import StrEnum

__all__ = ["CURVE_CONDITIONS", "BifurcationKind"]


class BifurcationKind(StrEnum):
    """What happens at a bifurcation of a branch of periodic orbits (a ``str``: files and
    JSON store the value).

    Smooth ones, from the Floquet multipliers: ``FOLD`` (the branch turns back, a
    multiplier at +1), ``PERIOD_DOUBLING`` (a real multiplier through -1), ``TORUS`` (a
    complex pair through the unit circle), ``BRANCH_POINT`` (a multiplier through +1
    without a fold), ``SYMMETRY_BREAKING`` (a crossing whose eigenvector breaks the
    orbit's spatio-temporal symmetry). Discontinuity-induced ones: ``GRAZING`` (a phase
    of a slider appears or vanishes where the orbit touches a switching boundary: the slip
    speed reaching zero, a stick phase appearing, or the normal force reaching zero),
    ``STICK_SPLIT`` (the friction needed to stick touches its static limit inside a stick
    phase: a short slip appears in it),
    ``SIGNATURE_CHANGE`` (another change of the sequence of phases), ``SWITCHING_ORDER``
    (switches of different sliders change order, the flow map continuous),
    ``DISCONTINUITY`` (they change order and the flow map jumps: the branch jumps with it).
    Ends: ``DISCONTINUITY_END`` and ``CASCADE_END`` (the flow map jumps and no orbit lies
    past the border), ``END`` (lost there, no border found), ``GAP`` (the corrector could
    not follow; a forward run found the orbit again past it).

    Examples
    --------
    >>> from fivdisc import BifurcationKind
    >>> BifurcationKind.FOLD == "fold", BifurcationKind("period doubling").name
    (True, 'PERIOD_DOUBLING')
    """

    FOLD = "fold"
    PERIOD_DOUBLING = "period doubling"
    TORUS = "torus"
    BRANCH_POINT = "branch point"
    SYMMETRY_BREAKING = "symmetry breaking"
    GRAZING = "grazing"
    STICK_SPLIT = "stick split"
    SIGNATURE_CHANGE = "signature change"
    SWITCHING_ORDER = "switching order"
    DISCONTINUITY = "discontinuity"
    DISCONTINUITY_END = "discontinuity end"
    CASCADE_END = "cascade end"
    END = "end"
    GAP = "gap"


#: The bifurcations a curve in two keys follows by their defining conditions
#: (:func:`fivdisc.continuation.codim2.bifurcation_curve`).
CURVE_CONDITIONS = (BifurcationKind.FOLD, BifurcationKind.PERIOD_DOUBLING,
                    BifurcationKind.TORUS, BifurcationKind.SYMMETRY_BREAKING,
                    BifurcationKind.GRAZING, BifurcationKind.STICK_SPLIT)
