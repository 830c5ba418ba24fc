"""Progress of long computations on a terminal: a tqdm bar on stderr, silent when stderr
is not a terminal or when not asked for."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


@contextmanager
def progress_bar(show: bool, **options: Any) -> Iterator[Any]:
    """A :class:`tqdm.tqdm` bar on stderr when `show` and stderr is a terminal, else one
    that draws nothing (its ``update`` and ``set_postfix_str`` still work).

    Parameters
    ----------
    show
        False: draw nothing.
    **options
        Passed to tqdm (``total``, ``desc``, ``unit``, ...).
    """
    from tqdm import tqdm

    live = show and sys.stderr.isatty()
    bar = tqdm(file=sys.stderr, disable=not live, leave=False, dynamic_ncols=True, **options)
    try:
        yield bar
    finally:
        bar.close()
