"""A run's fit, its points in contact and its caveats on the Run and Results tabs at 60x20,
80x24 and 120x40: whole, never cut at the panel's edge or below it."""

import re
from pathlib import Path
from types import SimpleNamespace

import pytest
import yaml

from frictionlab.tui.text import format_count
from frictionlab.tui.widgets.results import _entry_lines

from ..conftest import merge
from .conftest import SWEEP, TINY, fits_width, make_app, press_settled, run_to_the_end, screen_text, sweep_app, sync

FEW = merge(TINY, {"name": "few", "loading": {"start": 0.0005, "stop": 5.0}})  # caveats: few points in contact


def ended(app):
    """The run the Run tab shows at the end (a sweep's: its last point's): its counts, caveats and fit."""
    run = getattr(app.last_outcome, "last", None) or app.last_outcome
    return run.result.table["contact_count"], run.result.caveats, run.result.fit


def words(text: str) -> str:
    return " ".join(text.split())


@pytest.mark.parametrize("size", [(60, 20), (80, 24), (120, 40)])
@sync
async def test_a_runs_contacts_and_caveats_are_whole_beside_a_plot_that_keeps_its_width(folders, registry, size):
    """The caveats, set beside the fit, made its panel as wide as they were: the plot gone and
    each caveat cut at the tab's edge."""
    (folders / "presets" / "few.yaml").write_text(yaml.safe_dump(FEW))
    app = make_app(registry, preset="presets/few.yaml", workers=1)
    async with app.run_test(size=size) as pilot:
        await run_to_the_end(pilot)
        await pilot.pause()
        screen = screen_text(app)
        chart = app.query_one("#run-chart").size.width
    count, caveats, _ = ended(app)
    assert len(caveats) >= 1
    assert chart >= size[0] // 3, screen
    first, last = format_count(count[0]), format_count(count[-1])
    forms = (f"contacts {first}..{last}", f"{count[0]:.2f} first .. {count[-1]:.2f} last", f"{count[-1]:.2f} at last load")
    assert any(form in screen for form in forms), screen  # as many lines as the plot's rows leave
    if size != (60, 20):  # there the box shows its first lines and scrolls
        for caveat in caveats:
            assert words(f"caveat: {caveat}") in words(screen), screen
    else:
        assert words(f"caveat: {caveats[0]}")[:100] in words(screen), screen


@sync
async def test_a_sweeps_contacts_show_in_the_rows_its_plot_has_at_60x20(folders, registry):
    """A sweep's plot at 60x20 has 7 rows: the fit took them all, its points in contact below, out of sight."""
    app = sweep_app(folders, registry)
    async with app.run_test(size=(60, 20)) as pilot:
        await run_to_the_end(pilot)
        await pilot.pause()
        screen = screen_text(app)
    count, _, _ = ended(app)
    assert f"contacts {format_count(count[0])}..{format_count(count[-1])}" in screen, screen


def rows_on_screen(table, screen: str) -> list[str]:
    """The table's rows whose point number, swept value and contacts are on one line of the screen."""
    lines = [line.split() for line in screen.splitlines()]
    cells = [[str(cell) for cell in table.get_row_at(i)] for i in range(table.row_count)]
    return [row[0] for row in cells if any(line[:2] == row[:2] and row[-1] in line for line in lines)]


@sync
async def test_a_sweeps_table_at_60x20_shows_four_points_with_every_column(folders, registry):
    """At 60x20 the Run tab showed the header and one row of 8 points, and a sideways scroll
    bar: a and b with their intervals pushed R^2 and the contacts out of sight (on the Results
    tab too). There the intervals are left out; the fit beside the plot keeps its contacts."""
    sweep = {**SWEEP, "sweep": {"parameters": {"spectrum.params.hurst": {"start": 0.3, "stop": 1.0, "num": 8}}}}
    app = sweep_app(folders, registry, sweep)
    async with app.run_test(size=(60, 20)) as pilot:
        await run_to_the_end(pilot)
        await pilot.pause()
        table, run_screen = app.query_one("#sweep-table"), screen_text(app)
        run_fits, run_rows = fits_width(table), rows_on_screen(table, run_screen)
        columns = [str(c.label) for c in table.columns.values()]
        await press_settled(pilot, "f5")
        await press_settled(pilot, "enter")
        await pilot.pause()
        points = app.query_one("#results-sweep")
        results_fits, results_rows = fits_width(points), rows_on_screen(points, screen_text(app))
    count, _, _ = ended(app)
    assert run_fits and len(run_rows) >= 4, run_screen
    assert columns == ["#", "hurst", "", "a", "b", "R^2", "contacts"]
    assert f"contacts {format_count(count[0])}..{format_count(count[-1])}" in run_screen, run_screen
    assert results_fits and len(results_rows) == 8


