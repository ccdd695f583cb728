"""Snapshots of the app at 80x24."""



from textual.widgets import Input

from .conftest import (
    SIZE,
    make_app,
    make_runs,
    open_first_preset,
    type_into,
)

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
