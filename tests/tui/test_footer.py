"""The footer lists only the keys that can act where the user is: on the highlighted row of
Results, with a preset open or not, with a run going or not. A listed key that cannot act
(u Resume on a completed run) sent a newcomer to it for a refusal; unlisted, it still says why."""

import json

import pytest

import yaml

from .conftest import (
    SIZE, SWEEP, TINY, make_app, make_runs, press_settled, screen_text, started, status_text, sync, type_into,
    wait_until,
)


def footer(app) -> str:
    return screen_text(app).splitlines()[-1]


def listed_keys(app) -> list[str]:
    """The descriptions of the keys the footer would list, given the room (the focused part's and the app's)."""
    return [binding.description for _, binding, enabled, _ in app.screen.active_bindings.values() if binding.show]


async def key_panel_words(pilot) -> set[str]:
    """Every word F1's key panel shows, page after page (F1 again) until F1 hides it."""
    words = set()
    await press_settled(pilot, "f1")
    for _ in range(10):
        panels = pilot.app.screen.query("HelpPanel")
        if not panels:
            break
        region = panels.first().region
        rows = screen_text(pilot.app).splitlines()[region.y : region.bottom]
        words |= {word for row in rows for word in row[region.x : region.right].split()}
        await press_settled(pilot, "f1")
    return words


def interrupted_copy(folders, name: str) -> None:
    """A copy of the completed run ``name`` as an interrupted run's summary tells it."""
    import shutil

    copy = folders / "runs" / "stopped"
    shutil.copytree(folders / "runs" / name, copy)
    (copy / "run.json").unlink()  # the summary alone says how it ended
    summary = json.loads((copy / "summary.json").read_text())
    summary["status"] = "interrupted"
    (copy / "summary.json").write_text(json.dumps(summary))


@pytest.mark.long  # two finished runs made first, then a TUI session: seconds (the footer's fast case: save and run below)
@sync
async def test_results_offers_resume_only_on_a_run_that_can_go_on(folders, registry):
    make_runs(folders, registry)
    interrupted_copy(folders, "seed1")
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await press_settled(pilot, "f5")
        pane = app.query_one("ResultsPane")
        rows = {entry.status: row for row, entry in enumerate(pane.runs)}
        table = app.query_one("#runs-table")
        table.move_cursor(row=rows["completed"])
        await pilot.pause()
        on_completed = footer(app)
        table.move_cursor(row=rows["interrupted"])
        await pilot.pause()
        on_interrupted = footer(app)
        table.move_cursor(row=rows["completed"])
        await pilot.pause()
        await pilot.press("u")  # not listed: it still says why
        await pilot.pause()
        said = status_text(app)
    assert "u Resume" not in on_completed and "space Compare" in on_completed
    assert "u Resume" in on_interrupted
    assert "complete: nothing to resume" in said


@sync
async def test_save_and_run_are_listed_once_a_preset_is_open(folders, registry):
    app = make_app(registry)
    async with started(app) as pilot:
        nothing_open = footer(app)
        await pilot.press("ctrl+r")  # not listed: it says why
        await pilot.pause()
        said = status_text(app)
        await pilot.press("enter")
        await wait_until(pilot, lambda: app.draft_path is not None)
        await pilot.pause()
        open_ = footer(app)
    assert "^s Save" not in nothing_open and "^r Run" not in nothing_open
    assert said.startswith("No preset open")
    assert "^s Save" in open_ and "^r Run" in open_


@sync
async def test_the_footer_is_remade_only_when_its_keys_change(folders, registry, monkeypatch):
    """Textual remade the footer (a dozen widgets mounted and styled) on every focus change, most
    often for the keys it already showed: Tab from field to field, each key a form's layout slower.
    Between two text fields it stays; Esc out of the fields (Edit, not Leave field) remakes it."""
    from frictionlab.tui.widgets.footer import KeysFooter

    made = []
    compose = KeysFooter.compose
    monkeypatch.setattr(KeysFooter, "compose", lambda self: (made.append(1), (yield from compose(self)))[1])
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        app.query_one("#field--seed").focus()
        await pilot.pause()
        in_a_field, before = footer(app), len(made)
        await press_settled(pilot, "tab")  # to realizations: a text field too
        tabbed = len(made) - before
        await press_settled(pilot, "escape")
        left, after_esc = footer(app), len(made) - before
    assert tabbed == 0 and after_esc >= 1
    assert "Leave field" in in_a_field and "Leave field" not in left and "Edit" in left


