"""The TUI and runs in processes of their own: a TUI opened later shows a running run
live; quitting during a run leaves it running or cancels it, as answered, at once."""

import contextlib
import json
import os
import signal
import time

import pytest
import yaml
from textual.widgets import Static

from frictionlab.runs.detached import process_alive, run_state, start_detached, wait_started
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.tui.following import FinishedSweep
from frictionlab.tui.widgets import ResultsPane

from ..conftest import merge
from .conftest import (
    LONG, SIZE, SWEEP, TINY, interrupted_long_run, long_run_going, make_app, numbers_in, press_run, press_settled,
    record_said, screen_text, status_text, sync, wait_until,
)


def stats(app) -> str:
    return str(app.query_one("#run-stats", Static).render())


def end(pid: int) -> None:
    """Stop a test's run that goes on (it would run for minutes)."""
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def wait_for(condition, timeout=60.0):
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.05)


@sync
async def test_a_tui_opened_later_shows_the_running_run_live_and_lists_it(folders, registry):
    with long_run_going(folders, registry) as (process, out):
        app = make_app(registry)
        async with app.run_test(size=SIZE) as pilot:
            await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= 2)
            first = numbers_in(stats(app))[0]
            await wait_until(pilot, lambda: numbers_in(stats(app))[0] > first)  # live: the count moves
            shown, said = screen_text(app), status_text(app)
            await press_settled(pilot, "f5")
            listed = app.query_one(ResultsPane).runs
            results = screen_text(app)
        assert "long: 100000 realizations" in shown and "/100000 realizations" in shown
        assert said.startswith("long is running in runs/long (a process of its own)")
        assert [(e.path.name, e.status) for e in listed] == [("long", "running")]
        assert "▶" in results and "long" in results
        assert process.poll() is None  # the TUI quit; the run goes on
    assert run_state(out).status == "interrupted"  # killed (kill -9): never read as running


@contextlib.asynccontextmanager
async def a_long_run_going(folders, registry, preset: str = "long.yaml", data: dict = LONG):
    """The TUI on a preset of a long run, the run started from it and two realizations done."""
    (folders / "presets" / preset).write_text(yaml.safe_dump(data))
    app = make_app(registry, preset=f"presets/{preset}", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await press_run(pilot)
        await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= 2)
        yield app, pilot


@sync
async def test_quit_during_a_run_asks_and_leaving_it_running_returns_without_waiting(folders, registry):
    async with a_long_run_going(folders, registry) as (app, pilot):
        pid, out = app.followed.pid, app.followed.folder
        await press_settled(pilot, "ctrl+q")
        asked = screen_text(app)
        await pilot.press("escape")  # stay: nothing is cancelled
        await pilot.pause(0.5)
        stayed = app.is_running and app.followed is not None and not app.followed.cancelling
        await press_settled(pilot, "ctrl+q", "l")
        quit_at_once = not app.is_running and process_alive(pid)
    try:
        assert "Leave it running" in asked and "cancel it" in asked and f"pid {pid}" in asked
        assert stayed and quit_at_once
        assert run_state(out).status == "running"  # the TUI is gone, the run is not
        # the shell is told where it went on and how to see it (the screen that said so is gone)
        assert f"pid {pid}" in app.farewell and f"frictionlab follow {out}" in app.farewell
    finally:
        end(pid)


@sync
async def test_a_run_that_ends_while_the_quit_question_is_up_is_asked_about_again(folders, registry):
    """In tmux: q while a run went on, and the run completed under the question, which kept
    saying that it was going (pid N), l to leave it running and c to cancel it."""
    from frictionlab.tui.screens import QuitDuringRunScreen, QuitRunEndedScreen

    async with a_long_run_going(folders, registry) as (app, pilot):
        pid = app.followed.pid
        await press_settled(pilot, "q")
        asked = isinstance(app.screen, QuitDuringRunScreen)
        end(pid)  # it ends (killed here: the question is the same for a run that completed)
        await wait_until(pilot, lambda: isinstance(app.screen, QuitRunEndedScreen), timeout=10.0)
        await pilot.pause()
        again = " ".join(screen_text(app).replace("│", " ").split())
        await press_settled(pilot, "n")  # stay
        stayed = app.is_running and not app.screen.query(".dialog")
        await press_settled(pilot, "q")  # nothing goes on: no question
        quit_at_once = not app.is_running
    assert asked and "has ended meanwhile: nothing is left to leave running or to cancel. Quit now?" in again
    assert stayed and quit_at_once


