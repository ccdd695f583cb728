"""The terminal UI driven as a user drives it (Textual's Pilot at 80x24): what it
shows is checked against the headless validator and the headless run, and the
files it writes against what ``frictionlab run`` accepts."""

import asyncio
import functools
import json
import re
import subprocess
import sys
from typing import ClassVar, Literal

import numpy as np
import pytest
import yaml
from pydantic import Field

from frictionlab import PluginParams, SlopeEstimator
from frictionlab.cli import main
from frictionlab.engine import run as engine_run
from frictionlab.errors import ExitCode, PresetError
from frictionlab.fit import least_squares
from frictionlab.preset import build_scene, load_scene
from frictionlab.runner import run_to_folder
from frictionlab.sweep import load_sweep, read_table, run_sweep
from frictionlab.tui.app import FrictionlabApp
from frictionlab.tui.live import LiveListener
from frictionlab.tui.folders import save_preset
from frictionlab.tui.form import PresetForm
from textual.widgets import Input, Select, Static, Switch

from .conftest import PRESETS, ROOT, SMALL_PRESET, merge

SIZE = (80, 24)


def sync(scenario):
    """Run an async Pilot scenario as a plain test (no async pytest plugin needed)."""

    @functools.wraps(scenario)
    def test(*args, **kwargs):
        asyncio.run(scenario(*args, **kwargs))

    return test
TINY = merge(SMALL_PRESET, {"spectrum": {"params": {"points": 512}}, "fit": {"bootstrap": 50}})


def headless_problems(data, registry):
    try:
        build_scene(data, registry=registry)
    except PresetError as exc:
        return exc.problems
    return []


