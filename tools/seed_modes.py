"""Write the disc modes that ship with fivdisc: ``src/fivdisc/model/plate-modes.json``.

Run ``python tools/seed_modes.py`` after a change of ``src/fivdisc/model/plate.py`` (the
file's stamp is a hash of that source: until it is rewritten, the packaged modes are
ignored and ``tests/model/test_mode_seed.py`` fails). Every packaged example case's model
is built in a fresh process with an empty user cache and no packaged modes, so that
every mode and every value at a slider's track or probe is solved; what those processes
stored is written with the new stamp.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

SEED = Path(__file__).resolve().parents[1] / "src" / "fivdisc" / "model" / "plate-modes.json"

_BUILD = """
import tomllib
from fivdisc import examples
from fivdisc.case import load_case
from fivdisc.model.build import build_model
for name in examples.available():
    if "axes" not in tomllib.loads(examples.path(name).read_text()):
        build_model(load_case(examples.path(name)))
"""


def main() -> None:
    SEED.unlink(missing_ok=True)
    with tempfile.TemporaryDirectory() as cache:
        subprocess.run([sys.executable, "-c", _BUILD], check=True,
                       env={**os.environ, "FIVDISC_CACHE_DIR": cache})
        modes = json.loads((Path(cache) / "fivdisc-plate-modes.json").read_text())["modes"]
    from fivdisc.model.mode_cache import source_stamp

    SEED.write_text(json.dumps({"stamp": source_stamp(), "modes": modes}, sort_keys=True))
    print(f"{SEED}: {len(modes)} entries")


if __name__ == "__main__":
    main()
