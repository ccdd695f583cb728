"""Unsaved edits are never dropped without a question: every way of putting another preset
on the form (Enter on the list, New, Duplicate) asks first, and No keeps the edits."""

import pytest
from textual.widgets import Input

from .conftest import make_app, press_settled, screen_text, started, sync, type_into, wait_until


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

