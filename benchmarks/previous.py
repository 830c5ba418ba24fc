"""An earlier fivdisc, installed from a commit into its own virtual environment, to time
side by side with the working tree in one benchmark run.

``run_previous(commit, code)`` builds (once, cached under ``~/.cache/fivdisc-bench``) a
virtual environment with fivdisc installed from ``git archive COMMIT`` of this repository,
then runs ``code`` with that environment's Python and returns its standard output. The
first call takes a minute or two (install, then numba's compilation on first use).
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
    with tempfile.TemporaryFile() as archive:
        subprocess.run(["git", "archive", "--format=tar", full], cwd=REPO, check=True,
                       stdout=archive)
        archive.seek(0)
        with tarfile.open(fileobj=archive) as tar:
            tar.extractall(src, filter="data")
    subprocess.run([sys.executable, "-m", "venv", str(home / "venv")], check=True)
    subprocess.run([str(python), "-m", "pip", "install", "-q", str(src)], check=True)
    (home / "ready").touch()
    return python


def run_previous(commit: str, code: str) -> str:
    """Standard output of ``code`` run by fivdisc at ``commit``."""
    python = environment(commit)
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    return subprocess.run([str(python), "-c", code], check=True, capture_output=True,
                          text=True, env=env, cwd=tempfile.gettempdir()).stdout
