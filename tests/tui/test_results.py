"""The Results tab: runs and sweeps listed, opened and overlaid."""

import json
import re

import pytest
import yaml
from textual.widgets import Static

from frictionlab.options import RunOptions
from frictionlab.runs.sweep import load_sweep, run_sweep
from frictionlab.runs.sweepfiles import read_table
from frictionlab.tui.widgets import ResultsPane

from ..conftest import merge
from .conftest import (
    SWEEP, fits_width, make_app, make_runs, numbers_in, press_settled, run_to_the_end, runs_app, screen_text, started, sync,
)

# ------------------------------------------------------------------ results


@pytest.mark.long  # a TUI session
@sync
async def test_results_lists_opens_and_overlays_runs(folders, registry):
    app = runs_app(folders, registry)
    async with started(app) as pilot:
        await pilot.press("f5")
        assert {entry.path.name for entry in app.query_one(ResultsPane).runs} == {"seed1", "seed2"}
        await pilot.press("enter")
        assert [e.path.name for e in app.query_one(ResultsPane).overlay] == [app.query_one(ResultsPane).runs[0].path.name]
        await pilot.press("down", "space")
        assert {e.path.name for e in app.query_one(ResultsPane).overlay} == {"seed1", "seed2"}
        info = str(app.query_one("#results-info", Static).render())
    for seed in (1, 2):
        summary = json.loads((folders / "runs" / f"seed{seed}" / "summary.json").read_text())
        assert f"a={summary['fit']['a']:.4f}" in info
    # under the runs, once for both, what each symbol of f is
    assert " ".join(info.split()).count(summary["normalisation"]["f"]) == 1
    assert "E* = E / (1 - nu^2) the contact modulus" in summary["normalisation"]["f"]


@pytest.mark.long  # a TUI session
@sync
async def test_space_taking_the_only_run_off_the_plot_says_it_is_hidden_not_that_there_is_no_data(folders, registry):
    """Enter then Space on the same run took it off the overlay, and the plot said "no data yet"
    beside a run whose curve is there: it says the run is hidden, and Space shows it again."""
    app = runs_app(folders, registry)
    async with started(app) as pilot:
        await press_settled(pilot, "f5", "enter", "space")
        name = app.query_one(ResultsPane).runs[0].path.name
        hidden_screen = screen_text(app)
        info = str(app.query_one("#results-info", Static).render())
        plotted_while_hidden = app.query_one("#results-chart").series
        await press_settled(pilot, "space")
        plotted_again = app.query_one("#results-chart").series
    assert "no data yet" not in hidden_screen and "run hidden" in hidden_screen
    assert " ".join(info.split()) == f"{name} is hidden from the plot: Space on its row shows it again; Enter opens a run."
    assert not plotted_while_hidden and plotted_again

@pytest.mark.long  # a TUI session
@sync
async def test_the_results_plot_before_any_run_is_opened_says_none_is_open(folders, registry):
    """The Results tab's plot said "no data yet" beside a list of finished runs: it says
    no run is open (the hint below says how to open one), until Enter opens one."""
    app = runs_app(folders, registry)
    async with started(app) as pilot:
        await press_settled(pilot, "f5")
        first = screen_text(app)
        hint = " ".join(str(app.query_one("#results-info", Static).render()).split())
        await press_settled(pilot, "enter")
        opened = screen_text(app)
    assert "no data yet" not in first and "no run open" in first and "Enter opens a run" in first
    assert "no run open" not in opened
    # and what the list's marks are (a newcomer found them explained nowhere): each mark with its status
    from frictionlab.tui.sweepview import STATUS_MARKS

    for status, mark in STATUS_MARKS.items():
        assert re.search(rf"{re.escape(mark)} (\w+ or )*{status}\b", hint), (status, hint)


async def wheel_read(pilot, region, turns: int = 12) -> list[str]:
    """What the screen shows within ``region`` as the mouse wheel turns down over its bottom
    row, ``turns`` steps, as a terminal sends it (the widget there scrolls, if it can): each
    step's rows joined, without spaces nor a scrollbar's marks (a line wrapped reads whole)."""
    from textual import events

    x, y = region.x + 1, region.bottom - 1
    seen = []
    for _ in range(turns + 1):
        rows = [row[region.x : region.right] for row in screen_text(pilot.app).splitlines()[region.y : region.bottom]]
        seen.append("".join(char for char in "".join(rows) if not char.isspace() and char not in "▁▂▃▄▅▆▇█▍▌▎▏"))
        pilot.app.post_message(events.MouseScrollDown(None, x, y, 0, 0, 0, False, False, False, screen_x=x, screen_y=y))
        await pilot.pause()
    return seen


