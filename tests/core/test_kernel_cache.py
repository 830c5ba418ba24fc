"""numba's cache never serves a stale kernel (issue 11, item 4): the cache entry of every
kernel is keyed to all the sources of ``fivdisc.core``, so editing one file
recompiles the kernels of the others that call into it."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import fivdisc

# switch._aux slices the work array at the offset that layout.work_rows computes: its
# own file stays the same when layout.py changes, which is the case numba's per-file
# stamp missed.
_PROBE = """
import json
import numpy as np
from fivdisc.core.cache import sources_hash
from fivdisc.core.switch import _aux
from fivdisc.model.layout import KernelModel
mdl = KernelModel(*(np.zeros((1, 1)) for _ in range(5)), np.zeros(1))
rows = _aux(mdl, np.zeros((40, 1))).shape[0]
stats = _aux.stats
print(json.dumps({"rows": rows, "hits": sum(stats.cache_hits.values()),
                  "misses": sum(stats.cache_misses.values()), "hash": sources_hash()}))
"""


def _probe(root: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["PYTHONPATH"] = str(root)
    out = subprocess.run([sys.executable, "-c", _PROBE], env=env, check=True,
                         capture_output=True, text=True, timeout=300).stdout
    return json.loads(out)


def test_an_edited_kernel_is_recompiled(tmp_path):
    package = Path(fivdisc.__file__).parent
    shutil.copytree(package, tmp_path / "fivdisc",
                    ignore=shutil.ignore_patterns("__pycache__"))
    layout = tmp_path / "fivdisc" / "_kernels" / "layout.py"

    first = _probe(tmp_path)
    assert (first["hits"], first["misses"]) == (0, 1)
    again = _probe(tmp_path)
    assert (again["hits"], again["misses"], again["rows"]) == (1, 0, first["rows"])

    # One row more for the auxiliary block's offset: _aux returns one row less.
    text = layout.read_text()
    old = "    aux = trig + 2 * n_sliders\n"
    assert text.count(old) == 1
    layout.write_text(text.replace(old, "    aux = trig + 2 * n_sliders + 1\n"))
    edited = _probe(tmp_path)
    assert edited["hash"] != first["hash"]
    assert (edited["hits"], edited["misses"]) == (0, 1)
    assert edited["rows"] == first["rows"] - 1

    # A comment is an edit too: numba cannot tell, so the kernels recompile.
    layout.write_text(layout.read_text() + "# edited\n")
    assert _probe(tmp_path)["misses"] == 1


def test_other_numba_code_keeps_numba_s_own_locators():
    from numba.core import caching

    from fivdisc.core import cache

    classes = cache._impl()._locator_classes
    assert classes[: len(cache.LOCATORS)] == list(cache.LOCATORS)
    assert classes[len(cache.LOCATORS):].count(caching.InTreeCacheLocator) == 1
    assert cache.InTreeLocator.from_function(_probe, __file__) is None
