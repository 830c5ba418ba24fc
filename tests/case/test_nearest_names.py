"""Unknown keys anywhere get the nearest valid key (issue 13, item 7): case files,
``--x/--y/--curves`` and sweep files, even when the misspelling is far from every key."""

from __future__ import annotations

import pytest

from fivdisc.errors import nearest

from support.cli import run_cli


def test_nearest_compares_whole_keys_and_their_last_part():
    keys = ["friction.decay", "slider.normal_damping", "slider.mass"]
    assert nearest("dcay", keys) == "; did you mean 'friction.decay'?"
    assert nearest("slider.mas", keys) == "; did you mean 'slider.mass'?"
    assert nearest("zzz", keys).startswith("; did you mean '")  # however far
    # in capitals: the same key, not the one sharing most capital-blind letters
    keys = ["disc.modes", "speed.value", "speed.profile", "slider.mass"]
    assert nearest("SPEED.VALUE", keys) == "; did you mean 'speed.value'?"
    assert nearest("x", []) == ""


SWEEP = '[axes]\n"slider.mass" = [0.1]\n[reduce]\nkeep = ["separated"]\n'


@pytest.mark.parametrize(
    ("files", "args", "words"),
    [
        ({"c.toml": "[slider]\nrotation_damping = 1.0\n"}, ["simulate", "c.toml"],
         "unknown key 'slider.rotation_damping'; did you mean 'slider.rotational_damping'?"),
        ({}, ["stability", "--x", "dcay=0:1:3", "--y", "normal_damping=0:1:2"],
         "--x: unknown case key 'dcay'; did you mean 'friction.decay'? (every key, with its "
         "unit: fivdisc examples default)"),
        ({}, ["stability", "two-pads", "--x", "sliders.1.normal_dampin=0:1:2", "--y",
              "decay=0:1:2"], "did you mean 'sliders.1.normal_damping'?"),
        ({}, ["stability", "--x", "decay=0:1:2", "--y", "normal_damping=0:1:2", "--curves",
              "prelod=1,2"], "--curves: unknown case key 'prelod'; did you mean 'slider.preload'?"),
        ({"s.toml": SWEEP.replace("slider.mass", "slider.mas")}, ["sweep", "s.toml"],
         "axes: unknown case key 'slider.mas'; did you mean 'slider.mass'?"),
        ({"s.toml": SWEEP.replace("[axes]", "[axis]")}, ["sweep", "s.toml"],
         "unknown key 'axis'; did you mean 'axes'?"),
        ({"s.toml": SWEEP.replace("keep", "kep")}, ["sweep", "s.toml"],
         "unknown key 'reduce.kep'; did you mean 'reduce.keep'?"),
        ({"s.toml": SWEEP.replace('"separated"', '"seprated"')}, ["sweep", "s.toml"],
         "unknown reduction 'seprated'; did you mean 'separated'?"),
        ({"s.toml": "[base.slider]\nmas = 1.0\n" + SWEEP}, ["sweep", "s.toml"],
         "base: unknown key 'slider.mas'; did you mean 'slider.mass'?"),
        ({"s.toml": SWEEP + '[link]\n"simulation.duraton" = "slider.mass"\n'},
         ["sweep", "s.toml"], "unknown case key 'simulation.duraton'; did you mean "
         "'simulation.duration'?"),
    ],
)
def test_unknown_keys_name_the_nearest(tmp_path, monkeypatch, files, args, words):
    monkeypatch.chdir(tmp_path)
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    result = run_cli(args)
    assert result.exit_code == 2, result.output
    (line,) = result.stderr.strip().splitlines()
    assert words in line