@sync
async def test_quit_and_cancel_ends_the_run_interrupted_keeping_what_finished(folders, registry):
    async with a_long_run_going(folders, registry) as (app, pilot):
        pid, out = app.followed.pid, app.followed.folder
        await press_settled(pilot, "ctrl+q", "c")
        quit_at_once = not app.is_running
    try:
        wait_for(lambda: not process_alive(pid))
        state = run_state(out)
        assert quit_at_once and state.status == "interrupted" and 2 <= state.done < 100_000
        assert "told to stop" in app.farewell and f"frictionlab resume {out}" in app.farewell
    finally:
        end(pid)


@sync
async def test_unsaved_changes_are_asked_about_first_and_keeping_them_cancels_nothing(folders, registry):
    """Ctrl+Q during a run with unsaved changes: "Quit anyway?" comes first, and n keeps the
    app and the run (the run's question, which can cancel it, comes only for a quit that happens)."""
    async with a_long_run_going(folders, registry) as (app, pilot):
        pid = app.followed.pid
        app.modified = True  # the preset was edited meanwhile
        await press_settled(pilot, "ctrl+q")
        asked = screen_text(app)
        await pilot.press("n")
        await pilot.pause(0.5)
        before = app.last_snapshot.done
        await wait_until(pilot, lambda: app.last_snapshot.done > before)
        after = stats(app)
        still = app.is_running and app.followed is not None and not app.followed.cancelling
        alive = process_alive(pid)
        await pilot.press("ctrl+q", "y")  # now quit: the run's question follows
        await pilot.pause()
        then = screen_text(app)
        await press_settled(pilot, "l")
        left = not app.is_running and process_alive(pid)
    end(pid)
    assert "unsaved changes. Quit anyway?" in asked and "Leave it running" not in asked
    assert still and alive and "cancelling" not in after and "/100000 realizations" in after
    assert "Leave it running" in then and left


@sync
async def test_a_long_solve_shows_its_load_and_the_elapsed_time_moves_between_events(folders, registry):
    """An exact solve reports its loads; between two reports the elapsed time still moves."""
    from frictionlab.compute.engine import RunInfo
    from frictionlab.runs.progresslog import ProgressLog
    from frictionlab.runs.rundir import RunDirectory

    out = folders / "runs" / "exact"
    scene = build_scene(merge(TINY, {"name": "exact", "realizations": 2}), registry=registry)
    with RunDirectory(out) as run_dir:  # this process plays the run: it holds the lock, writes the events
        run_dir.start(scene, resume=False)
        log = ProgressLog(out, clock=lambda: time.time() - 30.0)  # it began 30 s ago
        log.run_started(RunInfo(scene=scene, total=2, workers=1))
        log.load_done(index=0, done=3, total=16)
        app = make_app(registry)
        async with app.run_test(size=SIZE) as pilot:
            await wait_until(pilot, lambda: "load 3/16" in stats(app))
            first = stats(app)
            await pilot.pause(1.2)
            later = stats(app)
        log.close()
    assert first.startswith("0/2 realizations") and "realization 0: load 3/16" in first
    seconds = [float(line.split("elapsed ")[1].split(" s")[0]) for line in (first, later)]
    assert 29.0 < seconds[0] < seconds[1]  # the run's own clock, ticking with no new event


LONG_SWEEP = merge(SWEEP, {"name": "longsweep", "realizations": 100_000})
# a first point that ends at once, a second that runs for minutes: a sweep met halfway
HALFWAY_SWEEP = {**merge(SWEEP, {"name": "halfway"}), "sweep": {"parameters": {"realizations": {"values": [4, 100_000]}}}}


def start_sweep(data, out, registry):
    from frictionlab.runs.sweep import plan_sweep

    sweep = plan_sweep(data, registry=registry)
    process = start_detached(sweep.preset_data, out, RunOptions(workers=1), plot=False)
    wait_started(process, out)
    return process


