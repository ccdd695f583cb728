"""What a new user met in a first session at a terminal over SSH, each read off the screen
or the disk: messages and descriptions read whole, no empty folder left by a refused run,
file and preset names checked in the dialogs, a sweep's table inside its tab, one quit
question however often Ctrl+Q is pressed."""

from pathlib import Path

import pytest
import yaml
from textual.geometry import Region
from textual.widgets import DataTable

from frictionlab.preset.schema import NAME_RULE
from frictionlab.tui.running import NO_PRESET
from frictionlab.tui.screens.dialogs import ConfirmScreen, NewPresetScreen, PathScreen, QuitDuringRunScreen

from ..conftest import merge
from .conftest import (
    SWEEP, long_run_going, make_app, open_first_preset, press_settled, run_to_the_end, screen_text, started, status_text, sweep_app, sync,
    type_into, wait_until,
)

pytestmark = pytest.mark.long  # a TUI session each, 2 to 5 s: with the long tests, as the other sessions are


async def refuse_for_memory(pilot):
    """The tiny preset's line made 10^12 points long, then Ctrl+R: refused, as it cannot fit."""
    await type_into(pilot, "field--spectrum--params--points", "1000000000000")
    await press_settled(pilot, "escape", "ctrl+r")


@sync
async def test_a_long_refusal_is_on_screen_whole(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app, size=(80, 24)) as pilot:
        await refuse_for_memory(pilot)
        said = status_text(app)
        screen = " ".join(screen_text(app).split())
    assert said.startswith("Cannot run: this run would need about"), said
    # its advice comes last: the status line kept its first three lines only
    assert said.endswith("an upper bound.)") and "It would fit with" in screen and "an upper bound.)" in screen, screen


@sync
async def test_a_long_refusal_at_60x16_is_read_to_its_end_with_the_wheel(folders, registry):
    """At 60x20 the status line's 40 % cut the refusal's advice ('(run and resume ...'), and no
    wheel nor key brought it. (The advice is shorter now, and fits at 60x20: 16 rows cut it.)"""
    from .test_results import wheel_read

    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app, size=(60, 16)) as pilot:
        await refuse_for_memory(pilot)
        said = "".join(status_text(app).split())
        rows = screen_text(app).splitlines()
        top = next(i for i, row in enumerate(rows) if "Cannot run" in row)
        first = "".join("".join(rows).split())
        seen = await wheel_read(pilot, Region(0, top, 60, 15 - top))  # to the footer
    assert said.endswith("anupperbound.)") and "anupperbound.)" not in first
    assert any(rows.endswith("anupperbound.)") for rows in seen), seen[-1]


@sync
async def test_a_run_refused_leaves_no_folder_behind(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        for _ in range(2):
            await refuse_for_memory(pilot)
        said = status_text(app)
    assert said.startswith("Cannot run"), said
    runs = folders / "runs"
    assert not runs.exists() or list(runs.iterdir()) == []


async def type_path(pilot, path) -> None:
    """``path`` into the open path dialog, then Enter: its last character typed, the rest set
    at once (each key pressed through the pilot costs about 0.1 s, and a tmp path is long)."""
    field = pilot.app.screen.query_one("#path-input")
    field.value = str(path)[:-1]
    field.cursor_position = len(field.value)
    await press_settled(pilot, str(path)[-1], "enter")


@sync
async def test_save_as_a_folder_is_refused_not_saved_beside_it(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "ctrl+o")
        assert isinstance(app.screen, PathScreen)
        await type_path(pilot, folders / "presets")
        still_asking = isinstance(app.screen, PathScreen)
        said = str(app.screen.query_one("#path-error").render())
    assert still_asking and said == f"path: {folders / 'presets'} is a folder; give a file name", said
    assert sorted(p.name for p in folders.iterdir()) == ["presets"]  # no presets.yaml beside the folder


@sync
async def test_the_new_dialog_refuses_a_name_the_form_would(folders, registry):
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "n")
        assert isinstance(app.screen, NewPresetScreen)
        await press_settled(pilot, "ctrl+u", *"my scene", "enter")
        still_asking = isinstance(app.screen, NewPresetScreen)
        said = str(app.screen.query_one("#new-error").render())
        opened = app.query_one("#form").data
    assert still_asking and opened is None, said
    assert said == f"name: {NAME_RULE}, got 'my scene'"
    assert sorted(p.name for p in (folders / "presets").iterdir()) == ["tiny.yaml"]


@sync
async def test_no_preset_open_is_taken_back_once_one_opens(folders, registry):
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "ctrl+s")
        before = status_text(app)
        await open_first_preset(pilot)
        after = status_text(app)
    assert before == NO_PRESET
    assert after == "", after


