"""A spectrum whose short cut-off spans few pixels says so in the run's caveats: xi then
depends on the grid (docs/explanation/physics.md, "Pixels on the short cut-off")."""

import json

import pytest

import frictionlab
from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab.plugin import MIN_SHORT_CUTOFF_PIXELS
from frictionlab.plugin.registry import default_registry
from frictionlab.tui.fields import validation_of

from .cli.conftest import write_preset
from .conftest import SMALL_PRESET, merge

FAST = {"workers": 1, "progress": False}


def line(short_cutoff: float) -> dict:
    """SMALL_PRESET (spacing 1) with ``short_cutoff`` pixels on its short cut-off."""
    return merge(SMALL_PRESET, {"spectrum": {"params": {"short_cutoff": short_cutoff}}})


def surface(points: int) -> dict:
    """A surface of side 32 with a short cut-off of 2: ``points / 16`` pixels on it."""
    params = {"hurst": 0.5, "points": points, "length": 32.0, "long_cutoff": 16.0, "short_cutoff": 2.0}
    return merge(SMALL_PRESET, {"spectrum": {"name": "power-law-2d", "params": params},
                                "solver": {"name": "bem-halfspace", "params": {"youngs_modulus": 1.0}}})  # fmt: skip


def test_the_thresholds_are_the_measured_ones_and_the_exact_study_shares_the_surfaces():
    from frictionlab.exact3d.plan import MIN_PIXELS_QUOTED

    assert MIN_SHORT_CUTOFF_PIXELS == {1: 8, 2: 16} and MIN_PIXELS_QUOTED == MIN_SHORT_CUTOFF_PIXELS[2]


@pytest.mark.parametrize("pixels", [2.0, 4.0])
def test_a_line_with_few_pixels_on_its_short_cutoff_carries_the_caveat_with_its_own_numbers(tmp_path, capsys, pixels):
    preset = write_preset(tmp_path, line(pixels))
    assert main(["run", str(preset), "--out", str(tmp_path / "run"), "--workers", "1", "--no-plot", "--quiet"]) == 0
    said = f"the short cut-off spans {pixels:g} pixels"
    printed = [text for text in capsys.readouterr().out.splitlines() if said in text]
    assert printed and printed[0].strip().startswith("caveat: ") and "put 8 or more pixels on it" in printed[0]
    caveats = json.loads((tmp_path / "run" / "summary.json").read_text())["caveats"]
    assert [c for c in caveats if said in c] == [printed[0].strip().removeprefix("caveat: ")]


def test_the_default_line_and_the_built_in_presets_with_enough_pixels_carry_none(tmp_path):
    result = frictionlab.run(SMALL_PRESET, out=tmp_path / "default", plot=False, **FAST)  # short cut-off 10 pixels
    assert not [c for c in result.caveats if "short cut-off" in c]
    assert not [c for c in frictionlab.run(line(8.0), **FAST).caveats if "short cut-off" in c]
    for name in ("quickstart", "benad2012-fig2", "exact3d-h05", "exact3d-h08"):  # 10 pixels on lines, 32 on surfaces
        assert frictionlab.validate(name)["caveats"] == [], name


def test_validate_and_the_tui_say_it_of_a_surface_before_it_runs(tmp_path, capsys):
    preset = write_preset(tmp_path, surface(64))  # 4 pixels
    assert main(["validate", str(preset)]) == ExitCode.OK
    out = capsys.readouterr().out
    assert "caveat: the short cut-off spans 4 pixels" in out and "put 16 or more pixels on it" in out
    assert main(["validate", str(preset), "--json"]) == ExitCode.OK
    (caveat,) = json.loads(capsys.readouterr().out)["presets"][0]["caveats"]
    assert caveat.startswith("the short cut-off spans 4 pixels")
    problems, shown = validation_of(surface(64), default_registry())
    assert problems == [] and f"caveat: {caveat}" in shown.splitlines()
    assert validation_of(surface(256), default_registry()) == ([], "")  # 16 pixels: enough


def test_a_surface_run_lists_it_beside_its_own_caveats():
    result = frictionlab.run(merge(surface(32), {"realizations": 2, "loading": {"steps": 3}}), **FAST)  # 2 pixels
    assert [c for c in result.caveats if c.startswith("the short cut-off spans 2 pixels")]
