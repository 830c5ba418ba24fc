"""An earlier fivdisc, installed from a commit into its own virtual environment, to time
side by side with the working tree in one benchmark run.

``run_previous(commit, code)`` builds (once, cached under ``~/.cache/fivdisc-bench``) a
virtual environment with fivdisc installed from ``git archive COMMIT`` of this repository,
then runs ``code`` with that environment's Python and returns its standard output. The
first call takes a minute or two (the install; for a commit whose kernel was numba, also
numba's compilation on first use).

``source_tree(commit)`` only unpacks the commit's ``src`` (cached in the same place), for
the benchmarks of whole processes (start-up, first use), which run it with the same
interpreter and libraries as the working tree, on ``PYTHONPATH``: then only fivdisc's
own code differs between the two.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
CACHE = Path(os.environ.get("FIVDISC_BENCH_CACHE", Path.home() / ".cache" / "fivdisc-bench"))

# main before the model family (several sliders, damping, friction laws) landed: the
# kernel the single-slider figures are compared against.
BEFORE_FAMILY = "ba8c35d"
# The last kernel in numba (issue 37 ported it to the compiled C++ core): main before the
# layer folders; the numba kernel was only moved after it.
LAST_NUMBA = "a96e870"


def _resolve(commit: str) -> str:
    return subprocess.run(["git", "rev-parse", commit], cwd=REPO, check=True,
                          capture_output=True, text=True).stdout.strip()


def environment(commit: str) -> Path:
    """Python executable of a virtual environment with fivdisc at ``commit``."""
    full = _resolve(commit)
    home = CACHE / full
    python = home / "venv" / "bin" / "python"
    if (home / "ready").exists():
        return python
    home.mkdir(parents=True, exist_ok=True)
    src = home / "src"
    _unpack(full, src)
    subprocess.run([sys.executable, "-m", "venv", str(home / "venv")], check=True)
    subprocess.run([str(python), "-m", "pip", "install", "-q", str(src)], check=True)
    (home / "ready").touch()
    return python


def _unpack(full: str, dest: Path, *paths: str) -> None:
    with tempfile.TemporaryFile() as archive:
        subprocess.run(["git", "archive", "--format=tar", full, *paths], cwd=REPO,
                       check=True, stdout=archive)
        archive.seek(0)
        with tarfile.open(fileobj=archive) as tar:
            tar.extractall(dest, filter="data")


def source_tree(commit: str) -> Path:
    """The directory holding the package ``fivdisc`` at ``commit`` (to put on
    ``PYTHONPATH``), unpacked once."""
    full = _resolve(commit)
    home = CACHE / f"{full}-src"
    if not (home / "ready").exists():
        home.mkdir(parents=True, exist_ok=True)
        _unpack(full, home, "src")
        (home / "ready").touch()
    return home / "src"


def run_previous(commit: str, code: str) -> str:
    """Standard output of ``code`` run by fivdisc at ``commit``."""
    python = environment(commit)
    # Without PYTHONPATH: set to a clone's src (to time it), it would put today's fivdisc
    # before the one installed at `commit`.
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    env.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    return subprocess.run([str(python), "-c", code], check=True, capture_output=True,
                          text=True, env=env, cwd=tempfile.gettempdir()).stdout
