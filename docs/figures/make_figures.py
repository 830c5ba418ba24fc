"""Regenerate the figures of the README and the docs (``docs/figures/*.png``).

    python docs/figures/make_figures.py bifurcation-speed   # about 2 min on 2 cores
    python docs/figures/make_figures.py fig10 fig27          # fivdisc reproduce's figures
    python docs/figures/make_figures.py bistable-three-pads  # about 4 min on 2 cores
    python docs/figures/make_figures.py all

Each figure is drawn by the command a user would run (``fivdisc bifurcation``,
``fivdisc reproduce``, ``fivdisc bistable``), so a figure in the README is what that
command gives today. The bifurcation diagram also prints the evidence its description in
the README rests on: per stretch of speeds, the exponents with their uncertainties, the
number of distinct section values, and the spectral verdict (:func:`fivdisc.classify`) of
the slider's angle at one speed of each stretch.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def bifurcation_speed(work: Path) -> None:
    from fivdisc import examples
    from fivdisc.plots import plot_bifurcation
    from fivdisc.sweep import load_sweep, open_sweep, run_sweep

    store = work / "bifurcation-speed.zarr"
    spec = load_sweep(examples.path("bifurcation-speed"))
    run_sweep(spec, store, progress=True)
    plot_bifurcation(store, HERE / "bifurcation-speed.png", name="bifurcation-speed")
    data = open_sweep(store)
    speed = data["speed.value"].values
    exponent = data["largest_lyapunov"].values
    error = data["largest_lyapunov_uncertainty"].values
    values = data[spec.sections[0].name].values
    print(f"{'speed':>7} {'lambda_1 [1/s]':>16} {'distinct maxima':>16}")
    for i in range(speed.size):
        finite = values[i][np.isfinite(values[i])]
        distinct = np.unique(np.round(finite, 1)).size  # to 0.1 N
        print(f"{speed[i]:7.3f} {exponent[i]:+8.2f} +- {error[i]:5.2f} {distinct:16d}")
    _spectra(spec.base, speed)


def _spectra(base, speeds: np.ndarray) -> None:
    """The spectral verdict on the slider's angle after the transient, at a few speeds."""
    from fivdisc import classify, find_peaks, simulate, spectrum

    print(f"\n{'speed':>7}  verdict on phi over 3-6 s")
    for value in (6.5, 9.5, 12.5, 14.0, 15.0, 18.0):
        case = base.replace({"speed.value": float(speeds[np.argmin(abs(speeds - value))])})
        peaks = find_peaks(spectrum(simulate(case), "phi", t0=3.0), fmax=2000.0)
        verdict = classify(peaks)
        lines = ", ".join(f"{f:.1f}" for f in verdict.frequencies)
        print(f"{case.speed.value:7.3f}  {verdict.kind} ({lines} Hz)")


def reproduced(figure: str, work: Path) -> None:
    """A figure of the paper as ``fivdisc reproduce --figures N`` draws it."""
    from fivdisc.paper import reproduce

    reproduce([int(figure[3:])], outdir=work / figure, progress=True)
    shutil.copyfile(work / figure / f"{figure}.png", HERE / f"{figure}.png")


def bistable_three_pads(work: Path) -> None:
    """Issue 36's three pads (``tests/data/three_pads_issue36.toml``) as ``fivdisc
    bistable`` maps them in (speed, disc damping), the box of the tutorial."""
    from click.testing import CliRunner

    from fivdisc.cli import cli

    case = HERE.parents[1] / "tests" / "data" / "three_pads_issue36.toml"
    res = CliRunner().invoke(cli, [
        "bistable", str(case), "--x", "speed.value=15:50", "--y",
        "disc.damping_ratio=0.002:0.004", "--points", "2", "--grid", "71:41",
        "-o", str(work / "region.nc"), "--figure", str(HERE / "bistable-three-pads.png"),
        "--no-progress"])
    print(res.output)
    if res.exit_code:
        sys.exit(res.exit_code)


def main(names: list[str]) -> None:
    known = ["bifurcation-speed", "fig10", "fig27", "bistable-three-pads"]
    names = known if names == ["all"] else names
    unknown = sorted(set(names) - set(known))
    if unknown or not names:
        sys.exit(f"usage: make_figures.py {{{' | '.join(known)} | all}} ...; unknown: {unknown}")
    with tempfile.TemporaryDirectory() as directory:
        for name in names:
            if name == "bifurcation-speed":
                bifurcation_speed(Path(directory))
            elif name == "bistable-three-pads":
                bistable_three_pads(Path(directory))
            else:
                reproduced(name, Path(directory))
            print(f"wrote {HERE / (name + '.png')}")


if __name__ == "__main__":
    main(sys.argv[1:])