@sync
async def test_ctrl_r_on_a_sweep_starts_it_detached_and_quit_leave_keeps_it_running(folders, registry):
    from frictionlab.tui.following import FollowedSweep

    async with a_long_run_going(folders, registry, "sweep.yaml", LONG_SWEEP) as (app, pilot):
        followed = app.followed
        pid, out = followed.pid, followed.folder
        shown = screen_text(app)
        await press_settled(pilot, "ctrl+q")
        asked = screen_text(app)
        await press_settled(pilot, "l")
        quit_at_once = not app.is_running and process_alive(pid)
    try:
        assert isinstance(followed, FollowedSweep) and pid != os.getpid()  # a process of its own, not this one
        assert "point 1/3: hurst=0.5" in shown and "/100000 realizations" in shown
        assert "A sweep is going" in asked and "Leave it running" in asked and f"pid {pid}" in asked
        assert quit_at_once
        state = run_state(out)
        assert (state.kind, state.status, state.pid, state.total) == ("sweep", "running", pid, 3)
    finally:
        end(pid)
    wait_for(lambda: not process_alive(pid))
    # killed: read as interrupted once the kernel has let go of its lock (the lock, not a
    # pid, says who runs: that can lag the process's end by a moment), never running after
    wait_for(lambda: run_state(out).status == "interrupted", timeout=10.0)


@sync
async def test_a_tui_opened_later_attaches_to_a_running_sweep_its_table_and_point_live(folders, registry):
    out = folders / "runs" / "halfway"
    process = start_sweep(HALFWAY_SWEEP, out, registry)
    try:
        wait_for(lambda: run_state(out).done == 1)  # the first point is over, the second runs
        app = make_app(registry)
        async with app.run_test(size=SIZE) as pilot:
            await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= 2)
            first = app.last_snapshot.done
            await wait_until(pilot, lambda: app.last_snapshot.done > first)  # live: the count moves
            table = app.query_one("#sweep-table")
            cells = [[str(c) for c in table.get_row_at(i)] for i in range(table.row_count)]
            shown = screen_text(app)
            await press_settled(pilot, "f5")
            listed = [(e.path.name, e.status) for e in app.query_one(ResultsPane).runs]
            await pilot.press("enter")  # on the running sweep: the Run tab, following it
            await pilot.pause()
            tab = app.query_one("#tabs").active
        rows = json.loads((out / "sweep.json").read_text())["points"]
        assert [c[0] for c in cells] == ["1"] and cells[0][2] == "✓"  # the point that ended, as sweep.json has it
        assert numbers_in(cells[0][3])[0] == pytest.approx(rows[0]["a"], abs=5e-5) and cells[0][1] == "4"
        assert "point 2/2: realizations=100000" in shown and "/100000 realizations" in shown
        assert listed == [("halfway", "running")] and tab == "run"
        assert process.poll() is None  # the TUI quit; the sweep goes on
    finally:
        end(process.pid)
        process.wait()


@sync
async def test_u_on_an_interrupted_sweep_resumes_it_detached(folders, registry):
    from frictionlab.tui.following import FollowedSweep

    out = folders / "runs" / "halfway"
    process = start_sweep(HALFWAY_SWEEP, out, registry)
    wait_for(lambda: run_state(out).done == 1)
    process.kill()  # kill -9: its sweep.json still says running
    process.wait()
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await press_settled(pilot, "f5")
        listed = [(e.path.name, e.status) for e in app.query_one(ResultsPane).runs]
        said_since = record_said(app)  # the resumed process's own warning (chunks it recomputes) may follow
        await pilot.press("u")
        await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.total == 100_000
                         and app.last_snapshot.done >= 2)  # fmt: skip
        followed = app.followed
        said = said_since[0] if said_since else ""
        await pilot.press("ctrl+q", "c")  # cancel it: the test ends
        await pilot.pause()
    try:
        assert listed == [("halfway", "interrupted")]
        assert isinstance(followed, FollowedSweep) and said.startswith("Resuming the sweep halfway into")
        wait_for(lambda: not process_alive(followed.pid))
        state = run_state(out)
        assert (state.status, state.done) == ("interrupted", 1)  # the first point kept, the second resumable
    finally:
        end(followed.pid)


