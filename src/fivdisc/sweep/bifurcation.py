"""Bifurcation diagrams: the values of a section over the one swept key of a sweep.

Every point's section values (see :mod:`fivdisc.sweep.sections`) are drawn as dots above
its value of the swept key (small ones where the points are many, visible ones where they
are few); where the sweep keeps ``largest_lyapunov``, a second panel below, sharing the
axis, draws the exponent with a line at zero, and its uncertainty as error bars where
the sweep keeps ``largest_lyapunov_uncertainty`` too: a finite-time exponent whose bar
reaches across zero does not tell chaos from a regular motion. Exponents stored as
inconclusive (``largest_lyapunov_inconclusive``: uncertainty unknown or larger than the
exponent, or positive where the motion stays near a periodic orbit) are ringed and named
in a legend.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from fivdisc.errors import SweepError, nearest

if TYPE_CHECKING:

    from fivdisc.sweep.spec import Sweep


__all__ = ["check_diagram", "diagram_section"]


def diagram_section(axes: list[str], sections: list[dict[str, Any]],
                    section: str | None = None) -> dict[str, Any]:
    """The section a diagram draws, after checking that the sweep can give one.

    Parameters
    ----------
    axes
        The swept keys.
    sections
        The sweep's sections, as :meth:`Section.to_dict` gives them.
    section
        Name of the section to draw; None: the first.

    Raises
    ------
    SweepError
        Not exactly one swept key, no section, or no section named `section`.
    """
    if len(axes) != 1:
        raise SweepError(
            f"a bifurcation diagram needs a sweep over one key; this one sweeps "
            f"{len(axes)}: {', '.join(repr(a) for a in axes)}"
        )
    if not sections:
        raise SweepError(
            "a bifurcation diagram needs a section: add a [[reduce.section]] table to the "
            "sweep file (e.g. variable = \"phi_dot\", at = \"maxima\")"
        )
    names = [s["name"] for s in sections]
    if section is None:
        return sections[0]
    if section not in names:
        raise SweepError(f"section = {section!r} is invalid: the sweep's sections are "
                         f"{', '.join(names)}{nearest(section, names)}")
    return sections[names.index(section)]


def check_diagram(spec: Sweep, section: str | None = None) -> dict[str, Any]:
    """:func:`diagram_section` of a sweep, before it runs."""
    return diagram_section(list(spec.axes), [s.to_dict() for s in spec.sections], section)
