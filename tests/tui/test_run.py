"""A run and a sweep from the Run tab: the headless numbers, cancelling keeps what finished."""

import json
import re
import signal
import threading

import numpy as np
import pytest
import yaml
from textual.widgets import Static

from frictionlab.plugin.hookspecs import hookimpl
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.runs.runner import run_to_folder
from frictionlab.runs.sweep import load_sweep, run_sweep
from frictionlab.runs.sweepfiles import read_table
from frictionlab.tui.widgets import ResultsPane

from ..conftest import merge
from .conftest import (
    SIZE, SWEEP, TINY, fits_width, make_app, numbers_in, post_keys, press_run, press_settled, record_said, run_to_the_end,
    screen_text, started, status_text, sweep_app, sync, wait_until,
)

# ------------------------------------------------------------------ running


@sync
async def test_a_run_shows_the_headless_coefficients(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        shown = str(app.query_one("#run-fit", Static).render())
        out_dir = app.last_out_dir
        runs_listed = [entry.path.name for entry in app.query_one(ResultsPane).runs]

    outcome, _ = run_to_folder(build_scene(TINY, registry=registry), folders / "headless", RunOptions(workers=2))
    fit = outcome.fit
    assert app.last_outcome.fit == fit  # same seed, any worker count: the same numbers
    assert f"a = {fit.a:.4f} [{fit.a_ci[0]:.4f}, {fit.a_ci[1]:.4f}]" in shown
    assert f"b = {fit.b:.4f} [{fit.b_ci[0]:.4f}, {fit.b_ci[1]:.4f}]" in shown
    assert f"R^2 = {fit.r2:.4f}" in shown
    assert f"{outcome.contact_count[-1]:.2f} at last load" in shown
    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["fit"]["a"] == fit.a
    assert runs_listed == [out_dir.name]


NO_LAW = merge(TINY, {"name": "nolaw", "spectrum": {"params": {"rms_height": 1.0e6}}, "loading": {"start": 1.0, "stop": 2.0}})


@sync
async def test_a_run_with_no_law_says_so_once_not_no_realization_yet(folders, registry):
    """Found in tmux: a run that ended with no law (every load pressing the same points) showed
    '(no realization yet)' beside its 8 realizations, the last interim line over its points, and
    under the caveat the same reason again as '0 realization(s) failed; no law: ...'."""
    (folders / "presets" / "nolaw.yaml").write_text(yaml.safe_dump(NO_LAW))
    app = make_app(registry, preset="presets/nolaw.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        fit = str(app.query_one("#run-fit", Static).render())
        error = str(app.query_one("#run-error", Static).render())
        caveats = str(app.query_one("#run-caveats", Static).render())
        series = app.query_one("#run-chart").series
    assert app.last_outcome.fit is None and "no law" in caveats
    assert "(no fit)" in fit and "no realization yet" not in fit
    assert "realization(s) failed" not in error and "no law" not in error  # said once, as the caveat
    assert len(series) == 1  # the mean curve alone, no fitted line


async def u_on_the_run_and_results_tabs(pilot, app) -> tuple[list[str], list[tuple[str, bool]]]:
    """The footer of the Run (F4) and Results (F5) tabs, and what ``u`` said on each (the status
    line, and whether a run started)."""
    footers, said = [], []
    for tab in ("f4", "f5"):
        await press_settled(pilot, tab)
        footers.append(screen_text(app).splitlines()[-1])
        await press_settled(pilot, "u")
        said.append((status_text(app), app.running))
    return footers, said


@sync
async def test_u_on_a_run_with_no_law_says_why_a_resume_cannot_help_and_starts_nothing(folders, registry):
    """In tmux: u on a run that failed with no law (its 8 of 8 realizations finished) resumed it,
    computed nothing and failed again the same way; the footer offered it on the Run and Results tabs."""
    (folders / "presets" / "nolaw.yaml").write_text(yaml.safe_dump(NO_LAW))
    app = make_app(registry, preset="presets/nolaw.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        out_dir = app.last_out_dir
        before = {path.name: path.stat().st_mtime_ns for path in out_dir.iterdir()}
        footers, said = await u_on_the_run_and_results_tabs(pilot, app)
        after = {path.name: path.stat().st_mtime_ns for path in out_dir.iterdir()}
    assert all("Resume" not in footer for footer in footers), footers
    for text, running in said:
        assert not running and text.startswith(f"Cannot resume: {out_dir.name} failed with all its 8 realizations "
                                               "finished: no law: every load"), text  # fmt: skip
        assert "A resume computes nothing new and fails the same way" in text and "raise the loads" in text
    assert after == before  # nothing started, nothing rewritten


NO_LAW_SWEEP = merge(NO_LAW, {"name": "nolawsweep", "spectrum": {"params": {"rms_height": 1.0}},
                              "sweep": {"parameters": {"spectrum.params.rms_height": {"values": [1.0, 1.0e6]}}}})  # fmt: skip


@sync
async def test_u_on_a_sweep_whose_only_failures_are_no_law_fits_says_why_and_starts_nothing(folders, registry):
    """A sweep whose points all ended, the second with no law (8 of 8 realizations finished):
    u resumed it from the Run and Results tabs, computed nothing and failed again the same way."""
    app = sweep_app(folders, registry, NO_LAW_SWEEP)
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        out_dir = app.last_out_dir
        before = {path: path.stat().st_mtime_ns for path in out_dir.rglob("*")}
        footers, said = await u_on_the_run_and_results_tabs(pilot, app)
        after = {path: path.stat().st_mtime_ns for path in out_dir.rglob("*")}
    assert json.loads((out_dir / "sweep.json").read_text())["status"] == "failed"
    assert all("Resume" not in footer for footer in footers), footers
    for text, running in said:
        assert not running and text.startswith(f"Cannot resume: {out_dir.name}: every point ended, and at 1 point all the "
                                               "realizations finished but the fit failed: point 2: no law: every load"), text  # fmt: skip
        assert "A resume computes nothing new and fails the same way" in text
    assert after == before  # nothing started, nothing rewritten


def test_a_sweep_with_a_point_that_can_go_on_stays_resumable(tmp_path, registry):
    """Beside a point with no law, a point interrupted, in error or with a failed realization is
    one a resume computes again: the sweep stays resumable (u offered, its points not refused)."""
    from frictionlab.tui.folders import read_sweep

    run_sweep(load_sweep(_written(tmp_path, NO_LAW_SWEEP), registry=registry), tmp_path / "sw", RunOptions(workers=1), plot=False)
    entry = read_sweep(tmp_path / "sw")
    assert entry.failed_for_good.startswith("point 2: no law: every load")
    for status in ("interrupted", "error"):
        entry = read_sweep(tmp_path / "sw")
        entry.points[0]["status"] = status
        assert entry.failed_for_good == "", status
    summary_path = tmp_path / "sw" / entry.points[1]["folder"] / "summary.json"
    summary = json.loads(summary_path.read_text())
    summary["realizations"]["failed"] = 1
    summary_path.write_text(json.dumps(summary))
    assert read_sweep(tmp_path / "sw").failed_for_good == ""


def _written(folder, data):
    path = folder / "preset.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.mark.parametrize("failed", [0, 8])
def test_a_run_whose_realizations_failed_stays_resumable(tmp_path, failed):
    """A run whose every realization failed (out of memory, say) has 8 of 8 done and an error too,
    but a resume computes the failed ones again: only a run of no failed realization, failed at
    its fit (no law), is one a resume cannot help."""
    from frictionlab.tui.folders import read_run

    error = "no realization finished: 8 failed; the first, #0: MemoryError" if failed else "no law: every load ..."
    summary = {"status": "failed", "error": error, "realizations": {"done": 8, "requested": 8, "failed": failed}}
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    assert read_run(tmp_path).failed_for_good == ("" if failed else error)


def long_run_app(folders, registry):
    """The app on a preset of 100000 realizations: a run that goes on until cancelled."""
    big = merge(TINY, {"name": "long", "realizations": 100_000})
    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(big))
    return make_app(registry, preset="presets/long.yaml", workers=1)


@sync
async def test_cancel_keeps_and_writes_what_finished(folders, registry):
    app = long_run_app(folders, registry)
    async with app.run_test(size=SIZE) as pilot:
        await press_run(pilot)
        await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= 3)
        said_since = record_said(app)
        await pilot.press("c")  # the Run tab has focus
        await wait_until(pilot, lambda: app.last_outcome is not None)
        said = said_since[0] if said_since else ""  # the first thing c said, before the run had ended
        outcome, out_dir = app.last_outcome, app.last_out_dir
        stats = str(app.query_one("#run-stats", Static).render())
    # c is SIGTERM to the run's process, as a kill from a shell: it ends interrupted, resumable
    assert outcome.status == "interrupted" and 3 <= outcome.done < 100_000
    assert said.startswith("Cancelling: ")
    assert stats.startswith(f"interrupted: {outcome.done}/100000")
    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["status"] == "interrupted"
    assert summary["realizations"]["done"] == outcome.done
    with np.load(out_dir / "realizations.npz") as arrays:
        assert arrays["xi"].shape[0] == outcome.done


@sync
async def test_c_on_another_tab_while_a_run_goes_says_where_it_cancels_and_cancels_nothing(folders, registry):
    """In tmux: Ctrl+R, F3, c: nothing happened and nothing said so (c cancels on the Run tab)."""
    app = long_run_app(folders, registry)
    async with app.run_test(size=SIZE) as pilot:
        await press_run(pilot)
        await wait_until(pilot, lambda: app.last_snapshot is not None)
        said = {}
        for tab in ("f3", "f2", "f5"):
            await press_settled(pilot, tab, "c")
            said[tab] = status_text(app)
        going = not app.followed.cancelling
        await press_settled(pilot, "f4", "c")  # the run's own c: cancels it
        await wait_until(pilot, lambda: app.last_outcome is not None)
    assert all(text.startswith("c cancels the run on the Run tab (F4)") for text in said.values()), said
    assert going and app.last_outcome.status == "interrupted"


SOLVING_EARLY = r"realization [1-9]\d*: load [1-4]/8, iteration"  # a later realization, half its loads to go


async def stopped_in_a_solve(pilot, process) -> None:
    """The run's process stopped (SIGSTOP) where the screen, having read all it wrote, shows a
    realization early in its solve: c then lands there. Unstopped, a loaded machine ran the
    realization to its end between the screen's read (every 0.25 s) and c's signal."""
    app = pilot.app
    log = app.followed.folder / "progress.jsonl"
    for _ in range(20):
        await wait_until(pilot, lambda: app.last_snapshot is not None and re.match(SOLVING_EARLY, app.last_snapshot.solving or ""))
        process.send_signal(signal.SIGSTOP)
        await wait_until(pilot, lambda: app.followed.follower.reader.offset == log.stat().st_size)
        read = app.last_snapshot
        await wait_until(pilot, lambda: app.last_snapshot is not read)  # a tick after: the last event read is shown
        # its last event an iteration at load 4 or before: another comes every 0.25 s of solving, the
        # realization's last 4 loads take 0.5 s and more, so it is still being solved
        if re.match(SOLVING_EARLY, app.last_snapshot.solving):
            return
        process.send_signal(signal.SIGCONT)
    raise AssertionError("the run was never stopped early in a solve")


@sync
async def test_a_long_solve_shows_its_iterations_and_cancel_stops_it_within_the_realization(folders, registry):
    from ..test_load_progress import LONG_LOADS

    # 512 x 512: a second or more a realization, so that the run's file, read every 0.25 s, is met
    # within a solve; twelve of them, so that one is met early in its solve even on a fast machine
    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(merge(LONG_LOADS, {"realizations": 12, "spectrum": {"params": {"points": 512}}})))
    app = make_app(registry, preset="presets/long.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await press_run(pilot)
        process = app.followed.process
        try:
            await stopped_in_a_solve(pilot, process)
            solving = app.last_snapshot.solving
            stats = str(app.query_one("#run-stats", Static).render())
            await pilot.press("c")  # SIGTERM to the run's process, answered as it goes on
        finally:
            process.send_signal(signal.SIGCONT)
        await wait_until(pilot, lambda: app.last_outcome is not None)
        outcome, out_dir = app.last_outcome, app.last_out_dir
    assert solving in stats.splitlines()[1] and re.match(r"realization [1-9]\d*: load ", solving)
    index = int(solving.split()[1].rstrip(":"))
    with np.load(out_dir / "realizations.npz") as arrays:
        kept = arrays["index"].tolist()
    # the realization being solved is abandoned, not waited for: never kept, never failed
    assert outcome.status == "interrupted" and index not in kept and outcome.failures == []


@sync
async def test_c_pressed_again_while_cancelling_signals_the_run_once(folders, registry):
    """c stayed in the footer while the run wrote what finished, and pressed again sent a second
    SIGTERM, which stops the run's process at once: its summary, curve and realizations unwritten."""
    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": "long", "realizations": 100_000})))
    app = make_app(registry, preset="presets/long.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await press_run(pilot)
        await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= 3)
        process, signals = app.followed.process, []
        terminate = process.terminate
        process.terminate = lambda: (signals.append("SIGTERM"), terminate())[1]
        said_since = record_said(app)
        # the run's process stopped until both are answered: under load it wrote what finished and ended
        # between the two (a tick of the app's own comes between them), and the second said it had ended
        process.send_signal(signal.SIGSTOP)
        try:
            post_keys(app, ["c", "c"])  # the second at once, while the run is still writing what finished
            await wait_until(pilot, lambda: len(said_since) >= 2)
            await pilot.pause()
            listed = [binding.description for _, binding, _, _ in app.screen.active_bindings.values() if binding.show]
        finally:
            process.send_signal(signal.SIGCONT)
        await wait_until(pilot, lambda: app.last_outcome is not None)
        out_dir = app.last_out_dir
    assert signals == ["SIGTERM"] and "Cancel" not in listed
    said = said_since[1] if len(said_since) > 1 else ""  # what the second c said
    assert said.startswith("Cancelling already: what finished is being written")
    assert json.loads((out_dir / "summary.json").read_text())["status"] == "interrupted"


@sync
async def test_a_sweep_fills_the_table_with_the_rows_of_sweep_csv(folders, registry):
    app = sweep_app(folders, registry, merge(SWEEP, {"fit": {"confidence": 0.9}}))  # the columns say the level
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        table = app.query_one("#sweep-table")
        cells = [[str(c) for c in table.get_row_at(i)] for i in range(table.row_count)]
        columns = [str(c.label) for c in table.columns.values()]
        point_text = str(app.query_one("#sweep-point", Static).render())
        out_dir = app.last_out_dir
        fits = fits_width(table)
    assert app.last_outcome.status == "completed" and point_text.startswith("completed: 3/3 points")
    assert out_dir.parent.name == "runs" and out_dir.name.startswith("tinysweep-")
    assert columns == ["#", "hurst", "", "a [90% CI]", "b [90% CI]", "R^2", "contacts"]
    assert fits, "the sweep table is cut at 80 columns"
    rows = read_table(out_dir / "sweep.csv")
    assert len(cells) == len(rows) == 3
    for shown, row in zip(cells, rows, strict=True):
        number, hurst, status, a, b, r2, contacts = shown
        assert int(number) == int(row["point"]) and float(hurst) == float(row["spectrum.params.hurst"])
        for cell, name in ((a, "a"), (b, "b")):  # the estimate to 4 decimals, its interval to 3
            assert numbers_in(cell)[0] == pytest.approx(float(row[name]), abs=5e-5)
            assert numbers_in(cell)[1:] == pytest.approx([float(row[f"{name}_lo"]), float(row[f"{name}_hi"])], abs=5e-4)
        assert numbers_in(r2) == pytest.approx([float(row["r2"])], abs=5e-4)
        assert numbers_in(contacts) == pytest.approx([float(row["contact_first"]), float(row["contact_last"])], rel=5e-3)
        assert status == "✓" and row["status"] == "completed"
    # the same numbers as a headless sweep of the same preset
    headless = run_sweep(load_sweep(folders / "presets" / "sweep.yaml", registry=registry), folders / "hl", RunOptions(workers=1))
    assert [(float(r["a"]), float(r["b"])) for r in rows] == [  # the sweep's own process wrote them
        (r.outcome.fit.a, r.outcome.fit.b) for r in headless.results
    ]
    assert [r.point.scene.spectrum.params.hurst for r in headless.results] == [0.5, 0.7, 0.9]
    assert (out_dir / "sweep.png").stat().st_size > 0
    assert {p.name for p in (out_dir / "points").iterdir()} == {"01-hurst-0.5", "02-hurst-0.7", "03-hurst-0.9"}


@sync
async def test_cancelling_a_sweep_writes_the_running_points_realizations(folders, registry):
    """c stops the sweep's process (SIGTERM): the point running keeps what finished, ends interrupted."""
    big = merge(SWEEP, {"realizations": 100_000})
    app = sweep_app(folders, registry, big)
    async with app.run_test(size=SIZE) as pilot:
        await press_run(pilot)
        await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= 3)
        await pilot.press("c")
        await wait_until(pilot, lambda: app.last_outcome is not None)
        await pilot.pause()
        table = app.query_one("#sweep-table")
        cells = [[str(c) for c in table.get_row_at(i)] for i in range(table.row_count)]
        out_dir = app.last_out_dir
    assert app.last_outcome.status == "interrupted"
    rows = read_table(out_dir / "sweep.csv")
    assert [r["status"] for r in rows] == ["interrupted", "pending", "pending"]
    assert [c[2] for c in cells] == ["i"]  # only finished points get a row, marked interrupted
    done = int(rows[0]["done"])
    assert 3 <= done < 100_000 and app.last_outcome.finished == 0  # none of its points ended: a resume runs it on
    with np.load(out_dir / rows[0]["folder"] / "realizations.npz") as arrays:
        assert arrays["xi"].shape[0] == done
    assert not (out_dir / "points" / "02-hurst-0.7").exists()