@sync
async def test_a_part_of_the_run_tab_that_grows_or_shrinks_refits_the_sweeps_table(folders, registry):
    """The table was fitted to the tab only when the progress line, an error or the caveats
    changed: fitted to sizes read before a layout (under load), it kept them, 3 of 8 points in
    sight at 60x20 where 4 fit. Any part that changes the plot's rows refits it."""
    sweep = {**SWEEP, "sweep": {"parameters": {"spectrum.params.hurst": {"start": 0.3, "stop": 1.0, "num": 8}}}}
    app = sweep_app(folders, registry, sweep)
    async with app.run_test(size=(60, 20)) as pilot:
        await run_to_the_end(pilot)
        await pilot.pause()
        table, title = app.query_one("#sweep-table"), app.query_one("#run-title")
        fitted = table.styles.max_height.value
        table.styles.max_height = 2  # as fitted to stale sizes
        title.styles.height = 2  # a part above the plot grows: the plot's rows change
        await pilot.pause()
        await pilot.pause()
        grown = table.styles.max_height.value
        title.styles.height = 1
        await pilot.pause()
        await pilot.pause()
        assert table.styles.max_height.value == fitted and grown == fitted - 1, (fitted, grown)
        assert len(rows_on_screen(table, screen_text(app))) >= 4


@sync
async def test_the_results_box_at_60x20_breaks_its_lines_between_numbers(folders, registry):
    """Its 20 columns wrapped `completed 8/8, contacts 1.38..38.6` within the run's name and numbers."""
    (folders / "presets" / "few.yaml").write_text(yaml.safe_dump(FEW))
    app = make_app(registry, preset="presets/few.yaml", workers=1)
    async with app.run_test(size=(60, 20)) as pilot:
        await run_to_the_end(pilot)
        await press_settled(pilot, "f5")
        await press_settled(pilot, "enter")
        await pilot.pause()
        lines = [line.strip() for line in screen_text(app).splitlines()]
        info = app.query_one("#results-info")
        rows, said = info.size.height, str(info.render()).splitlines()
    count, _, fit = ended(app)
    shown = " ".join(line.split("  ")[-1].strip() for line in lines)
    assert f"{format_count(count[0])}..{format_count(count[-1])}" in shown, "\n".join(lines)
    assert f"[{fit.a_ci[0]:.4f}, {fit.a_ci[1]:.4f}]" in shown, "\n".join(lines)
    assert f"R^2={fit.r2:.4f}" in shown, "\n".join(lines)
    assert rows == len(said), said  # each line within the box's columns: none wrapped again by the box


def test_a_status_line_breaks_between_its_parts_in_a_narrow_box():
    """`interrupted 3613/30000,` was one part, wider than the 18 columns of the box at 60x20."""
    entry = SimpleNamespace(contact_counts=(26.5, 326.63), formula="F / (E* h L)", path=Path("quickstart-20261130-014711"),
                            status="interrupted", done=3613, requested=30000, summary={}, fit=None)
    lines = [str(line) for line in _entry_lines(entry, "cyan", 18)]
    assert all(len(line) <= 18 for line in lines), lines
    assert " ".join(" ".join(lines).split()).endswith("interrupted 3613/30000, contacts 26.5..327")


def keys_panel_first_line(app) -> str:
    lines = [line.strip(" ▏") for line in screen_text(app).splitlines()]
    return next((line for line in lines if line), "")