@sync
async def test_a_sweeps_resume_shows_its_done_points_and_the_count_its_next_points_chunks_hold_at_once(folders, registry):
    """Not 0 % of the first point, "starting", and an empty table until its process has begun
    and replayed them (2 s and more under load)."""
    from frictionlab.runs.detached import stored_count

    out = folders / "runs" / "halfway"
    process = start_sweep(HALFWAY_SWEEP, out, registry)
    second = lambda: next(iter((out / "points").glob("02-*")), None)  # noqa: E731
    wait_for(lambda: run_state(out).done == 1 and second() is not None and (second() / "run.json").exists()
             and (run_state(second()).done or 0) >= 20)  # fmt: skip
    os.kill(process.pid, signal.SIGTERM)  # cancelled: what finished of the second point is stored
    process.wait()
    stored, total = stored_count(second())
    assert stored and total == 100_000
    rows = json.loads((out / "sweep.json").read_text())["points"]  # before the resume, which rewrites it
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await press_settled(pilot, "f5")
        app.resume_run(out)  # what the Run tab shows before the resumed process has said anything
        bar = app.query_one("#run-bar")
        shown = (bar.progress, bar.total, stats(app), str(app.query_one("#sweep-point").render()))
        table = app.query_one("#sweep-table")
        cells = [[str(c) for c in table.get_row_at(i)] for i in range(table.row_count)]
        followed = app.followed
        await pilot.press("ctrl+q", "c")  # cancel it: the test ends
        await pilot.pause()
    try:
        assert shown == (stored, total, f"{stored}/{total} realizations stored (resuming)",
                         "point 2/2: realizations=100000")  # fmt: skip
        assert [c[:3] for c in cells] == [["1", "4", "✓"]]
        assert numbers_in(cells[0][3])[0] == pytest.approx(rows[0]["a"], abs=5e-5)
    finally:
        end(followed.pid)


@sync
async def test_u_after_a_cancel_shows_this_invocations_elapsed_time_rate_and_the_restored_count(folders, registry):
    """The resumed run rewrites progress.jsonl, larger than the cancelled run's: the TUI,
    which may read the old file first, must follow the new one from its start."""
    out = interrupted_long_run(folders, registry, done=30)
    restored = run_state(out).done
    time.sleep(3.0)  # the cancelled run's clock would count this
    app = make_app(registry)
    try:
        async with app.run_test(size=SIZE) as pilot:
            await press_settled(pilot, "f5")
            pressed = time.monotonic()
            await pilot.press("u")
            await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= restored + 10)
            shown, waited = stats(app), time.monotonic() - pressed
            followed = app.followed
            await press_settled(pilot, "ctrl+q", "c")
    finally:
        end(followed.pid)
    done, total, kept, rate, elapsed = numbers_in(shown.split(", left")[0])
    assert (total, kept) == (100_000, restored) and f"({restored} restored)" in shown
    assert elapsed <= waited  # this invocation's time, not since the cancelled run began
    new = done - restored  # only what it computed counts in the rate (elapsed is shown to 0.1 s)
    assert new / (elapsed + 0.05) - 0.05 <= rate <= new / max(elapsed - 0.05, 1e-3) + 0.05


@sync
async def test_a_resumed_sweep_has_one_row_a_point_in_the_run_tabs_table_updated_in_place(folders, registry):
    data = {**merge(SWEEP, {"name": "thrice"}), "sweep": {"parameters": {"realizations": {"values": [4, 5_000, 5]}}}}
    out = folders / "runs" / "thrice"
    process = start_sweep(data, out, registry)

    def second_point_begun() -> bool:
        folders = list((out / "points").glob("02-*"))
        return run_state(out).done == 1 and bool(folders) and (folders[0] / "run.json").exists() \
            and (run_state(folders[0]).done or 0) > 0

    wait_for(second_point_begun)
    os.kill(process.pid, signal.SIGTERM)  # cancelled during its second point
    process.wait()
    assert run_state(next((out / "points").glob("02-*"))).done < 5_000, "the second point finished: nothing was tested"
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await press_settled(pilot, "f5")
        await pilot.press("u")
        await wait_until(pilot, lambda: isinstance(app.last_outcome, FinishedSweep), timeout=120)
        await press_settled(pilot, "f4")
        table = app.query_one("#sweep-table")
        cells = [[str(c) for c in table.get_row_at(i)] for i in range(table.row_count)]
    rows = json.loads((out / "sweep.json").read_text())["points"]
    assert [(c[0], c[1], c[2]) for c in cells] == [("1", "4", "✓"), ("2", "5000", "✓"), ("3", "5", "✓")]
    assert [numbers_in(c[3])[0] for c in cells] == pytest.approx([row["a"] for row in rows], abs=5e-5)


