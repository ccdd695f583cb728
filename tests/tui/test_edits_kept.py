"""Unsaved edits are never dropped without a question: every way of putting another preset
on the form (Enter on the list, New, Duplicate) asks first, and No keeps the edits."""

import pytest
from textual.widgets import Input

from .conftest import make_app, press_settled, screen_text, started, status_text, sync, type_into, wait_until


async def edit_realizations(pilot, value="7"):
    """The open tiny preset's realizations typed as ``value``, then back to the Presets list."""
    await type_into(pilot, "field--realizations", value)
    await press_settled(pilot, "escape", "f2")
    assert pilot.app.modified


def asks_discard(app) -> bool:
    return "unsaved changes. Discard them?" in screen_text(app)


@sync
async def test_new_asks_before_it_replaces_unsaved_edits_and_no_keeps_them(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await edit_realizations(pilot)
        await press_settled(pilot, "n")
        await press_settled(pilot, "ctrl+u", *"other", "enter")
        await wait_until(pilot, lambda: asks_discard(app) or app.draft_path.name != "tiny.yaml")
        asked = asks_discard(app)
        await press_settled(pilot, "n")
        kept = (app.draft_path.name, app.query_one("#field--realizations", Input).value, app.modified)
    assert asked, "New replaced the open preset's unsaved edits without a question"
    assert kept == ("tiny.yaml", "7", True)
    assert not (folders / "presets" / "other.yaml").exists()  # New writes nothing until Ctrl+S


@pytest.mark.long  # a TUI session (the question's fast case: New, above)
@sync
async def test_duplicate_asks_before_it_opens_the_copy_over_unsaved_edits(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await edit_realizations(pilot)
        await press_settled(pilot, "d", "enter")  # the default file, presets/tiny-copy.yaml
        await wait_until(pilot, lambda: asks_discard(app) or app.draft_path.name != "tiny.yaml")
        assert asks_discard(app), "Duplicate opened the copy over the open preset's unsaved edits without a question"
        await press_settled(pilot, "n")
        kept = (app.draft_path.name, app.query_one("#field--realizations", Input).value, app.modified)
        await press_settled(pilot, "d", "enter", "y")  # the copy's copy, over the same edits: y opens it
        await wait_until(pilot, lambda: app.draft_path.name == "tiny-copy-copy.yaml")
    assert kept == ("tiny.yaml", "7", True)
    assert (folders / "presets" / "tiny-copy.yaml").is_file()  # the copy asked for is written either way



def move_to(app, name: str) -> None:
    """The Presets list's cursor on the project preset ``name``."""
    from frictionlab.tui.widgets import PresetsPane

    rows = [entry.path.name for entry in app.query_one(PresetsPane).presets]
    app.query_one("#preset-table").move_cursor(row=rows.index(name))


@pytest.mark.long  # a TUI session
@sync
async def test_enter_on_the_open_preset_shows_it_with_its_edits_and_on_another_asks(folders, registry):
    """Found by a newcomer: Enter on the row of the preset already open asked to discard its
    unsaved edits (y threw them away) where the user only wanted to go back to it."""
    (folders / "presets" / "other.yaml").write_text((folders / "presets" / "tiny.yaml").read_text())
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await edit_realizations(pilot)
        move_to(app, "tiny.yaml")
        await press_settled(pilot, "enter")
        await wait_until(pilot, lambda: app.query_one("#tabs").active == "edit")
        shown = (asks_discard(app), app.draft_path.name, app.query_one("#field--realizations", Input).value, app.modified)
        said = status_text(app)
        await press_settled(pilot, "f2")
        move_to(app, "other.yaml")
        await press_settled(pilot, "enter")
        await wait_until(pilot, lambda: asks_discard(app) or app.draft_path.name != "tiny.yaml")
        asked_for_another = asks_discard(app)
    assert shown == (False, "tiny.yaml", "7", True)
    assert said == "tiny.yaml is open, with unsaved changes: Ctrl+S saves them"
    assert asked_for_another


@pytest.mark.long  # a TUI session
@sync
async def test_a_copy_saved_outside_the_listed_folders_says_it_is_not_listed(folders, registry):
    """Found by a newcomer: `d`, then a bare name (dup2) typed over presets/tiny-copy.yaml, saved
    ./dup2.yaml, said "Saved dup2.yaml", and the list never showed it. It says where the list looks."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "f2")
        move_to(app, "tiny.yaml")
        await press_settled(pilot, "d", "ctrl+u", *"dup2", "enter")
        await wait_until(pilot, lambda: (folders / "dup2.yaml").is_file() and "Saved" in status_text(app))
        outside = status_text(app)
        await press_settled(pilot, "f2")
        move_to(app, "tiny.yaml")
        await press_settled(pilot, "d", "enter")  # the default, presets/tiny-copy.yaml: listed
        await wait_until(pilot, lambda: (folders / "presets" / "tiny-copy.yaml").is_file() and "Saved" in status_text(app))
        inside = status_text(app)
    assert outside == "Saved dup2.yaml (not listed: the Presets list shows the presets in presets)"
    assert inside == "Saved presets/tiny-copy.yaml"