@sync
async def test_the_keys_panel_at_30x8_fits_the_screen_says_how_to_close_it_and_closes(folders, registry):
    """At 30x8 it covered the screen, footer included, 46 columns wide: its keys cut off at the
    left, and nothing in sight said that Esc, F1 or ? closes it."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=(30, 8)) as pilot:
        await press_settled(pilot, "f1")
        panel = app.screen.query_one("HelpPanel")
        inside, first = panel.region.x >= 0 and panel.region.right <= 30, keys_panel_first_line(app)
        keys_shown = "Scroll Up" in screen_text(app) and "↑" in screen_text(app)
        await press_settled(pilot, "escape")
        closed_by_esc = not app.screen.query("HelpPanel")
        await press_settled(pilot, "f1")
        last = ""
        for _ in range(40):  # F1 pages on, then closes it after the last page
            last = keys_panel_first_line(app)
            await press_settled(pilot, "f1")
            if not app.screen.query("HelpPanel"):
                break
        closed_by_f1 = not app.screen.query("HelpPanel")
        await press_settled(pilot, "question_mark")
        await press_settled(pilot, "question_mark")
        closed_by_question_mark = not app.screen.query("HelpPanel")
    assert inside and keys_shown, panel.region
    assert first == "Esc closes; F1: next page" and last == "Esc or F1 closes"
    assert closed_by_esc and closed_by_f1 and closed_by_question_mark


@pytest.mark.parametrize("size", [(30, 8), (59, 20)])
@sync
async def test_the_keys_panel_under_60_columns_covers_every_row_and_gives_the_footer_back(folders, registry, size):
    """Under 60 columns the panel split the screen at its whole width: the footer kept one column,
    its ⏎ drawn in the panel's last row in place of the panel's border."""
    app = make_app(registry)
    async with app.run_test(size=size) as pilot:
        await press_settled(pilot, "f1")
        shown = screen_text(app).splitlines()
        await press_settled(pilot, "escape")
        footer = screen_text(app).splitlines()[-1]
    assert all(line.startswith("▏") for line in shown), shown
    assert footer.strip().startswith("⏎ Open"), footer


@pytest.mark.parametrize(("width", "app_keeps", "panel_keeps"), [(60, 30, 30), (70, 35, 35), (80, 32, 46)])
@sync
async def test_the_keys_panel_from_60_columns_leaves_the_app_room_beside_it(folders, registry, width, app_keeps, panel_keeps):
    """In tmux at 60x30: F1 on the Edit tab left the form 14 columns beside the panel (24 at 70),
    its values cut to a letter or two; from 80 columns the panel keeps its 46 so that a key and its
    line sit side by side."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=(width, 24)) as pilot:
        await press_settled(pilot, "f1")
        panel, form = app.screen.query_one("HelpPanel").region, app.query_one("#form").region
        shown = screen_text(app)
    assert form.right <= panel.x and panel.right == width  # side by side, not over the form
    assert form.width >= app_keeps and panel.width >= panel_keeps, (form, panel)
    assert "Scroll Up" in shown and "realizations" in shown


@sync
async def test_a_dialog_taller_than_a_30x8_screen_stays_on_it_and_the_arrows_bring_its_answers(folders, registry):
    """At 30x8 a question (save with problems?) ran past the screen's bottom edge, its answers
    (y, n, Esc) out of reach below it, and no key scrolled it."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=(30, 8)) as pilot:
        await press_settled(pilot, "enter", "ctrl+u", *"bad name", "escape", "ctrl+s")
        dialog = app.screen.query_one(".dialog")
        inside = dialog.region.y >= 0 and dialog.region.bottom <= 7  # the footer takes the last row
        before = screen_text(app)
        await press_settled(pilot, *["down"] * 30)
        after = screen_text(app)
    assert inside, dialog.region
    assert "n / Esc: no" not in before and "n / Esc: no" in after


@sync
async def test_the_new_dialog_at_30x8_shows_its_values_not_only_its_labels(folders, registry):
    """At 30x8 its labels kept 20 of the dialog's 26 columns: the name read 'scene', the file 'prese'."""
    app = make_app(registry)
    async with app.run_test(size=(30, 8)) as pilot:
        await press_settled(pilot, "n")
        text = screen_text(app)
    assert "my-scene" in text and "quickstart" in text, text


@sync
async def test_the_form_at_30x8_keeps_rows_beside_the_help_and_problems(folders, registry):
    """At 30x8 the field's help and the problems took every row: the form showed none of its
    fields, Enter went into a name that could not be seen."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=(30, 8)) as pilot:
        await press_settled(pilot, "enter")
        rows, text = app.query_one("#form").region.height, screen_text(app)
    assert rows >= 2 and any(line.startswith("name") for line in text.splitlines()), text


async def screens_while(pilot, *keys) -> list[str]:
    """The screen, then again after each key of ``keys``."""
    seen = [screen_text(pilot.app)]
    for key in keys:
        await press_settled(pilot, key)
        seen.append(screen_text(pilot.app))
    return seen


@sync
async def test_a_runs_fit_at_30x8_is_reached_on_the_run_and_results_tabs(folders, registry):
    """At 30x8 the Run tab's fit was below the progress, out of sight, and no key scrolled to it;
    the Results tab kept its list 40 columns wide and the plot and its box beside it, off the screen.
    The Run tab scrolls with the arrows; the Results list takes the width, its box under it,
    which Tab goes to and the arrows scroll."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=(30, 8)) as pilot:
        await run_to_the_end(pilot)
        await press_settled(pilot, "f4")
        run_screens = await screens_while(pilot, *["down"] * 20)
        await press_settled(pilot, "f5", "enter")
        listed = screen_text(app)
        results_screens = await screens_while(pilot, "tab", *["down"] * 20)
    _, _, fit = ended(app)
    interval = f"[{fit.a_ci[0]:.4f}, {fit.a_ci[1]:.4f}]"
    assert any(interval in screen and "a = " in screen for screen in run_screens), run_screens[-1]
    assert any(f"R^2 = {fit.r2:.4f}" in screen for screen in run_screens), run_screens[-1]
    assert "✓" in listed and next((folders / "runs").iterdir()).name[-6:] in listed, listed
    assert any(interval in screen for screen in results_screens), "\n=====\n".join(results_screens[:3])
    assert any(f"R^2={fit.r2:.4f}" in screen for screen in results_screens), results_screens[-1]