@sync
async def test_the_run_tabs_footer_offers_only_the_keys_that_apply_now(folders, registry):
    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(merge(LONG, {"realizations": 20})))
    app = make_app(registry, preset="presets/long.yaml", workers=1)
    footer = lambda: screen_text(app).splitlines()[-1]  # noqa: E731
    async with app.run_test(size=(120, 24)) as pilot:
        await press_settled(pilot, "f4")
        before = footer()
        await press_run(pilot)
        await wait_until(pilot, lambda: app.last_outcome is not None)
        await pilot.pause()
        completed = footer()
        app.query_one("#run-pane").focus()
        (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(LONG))
        await pilot.press("f2", "enter")  # the preset read again: 100000 realizations
        await pilot.pause()
        await press_run(pilot)
        await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.total == 100_000)
        await pilot.pause()
        running = footer()
        await pilot.press("c")
        await wait_until(pilot, lambda: app.last_outcome is not None)
        await pilot.pause()
        cancelled = footer()
    for shown in (before, completed, cancelled):  # Run once (^r), never also as r
        assert "^r Run" in shown and " r Run" not in shown
    assert "^r Run" not in running and " r Run" not in running  # a run going: Run cannot act
    assert "c Cancel" not in before and "u Resume" not in before
    assert "c Cancel" not in completed and "u Resume" not in completed
    assert "c Cancel" in running and "u Resume" not in running
    assert app.last_outcome.status == "interrupted"
    assert "u Resume" in cancelled and "c Cancel" not in cancelled


@sync
async def test_ctrl_c_during_a_run_says_which_key_cancels_it(folders, registry):
    """Ctrl+C, which stops a program in a shell, said only how to quit while a run went on: not
    that c on the Run tab cancels it."""
    async with a_long_run_going(folders, registry) as (app, pilot):
        pid = app.followed.pid
        await press_settled(pilot, "f2", "ctrl+c")
        said = status_text(app)
        await press_settled(pilot, "f4", "c")
        await wait_until(pilot, lambda: app.followed is None)
    wait_for(lambda: not process_alive(pid))  # c did as said
    assert said.startswith("Ctrl+C does not stop the run: c on the Run tab (F4) cancels it, keeping what finished.")


@sync
async def test_a_warning_of_the_run_s_process_shows_in_the_status_line(folders, registry, monkeypatch):
    """The run's process has no terminal: a warning it gives (here: worker processes cannot
    start, so it goes on in its own process) reaches the TUI through its progress log."""
    from ..test_no_semaphores import REFUSING

    (folders / "site").mkdir()
    (folders / "site" / "sitecustomize.py").write_text(REFUSING)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(folders / "site"), *__import__("sys").path]))
    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(LONG))
    app = make_app(registry, preset="presets/long.yaml", workers=2)
    async with app.run_test(size=SIZE) as pilot:
        await press_run(pilot)
        pid = app.followed.pid
        try:
            await wait_until(pilot, lambda: "worker processes cannot start here" in status_text(app), timeout=30.0)
        finally:
            end(pid)


@sync
async def test_a_run_that_ends_as_the_tui_quits_does_not_reach_its_gone_widgets(folders, registry):
    """The app's timers go on while it shuts down: a run that ended then (here: killed) was
    shown on widgets already removed, a traceback on the way out (NoMatches: '#run-stats')."""
    import asyncio

    from frictionlab.tui.app import FOLLOW_SECONDS

    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(LONG))
    app = make_app(registry, preset="presets/long.yaml", workers=1)
    close_all = app._close_all

    async def closing_slowly():  # the widgets go first, then ticks come before the app's own end
        await close_all()
        await asyncio.sleep(4 * FOLLOW_SECONDS)

    app._close_all = closing_slowly
    async with app.run_test(size=SIZE) as pilot:
        await press_run(pilot)
        await wait_until(pilot, lambda: app.followed is not None and app.followed.pid is not None)
        pid = app.followed.pid
        end(pid)
        wait_for(lambda: not process_alive(pid))
    assert app.return_code in (0, None)