@pytest.fixture
def folders(tmp_path, monkeypatch):
    """A presets folder with one tiny preset and an empty runs folder, as relative
    paths (so snapshots do not show the temporary directory)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "presets").mkdir()
    (tmp_path / "presets" / "tiny.yaml").write_text(yaml.safe_dump(TINY, sort_keys=False))
    return tmp_path


def make_app(registry, preset=None, workers=1):
    return FrictionlabApp(preset, presets_dir="presets", runs_dir="runs", workers=workers, registry=registry)


async def open_first_preset(pilot):
    await pilot.pause()
    await pilot.press("enter")
    await pilot.pause()
    form = pilot.app.query_one(PresetForm)
    assert form.data is not None, "Enter on the presets list did not open the preset"
    return form


async def type_into(pilot, widget_id, text):
    field = pilot.app.query_one(f"#{widget_id}", Input)
    field.focus()
    await pilot.press("end", "ctrl+u", *text)
    await pilot.pause()


async def choose(pilot, select_id, value):
    """Pick an option of a Select with the keyboard: Enter opens it, arrows move, Enter picks."""
    select = pilot.app.query_one(f"#{select_id}", Select)
    select.focus()
    await pilot.press("enter")
    options = [v for _, v in select._options if v is not Select.NULL]
    current = options.index(select.value) if select.value in options else -1
    target = options.index(value)
    await pilot.press(*(["down"] * (target - current) if target > current else ["up"] * (current - target)))
    await pilot.press("enter")
    await pilot.pause()
    assert select.value == value


async def wait_until(pilot, condition, timeout=60.0):
    for _ in range(int(timeout / 0.05)):
        if condition():
            return
        await pilot.pause(0.05)
    raise AssertionError("timed out waiting for the app")


def error_text(app, widget_id):
    label = app.query_one(f"#{widget_id}--error", Static)
    return str(label.render()) if label.display else ""


# ------------------------------------------------------------------ edit and save


@sync
async def test_invalid_value_shows_the_headless_message_then_save_round_trips(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        await type_into(pilot, "field--spectrum--params--hurst", "2.0")
        expected = headless_problems(merge(TINY, {"spectrum": {"params": {"hurst": 2.0}}}), registry)
        assert expected == ["spectrum.params.hurst: must be <= 1.5, got 2.0"]
        assert form.problems == expected
        assert error_text(app, "field--spectrum--params--hurst") == expected[0]
        assert app.query_one("#field--spectrum--params--hurst", Input).has_class("-invalid")
        assert expected[0] in str(app.query_one("#problems", Static).render())

        # text where a number belongs: the same words as `frictionlab validate`
        await type_into(pilot, "field--loading--steps", "abc")
        assert form.problems == headless_problems(
            merge(TINY, {"spectrum": {"params": {"hurst": 2.0}}, "loading": {"steps": "abc"}}), registry
        )
        assert error_text(app, "field--loading--steps") == "loading.steps: must be a whole number, got 'abc'"

        await type_into(pilot, "field--loading--steps", "12")
        await type_into(pilot, "field--spectrum--params--hurst", "0.9")
        assert form.problems == []
        assert error_text(app, "field--spectrum--params--hurst") == ""
        await pilot.press("ctrl+s")
        await pilot.pause()
        assert not app.modified

    saved = yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())
    assert saved == merge(TINY, {"spectrum": {"params": {"hurst": 0.9}}, "loading": {"steps": 12}})
    # accepted unchanged by the headless front end
    scene = load_scene(folders / "presets" / "tiny.yaml", registry=registry)
    assert scene.spectrum.params.hurst == 0.9 and scene.preset.loading.steps == 12
    assert main(["run", "presets/tiny.yaml", "--out", "runs/headless", "--quiet", "--workers", "1"]) == ExitCode.OK


@sync
async def test_save_with_problems_asks_first_and_keeps_unknown_sections(folders, registry):
    data = merge(TINY, {"realizations": 0, "notes": {"author": "me", "tags": ["a", "b"]}})
    (folders / "presets" / "tiny.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        assert form.problems == headless_problems(data, registry)
        assert any(p.startswith("notes: ") for p in form.problems)
        await type_into(pilot, "field--seed", "11")
        await pilot.press("ctrl+s")
        await pilot.pause()
        assert app.modified, "saved a preset with problems without asking"
        await pilot.press("n")  # no: nothing is written
        await pilot.pause()
        assert yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())["seed"] == TINY["seed"]
        await pilot.press("ctrl+s")
        await pilot.pause()
        await pilot.press("y")
        await pilot.pause()
        assert not app.modified
        # and a run is refused, with the problems named
        await pilot.press("ctrl+r")
        await pilot.pause()
        assert app.last_snapshot is None and not app.running
    saved = yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())
    assert saved == {**data, "seed": 11}


@sync
async def test_switching_the_solver_swaps_its_parameters(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        assert app.query("#field--solver--params--youngs_modulus")
        await choose(pilot, "plugin--solver", "winkler")
        assert not app.query("#field--solver--params--youngs_modulus")
        modulus = app.query_one("#field--solver--params--modulus", Input)
        assert "stiffness per unit length" in str(modulus.tooltip)
        await type_into(pilot, "field--solver--params--modulus", "-1")
        assert form.problems == ["solver.params.modulus: must be > 0.0, got -1.0"]
        await type_into(pilot, "field--solver--params--modulus", "4")
        assert form.data["solver"] == {"name": "winkler", "params": {"modulus": 4.0}}
        # back to mdr: its values come back
        await choose(pilot, "plugin--solver", "mdr")
        assert form.data["solver"] == TINY["solver"]
        assert app.query_one("#field--solver--params--youngs_modulus", Input).value == "1.0"
        assert form.problems == []


COMMENTED = """\
# why this preset
name: commented  # the name
description: >
  folded text
  over two lines
spectrum:
  name: power-law
  params:
    hurst: 0.8    # H
    points: 1024
solver:
  name: mdr
  params:
    # the modulus first
    youngs_modulus: 1.0  # E
    poisson_ratio: 0.0  # nu: zero, so E* = E
# the slope estimator below
slope:
  name: forward-difference
loading:
  stop: 2.0e+1
  values:
    - 1  # one