@sync
async def test_an_open_sweeps_points_at_30x8_are_each_reached_with_the_arrows(folders, registry):
    """At 30x8 an open sweep's points took the rows the list's own row needed, and its sideways
    scroll bar the row of a point: the arrows moved among points none of which was on the screen.
    On the Run tab the sweep's line was cut at 30 columns."""
    app = sweep_app(folders, registry)
    async with app.run_test(size=(30, 8)) as pilot:
        await run_to_the_end(pilot)
        await press_settled(pilot, "f4")
        run_screens = await screens_while(pilot, *["down"] * 6)
        await press_settled(pilot, "f5", "enter")
        screens = await screens_while(pilot, "down", "down")
    sweep = next((folders / "runs").iterdir()).name
    assert any("sweep.png)" in screen for screen in run_screens), run_screens  # its line wrapped, not cut at 30
    assert all(sweep[-6:] in screen for screen in screens), screens[0]
    for number, screen in zip((1, 2, 3), screens, strict=True):
        assert any(line.split()[:1] == [str(number)] and "✓" in line for line in screen.splitlines()), screen


@sync
async def test_the_presets_list_at_30x8_shows_a_presets_whole_name(folders, registry):
    """At 30x8 the list kept its three columns and gave the name 8 (``ben…fig2``): under 60 columns
    the file column is left out (the line under the list names the file) and the name gets the room."""
    for name in ("benad2012-fig2", "exact3d-h08-rolloff"):
        (folders / "presets" / f"{name}.yaml").write_text(yaml.safe_dump({**TINY, "name": name}))
    app = make_app(registry)
    async with app.run_test(size=(30, 8)) as pilot:
        screens = await screens_while(pilot, *["down"] * 3)
    for name in ("benad2012-fig2", "exact3d-h08-rolloff"):
        assert any(name in screen for screen in screens), "\n".join(screens)


@sync
async def test_a_run_at_30x8_shows_its_progress_first(folders, registry):
    """At 30x8 the run's title (two lines) and folder took the rows the status line left: its
    progress bar and counts were below them, out of sight while it ran. The tab starts at the
    progress; Up shows the title."""
    import re

    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=(30, 8)) as pilot:
        await run_to_the_end(pilot)
        await press_settled(pilot, "f4")
        shown = screen_text(app)
        above = await screens_while(pilot, *["up"] * 4)
    assert any(re.fullmatch(r"━{25,}\W?", line.rstrip()) for line in shown.splitlines()), shown  # the bar, 100 %
    assert "completed: 8/8 realizations" in shown.replace(" Run completed", ""), shown
    assert any("small: 8 realizations" in screen for screen in above), above[-1]


@pytest.mark.parametrize("size", [(40, 12), (30, 12)])
@sync
async def test_a_run_at_40x12_shows_its_elapsed_time_and_time_left(folders, registry, size):
    """In tmux at 40x12 the status line's four rows (the run, its pid, that it goes on) left the
    tab five: the title (two), the folder and the bar took four, and the progress line's second
    row, its elapsed time and time left, was cut off below them while the run went on."""
    from .conftest import LONG, wait_until

    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(LONG))
    app = make_app(registry, preset="presets/long.yaml")
    async with app.run_test(size=size) as pilot:
        await press_settled(pilot, "ctrl+r")
        try:
            await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= 4)
            await pilot.pause(1.2)  # a tick: the line as it is redrawn each second
            screen = screen_text(app)
        finally:
            app.followed.process.kill()
    # at 30 columns the line takes three rows: the third, the time left, was cut off (two at most)
    assert re.search(r"elapsed [\d.]+ \w+, left [\d.?]", words(screen)), screen