@pytest.mark.long  # a sweep made first, then a TUI session at 60x20: seconds
@sync
async def test_a_60_column_footer_keeps_save_run_and_keys_and_f1_lists_what_it_leaves_out(folders, registry):
    """At 60 columns the footer was cut at the right edge: with a preset open the Presets list's
    `^s Save` and `^r Run`, and a sweep's points' `f1 Keys` too, were past it (they worked, unseen)."""
    from frictionlab.options import RunOptions
    from frictionlab.runs.sweep import load_sweep, run_sweep

    (folders / "sweep.yaml").write_text(yaml.safe_dump({**SWEEP, "realizations": 3}, sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", RunOptions(workers=1), plot=False)
    app = make_app(registry, preset="presets/tiny.yaml")
    seen = {}
    async with started(app, size=(60, 20)) as pilot:
        for where, keys in (("presets", ("f2",)), ("points", ("f5", "enter"))):
            await press_settled(pilot, *keys)
            seen[where] = (footer(app), listed_keys(app), await key_panel_words(pilot))
        assert app.query_one("#results-sweep").has_focus  # the points' footer was read
    for where, (line, listed, panel) in seen.items():
        assert line.rstrip().endswith("^r Run") and "^s Save" in line and "f1 Keys" in line, (where, line)
        left_out = [description for description in listed if description not in line]
        assert len(left_out) < len(listed) / 2, (where, line)  # the focused part's keys are there too
        assert all(set(description.split()) <= panel for description in left_out), (where, left_out)
    assert "Open" in seen["presets"][0] and "Compare" in seen["points"][0]

@pytest.mark.long  # a TUI session with a preset open and edited twice: seconds
@sync
async def test_run_is_listed_only_while_the_open_preset_has_no_problem(folders, registry):
    """Ctrl+R on a preset with a problem is refused (it names the problem and points at the
    field): the footer lists it only while the preset is valid."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        valid = footer(app)
        await type_into(pilot, "field--realizations", "x")
        await wait_until(pilot, lambda: "^r Run" not in footer(app), timeout=10.0)
        await pilot.press("ctrl+r")  # not listed: still says why
        await pilot.pause()
        said = status_text(app)
        await type_into(pilot, "field--realizations", "3")
        await wait_until(pilot, lambda: "^r Run" in footer(app), timeout=10.0)
    assert "^r Run" in valid
    assert said.startswith("Cannot run: 1 problem: realizations")


@pytest.mark.long  # a TUI session through two dialogs: seconds
@sync
async def test_a_dialog_footer_lists_its_own_keys_not_those_of_the_screen_behind(folders, registry):
    """The New dialog's footer said "⏎ Open d Duplicate n New r Reload", the Presets list's
    keys, none of which acts in the dialog; the unsaved-changes question did the same."""
    app = make_app(registry)
    async with started(app) as pilot:
        behind = footer(app)
        await press_settled(pilot, "n")
        on_new = footer(app)
        await press_settled(pilot, "escape", "enter")  # the New dialog closed, tiny opened
        app.modified = True
        await press_settled(pilot, "ctrl+q")
        on_question = footer(app)
        await press_settled(pilot, "n")
    assert "Open" in behind and "Duplicate" in behind  # what neither dialog may list
    assert "⏎ Create" in on_new and "esc Cancel" in on_new, on_new
    assert "y Yes" in on_question and "n No" in on_question, on_question
    for said in (on_new, on_question):
        for key in ("Open", "Duplicate", "New", "Reload", "Save", "Run"):
            assert key not in said, said


# the sweep's case is long (a sweep made first, then a TUI session: seconds); the run's is the same path
@pytest.mark.parametrize("kind", ["run", pytest.param("sweep", marks=pytest.mark.long)])
@sync
async def test_cancel_leaves_the_footer_once_the_runs_last_event_came_while_its_process_closes(folders, registry, kind):
    """A sweep's process writes its last event, then closes (1 to 2 s on a loaded machine); a
    run's draws its plot first: c Cancel stayed listed all that while, with nothing left to
    cancel. Here this process played the run and keeps its folder's lock, as one that is closing."""
    from frictionlab.preset import build_scene
    from frictionlab.runs.progresslog import ProgressLog
    from frictionlab.runs.rundir import RunDirectory
    from frictionlab.runs.runner import run_to_folder
    from frictionlab.runs.sweep import plan_sweep, run_sweep
    from frictionlab.runs.sweeplog import SweepProgressLog

    out = folders / "runs" / kind
    if kind == "sweep":
        log = SweepProgressLog(out)
        run_sweep(plan_sweep(SWEEP, registry=registry), out, listeners=[log], plot=False)
    else:
        log = ProgressLog(out)
        run_to_folder(build_scene(TINY, registry=registry), out, listeners=[log], plot=False)
    log.close()
    app = make_app(registry)
    with RunDirectory(out):  # its lock: the process is still there
        async with started(app) as pilot:
            app.follow_run(out)
            await wait_until(pilot, lambda: app.followed is not None and app.followed.follower.finished is not None)
            await press_settled(pilot, "f4")
            listed = footer(app)
            assert "c Cancel" not in listed  # before c: on main, c signals the lock's holder, this process
            await press_settled(pilot, "c")
            said = status_text(app)
            still_following = app.followed is not None
    assert still_following  # its outcome is read once its process is gone
    assert said == "The run has ended: its files are being written; nothing is left to cancel."


@pytest.mark.long  # two finished runs made first, then a TUI session through the four tabs: seconds
@sync
async def test_a_30_column_footer_shows_whole_keys_and_keeps_f1(folders, registry):
    """At 30 columns the footer ran past the edge and Textual cut its last key to a stray `^`
    (`⏎ Open space Compare f1 Keys ^`): the keys past the edge are left out whole, F1's kept."""
    make_runs(folders, registry)
    app = make_app(registry, preset="presets/tiny.yaml")
    lines = []
    async with started(app, size=(30, 8)) as pilot:
        for keys in (("f2",), ("f3",), ("f4",), ("f5",)):
            await press_settled(pilot, *keys)
            lines.append(footer(app).rstrip())
    for line in lines:
        assert "f1 Keys" in line, lines
        assert line.endswith(("Keys", "Open", "Compare", "Save", "Run", "Edit", "Resume", "Cancel", "New")), lines


@sync
async def test_the_keys_panel_told_of_a_resize_after_its_lines_went_says_nothing(folders, registry):
    """F1 and Esc typed together (or a terminal widened as the panel closes): the resize's update
    of its first line came once Esc had removed its lines, and the app ended in a traceback
    ("NoMatches: No nodes match '#keys-close'"), unsaved edits lost."""
    from frictionlab.tui.widgets.keyspanel import KeysPanel

    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "f1")
        panel = app.screen.query_one(KeysPanel)
        await panel.remove_children()  # as Esc leaves it, the update still queued
        panel.say_close()
        await pilot.pause()
        assert app.is_running