@pytest.mark.long  # a sweep run first, then a TUI session
@sync
async def test_the_info_box_under_the_plot_is_read_whole_at_60x20(folders, registry):
    """At 60x20 the box under the plot lost its last lines: a run's `b=` line (the box held 8
    rows, the run's lines wrap to 9 there), and beside a sweep's points the box ran 3 rows past
    the plot's own space, cut at the table. Now it takes up to half the plot's column and
    scrolls (with the mouse wheel) the rest."""
    make_runs(folders, registry)
    (folders / "sweep.yaml").write_text(yaml.safe_dump({**SWEEP, "realizations": 3}, sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", RunOptions(workers=1), plot=False)
    (folders / "runs" / "seed1").rename(folders / "runs" / "seed1-with-a-longer-name")  # 9 lines at 60x20
    app = make_app(registry)
    async with started(app, size=(60, 20)) as pilot:
        await press_settled(pilot, "f5")
        names = [entry.path.name for entry in app.query_one(ResultsPane).runs]
        read = {}
        for name in ("seed1-with-a-longer-name", "sw"):
            await press_settled(pilot, "home", *["down"] * names.index(name), "enter")
            await pilot.pause()
            body = app.query_one("#results-body").region
            said = str(app.query_one("#results-info", Static).render()).splitlines()
            read[name] = (said, await wheel_read(pilot, body))
    for name, (said, seen) in read.items():  # each word of the box on the screen at one turn of the wheel or another
        missing = [word for word in " ".join(said).split() if not any(word in step for step in seen)]
        assert len(said) >= 2 and not missing, (name, missing)
    assert said[-1].strip().endswith("Esc goes back to the list.")
    lines = read["seed1-with-a-longer-name"][0]
    b_line = next(i for i, line in enumerate(lines) if "b=0.0150" in line)
    assert lines[b_line + 1].strip().startswith("[")  # b's interval, on a line of its own in 20 columns
    # then what a and b are, and the intervals' level, as the Run tab says them
    definition = next(i for i, line in enumerate(lines) if line.startswith("f = "))
    assert " ".join(lines[b_line + 2:definition]).split() == ["in", "xi", "=", "a", "+", "b", "ln", "f,", "95%", "CI"]
    # last, what each symbol of f is, broken between words within the box
    assert " ".join(lines[definition:]).split()[:4] == ["f", "=", "F", "/"] and "(1 - nu^2)" in " ".join(lines[definition:])

@pytest.mark.long  # a TUI session
@sync
async def test_results_lists_a_sweep_shows_its_points_and_opens_a_points_run(folders, registry):
    make_runs(folders, registry)
    # intervals at 90%: the table says their level (it said 95% whatever the preset's)
    (folders / "sweep.yaml").write_text(yaml.safe_dump(merge(SWEEP, {"fit": {"confidence": 0.9}}), sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", RunOptions(workers=1), plot=False)
    rows = read_table(folders / "runs" / "sw" / "sweep.csv")
    app = make_app(registry)
    async with started(app) as pilot:
        await pilot.press("f5")
        assert sorted(e.path.name for e in app.query_one(ResultsPane).runs) == ["seed1", "seed2", "sw"]
        index = [e.path.name for e in app.query_one(ResultsPane).runs].index("sw")
        listed = [str(c) for c in app.query_one("#runs-table").get_row_at(index)]
        assert listed[1:] == ["sw", "sweep", "3 pts"]  # marked as a sweep
        await press_settled(pilot, *["down"] * index, "enter")
        points = app.query_one("#results-sweep")
        assert points.display and points.has_focus
        cells = [[str(c) for c in points.get_row_at(i)] for i in range(points.row_count)]
        assert [str(c.label) for c in points.columns.values()][3:5] == ["a [90% CI]", "b [90% CI]"]
        assert fits_width(points), "the sweep table is cut at 80 columns"
        await pilot.press("down", "enter")  # the second point's own run
        await pilot.pause()
        overlay = [e.path for e in app.query_one(ResultsPane).overlay]
        await pilot.press("up", "space")  # and the first point's, for comparison
        await pilot.pause()
        compared = [e.path for e in app.query_one(ResultsPane).overlay]
        info = str(app.query_one("#results-info", Static).render())
    assert len(cells) == 3
    for shown, row in zip(cells, rows, strict=True):
        number, hurst, mark, a, b, r2, contacts = shown
        assert int(number) == int(row["point"]) and float(hurst) == float(row["spectrum.params.hurst"])
        assert mark == "✓" and row["status"] == "completed"
        assert numbers_in(a)[0] == pytest.approx(float(row["a"]), abs=5e-5)
        assert numbers_in(b)[1:] == pytest.approx([float(row["b_lo"]), float(row["b_hi"])], abs=5e-4)
        assert numbers_in(r2) == pytest.approx([float(row["r2"])], abs=5e-4)
    point_dirs = [folders / "runs" / "sw" / r["folder"] for r in rows]
    overlay, compared = [p.resolve() for p in overlay], [p.resolve() for p in compared]
    assert overlay == [point_dirs[1]]
    assert compared == [point_dirs[1], point_dirs[0]]
    for folder in point_dirs[:2]:
        summary = json.loads((folder / "summary.json").read_text())
        assert f"a={summary['fit']['a']:.4f}" in info


@pytest.mark.long  # a TUI session over a sweep run first
@sync
async def test_esc_leaves_a_sweeps_points_and_a_damaged_row_opened_after_shows_nothing_of_the_sweep(folders, registry):
    """Esc did not leave the open sweep's table of points (only Shift+Tab did, unlisted), and
    Enter on a damaged row left the sweep's points and a point's plot beside its reason."""
    (folders / "sweep.yaml").write_text(yaml.safe_dump(SWEEP, sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", RunOptions(workers=1), plot=False)
    make_runs(folders, registry)
    (folders / "runs" / "seed1" / "summary.json").write_text("{not json")  # damaged
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "f5")
        names = [e.path.name for e in app.query_one(ResultsPane).runs]
        await press_settled(pilot, *["down"] * names.index("sw"), "enter")
        points = app.query_one("#results-sweep")
        opened = points.display and points.has_focus
        await press_settled(pilot, "enter")  # a point's run drawn
        drawn = bool(app.query_one(ResultsPane).overlay)
        await press_settled(pilot, "escape")
        back = app.query_one("#runs-table").has_focus
        await press_settled(pilot, "home", *["down"] * names.index("seed1"), "enter")
        sweep_shown = app.query_one("#results-sweep").display
        info = str(app.query_one("#results-info", Static).render())
        plotted = app.query_one("#results-chart").series
    assert opened and drawn and back
    assert not sweep_shown and "seed1: damaged" in info
    assert not plotted


@pytest.mark.long  # a TUI session over a sweep run first
@sync
async def test_a_run_opened_after_esc_leaves_a_sweeps_points_is_shown_without_them(folders, registry):
    """In tmux at 80x24: Enter on a sweep, Esc, Enter on a plain run: the plot showed the run,
    and under it the sweep's table of points stayed, as if they were the run's."""
    (folders / "sweep.yaml").write_text(yaml.safe_dump({**SWEEP, "realizations": 3}, sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", RunOptions(workers=1), plot=False)
    make_runs(folders, registry)
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "f5")
        names = [e.path.name for e in app.query_one(ResultsPane).runs]
        await press_settled(pilot, *["down"] * names.index("sw"), "enter")
        opened = app.query_one("#results-sweep").display
        await press_settled(pilot, "escape", "home", *["down"] * names.index("seed1"), "space")
        beside = app.query_one("#results-sweep").display  # Space adds a run beside the points
        await press_settled(pilot, "enter")
        shown, pane, text = app.query_one("#results-sweep").display, app.query_one(ResultsPane), screen_text(app)
    assert opened and beside
    assert not shown and pane.open_sweep is None and "hurst" not in text
    assert [entry.path.name for entry in pane.overlay] == ["seed1"]


@pytest.mark.long  # a sweep run first, then a TUI session
@sync
async def test_esc_over_a_sweeps_points_closes_the_keys_panel_before_it_goes_back(folders, registry):
    """In tmux at 80x24: the keys panel says Esc closes it, but over a sweep's points Esc went
    back to the runs and left the panel up."""
    (folders / "sweep.yaml").write_text(yaml.safe_dump({**SWEEP, "realizations": 3}, sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", RunOptions(workers=1), plot=False)
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "f5", "enter", "f1")
        shown = bool(app.screen.query("HelpPanel"))
        await press_settled(pilot, "escape")
        closed, on_points = not app.screen.query("HelpPanel"), app.query_one("#results-sweep").has_focus
        await press_settled(pilot, "escape")
        back = app.query_one("#runs-table").has_focus
    assert shown and closed and on_points and back


@pytest.mark.long  # a sweep run first, then a TUI session
@sync
async def test_a_sweeps_points_footer_fits_80_columns_whole(folders, registry):
    """The points' footer ('esc Back to the runs' among the list's keys) ran past 80 columns
    with a preset open: Ctrl+S and Ctrl+R were cut from it."""
    (folders / "sweep.yaml").write_text(yaml.safe_dump({**SWEEP, "realizations": 3}, sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", RunOptions(workers=1), plot=False)
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "f5", "enter")
        footer = screen_text(app).splitlines()[-1]
        assert app.query_one("#results-sweep").display
    assert "esc Back" in footer and footer.rstrip().endswith("^r Run")


@pytest.mark.long  # two runs made first, then one in the TUI
@sync
async def test_a_run_made_before_results_is_first_shown_is_the_row_highlighted_there(folders, registry):
    """Ctrl+R, then F5: the row highlighted was the run listed first before, moved down as the
    new run was listed above it, so Enter opened the run before the one just made."""
    make_runs(folders, registry)
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await run_to_the_end(pilot)
        await pilot.pause(0.6)  # the runs folder looked at again (twice a second)
        await press_settled(pilot, "f5", "enter")
        pane = app.query_one(ResultsPane)
        highlighted, opened = pane.highlighted().path, [entry.path for entry in pane.overlay]
        await press_settled(pilot, "down")
        moved = pane.highlighted().path
        app.reload_runs()  # the user's row stays highlighted as the list is read again
        await pilot.pause()
        kept = pane.highlighted().path
    assert highlighted == app.last_out_dir and opened == [app.last_out_dir]
    assert kept == moved != highlighted


@sync
async def test_a_failed_run_opened_says_why_it_failed(folders, registry):
    """A failed run (a sweep's point with no law) opened in Results said `failed 8/8, contacts
    1.12..1.12` and nothing of why; its summary.json says why, with what to change."""
    make_runs(folders, registry)
    why = "no law: every load from 1 to 20 presses the same points; raise the loads or widen their range"
    summary_file = folders / "runs" / "seed2" / "summary.json"
    summary = json.loads(summary_file.read_text())
    summary.update(status="failed", error=why, fit=None)  # as a run with no law writes it
    summary_file.write_text(json.dumps(summary))
    run_file = folders / "runs" / "seed2" / "run.json"
    run_file.write_text(json.dumps({**json.loads(run_file.read_text()), "status": "failed"}))
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "f5")
        names = [entry.path.name for entry in app.query_one(ResultsPane).runs]
        app.query_one("#runs-table").move_cursor(row=names.index("seed2"))
        await press_settled(pilot, "enter")
        box = app.query_one("#results-info", Static)
        info, width = str(box.render()), box.content_size.width
    assert "failed" in info and why in " ".join(info.split())
    # why, broken between words and indented as the box's other lines: wrapped, it went on at the box's edge
    lines = info.splitlines()
    definition = next(i for i, line in enumerate(lines) if line.startswith("f = "))  # what f is, under the runs
    assert all(line.startswith("  ") and len(line) <= width for line in lines[1:definition]), lines
    assert all(len(line) <= width for line in lines[definition:]), lines


@sync
async def test_the_runs_list_at_40x12_keeps_its_rows_in_sight_beside_an_open_sweep(folders, registry):
    """In tmux at 40x12: Enter on a sweep left the list's header over blank rows, its own row
    gone from sight, and so it stayed after Esc went back to the list."""
    make_runs(folders, registry)
    (folders / "sweep.yaml").write_text(yaml.safe_dump(SWEEP, sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", RunOptions(workers=1), plot=False)
    app = make_app(registry)
    async with app.run_test(size=(40, 12)) as pilot:
        await press_settled(pilot, "f5")
        index = [e.path.name for e in app.query_one(ResultsPane).runs].index("sw")
        await press_settled(pilot, *["down"] * index, "enter")
        opened = screen_text(app)
        await press_settled(pilot, "escape")
        back = screen_text(app)
    for screen in (opened, back):
        assert any(line.split()[:2] == ["✓", "sw"] for line in screen.splitlines()), screen


@sync
async def test_a_killed_run_opened_says_how_it_ended_not_that_its_curve_file_is_missing(folders, registry):
    """In tmux: Enter on a run whose process was killed (kill -9: no summary, no curve) said
    "no curve (runs/.../curve.csv: no such curve.csv)", as of a damaged folder, and the footer
    offered Space, which said the same; nothing said it can be resumed."""
    import time

    from frictionlab.runs.detached import run_state
    from frictionlab.tui.widgets.results import ResultsPane as Pane

    from .conftest import start_long_run, status_text

    process, out = start_long_run(folders, registry)
    deadline = time.monotonic() + 60.0
    while (run_state(out).done or 0) < 2:
        assert time.monotonic() < deadline
        time.sleep(0.05)
    process.kill()
    process.wait()
    app = make_app(registry)
    async with app.run_test(size=(80, 24)) as pilot:
        await press_settled(pilot, "f5")
        pane = app.query_one(Pane)
        compare_offered = pane.check_action("compare", ())
        await press_settled(pilot, "enter")
        info = " ".join(str(app.query_one("#results-info", Static).render()).split())
        said = status_text(app)
    assert not compare_offered
    assert "no such" not in info and "interrupted before its results were written" in info, info
    assert "realizations stored; u resumes it" in info and "u resumes it" in said, said


@pytest.mark.long  # a TUI session that runs a sweep
@sync
async def test_enter_on_a_point_of_the_run_tabs_sweep_opens_its_run_on_the_results_tab(folders, registry):
    """In tmux: F1 on the Run tab's table of a finished sweep listed Enter as Select, and Enter on a
    point did nothing (on the Results tab Enter on a point opens its run); Left, Right, Ctrl+PgUp
    and Ctrl+PgDn were listed too, where the table fits the screen and they do nothing."""
    from textual.widgets import TabbedContent

    from .conftest import sweep_app

    app = sweep_app(folders, registry)
    async with started(app) as pilot:
        await run_to_the_end(pilot)
        table = app.query_one("#sweep-table")
        table.focus()
        await pilot.pause()
        listed = {binding.action for _, binding, enabled, _ in app.active_bindings.values() if enabled}
        await press_settled(pilot, "down", "enter")
        await pilot.pause()
        tab = app.query_one("#tabs", TabbedContent).active
        shown = [e.path.resolve() for e in app.query_one(ResultsPane).overlay]
        on_points = app.query_one("#results-sweep").has_focus
        point = app.query_one("#results-sweep").cursor_row
        folder = app.last_out_dir
    second = json.loads((folder / "sweep.json").read_text())["points"][1]["folder"]
    assert (tab, shown, on_points, point) == ("results", [(folder / second).resolve()], True, 1)
    assert not listed & {"cursor_left", "cursor_right", "page_left", "page_right"}


@pytest.mark.long  # a TUI session that runs a sweep, cancelled
@sync
async def test_enter_on_a_finished_point_while_the_sweep_goes_on_opens_its_run(folders, registry):
    """The same while the sweep's next point runs: the TUI quit with a traceback (the last run's
    folder, read there, is set only once a run has ended)."""
    from textual.widgets import TabbedContent

    from .conftest import SWEEP, merge, sweep_app, wait_until

    app = sweep_app(folders, registry, merge(SWEEP, {"sweep": {"parameters": {"realizations": {"values": [4, 100_000]}}}}))
    async with started(app) as pilot:
        await pilot.press("ctrl+r")
        table = app.query_one("#sweep-table")
        await wait_until(pilot, lambda: table.row_count == 1)
        table.focus()
        await pilot.pause()
        await press_settled(pilot, "enter")
        await pilot.pause()
        tab = app.query_one("#tabs", TabbedContent).active
        shown = [e.path.resolve() for e in app.query_one(ResultsPane).overlay]
        folder, running = app.followed.folder, app.is_running
        app.followed.cancel()
        await wait_until(pilot, lambda: app.followed is None)
    first = json.loads((folder / "sweep.json").read_text())["points"][0]["folder"]
    assert (running, tab, shown) == (True, "results", [(folder / first).resolve()])