@sync
async def test_u_resumes_a_cancelled_run_to_the_numbers_of_an_uncancelled_one(folders, registry):
    data = merge(TINY, {"realizations": 24})
    scene = build_scene(data, registry=registry)
    cancel = threading.Event()

    class CancelAfterThree:
        @hookimpl
        def realization_done(self, result, done, total):
            if done >= 3:
                cancel.set()

    stopped, _ = run_to_folder(scene, folders / "runs" / "stopped", RunOptions(workers=1), listeners=[CancelAfterThree()], cancel=cancel)
    assert stopped.status == "cancelled" and stopped.done < 24
    app = make_app(registry)
    async with started(app) as pilot:
        await pilot.press("f5", "u")
        await wait_until(pilot, lambda: app.last_outcome is not None)
        outcome, out_dir = app.last_outcome, app.last_out_dir
        await pilot.press("u")  # again: nothing left to do, and it says so
        said = str(app.query_one("#status").render())
    whole, _ = run_to_folder(scene, folders / "whole", RunOptions(workers=1))
    assert out_dir == folders / "runs" / "stopped" or out_dir.resolve() == (folders / "runs" / "stopped").resolve()
    assert outcome.status == "completed" and outcome.done == 24
    assert outcome.fit == whole.fit  # same seed: the same numbers as a run never stopped
    assert said == "stopped is complete: nothing to resume."


