"""What a person on a remote terminal met (the keys, the status line, the form, the
Run tab), each read off the screen."""

import yaml
from textual.widgets import DataTable, Input, Static

from ..conftest import merge
from .conftest import SIZE, SWEEP, TINY, make_app, run_to_the_end, screen_text, status_text, sync, type_into, wait_until


@sync
async def test_ctrl_r_with_stop_not_above_start_focuses_the_stop_field(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await type_into(pilot, "field--loading--stop", "0.1")
        await pilot.press("ctrl+r")
        await pilot.pause()
        focused = app.focused.id
        said = status_text(app)
    assert said.startswith("Cannot run: 1 problem: loading: stop must be > start")
    assert focused == "field--loading--stop"


@sync
async def test_the_status_line_takes_back_valid_when_a_new_problem_appears(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await type_into(pilot, "field--loading--stop", "0.1")
        await pilot.press("ctrl+r")
        await pilot.pause()
        await type_into(pilot, "field--loading--stop", "20")
        await pilot.pause()
        valid = status_text(app)
        await type_into(pilot, "field--realizations", "0")
        await pilot.pause()
        after = status_text(app)
        screen = screen_text(app)
    assert valid == "The preset is valid: Ctrl+R runs it."
    assert "1 problem" in screen and "valid" not in after


@sync
async def test_opening_another_preset_clears_the_error_about_the_first(folders, registry):
    (folders / "presets" / "other.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": "other"})))
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await type_into(pilot, "field--loading--stop", "0.1")
        await pilot.press("ctrl+r")
        await pilot.pause()
        before = status_text(app)
        app.modified = False  # no question about the edit: the point is the old message
        await pilot.press("f2")
        await pilot.pause()
        await app.open_preset(folders / "presets" / "other.yaml")
        await pilot.pause()
        after = status_text(app)
    assert before.startswith("Cannot run") and after == ""


@sync
async def test_q_quits_outside_a_text_field_and_ctrl_c_says_how_in_the_status_line(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        app.query_one("#field--name", Input).focus()
        await pilot.press("q")  # typed into the field, not a quit
        await pilot.pause()
        typed = app.query_one("#field--name", Input).value
        await pilot.press("f2", "ctrl+c")  # in a text field Ctrl+C copies
        await pilot.pause()
        said, toasts = status_text(app), len(app.query("Toast"))
        app.modified = False
        await pilot.press("q")
        await pilot.pause()
        quit_by_q = not app.is_running
    assert typed == "smallq"  # and typed at the end of the name: the cursor starts there
    assert said.startswith("Ctrl+Q quits (q too, outside a text field)") and toasts == 0
    assert quit_by_q


@sync
async def test_on_off_switches_say_their_state_in_words(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=(80, 60)) as pilot:
        await pilot.pause()
        state = app.query_one("#field--output--plot--state", Static)
        before = str(state.render())
        app.query_one("#field--output--plot").focus()
        await pilot.press("enter")
        await pilot.pause()
        after = str(state.render())
    assert (before, after) == ("on", "off")


@sync
async def test_a_new_run_shows_no_fit_of_the_run_before(folders, registry):
    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": "long", "realizations": 100_000})))
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        finished = str(app.query_one("#run-fit", Static).render())
        await app.open_preset(folders / "presets" / "long.yaml")
        app.action_start_run()  # Ctrl+R, read before its run has finished a realization
        started = str(app.query_one("#run-fit", Static).render())
        app.followed.cancel()
        await wait_until(pilot, lambda: app.followed is None)
    assert "95% CI" in finished
    assert "(no realization yet)" in started and "95% CI" not in started and "a = " not in started


@sync
async def test_the_sweep_table_takes_a_cursor_and_interim_goes_once_the_sweep_is_over(folders, registry):
    (folders / "presets" / "sweep.yaml").write_text(yaml.safe_dump(SWEEP, sort_keys=False))
    app = make_app(registry, preset="presets/sweep.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        fit = str(app.query_one("#run-fit", Static).render())
        table = app.query_one("#sweep-table", DataTable)
        table.focus()
        await pilot.press("down")
        await pilot.pause()
        row = table.cursor_row
    assert "(interim)" not in fit and "95% CI" in fit
    assert table.cursor_type == "row" and row == 1
