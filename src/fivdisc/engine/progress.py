"""Progress bars for long work: a tqdm bar on stderr when it is a terminal, nothing
otherwise (a pipe, a log file, a notebook's captured stream).

>>> from fivdisc.engine.progress import progress_bar
>>> with progress_bar(total=10, desc="Newton", unit="it", show=True) as bar:
...     for _ in range(10):
...         bar.update()
"""

from __future__ import annotations

import sys
from typing import Any

__all__ = ["SIMULATED_TIME", "progress_bar"]

#: ``bar_format`` of a bar counting simulated seconds (``total`` and ``update`` in [s]).
SIMULATED_TIME = "{l_bar}{bar}| {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]"


def progress_bar(total: float | None, desc: str, unit: str = "it", show: bool = True,
                 **options: Any) -> Any:
    """A tqdm bar, shown only if `show` and stderr is a terminal.

    Parameters
    ----------
    total
        What a finished run counts (iterations, points, simulated seconds); None if not
        known beforehand.
    desc
        What is counted, shown before the bar.
    unit
        The unit of one count.
    show
        False: never show it.
    **options
        Passed to :class:`tqdm.tqdm` (``bar_format``, ``postfix``, ...).

    Returns
    -------
    tqdm.tqdm
        Use it as tqdm (``update``, ``set_postfix_str``, ``close``, ``with``).
    """
    from tqdm import tqdm

    # disable=None is tqdm's "only on a terminal".
    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr,
                disable=None if show else True, **options)