@pytest.mark.parametrize("size", [SIZE, (100, 50), (120, 40)])
@sync
async def test_a_finished_sweeps_plot_keeps_its_whole_legend_and_the_room_the_table_does_not_use(folders, registry, size):
    """Found by a tester: once the fit was final (its interval lines added), the legend lost
    its last line; at 120x40 the plot had 9 rows while the table left 20 empty."""
    from frictionlab.tui.following import FinishedSweep

    app = sweep_app(folders, registry)
    async with app.run_test(size=size) as pilot:
        await run_to_the_end(pilot)
        assert isinstance(app.last_outcome, FinishedSweep)
        await press_settled(pilot, "f4")
        legend = str(app.query_one("#run-fit").render()).splitlines()
        table = app.query_one("#sweep-table")
        body_rows, table_rows, points = app.query_one("#run-body").size.height, table.size.height, table.row_count
        shown = screen_text(app)
    assert legend[-1].endswith("at last load") and "CI, bootstrap" in "\n".join(legend)
    assert body_rows >= len(legend) and legend[-1].strip() in shown  # every line of it on screen
    if size != SIZE:  # room enough: the table takes its rows (and header), the plot the rest
        assert table_rows == points + 1
        assert body_rows >= size[1] - 17


@sync
async def test_a_linspace_sweeps_table_keeps_its_contacts_on_an_80_column_screen(folders, registry):
    """hurst 0.3 .. 1.0 in 4 points: its column showed 0.533333333333, and the contacts column
    was cut at 80 columns ('con', '1.1')."""
    sweep = {**SWEEP, "sweep": {"parameters": {"spectrum.params.hurst": {"start": 0.3, "stop": 1.0, "num": 4}}}}
    app = sweep_app(folders, registry, sweep)
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        table = app.query_one("#sweep-table")
        hurst = [str(table.get_row_at(i)[1]) for i in range(table.row_count)]
        fits = fits_width(table)
    assert hurst == ["0.3", "0.533333", "0.766667", "1.0"]
    assert fits, "the sweep table is cut at 80 columns"


@sync
async def test_r_on_the_run_tab_starts_no_run_and_says_what_does(folders, registry):
    """r reloads a list on the Presets and Results tabs: on the Run tab it started a run (an
    hour-long one, for whoever expected a reload); it now says which keys do what."""
    app = make_app(registry, preset="presets/tiny.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await press_settled(pilot, "f4")
        await press_settled(pilot, "r")
        await pilot.pause(0.2)
        running, said, out_dir = app.running, status_text(app), app.last_out_dir
    assert not running and out_dir is None
    assert not list((folders / "runs").glob("*"))  # no run folder made
    assert "Ctrl+R runs the open preset" in said


@sync
async def test_a_finished_run_shows_its_caveats_as_the_cli_prints_them(folders, registry):
    coarse = merge(TINY, {"name": "coarse", "spectrum": {"params": {"short_cutoff": 4.0}}})  # 4 pixels on it
    (folders / "presets" / "coarse.yaml").write_text(yaml.safe_dump(coarse, sort_keys=False))
    app = make_app(registry, preset="presets/coarse.yaml", workers=1)
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        shown = " ".join(str(app.query_one("#run-caveats", Static).render()).split())  # under the plot, wrapped
    assert "caveat: the short cut-off spans 4 pixels" in shown