fit: {bootstrap: 50}
"""


def _comment_lines(text):
    return [line.split("#", 1)[1].strip() for line in text.splitlines() if "#" in line]


def test_save_keeps_comments_order_and_spelling_with_nested_removed_and_added_keys(tmp_path):
    path, source = tmp_path / "saved.yaml", tmp_path / "source.yaml"
    source.write_text(COMMENTED)
    data = yaml.safe_load(COMMENTED)
    data["spectrum"]["params"]["hurst"] = 0.6  # a nested change
    data["solver"] = {"name": "winkler", "params": {"modulus": 1e-05}}  # two keys removed, one added
    data["fit"]["confidence"] = 0.9
    data["seed"] = 3  # a new top-level key: last, as in the edited data
    save_preset(path, data, template=source)
    text = path.read_text()
    assert yaml.safe_load(text) == data  # PyYAML (what frictionlab loads with) reads the new values
    assert _comment_lines(text) == _comment_lines(COMMENTED)  # every comment, in order
    lines = text.splitlines()
    # untouched lines are byte for byte the same, in the same order ("2.0e+1" is not rewritten as 20.0)
    kept = [line for line in COMMENTED.splitlines() if line in lines]
    assert kept == [line for line in lines if line in COMMENTED.splitlines()]
    for line in ("name: commented  # the name", "description: >", "  folded text", "  stop: 2.0e+1", "    - 1  # one"):
        assert line in lines
    assert "    hurst: 0.6    # H" in lines and "    modulus: 1.0e-05" in lines
    # the comment above `slope` stays above it; the removed keys' own comments stay in the solver section
    assert lines[lines.index("slope:") - 1] == "# the slope estimator below"
    assert lines.index("    modulus: 1.0e-05") < lines.index("    # E") < lines.index("slope:")
    assert "youngs_modulus" not in text and "poisson_ratio" not in text
    assert list(yaml.safe_load(text)) == ["name", "description", "spectrum", "solver", "slope", "loading", "fit", "seed"]


def test_save_without_changes_rewrites_every_shipped_preset_byte_for_byte(tmp_path):
    for preset in sorted(PRESETS.glob("*.yaml")):
        original = preset.read_text()
        save_preset(tmp_path / preset.name, yaml.safe_load(original), template=preset)
        assert (tmp_path / preset.name).read_text() == original, preset.name


def test_new_text_values_are_spelled_so_pyyaml_reads_them_back(tmp_path):
    source = tmp_path / "source.yaml"
    source.write_text("name: x  # n\nseed: 1\n")
    data = {"name": "yes", "seed": 1, "description": "1e4", "notes": {"on": "0o17", "nan": float("inf")}}
    save_preset(tmp_path / "out.yaml", data, template=source)
    text = (tmp_path / "out.yaml").read_text()
    assert yaml.safe_load(text) == data and "# n" in text


@sync
async def test_editing_a_commented_shipped_preset_keeps_its_comments(folders, registry):
    original = (PRESETS / "benad2012-fig2.yaml").read_text()
    path = folders / "presets" / "tiny.yaml"  # the first row of the list
    path.write_text(original)
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        assert form.data["name"] == "benad2012-fig2"
        await type_into(pilot, "field--spectrum--params--hurst", "0.75")
        assert form.problems == []
        await pilot.press("ctrl+s")
        await pilot.pause()
        assert not app.modified
    text = path.read_text()
    assert _comment_lines(text) == _comment_lines(original) and "h = 1e4" in text
    changed = [(a, b) for a, b in zip(original.splitlines(), text.splitlines(), strict=True) if a != b]
    assert changed == [("    hurst: 1.0", "    hurst: 0.75")]
    assert main(["validate", str(path)]) == ExitCode.OK
    scene = load_scene(path, registry=registry)
    assert scene.spectrum.params.hurst == 0.75 and scene.spectrum.params.rms_height == 1e4


class SmoothedSlope(SlopeEstimator):
    """A third-party plugin registered only in this test: the form has no code for it."""

    name: ClassVar[str] = "smoothed-difference"
    summary: ClassVar[str] = "test plugin: central difference of a smoothed line"

    class Params(PluginParams):
        window: int = Field(3, ge=1, le=99, description="points in the moving average")
        weight: float = Field(0.5, gt=0.0, lt=1.0, description="weight of the centre point (dimensionless)")
        edge: Literal["wrap", "reflect"] = Field("wrap", description="how the line's ends are treated")
        normalise: bool = Field(False, description="divide by the rms slope")

    def slopes(self, heights, spacing):
        return np.gradient(heights, spacing)


@sync
async def test_a_third_party_plugin_gets_a_form_without_code(folders, register_plugin):
    registry = register_plugin(SmoothedSlope)
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        await choose(pilot, "plugin--slope", "smoothed-difference")
        prefix = "#field--slope--params--"
        assert isinstance(app.query_one(prefix + "window"), Input)
        assert isinstance(app.query_one(prefix + "weight"), Input)
        assert isinstance(app.query_one(prefix + "edge"), Select)
        assert isinstance(app.query_one(prefix + "normalise"), Switch)
        assert "allowed: >= 1, <= 99" in str(app.query_one(prefix + "window").tooltip)
        await type_into(pilot, "field--slope--params--window", "200")
        expected = headless_problems(merge(TINY, {"slope": {"name": "smoothed-difference", "params": {"window": 200}}}), registry)
        assert form.problems == expected == ["slope.params.window: must be <= 99, got 200"]
        await type_into(pilot, "field--slope--params--window", "5")
        await choose(pilot, "field--slope--params--edge", "reflect")
        app.query_one(prefix + "normalise", Switch).focus()
        await pilot.press("space")
        await pilot.pause()
        assert form.data["slope"] == {
            "name": "smoothed-difference",
            "params": {"window": 5, "edge": "reflect", "normalise": True},
        }
        assert form.problems == []


@sync
async def test_new_preset_from_a_plugins_defaults(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("n")
        await pilot.pause()
        await pilot.press("ctrl+u", *"fresh", "enter")
        await pilot.pause()
        form = app.query_one(PresetForm)
        assert form.data["spectrum"]["name"] == "power-law"
        # power-law's hurst and points have no default: the user is told, as headless would
        assert form.problems == headless_problems(form.data, registry)
        assert {p.split(":")[0] for p in form.problems} == {"spectrum.params.hurst", "spectrum.params.points"}
        await type_into(pilot, "field--spectrum--params--hurst", "0.7")
        await type_into(pilot, "field--spectrum--params--points", "256")
        assert form.problems == []
        await pilot.press("ctrl+s")
        await pilot.pause()
    assert app.draft_path is not None and app.draft_path.name == "fresh.yaml"
    assert load_scene(app.draft_path, registry=registry).spectrum.params.points == 256


# ------------------------------------------------------------------ running


@sync
async def test_a_run_shows_the_headless_coefficients(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("ctrl+r")
        await wait_until(pilot, lambda: app.last_outcome is not None)
        await pilot.pause()
        shown = str(app.query_one("#run-fit", Static).render())
        out_dir = app.last_out_dir
        runs_listed = [entry.path.name for entry in app.runs]

    outcome, _ = run_to_folder(build_scene(TINY, registry=registry), folders / "headless", workers=2)
    fit = outcome.fit
    assert app.last_outcome.fit == fit  # same seed, any worker count: the same numbers
    assert f"a = {fit.a:.4f} [{fit.a_ci[0]:.4f}, {fit.a_ci[1]:.4f}]" in shown
    assert f"b = {fit.b:.4f} [{fit.b_ci[0]:.4f}, {fit.b_ci[1]:.4f}]" in shown
    assert f"R^2 = {fit.r2:.4f}" in shown
    assert f"{outcome.contact_count[-1]:.2f} at last load" in shown
    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["fit"]["a"] == fit.a
    assert runs_listed == [out_dir.name]


@sync
async def test_cancel_keeps_and_writes_what_finished(folders, registry):
    big = merge(TINY, {"name": "long", "realizations": 100_000})
    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(big))
    app = make_app(registry, preset="presets/long.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("ctrl+r")
        await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= 3)
        await pilot.press("c")  # the Run tab has focus
        await wait_until(pilot, lambda: app.last_outcome is not None)
        outcome, out_dir = app.last_outcome, app.last_out_dir
        stats = str(app.query_one("#run-stats", Static).render())
    assert outcome.status == "cancelled" and 3 <= outcome.done < 100_000
    assert stats.startswith(f"cancelled: {outcome.done}/100000")
    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["status"] == "cancelled"
    assert summary["realizations"]["done"] == outcome.done
    with np.load(out_dir / "realizations.npz") as arrays:
        assert arrays["xi"].shape[0] == outcome.done


SWEEP = merge(
    TINY,
    {
        "name": "tinysweep",
        "realizations": 4,
        "spectrum": {"params": {"points": 256}},
        "loading": {"steps": 8},
        "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.7, 0.9]}}},
    },
)


def fits_width(table):
    """Every column of a DataTable is on screen: nothing to scroll sideways to."""
    return table.max_scroll_x == 0 and table.virtual_size.width <= table.scrollable_content_region.width


def _numbers(cell):
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", str(cell))]


@sync
async def test_a_sweep_fills_the_table_with_the_rows_of_sweep_csv(folders, registry):
    (folders / "presets" / "sweep.yaml").write_text(yaml.safe_dump(SWEEP, sort_keys=False))
    app = make_app(registry, preset="presets/sweep.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("ctrl+r")
        await wait_until(pilot, lambda: app.last_sweep is not None)
        await pilot.pause()
        table = app.query_one("#sweep-table")
        cells = [[str(c) for c in table.get_row_at(i)] for i in range(table.row_count)]
        columns = [str(c.label) for c in table.columns.values()]
        point_text = str(app.query_one("#sweep-point", Static).render())
        out_dir = app.last_out_dir
        fits = fits_width(table)
    assert app.last_sweep.status == "completed" and point_text.startswith("completed: 3/3 points")
    assert out_dir.parent.name == "runs" and out_dir.name.startswith("tinysweep-")
    assert columns == ["#", "hurst", "", "a [95% CI]", "b [95% CI]", "R^2", "contacts"]
    assert fits, "the sweep table is cut at 80 columns"
    rows = read_table(out_dir / "sweep.csv")
    assert len(cells) == len(rows) == 3
    for shown, row in zip(cells, rows, strict=True):
        number, hurst, status, a, b, r2, contacts = shown
        assert int(number) == int(row["point"]) and float(hurst) == float(row["spectrum.params.hurst"])
        for cell, name in ((a, "a"), (b, "b")):  # the estimate to 4 decimals, its interval to 3
            assert _numbers(cell)[0] == pytest.approx(float(row[name]), abs=5e-5)
            assert _numbers(cell)[1:] == pytest.approx([float(row[f"{name}_lo"]), float(row[f"{name}_hi"])], abs=5e-4)
        assert _numbers(r2) == pytest.approx([float(row["r2"])], abs=5e-4)
        assert _numbers(contacts) == pytest.approx([float(row["contact_first"]), float(row["contact_last"])], rel=5e-3)
        assert status == "✓" and row["status"] == "completed"
    # the same numbers as a headless sweep of the same preset
    headless = run_sweep(load_sweep(folders / "presets" / "sweep.yaml", registry=registry), folders / "hl", workers=1)
    assert [(r.outcome.fit.a, r.outcome.fit.b) for r in app.last_sweep.results] == [
        (r.outcome.fit.a, r.outcome.fit.b) for r in headless.results
    ]
    assert [r.point.scene.spectrum.params.hurst for r in headless.results] == [0.5, 0.7, 0.9]
    assert (out_dir / "sweep.png").stat().st_size > 0
    assert {p.name for p in (out_dir / "points").iterdir()} == {"01-hurst-0.5", "02-hurst-0.7", "03-hurst-0.9"}


@sync
async def test_cancelling_a_sweep_writes_the_running_points_realizations(folders, registry):
    big = merge(SWEEP, {"realizations": 100_000})
    (folders / "presets" / "sweep.yaml").write_text(yaml.safe_dump(big, sort_keys=False))
    app = make_app(registry, preset="presets/sweep.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("ctrl+r")
        await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= 3)
        await pilot.press("c")
        await wait_until(pilot, lambda: app.last_sweep is not None)
        await pilot.pause()
        table = app.query_one("#sweep-table")
        cells = [[str(c) for c in table.get_row_at(i)] for i in range(table.row_count)]
        out_dir = app.last_out_dir
    assert app.last_sweep.status == "interrupted"
    rows = read_table(out_dir / "sweep.csv")
    assert [r["status"] for r in rows] == ["cancelled", "pending", "pending"]
    assert [c[2] for c in cells] == ["c"]  # only finished points get a row, marked cancelled
    first = app.last_sweep.results[0].outcome
    assert 3 <= first.done < 100_000 and int(rows[0]["done"]) == first.done
    with np.load(out_dir / rows[0]["folder"] / "realizations.npz") as arrays:
        assert arrays["xi"].shape[0] == first.done
    assert not (out_dir / "points" / "02-hurst-0.7").exists()


def test_live_snapshots_coalesce_and_the_interim_fit_is_the_final_point_estimate(registry):
    scene = build_scene(merge(TINY, {"realizations": 12}), registry=registry)
    posted = []
    outcome = engine_run(scene, workers=1, listeners=[LiveListener(posted.append, interval=3600.0)])
    # started, the first and the last realization, finished: nothing for the ten in between
    assert [s.done for s in posted] == [0, 1, 12, 12]
    last = posted[-1]
    assert last.finished and last.failed == 0
    np.testing.assert_allclose(last.xi, outcome.xi, rtol=1e-12)
    np.testing.assert_allclose(last.f, outcome.f, rtol=1e-12)
    coef, *_ = least_squares(outcome.f, outcome.xi)
    assert last.fit.a == pytest.approx(outcome.fit.a, rel=1e-10) == pytest.approx(coef[0], rel=1e-10)
    assert last.fit.b == pytest.approx(outcome.fit.b, rel=1e-10)

    every = []
    engine_run(scene, workers=1, listeners=[LiveListener(every.append, interval=0.0)])
    assert [s.done for s in every] == [0, *range(1, 13), 12]


# ------------------------------------------------------------------ results


def make_runs(folders, registry):
    for seed in (1, 2):
        data = merge(TINY, {"seed": seed, "name": f"seed{seed}"})
        run_to_folder(build_scene(data, registry=registry), folders / "runs" / f"seed{seed}", workers=1)


@sync
async def test_results_lists_opens_and_overlays_runs(folders, registry):
    make_runs(folders, registry)
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("f5")
        assert {entry.path.name for entry in app.runs} == {"seed1", "seed2"}
        await pilot.press("enter")
        assert [e.path.name for e in app.overlay] == [app.runs[0].path.name]
        await pilot.press("down", "space")
        assert {e.path.name for e in app.overlay} == {"seed1", "seed2"}
        info = str(app.query_one("#results-info", Static).render())
    for seed in (1, 2):
        summary = json.loads((folders / "runs" / f"seed{seed}" / "summary.json").read_text())
        assert f"a={summary['fit']['a']:.4f}" in info


@sync
async def test_results_lists_a_sweep_shows_its_points_and_opens_a_points_run(folders, registry):
    make_runs(folders, registry)
    (folders / "sweep.yaml").write_text(yaml.safe_dump(SWEEP, sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", workers=1, plot=False)
    rows = read_table(folders / "runs" / "sw" / "sweep.csv")
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("f5")
        assert sorted(e.path.name for e in app.runs) == ["seed1", "seed2", "sw"]
        index = [e.path.name for e in app.runs].index("sw")
        listed = [str(c) for c in app.query_one("#runs-table").get_row_at(index)]
        assert listed[1:] == ["sw", "sweep", "3 pts"]  # marked as a sweep
        await pilot.press(*["down"] * index, "enter")
        await pilot.pause()
        points = app.query_one("#results-sweep")
        assert points.display and points.has_focus
        cells = [[str(c) for c in points.get_row_at(i)] for i in range(points.row_count)]
        assert fits_width(points), "the sweep table is cut at 80 columns"
        await pilot.press("down", "enter")  # the second point's own run
        await pilot.pause()
        overlay = [e.path for e in app.overlay]
        await pilot.press("up", "space")  # and the first point's, for comparison
        await pilot.pause()
        compared = [e.path for e in app.overlay]
        info = str(app.query_one("#results-info", Static).render())
    assert len(cells) == 3
    for shown, row in zip(cells, rows, strict=True):
        number, hurst, mark, a, b, r2, contacts = shown
        assert int(number) == int(row["point"]) and float(hurst) == float(row["spectrum.params.hurst"])
        assert mark == "✓" and row["status"] == "completed"
        assert _numbers(a)[0] == pytest.approx(float(row["a"]), abs=5e-5)
        assert _numbers(b)[1:] == pytest.approx([float(row["b_lo"]), float(row["b_hi"])], abs=5e-4)
        assert _numbers(r2) == pytest.approx([float(row["r2"])], abs=5e-4)
    point_dirs = [folders / "runs" / "sw" / r["folder"] for r in rows]
    overlay, compared = [p.resolve() for p in overlay], [p.resolve() for p in compared]
    assert overlay == [point_dirs[1]]
    assert compared == [point_dirs[1], point_dirs[0]]
    for folder in point_dirs[:2]:
        summary = json.loads((folder / "summary.json").read_text())
        assert f"a={summary['fit']['a']:.4f}" in info


# ------------------------------------------------------------------ help, README, CLI


def test_help_lists_every_binding_and_the_readme_has_them(registry):
    app = FrictionlabApp(registry=registry)
    keys = [key for _, rows in app.help_groups() for key, _ in rows]
    from frictionlab.tui.app import PresetsPane, ResultsPane, RunPane

    for bindings in (FrictionlabApp.BINDINGS, PresetsPane.BINDINGS, RunPane.BINDINGS, ResultsPane.BINDINGS):
        for binding in bindings:
            for key in binding.key.split(","):
                from textual.binding import Binding

                assert app.get_key_display(Binding(key, binding.action)) in keys
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Terminal UI", 1)[1].split("\n## ", 1)[0]
    for description in {d for _, rows in app.help_groups() for _, d in rows}:
        assert description in section, f"README's key table misses {description!r}"


def test_tui_command_passes_its_folders_and_never_loads_textual_before(tmp_path, monkeypatch):
    import frictionlab.tui

    calls = []
    monkeypatch.setattr(frictionlab.tui, "run_app", lambda *a, **k: calls.append((a, k)) or 0)
    assert main(["tui", "--presets", str(tmp_path), "--runs", str(tmp_path / "r"), "--workers", "1"]) == 0
    assert calls == [((None,), {"presets_dir": str(tmp_path), "runs_dir": str(tmp_path / "r"), "workers": 1})]

    # the headless commands, and `tui` refusing a missing file, never import Textual
    code = (
        "import sys; from frictionlab.cli import main; import frictionlab.tui; "
        f"rc = main(['tui', {str(tmp_path / 'missing.yaml')!r}]); "
        f"rc2 = main(['validate', {str(ROOT / 'presets' / 'quickstart.yaml')!r}]); "
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in {'textual', 'rich'}); "
        "print(rc, rc2, bad)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.stdout.strip().splitlines()[-1] == "3 0 []", result.stderr  # 3: ExitCode.INPUT_FILE
    assert "no such preset file" in result.stderr


POOL_UNDER_TEXTUAL = """
import sys, threading
import frictionlab.tui
from frictionlab.engine import run
from frictionlab.preset import build_scene

