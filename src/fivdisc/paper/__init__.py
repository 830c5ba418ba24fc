"""The paper's cases and figures, and ``reproduce``: every figure, one command.

>>> from fivdisc.paper import FIG8, reproduce
>>> FIG8.case.slider.normal_damping
0.1
>>> reproduce([8, 9], outdir="paper-figures")  # doctest: +SKIP

:mod:`fivdisc.paper.cases` holds the parameter sets (``FIG3`` ... ``FIG28``),
:mod:`fivdisc.paper.figures` the data behind each figure (``compute``) and its
drawing (``plot``), :mod:`fivdisc.paper.reproduce` the command. Matplotlib is
imported only when a figure is drawn.
"""

from fivdisc.paper.cases import (
    CITATION,
    FIG3,
    FIG4,
    FIG5,
    FIG6,
    FIG7,
    FIG8,
    FIG9,
    FIG10,
    FIG11,
    FIG12,
    FIG13,
    FIG14,
    FIG15,
    FIG16,
    FIG17,
    FIG18,
    FIG19,
    FIG20,
    FIG21,
    FIG22,
    FIG23,
    FIG24,
    FIG25,
    FIG26,
    FIG27,
    FIG28,
    FIGURES,
    PaperCase,
    cases,
)
from fivdisc.paper.figures import Row, Runs, compute, plot, rows
from fivdisc.paper.reproduce import ReproduceReport, parse_figures, reproduce

__all__ = [
    "CITATION",
    "FIG3",
    "FIG4",
    "FIG5",
    "FIG6",
    "FIG7",
    "FIG8",
    "FIG9",
    "FIG10",
    "FIG11",
    "FIG12",
    "FIG13",
    "FIG14",
    "FIG15",
    "FIG16",
    "FIG17",
    "FIG18",
    "FIG19",
    "FIG20",
    "FIG21",
    "FIG22",
    "FIG23",
    "FIG24",
    "FIG25",
    "FIG26",
    "FIG27",
    "FIG28",
    "FIGURES",
    "PaperCase",
    "ReproduceReport",
    "Row",
    "Runs",
    "cases",
    "compute",
    "parse_figures",
    "plot",
    "reproduce",
    "rows",
]
