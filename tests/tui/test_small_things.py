"""What a person on a remote terminal met (the keys, the status line, the form, the
Run tab), each read off the screen."""

from pathlib import Path

import pytest
import yaml
from textual.widgets import DataTable, Input, Static

from frictionlab.options import RunOptions
from frictionlab.tui.widgets import PresetsPane

from ..conftest import merge
from .conftest import (
    SIZE, TINY, make_app, press_settled, run_to_the_end, screen_text, started, status_text, sweep_app, sync,
    type_into, wait_until,
)


async def refuse_a_stop_below_the_start(pilot):
    """The tiny preset's stop set to 0.1, below its start, then Ctrl+R: refused."""
    await type_into(pilot, "field--loading--stop", "0.1")
    await press_settled(pilot, "ctrl+r")


@sync
async def test_ctrl_r_with_stop_not_above_start_focuses_the_stop_field(folders, registry):
    """Pressed in the stop field: the focus stays there (the keys typed next fix it); Esc leaves
    it, and Enter goes back in."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await refuse_a_stop_below_the_start(pilot)
        pointed = app.focused.id
        said = status_text(app)
        await press_settled(pilot, "escape")
        left = app.focused.id
        await pilot.press("enter")
        focused = app.focused.id
    assert said.startswith("Cannot run: 1 problem: loading: stop must be > start")
    assert pointed == "field--loading--stop" and left == "form" and focused == "field--loading--stop"


@sync
async def test_the_status_line_takes_back_valid_when_a_new_problem_appears(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await refuse_a_stop_below_the_start(pilot)
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
    async with started(app) as pilot:
        await refuse_a_stop_below_the_start(pilot)
        before = status_text(app)
        app.modified = False  # no question about the edit: the point is the old message
        await press_settled(pilot, "f2")
        await app.open_preset(folders / "presets" / "other.yaml")
        await pilot.pause()
        after = status_text(app)
    assert before.startswith("Cannot run") and after == ""


@sync
async def test_opening_another_preset_takes_back_saved_about_the_first(folders, registry):
    """`Saved presets/tiny.yaml` stayed under the next preset opened, as if that one were saved there."""
    (folders / "presets" / "other.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": "other"})))
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await type_into(pilot, "field--realizations", "3")
        await press_settled(pilot, "ctrl+s")
        before = status_text(app)
        await press_settled(pilot, "f2")
        await app.open_preset(folders / "presets" / "other.yaml")
        await pilot.pause()
        after = status_text(app)
    assert before == "Saved presets/tiny.yaml" and after == ""


@sync
async def test_q_quits_outside_a_text_field_and_ctrl_c_says_how_in_the_status_line(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        app.query_one("#field--name", Input).focus()
        await pilot.press("q")  # typed into the field, not a quit
        await pilot.pause()
        typed = app.query_one("#field--name", Input).value
        await pilot.press("ctrl+c")  # in a text field Ctrl+C copies, and says what quits
        await pilot.pause()
        said_in_field = status_text(app)
        await press_settled(pilot, "f2", "ctrl+c")
        said, toasts = status_text(app), len(app.query("Toast"))
        await press_settled(pilot, "ctrl+s")  # saved: q quits without a question
        await press_settled(pilot, "q")
        quit_by_q = not app.is_running
    assert typed == "smallq"  # and typed at the end of the name: the cursor starts there
    assert said.startswith("Ctrl+Q quits (q too, outside a text field") and toasts == 0
    assert said_in_field.startswith("Ctrl+C copies in a text field. Ctrl+Q quits")
    assert quit_by_q



@sync
async def test_a_watch_tick_after_exit_is_asked_finds_no_pane_to_fill(folders, registry):
    """exit() asked, the panes' children are taken away one by one while the runs folder's
    watch still ticks: it read ResultsPane as there (some children left) and filled a list
    already gone (NoMatches '#runs-table', a failed session)."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await pilot.pause()
        before = app._mounted("ResultsPane")
        app.exit()
        after = app._mounted("ResultsPane")
        app._watch_runs()  # a tick now reads nothing
    assert before is not None and after is None

@sync
async def test_on_off_switches_say_their_state_in_words(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=(80, 60)) as pilot:
        await pilot.pause()
        state = app.query_one("#field--output--plot--state", Static)
        before = str(state.render())
        app.query_one("#field--output--plot").focus()
        await press_settled(pilot, "enter")
        after = str(state.render())
    assert (before, after) == ("on", "off")


