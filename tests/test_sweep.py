"""Sweeps: points equal separate runs, grid/zip expansion, bad specs, CLI exit codes."""

import copy
import json
import threading

import numpy as np
import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import PresetError
from frictionlab.plugin.hookspecs import hookimpl
from frictionlab.preset import load_scene
from frictionlab.runs.runner import run_to_folder
from frictionlab.plugin.listeners import SweepListener
from frictionlab.preset import apply_overrides, yaml_scalar
from frictionlab.runs.sweep import load_sweep, plan_sweep, run_sweep
from frictionlab.runs.sweepfiles import read_table
from frictionlab.options import RunOptions

from .conftest import SMALL_PRESET


def sweep_preset(parameters, mode="grid", **changes):
    data = copy.deepcopy(SMALL_PRESET)
    data.update(realizations=6, fit={"bootstrap": 50}, output={"plot": False})
    data.update(changes)
    data["sweep"] = {"mode": mode, "parameters": parameters}
    return data


def write(tmp_path, data, name="sweep.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_points_equal_separate_runs_with_the_same_seed(tmp_path, registry):
    data = sweep_preset({"spectrum.params.hurst": {"values": [0.5, 0.9]}, "loading.stop": {"values": [5.0, 50.0]}})
    path = write(tmp_path, data)
    sweep = load_sweep(path, registry=registry)
    heard = Heard()
    outcome = run_sweep(sweep, tmp_path / "out", RunOptions(workers=1), listeners=[heard], plot=False)
    assert outcome.status == "completed" and len(outcome.results) == 4
    for result in outcome.results:
        # the documented way to rerun one point: the preset, sweep off, the point's --set options
        alone = load_scene(path, ["sweep=null", *result.point.assignments], registry=registry)
        single, _ = run_to_folder(alone, tmp_path / f"alone-{result.point.number}", RunOptions(workers=2))
        assert np.array_equal(heard.curves[result.point.number], single.per_realization["xi"])
        assert (result.outcome.fit.a, result.outcome.fit.b) == (single.fit.a, single.fit.b)
        assert result.outcome.fit.a_ci == single.fit.a_ci
        stored = np.load(result.folder / "realizations.npz")
        assert np.array_equal(stored["xi"], single.per_realization["xi"])
    # the swept values really reached the scenes
    assert [r.point.scene.spectrum.params.hurst for r in outcome.results] == [0.5, 0.5, 0.9, 0.9]
    assert [r.point.scene.loads[-1] for r in outcome.results] == [5.0, 50.0, 5.0, 50.0]


class Heard(SweepListener):
    """Each point's per-realization xi, as its listeners hear the point finish."""

    def __init__(self):
        self.curves = {}

    def point_finished(self, sweep, point, result):
        self.curves[point.number] = result.outcome.per_realization["xi"]


def test_a_sweep_holds_its_points_without_their_realizations_curves(tmp_path, registry):
    """Held to its end, each realization's curves would grow a sweep's memory at every point
    (realizations x load steps x curves: megabytes a point); they are in each point's folder."""
    data = sweep_preset({"spectrum.params.hurst": {"values": [0.6, 0.8]}}, realizations=5)
    heard = Heard()
    outcome = run_sweep(plan_sweep(data, registry=registry), tmp_path / "out", RunOptions(workers=1), listeners=[heard])
    steps = data["loading"]["steps"]
    for result in outcome.results:
        assert heard.curves[result.point.number].shape == (5, steps)  # the listeners heard the point whole
        assert result.outcome.per_realization == {}
        assert np.load(result.folder / "realizations.npz")["xi"].shape == (5, steps)
        assert result.outcome.xi.shape == (steps,) and result.fit is not None
        assert isinstance(result.outcome.caveats, list)  # read without the curves


def test_table_and_json_hold_each_points_fit(tmp_path, registry):
    data = sweep_preset({"spectrum.params.hurst": {"values": [0.6, 0.8]}})
    sweep = plan_sweep(data, registry=registry)
    out = tmp_path / "out"
    run_sweep(sweep, out, RunOptions(workers=1))
    rows = read_table(out / "sweep.csv")
    summary = json.loads((out / "sweep.json").read_text())
    assert [r["spectrum.params.hurst"] for r in rows] == ["0.6", "0.8"]
    for row, point in zip(rows, summary["points"], strict=True):
        run = json.loads((out / row["folder"] / "summary.json").read_text())
        assert float(row["a"]) == run["fit"]["a"] and float(row["b_hi"]) == run["fit"]["b_ci"][1]
        assert float(row["contact_last"]) == run["contact_count_at_last_load"]
        assert row["status"] == "completed" and point["set"] == [f"spectrum.params.hurst={row['spectrum.params.hurst']}"]
    assert (out / "sweep.png").stat().st_size > 0


def test_grid_is_the_product_and_zip_pairs_the_lists(registry):
    params = {"spectrum.params.hurst": {"values": [0.4, 0.6, 0.8]}, "loading.stop": {"start": 5, "stop": 50, "num": 3}}
    grid = plan_sweep(sweep_preset(params), registry=registry)
    assert len(grid.points) == 9
    assert {tuple(p.values.values()) for p in grid.points} == {(h, s) for h in (0.4, 0.6, 0.8) for s in (5, 27.5, 50)}
    zipped = plan_sweep(sweep_preset(params, mode="zip"), registry=registry)
    assert [tuple(p.values.values()) for p in zipped.points] == [(0.4, 5), (0.6, 27.5), (0.8, 50)]
    assert [p.folder_name for p in zipped.points] == ["01-hurst-0.4_stop-5", "02-hurst-0.6_stop-27.5", "03-hurst-0.8_stop-50"]


def test_ranges_linear_and_log(registry):
    params = {"loading.stop": {"start": 10, "stop": 1000, "num": 3, "spacing": "log"},
              "spectrum.params.hurst": {"start": 0.3, "stop": 1.0, "num": 8}}  # fmt: skip
    sweep = plan_sweep(sweep_preset(params, mode="grid"), registry=registry)
    stops = sorted({p.values["loading.stop"] for p in sweep.points})
    hursts = sorted({p.values["spectrum.params.hurst"] for p in sweep.points})
    assert stops == [10, 100, 1000] and all(isinstance(s, int) for s in stops)
    assert hursts == [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]


def test_a_range_of_long_whole_numbers_keeps_every_digit(registry):
    """Range values were rounded to 12 significant digits: seeds 1700000000000 .. 1700000000002 gave
    1700000000000 three times (refused as a value given twice), 1700000000001 .. 1700000012345 ran
    seeds other than those written; ends past 2**53 were floats first."""
    params = {"seed": {"start": 1700000000000, "stop": 1700000000002, "num": 3}}
    sweep = plan_sweep(sweep_preset(params), registry=registry)
    assert [p.values["seed"] for p in sweep.points] == [1700000000000, 1700000000001, 1700000000002]
    params = {"seed": {"start": 1700000000001, "stop": 1700000012345, "num": 2},
              "spectrum.params.hurst": {"values": [0.5]}}  # fmt: skip
    assert [p.values["seed"] for p in plan_sweep(sweep_preset(params), registry=registry).points] == [
        1700000000001, 1700000012345]
    big = 2**64 + 1
    params = {"seed": {"start": big, "stop": big + 4, "num": 3, "spacing": "log"}}
    seeds = [p.values["seed"] for p in plan_sweep(sweep_preset(params), registry=registry).points]
    assert seeds[0] == big and seeds[-1] == big + 4 and all(isinstance(s, int) for s in seeds)


@pytest.mark.parametrize("value", [0.3, 1e-05, 2.5e-07, 1e20, 10000.0, 3, True, None, "spectral", "0.5", -0.0])
def test_yaml_scalar_reads_back_as_the_same_value(value):
    text = yaml_scalar(value)
    assert yaml.safe_load(text) == value and type(yaml.safe_load(text)) is type(value)


def test_yaml_scalar_spells_text_that_looks_like_a_number_so_set_reads_text():
    for value in ("1e5", "2.5E-3", "1e400"):
        assert apply_overrides({}, [f"description={yaml_scalar(value)}"]) == {"description": value}


def test_swept_nan_and_infinities_are_refused_by_the_field_not_an_internal_error(tmp_path, capsys):
    preset = write(tmp_path, sweep_preset({"loading.start": {"values": [1.0, float("nan"), float("inf"), -float("inf")]}}))
    assert main(["validate", str(preset)]) == 2
    err = capsys.readouterr().err
    assert "sweep point 2 (loading.start=nan): loading.start: must be a finite number, got nan" in err
    assert "sweep point 3 (loading.start=inf): loading.start: must be a finite number, got inf" in err
    assert "sweep point 4 (loading.start=-inf): loading.start: must be a finite number, got -inf" in err
    assert "internal error" not in err and "sweep point 1" not in err


def test_swept_text_that_looks_like_a_number_stays_text(registry):
    swept = {"description": {"values": ["1e5", "plain"]}, "seed": {"values": [1, 2]}}  # a description alone: refused
    sweep = plan_sweep(sweep_preset(swept, mode="zip"), registry=registry)
    assert [p.scene.preset.description for p in sweep.points] == ["1e5", "plain"]


BAD_SPECS = [
    ({"spectrum.params.hurts": {"values": [0.5]}},
     "sweep.parameters.spectrum.params.hurts: the spectrum plugin has no parameter 'hurts'"),
    ({"loadin.stop": {"values": [5]}}, "sweep.parameters.loadin.stop: the preset has no field 'loadin'"),
    ({"loading": {"values": [5]}}, "sweep.parameters.loading: loading is a section"),
    ({"seed.x": {"values": [5]}}, "sweep.parameters.seed.x: seed is a value, not a section"),
    ({"sweep.mode": {"values": ["zip"]}}, "sweep.parameters.sweep.mode: a sweep cannot sweep its own sweep section"),
    ({"seed": {"values": []}}, "sweep.parameters.seed: values must not be empty"),
    ({"loading.stop": {"start": 1, "stop": 5, "num": 0}}, "sweep.parameters.loading.stop.num: must be >= 1, got 0"),
    ({"loading.stop": {"start": 0, "stop": 5, "num": 3, "spacing": "log"}},
     "a log range needs start > 0 and stop > 0. Got start=0, stop=5 instead"),  # as written
    ({"loading.stop": {"values": [5], "start": 1, "stop": 5, "num": 2}},
     "give either values or a range (start, stop, num), not both"),
    ({"loading.stop": {"start": 1, "stop": 5}}, "a range needs start, stop and num; missing: num"),
    ({"loading.stop": {}}, "give values: [...] or a range start, stop, num"),
    # a point twice runs the same ensemble twice, as loads from a value to itself are refused
    ({"seed": {"values": [1, 2, 1]}}, "sweep: seed: its values give 1 twice (values 1 and 3): each point with it would run twice"),
    ({"loading.stop": {"start": 5, "stop": 5, "num": 3}}, "loading.stop: its range (start, stop, num) gives 5 twice (values 1 and 2)"),
    # a range of one value made its start alone, its stop dropped without a word (linspace of num 1)
    ({"loading.stop": {"start": 5, "stop": 9, "num": 1}}, "sweep.parameters.loading.stop: a range of num 1 holds its start "
     "(5) only, never its stop (9): give num >= 2 for both ends, or values: [5] for one value"),
    # pydantic's own words: 'dictionary should have at least 1 item after validation, not 0'
    ({}, "sweep.parameters: must hold at least 1 item, got {}"),
    # spacing: log beside values was ignored without a word: the values ran as listed
    ({"loading.stop": {"values": [1, 5], "spacing": "log"}}, "sweep.parameters.loading.stop: spacing: log spaces a range "
     "(start, stop, num); values are taken as listed: drop spacing, or give a range instead of values"),
]  # fmt: skip


@pytest.mark.parametrize(("parameters", "message"), BAD_SPECS)
def test_bad_specs_name_the_field(parameters, message, registry):
    with pytest.raises(PresetError) as info:
        plan_sweep(sweep_preset(parameters), registry=registry)
    assert message in str(info.value)


def test_zip_lengths_must_match(registry):
    params = {"seed": {"values": [1, 2]}, "loading.stop": {"values": [5, 6, 7]}}
    with pytest.raises(PresetError) as info:
        plan_sweep(sweep_preset(params, mode="zip"), registry=registry)
    assert "mode zip needs the same number of values for every parameter. Got seed: 2, loading.stop: 3" in str(info.value)
    assert len(plan_sweep(sweep_preset(params), registry=registry).points) == 6  # fine as a grid


def test_a_zip_point_twice_is_refused_and_a_value_repeated_beside_others_is_not(registry):
    """Before, [1, 1] with [4, 4] ran one ensemble twice, and a grid with a value listed twice too."""
    twice = {"seed": {"values": [1, 2, 1]}, "realizations": {"values": [4, 5, 4]}}
    with pytest.raises(PresetError) as info:
        plan_sweep(sweep_preset(twice, mode="zip"), registry=registry)
    assert "mode zip: points 1 and 3 set the same values (seed=1, realizations=4): the same ensemble would run twice" in str(info.value)
    paired = {"seed": {"values": [1, 2, 1]}, "realizations": {"values": [4, 4, 5]}}
    assert len(plan_sweep(sweep_preset(paired, mode="zip"), registry=registry).points) == 3


def test_one_problem_of_many_points_is_said_for_three_then_once_for_the_rest(registry):
    """A log range over a whole-number field (40 values, 39 of them fractions) printed a line for
    each point, differing only in its numbers; each problem is now said for three points, then
    once for the rest, and another problem (a realization count of 0) apart."""
    parameters = {"spectrum.params.points": {"start": 100, "stop": 4000, "num": 40, "spacing": "log"},
                  "realizations": {"values": [2, 0]}}  # fmt: skip
    with pytest.raises(PresetError) as info:
        plan_sweep(sweep_preset(parameters), registry=registry)
    problems = info.value.problems
    assert problems[0] == "sweep point 2 (spectrum.params.points=100, realizations=0): realizations: must be >= 1, got 0"
    assert sum("must be a whole number, got" in p for p in problems) == 3
    assert sum("must be >= 1, got 0" in p for p in problems) == 3
    assert problems[-2:] == [
        "sweep points 6 to 78 (73 more): spectrum.params.points: the same problem, with their own values",
        "sweep points 8, 10, 12, ..., 80 (37 more): realizations: the same problem, with their own values",
    ]
    assert len(problems) == 8


@pytest.mark.parametrize(("parameters", "mode", "said"), [
    ({"seed": {"values": [1, "1"]}}, "grid", "sweep points 1 (seed=1) and 2 (seed='1') are one preset"),
    ({"spectrum.params.hurst": {"values": [0.5, "5e-1"]}}, "grid", "sweep points 1 (spectrum.params.hurst=0.5) and 2"),
    ({"seed": {"values": [1, "1"]}, "realizations": {"values": [4, 4.0]}}, "zip", "sweep points 1 (seed=1, realizations=4)"),
    # what changes no number: each point ran the same ensemble under another name
    ({"name": {"values": ["a", "b"]}}, "grid", "sweep points 1 (name=a) and 2 (name=b) are one preset"),
    ({"description": {"values": ["x", "y"]}}, "grid", "sweep points 1 (description=x) and 2"),
    ({"output.plot": {"values": [True, False]}}, "grid", "sweep points 1 (output.plot=true) and 2"),
    ({"output.realizations": {"values": [True, False]}, "seed": {"values": [1, 1]}}, "zip", "sweep points 1"),
    # a description of pages was said whole: each value is cut
    ({"description": {"values": ["x" * 3000, "y"]}}, "grid", f"sweep points 1 (description={'x' * 65}...) and 2"),
])  # fmt: skip
def test_two_points_that_read_as_one_preset_are_refused(parameters, mode, said, registry):
    """1 and '1' are two values to the values' own check, but one seed once read: the sweep ran
    the same ensemble twice, as it does for a value listed twice (refused)."""
    with pytest.raises(PresetError) as info:
        plan_sweep(sweep_preset(parameters, mode=mode), registry=registry)
    assert said in str(info.value) and "the same ensemble would run twice" in str(info.value)


def test_a_bad_point_value_names_the_point_and_field(registry):
    params = {"spectrum.params.hurst": {"values": [0.5, 2.0]}, "slope.name": {"values": ["spectral", "slopy"]}}
    with pytest.raises(PresetError) as info:
        plan_sweep(sweep_preset(params, mode="zip"), registry=registry)
    text = str(info.value)
    assert "sweep point 2 (spectrum.params.hurst=2.0, slope.name='slopy'): spectrum.params.hurst: must be <= 1.5, got 2.0" in text
    assert "sweep point 2 (spectrum.params.hurst=2.0, slope.name='slopy'): slope.name: no slope plugin named 'slopy'" in text
    assert "sweep point 1" not in text


def test_cancel_after_the_first_point_keeps_it_and_marks_the_rest(tmp_path, registry):
    cancel = threading.Event()

    class StopAfterFirst(SweepListener):
        def point_finished(self, sweep, point, result):
            cancel.set()

    sweep = plan_sweep(sweep_preset({"seed": {"values": [1, 2, 3]}}), registry=registry)
    outcome = run_sweep(sweep, tmp_path, RunOptions(workers=1), listeners=[StopAfterFirst()], cancel=cancel, plot=False)
    assert outcome.status == "interrupted"
    assert [r["status"] for r in read_table(tmp_path / "sweep.csv")] == ["completed", "pending", "pending"]
    assert not (tmp_path / "points" / sweep.points[1].folder_name).exists()


def test_cli_runs_a_sweep_and_exit_codes(tmp_path, capsys):
    good = write(tmp_path, sweep_preset({"spectrum.params.hurst": {"values": [0.5, 0.9]}}))
    assert main(["run", str(good), "--out", str(tmp_path / "out"), "--workers", "1"]) == 0
    captured = capsys.readouterr()
    assert "point 2/2: spectrum.params.hurst=0.9" in captured.err
    assert "2 points" in captured.out and "hurst=0.9: a = " in captured.out
    assert len(read_table(tmp_path / "out" / "sweep.csv")) == 2
    assert main(["run", str(good), "--out", str(tmp_path / "j"), "--workers", "1", "--quiet", "--json", "--no-plot"]) == 0
    assert json.loads(capsys.readouterr().out)["status"] == "completed"
    # one point alone, with sweep=null: a plain run
    assert main(["run", str(good), "--set", "sweep=null", "--set", "spectrum.params.hurst=0.9",
                 "--out", str(tmp_path / "one"), "--quiet", "--json"]) == 0  # fmt: skip
    alone = json.loads(capsys.readouterr().out)
    point = json.loads((tmp_path / "out" / "points" / "02-hurst-0.9" / "summary.json").read_text())
    assert alone["fit"]["a"] == point["fit"]["a"] and "sweep" not in alone["preset"]
    bad = write(tmp_path, sweep_preset({"spectrum.params.hurst": {"values": [0.5, 2.0]}}), "bad.yaml")
    assert main(["run", str(bad), "--out", str(tmp_path / "bad")]) == 2
    assert "sweep point 2 (spectrum.params.hurst=2.0)" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()  # nothing runs unless every point is valid


def test_validate_checks_every_point(tmp_path, capsys):
    good = write(tmp_path, sweep_preset({"spectrum.params.hurst": {"values": [0.5, 0.9]}}))
    assert main(["validate", str(good)]) == 0
    assert "sweep of 2 points" in capsys.readouterr().out
    bad = write(tmp_path, sweep_preset({"spectrum.params.hurst": {"values": [0.5, 2.0]}}), "bad.yaml")
    assert main(["validate", str(bad)]) == 2
    assert "sweep point 2 (spectrum.params.hurst=2.0): spectrum.params.hurst: must be <= 1.5" in capsys.readouterr().err


def test_an_interrupted_sweep_resumes_to_the_uninterrupted_tables_both_ways(tmp_path, registry, capsys):
    data = sweep_preset({"seed": {"values": [1, 2, 3]}})
    preset = write(tmp_path, data)
    whole = tmp_path / "whole"
    assert main(["run", str(preset), "--out", str(whole), "--workers", "1", "--quiet", "--no-plot"]) == 0  # tables only
    fits = lambda folder: [(r["status"], r["a"], r["b"]) for r in read_table(folder / "sweep.csv")]  # noqa: E731

    for how in (["resume", "{out}"], ["run", str(preset), "--out", "{out}", "--resume"]):
        out = tmp_path / how[0]
        cancel = threading.Event()

        class StopAfterFirst(SweepListener):
            def point_finished(self, sweep, point, result):
                cancel.set()

        sweep = plan_sweep(data, registry=registry, source=str(preset))
        run_sweep(sweep, out, RunOptions(workers=1), listeners=[StopAfterFirst()], cancel=cancel, plot=False)
        assert [r["status"] for r in read_table(out / "sweep.csv")] == ["completed", "pending", "pending"]
        capsys.readouterr()
        assert main([part.format(out=out) for part in how] + ["--workers", "1", "--quiet", "--no-plot"]) == 0, capsys.readouterr().err
        assert fits(out) == fits(whole)  # the points never reached ran afresh, the finished one was kept


def test_a_resumed_sweep_reads_its_completed_points_back_without_rewriting_them(tmp_path, registry):
    """A completed point is read back, its listeners told it is restored: its files are not
    written again (it was run again, 2 s a point under load); one missing its figure draws it."""
    data = sweep_preset({"seed": {"values": [1, 2]}}, output={"plot": True})
    sweep = plan_sweep(data, registry=registry, source=str(write(tmp_path, data)))

    def interrupted(out):
        cancel = threading.Event()

        class StopAfterFirst(SweepListener):
            def point_finished(self, sweep, point, result):
                cancel.set()

        return run_sweep(sweep, out, RunOptions(workers=1), listeners=[StopAfterFirst()], cancel=cancel, plot=False)

    class Heard(SweepListener):
        restored = []

        def run_listeners(self, point):
            class Started:
                @hookimpl
                def run_started(self, run):
                    Heard.restored.append((point.number, run.resumed))

            return [Started()]

    first = interrupted(tmp_path / "out")
    folder = first.results[0].folder
    files = {path: path.stat().st_mtime_ns for path in folder.rglob("*") if path.is_file()}
    resumed = run_sweep(sweep, tmp_path / "out", RunOptions(workers=1, resume=True), listeners=[Heard()], plot=False)
    assert {path: path.stat().st_mtime_ns for path in folder.rglob("*") if path.is_file()} == files
    assert [r.status for r in resumed.results] == ["completed", "completed"]
    assert Heard.restored[0] == (1, sweep.points[0].scene.preset.realizations)
    whole = run_sweep(sweep, tmp_path / "whole", RunOptions(workers=1), plot=False)
    assert [(r.outcome.fit.a, r.outcome.fit.b) for r in resumed.results] == [
        (r.outcome.fit.a, r.outcome.fit.b) for r in whole.results]  # fmt: skip
    drawn = interrupted(tmp_path / "drawn").results[0].folder
    run_sweep(sweep, tmp_path / "drawn", RunOptions(workers=1, resume=True), plot=True)
    assert (drawn / "plot.png").is_file()  # the figure its first run did not draw


@pytest.mark.parametrize("damage", ["summary", "curve", "realizations", "realizations altered"])
def test_a_resumed_sweep_writes_again_a_completed_points_damaged_files(tmp_path, registry, damage):
    """A completed point whose summary.json is not JSON, whose curve.csv was cut short, or
    whose realizations.npz was removed or altered (a value changed, a well-formed archive
    still) is run again (restored from its chunks) by the resume, which writes its files
    again as a resume of a run does: never read back as it is."""
    data = sweep_preset({"seed": {"values": [1]}}, output={"realizations": True})
    sweep = plan_sweep(data, registry=registry, source=str(write(tmp_path, data)))
    run_sweep(sweep, tmp_path / "out", RunOptions(workers=1), plot=False)
    folder = next((tmp_path / "out" / "points").iterdir())
    sound = {name: (folder / name).read_bytes() for name in ("curve.csv", "realizations.npz")}
    if damage == "summary":
        (folder / "summary.json").write_text("garbage")
    elif damage == "curve":
        (folder / "curve.csv").write_bytes(sound["curve.csv"][:100])
    elif damage == "realizations":
        (folder / "realizations.npz").unlink()
    else:
        with np.load(folder / "realizations.npz") as stored:
            arrays = {name: stored[name] for name in stored.files}
        arrays["xi"] = arrays["xi"] * 1.01
        np.savez(folder / "realizations.npz", **arrays)
    heard = []

    class Started(SweepListener):
        def run_listeners(self, point):
            class Told:
                @hookimpl
                def run_started(self, run):
                    heard.append(run.resumed)

            return [Told()]

    outcome = run_sweep(sweep, tmp_path / "out", RunOptions(workers=1, resume=True), listeners=[Started()], plot=False)
    assert [r.status for r in outcome.results] == ["completed"]
    assert len(heard) == 1  # told once, as the run that writes its files again: never "restored" first
    assert json.loads((folder / "summary.json").read_text())["status"] == "completed"
    assert (folder / "curve.csv").read_bytes() == sound["curve.csv"]
    assert (folder / "realizations.npz").read_bytes() == sound["realizations.npz"]


@pytest.mark.parametrize("text, said", [("[]", "is damaged (an array, not a JSON object)"), ("{", "is damaged (not valid JSON"),
                                        ('{"sweep": {}}', "is damaged: field 'sweep.parameters': field required; field 'base_preset': field required")])  # fmt: skip
def test_resume_of_a_sweep_folder_whose_record_is_damaged_names_it(tmp_path, capsys, text, said):
    (tmp_path / "sweep.json").write_text(text)
    assert main(["resume", str(tmp_path)]) == 5
    err = capsys.readouterr().err
    assert "sweep.json" in err and said in err


def test_a_points_entry_that_is_a_file_or_a_link_refuses_the_whole_sweep_before_any_point(tmp_path, capsys):
    """Each point failed on it one by one (exit code 1) and, with --quiet, nothing said why; now the sweep
    is refused up front, naming it: output refused (4) for a run, run folder (5) for a resume."""
    import os

    from frictionlab.errors import ExitCode

    preset = write(tmp_path, sweep_preset({"seed": {"values": [1, 2]}}))
    out = tmp_path / "out"
    assert main(["run", str(preset), "--out", str(out), "--workers", "1", "--quiet", "--no-plot"]) == ExitCode.OK
    capsys.readouterr()
    keep = tmp_path / "keep"
    keep.mkdir()
    for made in ("file", "link"):
        os.rename(out / "points", tmp_path / f"points-{made}")
        if made == "file":
            (out / "points").write_text("mine\n")
        else:
            (out / "points").symlink_to(keep)
        assert main(["resume", str(out), "--workers", "1", "--quiet", "--no-plot"]) == ExitCode.RUN_FOLDER
        err = capsys.readouterr().err
        assert f"{out / 'points'} is a symbolic link or not a folder" in err and "then resume the sweep" in err
        forced = ["run", str(preset), "--out", str(out), "--force", "--workers", "1", "--quiet", "--no-plot"]
        assert main(forced) == ExitCode.OUTPUT_REFUSED
        assert f"{out / 'points'} is a symbolic link or not a folder" in capsys.readouterr().err
        assert list(keep.iterdir()) == []  # nothing written through the link
        (out / "points").unlink()
        os.rename(tmp_path / f"points-{made}", out / "points")
    assert (out / "points" / "01-seed-1" / "summary.json").is_file()


def test_the_table_after_a_sweep_says_why_a_point_failed_even_with_quiet(tmp_path, capsys):
    """The last lines of a sweep said only 'error' for a point in error (its reason went to the progress,
    which --quiet silences), and listed sweep.png under --no-plot."""
    preset = write(tmp_path, sweep_preset({"seed": {"values": [1, 2]}}))
    out = tmp_path / "out"
    assert main(["run", str(preset), "--out", str(out), "--workers", "1", "--quiet", "--no-plot"]) == 0
    capsys.readouterr()
    point = out / "points" / "01-seed-1"
    elsewhere = tmp_path / "elsewhere"
    point.rename(elsewhere)
    point.symlink_to(elsewhere)
    assert main(["resume", str(out), "--workers", "1", "--quiet", "--no-plot"]) == 1
    printed, said = capsys.readouterr()
    assert "seed=1: a = " in printed  # its finished row kept (the point is not recomputed), and why it failed
    assert f"; error: {point} is a symbolic link or not a folder" in printed
    assert "seed=2: a = " in printed
    assert "(sweep.csv, points/)" in printed
    # on stderr too, as a run's failure is: under --quiet it said nothing there, exit 1 (a sweep
    # under ulimit -v whose second point was refused, in a script reading stderr)
    assert said.startswith(f"error: 1 of 2 points failed; first: point 1: {point} is a symbolic link or not a folder")
    assert f"`frictionlab resume {out}` computes the rest" in said


@pytest.mark.parametrize("detach", [False, True])
def test_a_refused_sweep_point_is_named_as_the_user_gave_the_preset(tmp_path, capsys, detach):
    """A built-in sweep run by name with a bad swept value was refused under the installed
    file's path, and without the --set that made the point bad (validate, and a run of a
    preset without a sweep, name it as typed)."""
    bad = "sweep.parameters.spectrum.params.hurst={values: [0.5, 2.0]}"
    args = ["run", "benad2012-fig5", "--set", bad, "--out", str(tmp_path / "out")] + (["--detach"] if detach else [])
    assert main(args) == 2
    err = capsys.readouterr().err
    assert f"error: built-in preset 'benad2012-fig5' --set {bad}: 1 problem in preset" in err
    assert "sweep point 2 (spectrum.params.hurst=2.0): spectrum.params.hurst: must be <= 1.5, got 2.0" in err
    assert not (tmp_path / "out").exists()


def test_a_sweep_whose_largest_point_does_not_fit_is_refused_before_its_first_point_runs(tmp_path, monkeypatch, registry):
    """Each point's memory was checked as the point started: a sweep planned without the check
    (the library's, a detached sweep's child) ran its first points, then failed at the large
    one. The largest point is checked before any runs, and the refusal names it."""
    from frictionlab.compute import memory
    from frictionlab.errors import RunError

    data = sweep_preset({"spectrum.params.points": {"values": [512, 30_000_000, 1024]}})
    sweep = plan_sweep(data, registry=registry)  # no memory check while planned
    monkeypatch.setattr(memory, "available_memory", lambda: (memory.GiB, "the memory of a test"))
    with pytest.raises(RunError, match=r"^sweep point 2 \(spectrum\.params\.points=30000000\): this run would need"):
        run_sweep(sweep, tmp_path / "out", RunOptions(workers=1))
    assert not (tmp_path / "out").exists()


def test_the_clis_memory_refusal_of_a_sweep_names_the_point(tmp_path, monkeypatch, capsys):
    from frictionlab.compute import memory

    monkeypatch.setattr(memory, "available_memory", lambda: (memory.GiB, "the memory of a test"))
    path = write(tmp_path, sweep_preset({"spectrum.params.points": {"values": [512, 30_000_000]}}))
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--workers", "1"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("error: sweep point 2 (spectrum.params.points=30000000): this run would need about")
    assert "the memory of a test" in err and not (tmp_path / "out").exists()


def test_a_bare_list_of_values_says_how_to_give_one():
    with pytest.raises(PresetError) as caught:
        plan_sweep(sweep_preset({"spectrum.params.hurst": [0.5, 0.8]}))
    assert caught.value.problems == [
        "sweep.parameters.spectrum.params.hurst: must be a mapping: {values: [...]} for a list, "
        "or {start: ..., stop: ..., num: ...} for a range, got [0.5, 0.8]"
    ]


def test_load_sweep_takes_a_built_ins_name_and_names_it_so():
    sweep = load_sweep("benad2012-fig5", ["realizations=2"])
    assert len(sweep.points) == 8
    with pytest.raises(PresetError, match=r"^built-in preset 'benad2012-fig5': 1 problem"):
        load_sweep("benad2012-fig5", ["realizations=0"])


def test_a_point_and_its_result_read_as_a_notebook_needs(tmp_path):
    finished = []

    class Listener(SweepListener):
        def point_finished(self, sweep, point, result):
            finished.append((repr(point), result.fit, result.outcome.fit))

    sweep = plan_sweep(sweep_preset({"spectrum.params.hurst": {"values": [0.5, 0.8]}}))
    run_sweep(sweep, tmp_path / "sweep", RunOptions(workers=1), listeners=[Listener()], plot=False)
    assert [shown for shown, _, _ in finished] == [
        "<SweepPoint 1: spectrum.params.hurst=0.5, folder '01-hurst-0.5'>",
        "<SweepPoint 2: spectrum.params.hurst=0.8, folder '02-hurst-0.8'>",
    ]
    assert all(fit is not None and fit == own for _, fit, own in finished)


def test_a_sweep_table_that_is_a_folder_or_a_folder_not_writable_is_said_so_at_once(tmp_path, capsys):
    """sweep.png a folder: the points ran, then the figure failed (exit code 1). A sweep folder
    that cannot be written in: `resume` said its sweep.json was edited. Each is now said as it
    is before any point runs (exit code 4), the folder left as it was."""
    import os
    import shutil
    import subprocess
    import sys

    preset = {**SMALL_PRESET, "realizations": 2, "fit": {"bootstrap": 20},
              "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.9]}}}}  # fmt: skip
    path, out = tmp_path / "s.yaml", tmp_path / "out"
    path.write_text(yaml.safe_dump(preset))
    assert main(["run", str(path), "--out", str(out), "--quiet", "--workers", "1"]) == 0
    shutil.rmtree(next((out / "points").iterdir()))  # a point to compute again
    (out / "sweep.png").unlink()
    (out / "sweep.png").mkdir()
    capsys.readouterr()
    for args in (["run", str(path), "--out", str(out), "--resume"], ["resume", str(out)]):
        assert main([*args, "--quiet", "--workers", "1"]) == 4
        assert f"{out / 'sweep.png'} is a folder, not a file: the sweep writes its sweep.png there" in capsys.readouterr().err
        assert len(list((out / "points").iterdir())) == 1
    (out / "sweep.png").rmdir()
    drop = ["setpriv", "--bounding-set=-dac_override,-dac_read_search"] if os.geteuid() == 0 else []
    out.chmod(0o555)
    try:
        done = subprocess.run([*drop, sys.executable, "-m", "frictionlab", "resume", str(out), "--quiet", "--workers", "1"],
                              capture_output=True, text=True, timeout=120)  # fmt: skip
    finally:
        out.chmod(0o755)
    assert done.returncode == 4 and f"{out} cannot be written in: Permission denied" in done.stderr, done.stderr
    assert "damaged" not in done.stderr and len(list((out / "points").iterdir())) == 1


def sweep_stopped_after_its_first_point(folder, registry):
    """A sweep of two seeds into ``folder``, cancelled once its first point has finished."""
    cancel = threading.Event()

    class StopAfterFirst(SweepListener):
        def point_finished(self, sweep, point, result):
            cancel.set()

    sweep = plan_sweep(sweep_preset({"seed": {"values": [1, 2]}}), registry=registry)
    run_sweep(sweep, folder, RunOptions(workers=1), listeners=[StopAfterFirst()], cancel=cancel, plot=False)
    return sweep


def test_a_sweep_started_with_spacing_log_beside_values_still_resumes(tmp_path, registry, capsys):
    """spacing: log beside values, now refused, was once accepted (and ignored): an interrupted
    sweep that holds it in its sweep.json resumed as 'damaged', its finished point out of reach."""
    sweep = sweep_stopped_after_its_first_point(tmp_path, registry)
    record = json.loads((tmp_path / "sweep.json").read_text())
    record["sweep"]["parameters"]["seed"]["spacing"] = "log"  # as such a sweep wrote it
    (tmp_path / "sweep.json").write_text(json.dumps(record))
    first = (tmp_path / "points" / sweep.points[0].folder_name / "summary.json").read_bytes()
    assert main(["resume", str(tmp_path), "--workers", "1", "--quiet", "--no-plot"]) == 0, capsys.readouterr().err
    assert [r["status"] for r in read_table(tmp_path / "sweep.csv")] == ["completed", "completed"]
    assert (tmp_path / "points" / sweep.points[0].folder_name / "summary.json").read_bytes() == first  # kept, not rerun


def test_a_sweep_started_with_fit_bootstrap_1_resumes_without_intervals(tmp_path, registry, recwarn):
    """fit.bootstrap: 1, now refused, was once taken: a sweep whose sweep.json and points hold it was
    refused by resume as a preset not valid here. Every point resumes with no intervals, and says so."""
    from frictionlab.runs.rundir import fingerprint

    sweep = sweep_stopped_after_its_first_point(tmp_path, registry)
    record = json.loads((tmp_path / "sweep.json").read_text())
    record["base_preset"]["fit"]["bootstrap"] = 1  # as such a sweep wrote it, in its point's folder too
    (tmp_path / "sweep.json").write_text(json.dumps(record))
    point = tmp_path / "points" / sweep.points[0].folder_name
    state = json.loads((point / "run.json").read_text())
    state["preset"]["fit"]["bootstrap"] = 1
    state["fingerprint"] = fingerprint(state["preset"])
    (point / "run.json").write_text(json.dumps(state))
    (point / "preset.yaml").write_text(yaml.safe_dump(state["preset"]))
    assert main(["resume", str(tmp_path), "--workers", "1", "--quiet", "--no-plot"]) == 0
    rows = read_table(tmp_path / "sweep.csv")
    assert [(r["status"], r["a_lo"]) for r in rows] == [("completed", ""), ("completed", "")]
    said = [str(w.message) for w in recwarn if "fit.bootstrap is 1" in str(w.message)]
    assert len(said) == 1 and f"resume of {point}: " in said[0], said
    assert json.loads((point / "summary.json").read_text())["fit"]["bootstrap"] == 0  # its record as it now reads


def _cancelled_in_point_2(data, out, registry):
    """``data``'s sweep run into ``out`` and cancelled within its second point (some of its
    realizations finished, in its folder); the points after it never reached."""
    cancel = threading.Event()

    class StopInSecond(SweepListener):
        def run_listeners(self, point):
            class Counting:
                @hookimpl
                def realization_done(self, done):
                    if point.number == 2 and done >= 2:
                        cancel.set()

            return [Counting()]

    sweep = plan_sweep(data, registry=registry)
    run_sweep(sweep, out, RunOptions(workers=1), listeners=[StopInSecond()], cancel=cancel, plot=False)
    return sweep


def test_resuming_one_point_of_a_sweep_writes_the_sweeps_tables(tmp_path, registry, capsys):
    """`frictionlab resume SWEEP/points/NN` completed the point, and left sweep.csv and sweep.json
    saying it was cancelled (and the sweep interrupted) until the whole sweep was resumed."""
    data = sweep_preset({"seed": {"values": [1, 2, 3]}}, realizations=12)
    whole = run_sweep(plan_sweep(data, registry=registry), tmp_path / "whole", RunOptions(workers=1), plot=False)
    sweep = _cancelled_in_point_2(data, tmp_path / "out", registry)
    rows = read_table(tmp_path / "out" / "sweep.csv")
    assert [r["status"] for r in rows] == ["completed", "cancelled", "pending"]
    point = tmp_path / "out" / "points" / sweep.points[1].folder_name
    capsys.readouterr()
    assert main(["resume", str(point), "--workers", "1", "--quiet", "--no-plot"]) == 0
    err = capsys.readouterr().err
    assert f"sweep.csv and sweep.json of the sweep in {tmp_path / 'out'}/ updated with this point (sweep interrupted)" in err
    rows = read_table(tmp_path / "out" / "sweep.csv")
    assert [r["status"] for r in rows] == ["completed", "completed", "pending"]
    assert float(rows[1]["a"]) == pytest.approx(whole.results[1].fit.a, rel=1e-12)
    record = json.loads((tmp_path / "out" / "sweep.json").read_text())
    assert record["status"] == "interrupted" and record["points"][1]["done"] == 12
    assert main(["resume", str(tmp_path / "out"), "--workers", "1", "--quiet", "--no-plot"]) == 0
    assert [(r["status"], r["a"]) for r in read_table(tmp_path / "out" / "sweep.csv")] == [
        (r["status"], r["a"]) for r in read_table(tmp_path / "whole" / "sweep.csv")]  # fmt: skip


def test_a_point_resumed_while_its_sweep_is_held_says_how_to_update_the_tables(tmp_path, registry, capsys):
    from frictionlab.runs.rundir import RunDirectory

    data = sweep_preset({"seed": {"values": [1, 2]}}, realizations=12)
    sweep = _cancelled_in_point_2(data, tmp_path, registry)
    before = (tmp_path / "sweep.csv").read_bytes()
    with RunDirectory(tmp_path):  # the sweep's lock, as a sweep running there holds it
        assert main(["resume", str(tmp_path / "points" / sweep.points[1].folder_name), "--workers", "1", "--quiet"]) == 0
    err = capsys.readouterr().err
    assert f"the tables of the sweep in {tmp_path}/ are not updated with this point ({tmp_path} is in use by another run" in err
    assert f"`frictionlab resume {tmp_path}` writes them (and runs what is unfinished)" in err
    assert (tmp_path / "sweep.csv").read_bytes() == before


def test_a_sweep_failed_by_a_points_failed_realizations_says_which_on_stderr(tmp_path, capsys, monkeypatch):
    """A point that completed with some realizations failed (out of memory, say) makes its sweep
    failed: stderr said '0 of 2 points failed', counting only the points with an error."""
    import frictionlab.runs.sweep as sweep_module

    real = sweep_module.run_sweep

    def with_a_failed_realization(sweep, out_dir, *args, **kwargs):
        outcome = real(sweep, out_dir, *args, **kwargs)
        outcome.results[1].outcome.failures = [(3, "MemoryError: a test's")]
        sweep_module._finish(sweep, outcome, out_dir, plot=False)
        return outcome

    monkeypatch.setattr(sweep_module, "run_sweep", with_a_failed_realization)
    preset = write(tmp_path, sweep_preset({"seed": {"values": [1, 2]}}))
    out = tmp_path / "out"
    assert main(["run", str(preset), "--out", str(out), "--workers", "1", "--quiet", "--no-plot"]) == 1
    said = capsys.readouterr().err
    assert said.startswith("error: 1 of 2 points failed; first: point 2: 1 realization failed, the first: "
                           "MemoryError: a test's"), said
