"""The disc modes that ship with the package (``fivdisc/model/plate-modes.json``): the
ones solved afresh, stamped by today's ``plate.py``, and enough for every packaged
example, so that a first command after an install solves nothing."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import fivdisc
from fivdisc.model import mode_cache
from fivdisc.model import plate as plate_module

SEED = Path(mode_cache.__file__).with_name("plate-modes.json")


def _seed() -> dict:
    return json.loads(SEED.read_text())


def test_the_packaged_modes_are_stamped_by_todays_plate_source() -> None:
    """A change of plate.py without `python tools/seed_modes.py` would leave the packaged
    modes ignored (and the first use slow again): the stamp is the source's hash,
    computed here independently of mode_cache."""
    import hashlib

    source = Path(plate_module.__file__).read_bytes()
    assert _seed()["stamp"] == hashlib.sha256(source).hexdigest()[:16], (
        "plate.py changed: run `python tools/seed_modes.py`")


def test_the_packaged_modes_are_the_solved_ones(monkeypatch, tmp_path) -> None:
    """Each packaged mode (frequency parameter, coefficients, norm) and each packaged value
    at a track equals the one solved now, with no packaged or stored modes. Tolerance
    1e-12 relative: the modes are simple roots of a smooth determinant, found to the
    last bits, and only scipy's Bessel functions may differ from the version that wrote
    the file in the last bits."""
    monkeypatch.setenv("FIVDISC_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(mode_cache, "_seeded", dict)
    monkeypatch.setattr(mode_cache, "_modes", None)
    plate_module.clear_cache()
    modes = _seed()["modes"]
    checked = 0
    for key, value in modes.items():
        values = key.startswith("values ")
        args = ast.literal_eval(key.removeprefix("values "))
        a, b, nu, k, l = args[:5]
        mode = fivdisc.AnnularPlate(a, b, 0.002, 7800.0, 200e9, nu).mode(k, l)
        if values:
            for radii, stored in value.items():
                solved = mode.shape(np.array(ast.literal_eval(radii)), args[5])
                np.testing.assert_allclose(stored, solved, rtol=1e-12, atol=0)
                checked += 1
        else:
            beta, coefficients, _ = value
            np.testing.assert_allclose(beta, mode.beta, rtol=1e-12)
            np.testing.assert_allclose(coefficients, mode.coefficients, rtol=1e-12,
                                       atol=1e-12 * np.max(np.abs(coefficients)))
            checked += 1
    assert checked >= 8
    plate_module.clear_cache()


@pytest.mark.parametrize("case", ["fig10", "two-pads", "stribeck"])
def test_a_first_command_after_an_install_solves_no_mode(tmp_path, case) -> None:
    """With an empty user cache (a fresh machine), building a packaged example's model
    reads the packaged modes: no root finder or Bessel function is imported (a third of
    a second of a short command), nor scipy at all (the user's cache, whose stamp names
    scipy's version, is not read when every mode is packaged), and nothing is written to
    the user's cache."""
    code = (
        "import sys\n"
        "from fivdisc import examples\n"
        "from fivdisc.case import load_case\n"
        "from fivdisc.model.build import build_model\n"
        f"build_model(load_case(examples.path({case!r})))\n"
        "print(sorted(m for m in ('scipy', 'scipy.optimize', 'scipy.special') "
        "if m in sys.modules))\n"
    )
    source = str(Path(fivdisc.__file__).parents[1])
    env = {**os.environ, "FIVDISC_CACHE_DIR": str(tmp_path),
           "PYTHONPATH": os.pathsep.join([source, os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines()[-1] == "[]"
    assert not list(tmp_path.iterdir())