@sync
async def test_the_run_tab_shows_no_progress_bar_until_a_run_is_shown(folders, registry):
    """With no run yet the bar had no total and pulsed (`--%`), as if something ran."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await press_settled(pilot, "f4")
        assert "No run yet" in screen_text(app)
        # and where the runs made before are (a newcomer, after a restart, read "No run yet" beside one)
        assert "F5 lists the runs made before" in " ".join(screen_text(app).split())
        assert not app.query_one("#run-bar").display and "--%" not in screen_text(app)
        await run_to_the_end(pilot)
        assert app.query_one("#run-bar").display and "100%" in screen_text(app)


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
    app = sweep_app(folders, registry)
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        fit = str(app.query_one("#run-fit", Static).render())
        table = app.query_one("#sweep-table", DataTable)
        table.focus()
        await press_settled(pilot, "down")
        row = table.cursor_row
    assert "(interim)" not in fit and "95% CI" in fit
    assert table.cursor_type == "row" and row == 1


@sync
async def test_f1_pages_through_the_key_panel_at_80x24_to_save_as_then_hides_it(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        pages = []
        for _ in range(12):
            await press_settled(pilot, "f1")
            if not app.screen.query("HelpPanel"):
                break
            pages.append(screen_text(app))
        hidden = not app.screen.query("HelpPanel")
    assert len(pages) >= 2 and hidden  # more than one page at 80x24, then hidden
    assert "Save a copy" not in pages[0] and any("Save a copy" in page for page in pages)


@sync
async def test_the_key_panel_lists_no_sideways_scroll_on_a_form_that_fits_the_width(folders, registry):
    """Found in tmux: F1 on the Edit tab listed Left, Right, Ctrl+PgUp and Ctrl+PgDn as Scroll
    Left/Right and Page Left/Right (Cursor left/right on the Presets list): the form and the list
    fit the screen's width, and they did nothing."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app, size=(120, 60)) as pilot:
        await press_settled(pilot, "f1")
        shown = screen_text(app)
        form = app.query_one("#form")
        await press_settled(pilot, "right")
        moved = form.scroll_x
        await press_settled(pilot, "f2")  # the Presets list, as wide as its columns: the same
        listed = screen_text(app)
    assert "Scroll Up" in shown and "Page Down" in shown and "Cursor down" in listed
    sideways = ("Scroll Left", "Scroll Right", "Page Left", "Page Right", "Cursor left", "Cursor right")
    assert not any(word in text for word in sideways for text in (shown, listed))
    assert moved == 0


@pytest.mark.parametrize("size", [SIZE, (60, 20)])  # at 60x20 its 45 % of the width cut 'a = 1.1474 [1.0319,'
@sync
async def test_the_fit_panel_keeps_each_interval_on_one_line_at_80_columns(folders, registry, size):
    from frictionlab.compute.fit import LogFit
    from frictionlab.tui.widgets import RunPane
    from frictionlab.tui.widgets.run import fit_lines

    fit = LogFit(a=-12.3456, b=-0.0469, a_se=0.1, b_se=0.01, a_ci=(-12.5678, -12.1234), b_ci=(-0.0712, -0.0231),
                 confidence=0.95, bootstrap=1000, r2=0.4006, residual_rms=0.01, points=16)  # fmt: skip
    app = make_app(registry)
    async with started(app, size=size) as pilot:
        app.action_show_tab("run")
        app.query_one(RunPane)._set("run-fit", "\n".join(fit_lines(fit, final=True, f_formula="F / (E* h L)")))
        await pilot.pause()
        screen = screen_text(app)
    assert "a = -12.3456 [-12.5678, -12.1234]" in screen
    assert "b = -0.0469 [-0.0712, -0.0231]" in screen


@sync
async def test_a_long_preset_name_is_cut_in_its_middle_and_keeps_every_column_on_screen(folders, registry):
    from .conftest import fits_width

    long_name = "a-very-long-preset-name-" + "x" * 55 + "-end-0060"  # 88 characters
    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": long_name, "realizations": 3})))
    app = make_app(registry)
    async with started(app) as pilot:
        table = app.query_one("#preset-table", DataTable)
        cells = [[str(c) for c in table.get_row_at(i)] for i in range(table.row_count)]
        fits = fits_width(table)
        await app.open_preset(folders / "presets" / "long.yaml")
        await pilot.pause()
        app.action_start_run()
        title = str(app.query_one("#run-title", Static).render())
        app.followed.cancel()
        await wait_until(pilot, lambda: app.followed is None)
    assert fits, "a column of the presets list is off screen"
    name, folder, file = next(row for row in cells if row[2] == "long.yaml")
    assert name.startswith("a-very-long") and name.endswith("-end-0060") and "…" in name
    assert folder and file == "long.yaml"
    assert title.startswith("a-very-long") and "-end-0060: 3 realizations, 16 force steps" in title and "…" in title