@sync
async def test_a_sweeps_table_of_eight_points_shows_each_row_at_80x24(folders, registry):
    """Its last rows lay below the tab: 4 of 8 on screen, and the arrows on the table did not reach them."""
    hursts = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]
    app = sweep_app(folders, registry, merge(SWEEP, {"sweep": {"parameters": {"spectrum.params.hurst": {"values": hursts}}}}))
    async with started(app) as pilot:
        await run_to_the_end(pilot)
        await press_settled(pilot, "f4")
        table, pane = app.query_one("#sweep-table", DataTable), app.query_one("RunPane")
        inside = table.region.bottom <= pane.region.bottom
        legend_whole = app.query_one("#run-body").size.height >= len(str(app.query_one("#run-fit").render()).splitlines())
        table.focus()
        await press_settled(pilot, *["down"] * 7)
        last_row = [line for line in screen_text(app).splitlines() if line.split()[:2] == ["8", "1.0"]]
    assert table.row_count == 8 and inside, (table.region, pane.region)
    assert legend_whole and last_row


@pytest.mark.long  # a sweep run in the TUI: seconds (the 80x24 case above stays in the quick suite)
@sync
async def test_a_sweeps_table_shows_rows_at_60x20(folders, registry):
    """At 60x20 the plot kept its 10 rows and pushed the table below the tab: its header alone
    was on screen, and Tab then the arrows showed no row of it."""
    app = sweep_app(folders, registry)
    async with started(app, size=(60, 20)) as pilot:
        await run_to_the_end(pilot)
        await press_settled(pilot, "f4")
        table, pane = app.query_one("#sweep-table", DataTable), app.query_one("RunPane")
        inside, rows = table.region.bottom <= pane.region.bottom, table.size.height
        table.focus()
        await press_settled(pilot, *["down"] * (table.row_count - 1))
        last = str(table.get_row_at(table.row_count - 1)[0])
        screen = screen_text(app)
        rows_shown = [line for line in screen.splitlines() if line.split()[:1] == [last]]
    assert rows >= 3 and inside, rows  # its header and two rows at least
    assert rows_shown, (last, screen)


@sync
async def test_a_duplicate_saved_under_another_file_name_takes_that_name(folders, registry):
    """It stayed '<name>-copy' whatever file it went to: the list showed 'small-copy' beside rough.yaml."""
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "d")
        assert isinstance(app.screen, PathScreen)
        await type_path(pilot, folders / "presets" / "rough.yaml")
        await wait_until(pilot, lambda: app.draft_path is not None and app.draft_path.name == "rough.yaml")
        shown = app.query_one("#form").data["name"]
    saved = yaml.safe_load((folders / "presets" / "rough.yaml").read_text())
    assert saved["name"] == shown == "rough"
    assert yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())["name"] == "small"


@sync
async def test_a_duplicate_saved_where_offered_is_named_copy(folders, registry):
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "d", "enter")
        await wait_until(pilot, lambda: app.draft_path is not None)
    assert yaml.safe_load((folders / "presets" / "tiny-copy.yaml").read_text())["name"] == "small-copy"


@sync
async def test_why_a_run_could_not_start_is_taken_back_once_the_preset_is_edited(folders, registry):
    """It stayed under the fixed preset ('Cannot run: this run would need ...') above 'valid: Ctrl+R runs it'."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await refuse_for_memory(pilot)
        refused = status_text(app)
        await type_into(pilot, "field--spectrum--params--points", "512")
        after = status_text(app)
    assert refused.startswith("Cannot run: this run would need")
    assert after == "", after


@sync
async def test_ctrl_q_twice_asks_once(folders, registry):
    """Pressed again while its question was up, Ctrl+Q stacked a second one: n left the same question."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await type_into(pilot, "field--seed", "8")
        await press_settled(pilot, "escape", "ctrl+q", "ctrl+q")
        asked = isinstance(app.screen, ConfirmScreen)
        await press_settled(pilot, "n")
        after, running = app.screen, app.is_running
    assert asked and running and not isinstance(after, ConfirmScreen), after


@sync
async def test_ctrl_q_twice_during_a_run_asks_once(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    with long_run_going(folders, registry) as (process, _):
        async with started(app) as pilot:
            await wait_until(pilot, lambda: app.followed is not None)
            await press_settled(pilot, "ctrl+q", "ctrl+q")
            asked = isinstance(app.screen, QuitDuringRunScreen)
            await press_settled(pilot, "escape")
            after, running = app.screen, app.is_running
        alive = process.poll() is None
    assert asked and running and alive and not isinstance(after, QuitDuringRunScreen), after


@sync
async def test_a_presets_description_is_shown_whole_at_80x24(folders, registry):
    """Cut at three lines ('... 300 realizations, F'), the study's numbers it ends with unread."""
    shipped = Path(__file__).parents[2] / "presets" / "benad2012-fig5.yaml"
    (folders / "presets" / "fig5.yaml").write_bytes(shipped.read_bytes())
    description = yaml.safe_load(shipped.read_text())["description"].split()
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "home")  # fig5 comes before tiny
        screen = " ".join(screen_text(app).split())
    assert len(" ".join(description)) > 3 * 80  # more than three lines
    assert " ".join(description[-8:]) in screen and " ".join(description[:8]) in screen, screen
