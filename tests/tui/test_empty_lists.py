"""An empty list (no presets in the folder, no runs yet) lists no key that needs a row."""

from frictionlab.options import RunOptions
from frictionlab.tui.app import FrictionlabApp

from .conftest import press_settled, screen_text, started, status_text, sync, wait_until


def footer(app) -> str:
    return screen_text(app).splitlines()[-1]


@sync
async def test_an_empty_list_offers_no_open_nor_duplicate_and_they_say_why(folders, registry):
    """Enter Open and d Duplicate were listed over an empty Presets list, and Enter Open over
    an empty Results list, each then refused; New is what acts there."""
    (folders / "empty").mkdir()
    app = FrictionlabApp(presets_dir="empty", runs_dir="runs", options=RunOptions(workers=1), registry=registry)
    async with started(app) as pilot:
        presets_footer = footer(app)
        await press_settled(pilot, "enter")
        said_enter = status_text(app)
        await press_settled(pilot, "d")
        said_d = status_text(app)
        await press_settled(pilot, "f5")
        results_footer = footer(app)
        await press_settled(pilot, "enter")
        said_results = status_text(app)
        await press_settled(pilot, "f2", "n")
        await press_settled(pilot, "ctrl+u", *"first", "enter")
        await wait_until(pilot, lambda: app.draft_path is not None)
        await press_settled(pilot, "ctrl+s", "f2")
        with_one = footer(app)
    assert "New" in presets_footer and "Open" not in presets_footer and "Duplicate" not in presets_footer
    assert "Open" not in results_footer
    assert said_enter == "No preset to open here: n makes a new one."
    assert said_d == "No preset to duplicate here: n makes a new one."
    assert said_results.startswith("No runs yet")
    assert (folders / "empty" / "first.yaml").is_file() and "Open" in with_one and "Duplicate" in with_one