class Capture:  # what Textual puts in sys.stderr while an app runs: fileno() is -1
    def write(self, text): return len(text)
    def flush(self): pass
    def fileno(self): return -1

if {prestart}:
    frictionlab.tui.start_process_helpers()  # what run_app does before the app starts
scene = build_scene({{"name": "t", "realizations": 4, "fit": {{"bootstrap": 0}},
    "spectrum": {{"name": "power-law", "params": {{"hurst": 0.8, "points": 256}}}},
    "loading": {{"start": 1, "stop": 5, "steps": 4}}}})
status = []
real, sys.stderr = sys.stderr, Capture()
def work():
    try:
        status.append(run(scene, workers=2).status)
    except Exception as exc:
        status.append(type(exc).__name__)
worker = threading.Thread(target=work)
worker.start(); worker.join()
sys.stderr = real
print(status)
"""


@pytest.mark.skipif(sys.platform != "linux", reason="forkserver start method")
def test_a_process_pool_starts_from_the_app_thread():
    """Found in tmux: a pool run from the app failed with 'bad value(s) in
    fds_to_keep' because Textual's stderr has no file descriptor."""
    for prestart, expected in ((False, "['ValueError']"), (True, "['completed']")):
        result = subprocess.run(
            [sys.executable, "-c", POOL_UNDER_TEXTUAL.format(prestart=prestart)],
            capture_output=True, text=True, timeout=120,
        )
        assert result.stdout.strip().splitlines()[-1] == expected, result.stderr[-2000:]


# ------------------------------------------------------------------ snapshots (80x24)


def _no_blink(pilot):
    for field in pilot.app.query(Input):
        field.cursor_blink = False


def test_snapshot_presets(folders, registry, snap_compare):
    assert snap_compare(make_app(registry), terminal_size=SIZE, run_before=_no_blink)


def test_snapshot_editor_with_a_problem(folders, registry, snap_compare):
    async def edit(pilot):
        await open_first_preset(pilot)
        await type_into(pilot, "field--spectrum--params--hurst", "2.0")
        _no_blink(pilot)

    assert snap_compare(make_app(registry), terminal_size=SIZE, run_before=edit)


def test_snapshot_help(folders, registry, snap_compare):
    assert snap_compare(make_app(registry), press=["f1"], terminal_size=SIZE, run_before=_no_blink)


def test_snapshot_results_overlay(folders, registry, snap_compare):
    make_runs(folders, registry)
    assert snap_compare(
        make_app(registry), press=["f5", "enter", "down", "space"], terminal_size=SIZE, run_before=_no_blink
    )