def test_a_run_name_cut_to_fit_keeps_its_whole_time_stamp_then_its_date_and_time():
    from frictionlab.tui.text import shorten_run_name

    assert shorten_run_name("long-20261127-172222", 20) == "long-20261127-172222"
    assert shorten_run_name("a-longer-study-20261125-210620", 24) == "a-l…tudy-20261125-210620"  # the name's middle
    assert shorten_run_name("long-20261127-172222", 17) == "long…1127-172222"  # then the year: day and time stay
    assert shorten_run_name("quickstart-20261127-172222-2", 17) == "qui…1127-172222-2"  # a second run of that second
    assert shorten_run_name("plain-name-without-stamp-at-all", 17) == "plain-na…p-at-all"  # no stamp: the middle
    for width in range(1, 40):
        cut = shorten_run_name("swp-20261127-172325", width)
        assert len(cut) <= width and (cut == "swp-20261127-172325") == (width >= 19)


def test_contact_counts_read_alike_in_every_row_of_the_sweep_table():
    from frictionlab.tui.sweepview import row_cells
    from frictionlab.tui.text import format_count

    assert [format_count(v) for v in (0.75, 30.64, 621.3, 1350.4, 99.96, 0.0, 123456.0)] == [
        "0.750", "30.6", "621", "1350", "100", "0", "1.23e+05"]  # fmt: skip
    row = {"point": 2, "status": "completed", "a": None, "a_lo": None, "a_hi": None, "b": None, "b_lo": None,
           "b_hi": None, "r2": None, "contact_first": 119.4, "contact_last": 1349.6}  # fmt: skip
    assert row_cells([], row)[-1] == "119..1350"


@sync
async def test_d_on_a_built_in_preset_offers_a_file_it_can_save_and_saves_it(tmp_path, monkeypatch, registry):
    """With no presets folder of the user's yet, the copy goes where n and Ctrl+S save: ./presets, made then."""
    from frictionlab.tui.app import FrictionlabApp

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))  # no user presets folder either
    app = FrictionlabApp(None, runs_dir="runs", options=RunOptions(workers=1), registry=registry)
    async with started(app) as pilot:
        first = app.query_one(PresetsPane).selected().path
        await press_settled(pilot, "d")
        await pilot.press("enter")
        await wait_until(pilot, lambda: app.draft_path is not None, timeout=10.0)
    assert app.draft_path == Path("presets") / f"{first.stem}-copy.yaml"
    assert (tmp_path / "presets" / f"{first.stem}-copy.yaml").is_file()


@sync
async def test_ctrl_z_suspends_to_the_shell_and_fg_draws_the_screen_again(folders, registry, monkeypatch):
    """Ctrl+Z did nothing and said nothing (a shell user's way to step out); the app now sends
    itself SIGTSTP as Textual's suspend does, and redraws once back (Textual re-entered the
    screen and left it blank until a key changed something)."""
    import signal

    import textual.app

    sent, redrawn = [], []
    monkeypatch.setattr(textual.app.os, "kill", lambda pid, sig: sent.append(sig))
    app = make_app(registry)
    async with started(app) as pilot:
        monkeypatch.setattr(type(app._driver), "can_suspend", property(lambda driver: True))
        await press_settled(pilot, "ctrl+z")
        monkeypatch.setattr(app, "refresh", lambda *args, **kwargs: redrawn.append(kwargs) or app)
        app.app_resume_signal.publish(app)  # what the driver's SIGCONT posts once the screen is back
        await pilot.pause()
    assert sent == [signal.SIGTSTP]
    assert {"layout": True} in redrawn


NO_LAW = ("point 2: no law: every load from 1 to 20 presses the same points (mean 1.125 in contact), so xi is "
          "0.245 at every load and a law in ln f is undefined; raise the loads or widen their range")  # fmt: skip


@pytest.mark.parametrize("size", [SIZE, (60, 20)])
@sync
async def test_a_sweep_points_error_is_shown_whole_on_the_run_tab(folders, registry, size):
    """At 80x24 the Run tab showed two lines of a failed point's error: it ended at 'raise the',
    its advice (the loads to change) out of sight, with no way to scroll to it."""
    app = sweep_app(folders, registry)
    async with started(app, size=size) as pilot:
        await press_settled(pilot, "f4")
        app.query_one("RunPane")._error(NO_LAW)
        await pilot.pause()
        shown = " ".join(screen_text(app).split())
    assert "raise the loads or widen their range" in shown
