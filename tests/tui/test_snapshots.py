"""Snapshots of every screen at 80x24 (the SSH terminal) and 120x40, cursor blink off.

What can change from one run to the next is fixed here: the run folder's time
stamp and the elapsed time. The numbers come from the presets' seeds."""

import pytest
import yaml
from textual.widgets import Input

from frictionlab.options import RunOptions
from frictionlab.runs.sweep import load_sweep, run_sweep

from ..conftest import merge
from .conftest import SIZE, SWEEP, make_app, make_runs, open_first_preset, run_to_the_end, type_into

SIZES = pytest.mark.parametrize("size", [SIZE, (120, 40)], ids=["80x24", "120x40"])


@pytest.fixture(autouse=True)
def steady(monkeypatch):
    """A fixed run folder name and elapsed time, so a snapshot shows the same text each time."""
    import frictionlab.runs.rundir
    import frictionlab.tui.widgets.run

    # the TUI imports it when a run starts (not for its first screen): patched where it is read then
    monkeypatch.setattr(frictionlab.runs.rundir, "new_run_folder", lambda name, runs_dir: runs_dir / f"{name}-run")
    monkeypatch.setattr(frictionlab.tui.widgets.run, "format_duration", lambda seconds: "1.0 s")
    monkeypatch.setattr(
        frictionlab.tui.widgets.run, "progress_text", lambda done, total, failed, elapsed, restored=0: f"{done}/{total} realizations"
    )


def no_blink(pilot):
    for field in pilot.app.screen.query(Input):
        field.cursor_blink = False


async def settle(pilot):
    no_blink(pilot)
    await pilot.pause()


async def run_and_settle(pilot):
    """Ctrl+R, the run (or sweep) to its end, then the screen at rest."""
    await run_to_the_end(pilot)
    await settle(pilot)


@SIZES
def test_snapshot_presets(folders, registry, snap_compare, size):
    assert snap_compare(make_app(registry), terminal_size=size, run_before=settle)


def typed(field: str, text: str, *keys: str):
    """A ``run_before``: the first preset opened, ``text`` typed into ``field``, then ``keys`` pressed."""

    async def run_before(pilot):
        await open_first_preset(pilot)
        await type_into(pilot, field, text)
        if keys:
            await pilot.press(*keys)
        await settle(pilot)

    return run_before


@SIZES
def test_snapshot_editor_with_a_problem(folders, registry, snap_compare, size):
    edit = typed("field--spectrum--params--hurst", "2.0")
    assert snap_compare(make_app(registry), terminal_size=size, run_before=edit)


@SIZES
def test_snapshot_key_panel(folders, registry, snap_compare, size):
    async def keys(pilot):
        await open_first_preset(pilot)
        await pilot.press("f1")
        await settle(pilot)

    assert snap_compare(make_app(registry), terminal_size=size, run_before=keys)


@SIZES
def test_snapshot_new_preset_dialog(folders, registry, snap_compare, size):
    async def new(pilot):
        await pilot.press("n", "ctrl+u", *"fresh")
        await settle(pilot)

    assert snap_compare(make_app(registry), terminal_size=size, run_before=new)


@SIZES
def test_snapshot_save_with_problems_asks(folders, registry, snap_compare, size):
    save = typed("field--realizations", "0", "ctrl+s")
    assert snap_compare(make_app(registry), terminal_size=size, run_before=save)


@SIZES
def test_snapshot_run_finished(folders, registry, snap_compare, size):
    assert snap_compare(make_app(registry, preset="presets/tiny.yaml"), terminal_size=size, run_before=run_and_settle)


@SIZES
def test_snapshot_sweep_finished(folders, registry, snap_compare, size):
    (folders / "presets" / "sweep.yaml").write_text(yaml.safe_dump(SWEEP, sort_keys=False))

    assert snap_compare(make_app(registry, preset="presets/sweep.yaml"), terminal_size=size, run_before=run_and_settle)


@SIZES
def test_snapshot_results_overlay(folders, registry, snap_compare, size):
    make_runs(folders, registry)

    async def overlay(pilot):
        await pilot.press("f5", "enter", "down", "space")
        await settle(pilot)

    assert snap_compare(make_app(registry), terminal_size=size, run_before=overlay)


@SIZES
def test_snapshot_results_sweep_points(folders, registry, snap_compare, size):
    (folders / "sweep.yaml").write_text(yaml.safe_dump(merge(SWEEP, {"realizations": 3}), sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", RunOptions(workers=1), plot=False)

    async def points(pilot):
        await pilot.press("f5", "enter", "down", "enter")
        await settle(pilot)

    assert snap_compare(make_app(registry), terminal_size=size, run_before=points)
