"""An earlier fivdisc, installed from a commit into its own virtual environment, to time
side by side with the working tree in one benchmark run.

``run_previous(commit, code)`` builds (once, cached under ``~/.cache/fivdisc-bench``) a
virtual environment with fivdisc installed from ``git archive COMMIT`` of this repository,
then runs ``code`` with that environment's Python and returns its standard output. The
first call takes a minute or two (the install; for a commit whose kernel was numba, also
numba's compilation on first use).

``environment(commit)`` is that environment's Python, for the benchmarks that run an
earlier commit in processes of its own (start-up, first use, the earlier store checks of
``bench_store``) because it needs a library the working tree no longer has: its kernel
in numba (``LAST_NUMBA`` and before), which its package imports. They run it without
``PYTHONPATH`` (``without_pythonpath``): the same interpreter (a virtual environment of
the same Python) with the same libraries, pinned to the versions this interpreter has
where the commit allows them, plus numba (``versions`` prints them; environments built
before the pinning have the versions the package indexes offered then: for
``LAST_NUMBA`` numpy, scipy and pydantic are the working tree's). ``environment(commit,
extras=("distributed",))`` also installs an extra's requirements into it (once), pinned
likewise.

``source_tree(commit)`` only unpacks the commit's ``src`` (cached in the same place), for
a baseline that needs nothing the working tree's libraries lack (``bench_sweep_pool``):
it runs with this interpreter and its libraries, on ``PYTHONPATH``, so that only
fivdisc's own code differs between the two.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tarfile
import tempfile
import tomllib
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
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


def environment(commit: str, extras: Iterable[str] = ()) -> Path:
    """Python executable of a virtual environment with fivdisc at ``commit``, and the
    requirements of its optional ``extras`` (e.g. ``"distributed"``, which ``fivdisc
    sweep`` needs)."""
    full = _resolve(commit)
    home = CACHE / full
    python = home / "venv" / "bin" / "python"
    if not (home / "ready").exists():
        home.mkdir(parents=True, exist_ok=True)
        src = home / "src"
        _unpack(full, src)
        subprocess.run([sys.executable, "-m", "venv", str(home / "venv")], check=True)
        with _constraints() as pins:
            pinned = subprocess.run([str(python), "-m", "pip", "install", "-q", "-c", pins,
                                     str(src)])
        if pinned.returncode:
            print(f"fivdisc at {commit} cannot have this interpreter's library versions; "
                  "installing it with the newest it allows", file=sys.stderr)
            subprocess.run([str(python), "-m", "pip", "install", "-q", str(src)], check=True)
        (home / "ready").touch()
    for extra in extras:
        if not (home / f"ready-{extra}").exists():
            _install_extra(home, python, extra)
            (home / f"ready-{extra}").touch()
    return python


def _extra_requirements(pyproject: Path, extra: str) -> list[str]:
    """The requirements of fivdisc's optional ``extra`` in ``pyproject``, the package's own
    extras it names (``fivdisc[plot,distributed]``) expanded."""
    project = tomllib.loads(pyproject.read_text())["project"]
    found: list[str] = []
    for requirement in project.get("optional-dependencies", {})[extra]:
        if requirement.replace(" ", "").startswith(project["name"] + "["):
            names = requirement.split("[", 1)[1].split("]", 1)[0].split(",")
            for name in names:
                found += _extra_requirements(pyproject, name.strip())
        else:
            found.append(requirement)
    return found


@contextmanager
def _constraints() -> Iterator[str]:
    """A pip constraints file: the version of every library this interpreter has
    (``pip freeze``, fivdisc left out)."""
    frozen = subprocess.run([sys.executable, "-m", "pip", "freeze"], check=True,
                            capture_output=True, text=True).stdout.splitlines()
    pins = [line for line in frozen if "==" in line and not line.startswith(("-", "#"))
            and not line.lower().startswith("fivdisc")]
    with tempfile.NamedTemporaryFile("w", suffix=".txt") as constraints:
        constraints.write("\n".join(pins) + "\n")
        constraints.flush()
        yield constraints.name


def _install_extra(home: Path, python: Path, extra: str) -> None:
    """Install the requirements of ``extra`` (not fivdisc again: that would replace the
    installed copy and its numba cache), at the versions this interpreter has."""
    requirements = _extra_requirements(home / "src" / "pyproject.toml", extra)
    with _constraints() as pins:
        subprocess.run([str(python), "-m", "pip", "install", "-q", "-c", pins,
                        *requirements], check=True)


def without_pythonpath() -> dict[str, str]:
    """This process's environment variables without ``PYTHONPATH``: set to a clone's
    ``src`` (to time it), it would put today's fivdisc before an earlier commit's
    installed one."""
    return {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}


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


_VERSIONS = ("import importlib.metadata as m, sys\n"
             "for name in sys.argv[1:]:\n"
             "    try: print(name, m.version(name))\n"
             "    except m.PackageNotFoundError: print(name, '-')")


def versions(python: str | Path, names: Iterable[str] = ("numpy", "scipy", "pydantic",
                                                         "numba")) -> str:
    """``name version`` of each library installed for ``python``, on one line ('-' where
    it has none)."""
    out = subprocess.run([str(python), "-c", _VERSIONS, *names], check=True,
                         capture_output=True, text=True, env=without_pythonpath()).stdout
    return ", ".join(out.split("\n")[:-1])


def run_previous(commit: str, code: str) -> str:
    """Standard output of ``code`` run by fivdisc at ``commit``."""
    python = environment(commit)
    env = without_pythonpath()
    env.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    out = subprocess.run([str(python), "-c", code], capture_output=True, text=True, env=env,
                         cwd=tempfile.gettempdir())
    if out.returncode != 0:
        raise SystemExit(f"fivdisc at {commit} failed ({out.returncode}):\n{out.stderr}")
    return out.stdout
