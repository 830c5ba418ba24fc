"""The packaged examples, the CASE resolver and ``fivdisc examples``.

These run against the installed package; ``.ci/check-package`` repeats the commands from a
wheel installed into a fresh virtual environment, away from the source tree.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest
import xarray as xr

from fivdisc import examples, load_case
from fivdisc.errors import FivdiscError
from fivdisc.sweep import load_sweep

from support.cli import run_cli


def _run(*argv: str):
    return run_cli(list(argv))


def test_every_example_loads_and_has_a_one_line_description():
    listing = examples.available()
    assert set(listing) == {p.stem for p in examples.DIRECTORY.glob("*.toml")}
    assert {"default", "fig10", "fig27_base", "sweep_fig27", "bifurcation-speed"} <= set(listing)
    for name, description in listing.items():
        assert description.endswith(".") and "\n" not in description, name
        assert len(description) <= 120, (name, description)
        # A sweep file has axes, which no case file has.
        if "axes" in tomllib.loads(examples.path(name).read_text(encoding="utf-8")):
            load_sweep(examples.path(name))
        else:
            load_case(examples.path(name))


def test_resolve_prefers_an_existing_file(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "fig10").write_text("[slider]\nmass = 0.2\n")
    assert examples.resolve("fig10") == Path("fig10")
    assert examples.resolve("fig10.toml") == examples.DIRECTORY / "fig10.toml"
    assert examples.resolve("fig04") == examples.path("fig04.toml")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("fig1", r"^'fig1' is neither a file nor a packaged example: nearest: fig10, fig11"),
        ("zzz", r"must be one of bifurcation-speed, damped-disc, default, fig03a, "
                r".*sweep_fig27, two-pads "
                r"\(`fivdisc examples`"),
        ("nowhere/fig10.toml", r"^file not found: nowhere/fig10.toml$"),
    ],
)
def test_resolve_errors(text, message, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(FivdiscError, match=message):
        examples.resolve(text)


def test_resolve_refuses_a_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "fig10").mkdir()
    with pytest.raises(FivdiscError, match=r"'fig10' is a directory: must be a TOML file"):
        examples.resolve("fig10")


def test_examples_command_lists_and_prints():
    listed = _run("examples")
    assert listed.exit_code == 0, listed.output
    lines = listed.output.splitlines()
    assert [line.split()[0] for line in lines] == list(examples.available())
    assert any(line.startswith("fig10 ") and "decelerating disc" in line for line in lines)
    shown = _run("examples", "fig10")
    assert shown.exit_code == 0
    assert shown.output == examples.path("fig10").read_text()
    unknown = _run("examples", "fig99")
    assert unknown.exit_code == 2
    assert unknown.output.startswith("error: 'fig99' is not a packaged example: nearest:")
    assert unknown.output.count("\n") == 1


def test_every_case_command_takes_an_example_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    modes = _run("modes", "fig10", "--json")
    assert modes.exit_code == 0 and '"frequency_hz"' in modes.output
    stability = _run("stability", "fig08")
    assert stability.exit_code == 0 and "unstable" in stability.output
    # Without -o, an example's result goes to the working directory, not the package.
    simulated = _run("simulate", "default", "--no-progress")
    assert simulated.exit_code == 0, simulated.output
    assert (tmp_path / "default.nc").exists()
    with xr.open_dataset(tmp_path / "default.nc") as ds:
        assert ds.attrs["status"] == "success"
    assert not (examples.DIRECTORY / "default.nc").exists()


@pytest.mark.parametrize(
    "argv",
    [
        ("simulate", "fig1"),
        ("modes", "fig1"),
        ("stability", "fig1"),
        ("sweep", "fig1"),
        ("separation-map", "--base", "fig1"),
    ],
)
def test_unknown_example_is_one_line(argv, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = _run(*argv)
    assert result.exit_code == 2
    assert result.output.startswith("error: 'fig1' is neither a file nor a packaged example")
    assert result.output.count("\n") == 1 and "Traceback" not in result.output


def _is_sweep(text: str) -> bool:
    return "axes" in tomllib.loads(text)


def _effective(text: str):
    """What an example makes run: the case, or the sweep's base, axes, reductions and the
    measurement window and interval of its Lyapunov exponent."""
    if not _is_sweep(text):
        return load_case_text(text)
    from fivdisc.analysis.exponents import DEFAULT_INTERVAL

    spec = load_sweep_text(text)
    lyap = None
    if spec.lyapunov is not None:
        transient, duration = spec.lyapunov.window(spec.base)
        interval = spec.lyapunov.interval
        lyap = (transient, duration,
                min(DEFAULT_INTERVAL, duration) if interval is None else interval)
    return spec.base, spec.axes, spec.keep, spec.sections, lyap


def load_case_text(text: str):
    from fivdisc import Case

    return Case.from_toml(text)


def load_sweep_text(text: str):
    import tempfile

    with tempfile.TemporaryDirectory() as directory:
        path = Path(directory) / "sweep.toml"
        path.write_text(text)
        base = tomllib.loads(text).get("base")
        if isinstance(base, str):  # a case file next to the example
            (Path(directory) / base).write_text(examples.path(Path(base).stem).read_text())
        return load_sweep(path)


@pytest.mark.parametrize("name", sorted(examples.available()))
def test_examples_are_formatted_for_a_reader(name):
    """Issue 27, item 7: no array written one number per line, no note a reader cannot
    act on."""
    text = examples.path(name).read_text(encoding="utf-8")
    for line in text.splitlines():
        assert not line.strip().rstrip(",").replace(".", "").replace("-", "").isdigit(), (
            name, line)
    assert "edit the code" not in text


@pytest.mark.parametrize("name", sorted(examples.available()))
def test_comments_calling_a_value_the_default_are_true(name):
    """Issue 27, item 7: a key whose comment says it is the default can be left out
    without changing what runs (a case's value, a sweep's resolved Lyapunov window and
    interval); one under a comment saying "these are the defaults" as well."""
    text = examples.path(name).read_text(encoding="utf-8")
    lines = text.splitlines()
    whole = _effective(text)
    under_defaults = False
    checked = 0
    for i, line in enumerate(lines):
        code, _, comment = line.partition("#")
        if not line.strip():
            under_defaults = False  # a blank line ends what a comment introduced
        if not code.strip():
            under_defaults = under_defaults or "these are the defaults" in comment
            continue
        if code.strip().startswith("["):
            continue
        # "default" opening a clause of the comment claims that the value is the default.
        if re.search(r"(^|[:;,(])\s*default\b", comment.strip()) or under_defaults:
            without = "\n".join(lines[:i] + lines[i + 1:])
            assert _effective(without) == whole, (name, line)
            checked += 1
    if name == "bifurcation-speed":
        assert checked  # the test reads the comments it is meant to
