"""The level of a sweep's intervals, as its tables' columns say it: the preset's ``fit.confidence``
(the columns said 95% whatever it was), "CI" alone where the sweep sets it point by point, and
from a sweep's folder only a level that ``fit.confidence`` accepts (sweep.json is untrusted)."""

import json

import pytest
import yaml

from frictionlab.options import RunOptions
from frictionlab.runs.sweep import load_sweep, run_sweep
from frictionlab.tui.folders import read_sweep
from frictionlab.tui.sweepview import sweep_confidence, table_columns

from ..conftest import merge
from .conftest import SWEEP

TWO_POINTS = merge(SWEEP, {"realizations": 2, "fit": {"bootstrap": 20}, "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.7]}}}})


def test_the_columns_say_the_level_of_the_intervals():
    assert table_columns(["spectrum.params.hurst"], True, 0.9)[3:5] == ["a [90% CI]", "b [90% CI]"]
    assert table_columns(["spectrum.params.hurst"], True, 0.999)[3:5] == ["a [99.9% CI]", "b [99.9% CI]"]
    assert table_columns(["fit.confidence"], True, None)[3:5] == ["a [CI]", "b [CI]"]
    assert table_columns(["spectrum.params.hurst"], False, 0.9)[3:5] == ["a", "b"]


@pytest.mark.parametrize(("changes", "level"), [
    ({"fit": {"confidence": 0.8}}, 0.8),
    ({}, 0.95),  # unsaid: the default
    ({"sweep": {"parameters": {"fit.confidence": {"values": [0.9, 0.99]}}}}, None),  # a level a point
])  # fmt: skip
def test_a_sweeps_level_live_and_read_back_from_its_folder(tmp_path, registry, changes, level):
    preset = tmp_path / "sweep.yaml"
    preset.write_text(yaml.safe_dump(merge(TWO_POINTS, changes)))
    sweep = load_sweep(preset, registry=registry)
    assert sweep_confidence(sweep) == level
    run_sweep(sweep, tmp_path / "sw", RunOptions(workers=1), plot=False)
    assert read_sweep(tmp_path / "sw").confidence == level


@pytest.mark.parametrize("forged", ["high", 1.5, 0.0, None, [0.9], {"level": 0.9}])
def test_a_forged_level_in_sweep_json_is_no_level(tmp_path, registry, forged):
    preset = tmp_path / "sweep.yaml"
    preset.write_text(yaml.safe_dump(TWO_POINTS))
    run_sweep(load_sweep(preset, registry=registry), tmp_path / "sw", RunOptions(workers=1), plot=False)
    record = json.loads((tmp_path / "sw" / "sweep.json").read_text())
    record["base_preset"]["fit"] = {**record["base_preset"].get("fit", {}), "confidence": forged}
    (tmp_path / "sw" / "sweep.json").write_text(json.dumps(record))
    assert read_sweep(tmp_path / "sw").confidence is None
    record["base_preset"]["fit"] = forged  # in place of the section: a mapping leaves the level unsaid
    (tmp_path / "sw" / "sweep.json").write_text(json.dumps(record))
    assert read_sweep(tmp_path / "sw").confidence == (0.95 if isinstance(forged, dict) else None)
    record["base_preset"]["fit"] = {"confidence": 0.9, "bootstrap": "many"}  # another field forged: the level stands
    (tmp_path / "sw" / "sweep.json").write_text(json.dumps(record))
    assert read_sweep(tmp_path / "sw").confidence == 0.9
