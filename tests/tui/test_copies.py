"""Ctrl+O (a copy of the open preset) and d (a copy of a listed one): the copy's file is a new
one by default, and its name is no other listed preset's."""

import yaml
from textual.widgets import Input

from frictionlab.tui.widgets.presets import PresetsPane

from ..conftest import merge
from .conftest import TINY, make_app, press_settled, started, sync, wait_until


def listed_names(app) -> list[str]:
    return [entry.name for entry in app.query_one(PresetsPane).presets]


def name_in(path) -> str:
    return yaml.safe_load(path.read_text())["name"]


async def save_a_copy(pilot, app, file_name: str) -> str:
    """Ctrl+O, Enter on the file offered, until the form edits ``file_name``: the file offered."""
    await press_settled(pilot, "ctrl+o")
    offered = app.screen.query_one(Input).value
    await press_settled(pilot, "enter")
    await wait_until(pilot, lambda: app.draft_path.name == file_name)
    return offered


@sync
async def test_ctrl_o_saves_a_copy_under_a_name_of_its_own_and_keeps_the_preset(folders, registry):
    """Ctrl+O offered the preset's own file and kept its name: saved elsewhere, two rows of the
    list had the same name."""
    before = (folders / "presets" / "tiny.yaml").read_text()
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        offered = await save_a_copy(pilot, app, "tiny-copy.yaml")
        await pilot.pause()
        shown, modified, names = app.query_one("#form").data["name"], app.modified, listed_names(app)
        field = app.query_one("#form").query_one("#field--name", Input).value
    assert offered == "presets/tiny-copy.yaml"
    assert name_in(folders / "presets" / "tiny-copy.yaml") == shown == field == "small-copy"
    assert not modified and sorted(names) == ["small", "small-copy"]
    assert (folders / "presets" / "tiny.yaml").read_text() == before


@sync
async def test_ctrl_o_offers_no_file_that_exists_and_no_name_that_is_listed(folders, registry):
    (folders / "presets" / "tiny-copy.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": "other"})))
    (folders / "presets" / "x.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": "small-copy-2"})))
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        offered = await save_a_copy(pilot, app, "tiny-copy-3.yaml")
    assert offered == "presets/tiny-copy-3.yaml"
    assert name_in(folders / "presets" / "tiny-copy-3.yaml") == "small-copy-3"
    assert name_in(folders / "presets" / "tiny-copy.yaml") == "other"


@sync
async def test_ctrl_o_to_a_file_of_your_naming_takes_its_name_unless_a_listed_preset_has_it(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "ctrl+o", "ctrl+u", *"presets/rough", "enter")
        await wait_until(pilot, lambda: app.draft_path.name == "rough.yaml")
        # the file's own name is the original's: the copy is named as offered
        await press_settled(pilot, "ctrl+o", "ctrl+u", *"presets/small", "enter")
        await wait_until(pilot, lambda: app.draft_path.name == "small.yaml")
        await pilot.pause()
        names = listed_names(app)
    assert name_in(folders / "presets" / "rough.yaml") == "rough"
    assert name_in(folders / "presets" / "small.yaml") == "rough-copy"
    assert sorted(names) == ["rough", "rough-copy", "small"]


@sync
async def test_ctrl_o_keeps_a_name_no_listed_preset_has(folders, registry):
    """Renamed in the form first, the copy keeps the name typed."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "enter", "ctrl+u", *"mine", "escape")  # into the name field and out
        await press_settled(pilot, "ctrl+o", "enter")
        await wait_until(pilot, lambda: app.draft_path.name == "tiny-copy.yaml")
    assert name_in(folders / "presets" / "tiny-copy.yaml") == "mine"
    assert name_in(folders / "presets" / "tiny.yaml") == "small"


@sync
async def test_d_offers_a_file_that_is_not_there_yet(folders, registry):
    """d offered <file>-copy.yaml even when it was there: Enter then asked to replace it."""
    (folders / "presets" / "tiny-copy.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": "other"})))
    app = make_app(registry)
    async with started(app) as pilot:
        await wait_until(pilot, lambda: len(listed_names(app)) == 2)
        app.query_one(PresetsPane).highlight(folders / "presets" / "tiny.yaml")
        await press_settled(pilot, "d")
        offered = app.screen.query_one(Input).value
        await press_settled(pilot, "enter")
        await wait_until(pilot, lambda: app.draft_path is not None)
    assert offered == "presets/tiny-copy-2.yaml"
    assert name_in(folders / "presets" / "tiny-copy-2.yaml") == "small-copy-2"
    assert name_in(folders / "presets" / "tiny-copy.yaml") == "other"
