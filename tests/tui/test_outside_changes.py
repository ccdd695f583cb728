"""What happens around the TUI while it is open: its preset's file written by another program (an
editor, a second TUI), a presets folder it cannot write in, a run folder removed while shown."""

import contextlib
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from textual.widgets import Static

from frictionlab.options import RunOptions
from frictionlab.runs.detached import lock_held, run_state
from frictionlab.runs.sweep import load_sweep, run_sweep
from frictionlab.tui.widgets import ResultsPane

from ..conftest import merge
from .conftest import (
    LONG, SWEEP, TINY, long_run_going, make_app, numbers_in, press_settled, record_said, runs_app, screen_text, started, status_text, sync, type_into, wait_until,
)


def _seed_written_by_another(folders, seed=41):
    """tiny.yaml as another program leaves it: its seed changed, a comment added."""
    path = folders / "presets" / "tiny.yaml"
    path.write_text("# edited elsewhere\n" + yaml.safe_dump(merge(TINY, {"seed": seed}), sort_keys=False))


@pytest.mark.long
@sync
async def test_ctrl_s_asks_before_it_replaces_a_preset_file_another_program_changed(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        _seed_written_by_another(folders)
        await wait_until(pilot, lambda: "changed on disk" in status_text(app))  # said as it happens
        assert "Ctrl+S asks before replacing it" in status_text(app)
        await type_into(pilot, "field--realizations", "7")
        await pilot.press("escape")
        await press_settled(pilot, "ctrl+s")
        assert "was changed on disk since it was opened here" in screen_text(app)
        await press_settled(pilot, "n")  # kept as the other program wrote it
        assert yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())["seed"] == 41
        assert app.modified
        await press_settled(pilot, "ctrl+s")
        await press_settled(pilot, "y")  # replaced, as asked
        saved = yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())
        assert (saved["seed"], saved["realizations"]) == (TINY["seed"], 7) and not app.modified
        await type_into(pilot, "field--realizations", "8")
        await pilot.press("escape")
        await press_settled(pilot, "ctrl+s")  # its own write since: saved without a question
        assert yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())["realizations"] == 8
        assert status_text(app) == "Saved presets/tiny.yaml"


@pytest.fixture
def read_only_presets(folders, monkeypatch):
    """presets/ refuses every write, as a read-only folder does (the tests may run as root, whom
    a mode does not stop); the user folder, mine/, is not there yet."""
    import frictionlab.tui.saving
    from frictionlab.tui.folders import save_preset

    def refused(path, data, template=None):
        if path.resolve().parent == (folders / "presets").resolve():
            raise OSError(30, "Read-only file system")
        save_preset(path, data, template)

    monkeypatch.setattr(frictionlab.tui.saving, "save_preset", refused)
    monkeypatch.setenv("FRICTIONLAB_PRESETS_DIR", str(folders / "mine"))
    return folders / "mine"


@pytest.mark.long
@sync
async def test_a_preset_that_cannot_be_saved_where_it_is_is_offered_the_user_folder(read_only_presets, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await type_into(pilot, "field--realizations", "7")
        await pilot.press("escape")
        await press_settled(pilot, "ctrl+s")
        assert status_text(app) == (
            "Not saved: presets/tiny.yaml cannot be written (Read-only file system): give another file, e.g. in "
            f"your own presets folder, {read_only_presets}; Esc leaves it unsaved"
        )
        assert app.screen.title_text == "tiny.yaml cannot be written there (Read-only file system): save it as"
        await press_settled(pilot, "enter")  # the user folder, made as it is first saved into
        assert "does not exist" not in screen_text(app)
        assert yaml.safe_load((read_only_presets / "tiny.yaml").read_text())["realizations"] == 7
        assert app.draft_path == read_only_presets / "tiny.yaml" and not app.modified


@pytest.mark.long
@sync
async def test_a_duplicate_that_cannot_be_written_is_asked_another_file_not_sent_to_ctrl_o(read_only_presets, registry):
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "d")
        await press_settled(pilot, "enter")  # presets/tiny-copy.yaml: refused
        assert app.screen.title_text.startswith("tiny-copy.yaml cannot be written there")
        assert "Ctrl+O" not in status_text(app)  # with no preset open, Ctrl+O said only that
        await press_settled(pilot, "enter")
        await wait_until(pilot, lambda: app.draft_path == read_only_presets / "tiny-copy.yaml")
    copied = yaml.safe_load((read_only_presets / "tiny-copy.yaml").read_text())
    assert copied == merge(TINY, {"name": f"{TINY['name']}-copy"})


@pytest.mark.long
@sync
async def test_a_plotted_run_whose_folder_is_removed_is_taken_off_the_plot_and_said(folders, registry):
    app = runs_app(folders, registry)
    async with started(app) as pilot:
        await press_settled(pilot, "f5", "enter", "down", "space")  # both runs plotted
        pane = app.query_one(ResultsPane)
        assert len(app.query_one("#results-chart").series) == 4  # each run's curve and fit
        removed = pane.overlay[0].path
        shutil.rmtree(removed)
        await wait_until(pilot, lambda: len(pane.runs) == 1)  # the list follows the folder
        await pilot.pause()
        info = " ".join(str(app.query_one("#results-info", Static).render()).split())
        assert [entry.path for entry in pane.overlay] == [pane.runs[0].path]
        assert len(app.query_one("#results-chart").series) == 2
        assert info.startswith(f"Removed from disk since opened: {removed.name}. ■ {pane.runs[0].path.name}")
        shutil.rmtree(pane.runs[0].path)
        await wait_until(pilot, lambda: not pane.runs)
        await pilot.pause()
        assert not pane.overlay and "run removed" in screen_text(app)


@pytest.mark.long
@sync
async def test_an_open_sweep_whose_folder_is_removed_leaves_its_table_of_points(folders, registry):
    (folders / "sweep.yaml").write_text(yaml.safe_dump({**SWEEP, "realizations": 2}, sort_keys=False))
    run_sweep(load_sweep(folders / "sweep.yaml", registry=registry), folders / "runs" / "sw", RunOptions(workers=1), plot=False)
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "f5", "enter")  # its points listed, the focus on them
        pane = app.query_one(ResultsPane)
        assert pane.open_sweep is not None and app.query_one("#results-sweep").has_focus
        shutil.rmtree(folders / "runs" / "sw")
        await wait_until(pilot, lambda: not pane.runs)
        await pilot.pause()
        assert pane.open_sweep is None and app.query_one("#results-sweep").row_count == 0
        assert app.query_one("#runs-table").has_focus  # Enter on a point no longer there: nothing left to press
        assert "Removed from disk since opened: sw." in str(app.query_one("#results-info", Static).render())


@pytest.mark.long
@sync
async def test_u_on_the_run_tab_after_the_runs_folder_was_removed_says_so(folders, registry):
    app = make_app(registry)
    with long_run_going(folders, registry) as (process, out):
        async with started(app) as pilot:
            await wait_until(pilot, lambda: app.followed is not None)  # shown live on the Run tab
            process.terminate()  # interrupted: u resumes it
            await wait_until(pilot, lambda: app.followed is None and app.last_resumable)
            shutil.rmtree(out)
            await wait_until(pilot, lambda: not app.last_resumable)  # the footer's u goes with the folder
            await press_settled(pilot, "u")
            said = status_text(app)
            assert not out.exists()  # nothing made again in its place
    assert said == "runs/long was removed from disk: nothing is left to resume; Ctrl+R runs the preset again."


async def count_moves_from_chunks(pilot, app) -> None:
    """Wait until the Run tab's count, read from the run's chunks, has moved on."""
    def stored() -> int:
        return numbers_in(str(app.query_one("#run-stats").render()).split("/")[0])[0]

    await wait_until(pilot, lambda: "stored" in str(app.query_one("#run-stats").render()))
    first = stored()
    await wait_until(pilot, lambda: stored() > first)


@contextlib.contextmanager
def run_in_a_terminal(folders, preset: str, data: dict, started):
    """``frictionlab run presets/PRESET --out runs/STEM`` as a user types it in another terminal
    (it writes no progress file), until ``started(folder)``; killed when the block ends."""
    (folders / "presets" / preset).write_text(yaml.safe_dump(data))
    out = folders / "runs" / Path(preset).stem
    command = [sys.executable, "-m", "frictionlab", "run", f"presets/{preset}", "--out", f"runs/{out.name}",
               "--quiet", "--no-plot", "--workers", "1"]  # fmt: skip
    process = subprocess.Popen(command, cwd=folders, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60.0
        while not started(out):
            assert process.poll() is None and time.monotonic() < deadline, "the run did not start"
            time.sleep(0.05)
        yield out
    finally:
        process.kill()
        process.wait()


@pytest.mark.long
@sync
async def test_a_followed_runs_progress_file_removed_says_so_and_counts_its_chunks(folders, registry):
    """Its folder removed by hand while it runs: the run writes on into the progress file it has
    open and its chunks into the folder made again; the Run tab froze at the count last read."""
    app = make_app(registry)
    with long_run_going(folders, registry) as (process, out):
        async with started(app) as pilot:
            await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done > 0)
            (out / "progress.jsonl").unlink()
            await wait_until(pilot, lambda: "was removed while the run goes on" in status_text(app))
            assert "the count comes from the run's chunks" in status_text(app)
            await count_moves_from_chunks(pilot, app)
            process.terminate()
            await wait_until(pilot, lambda: app.followed is None)


@pytest.mark.long
@sync
async def test_a_run_started_by_frictionlab_run_in_a_terminal_shows_its_count_from_its_chunks(folders, registry):
    """Found by a newcomer: a run started with ``frictionlab run`` in another terminal (it writes no
    progress file) stayed at 0 % on the Run tab until it ended. It is said, and its count moves,
    read from its chunks."""
    def begun(out) -> bool:  # the lock is taken before run.json is written
        return lock_held(out) and (out / "run.json").exists() and (run_state(out).done or 0) > 0

    with run_in_a_terminal(folders, "long.yaml", LONG, begun) as out:
        app = make_app(registry)
        said = record_said(app)  # every message, in order: another may follow this one at once
        async with started(app) as pilot:
            await wait_until(pilot, lambda: any("writes no progress.jsonl" in text for text in said))
            (told,) = [text for text in said if "writes no progress.jsonl" in text]
            assert told.endswith("the count comes from the run's chunks, without a live plot")
            await count_moves_from_chunks(pilot, app)
            assert not (out / "progress.jsonl").exists()


@pytest.mark.long
@sync
async def test_a_sweep_started_in_a_terminal_shows_its_point_and_the_count_its_chunks_hold(folders, registry):
    data = merge(SWEEP, {"realizations": 100_000})
    with run_in_a_terminal(folders, "longsweep.yaml", data, lambda out: list(out.glob("points/01-*/chunks/*"))):
        app = make_app(registry)
        said = record_said(app)
        async with started(app) as pilot:
            await wait_until(pilot, lambda: any("writes no progress.jsonl" in text for text in said))
            await wait_until(pilot, lambda: "stored (read from the run's chunks)" in str(app.query_one("#run-stats").render()))
            point = str(app.query_one("#sweep-point").render())
            await count_moves_from_chunks(pilot, app)
    assert point.startswith("point 1/")


@pytest.mark.long
@sync
async def test_a_read_only_preset_file_is_kept_and_another_file_asked(folders, registry, monkeypatch):
    """Renaming the new text over it replaced a file made read-only (mode 444), made writable."""
    monkeypatch.setenv("FRICTIONLAB_PRESETS_DIR", str(folders / "mine"))
    path = folders / "presets" / "tiny.yaml"
    before = path.read_text()
    path.chmod(0o444)
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await type_into(pilot, "field--realizations", "7")
        await pilot.press("escape")
        await press_settled(pilot, "ctrl+s")
        assert status_text(app).startswith("Not saved: presets/tiny.yaml cannot be written (the file is read-only)")
        assert app.screen.title_text == "tiny.yaml cannot be written there (the file is read-only): save it as"
        await press_settled(pilot, "escape")
        # the dialog gone, the status line no longer says to give another file (found in tmux)
        left = status_text(app)
    assert left == "Not saved: presets/tiny.yaml cannot be written (the file is read-only); nothing was written"
    assert path.read_text() == before and path.stat().st_mode & 0o777 == 0o444


@sync
async def test_the_presets_list_follows_its_folder(folders, registry):
    """A preset file added, rewritten or removed by another program is listed as it is now, without
    r; the highlighted preset stays highlighted as a file is listed above it."""
    from frictionlab.tui.widgets.presets import PresetsPane

    app = make_app(registry)
    async with started(app) as pilot:
        pane = app.query_one(PresetsPane)
        assert [e.path.name for e in pane.presets] == ["tiny.yaml"]
        (folders / "presets" / "added.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": "added"}), sort_keys=False))
        await wait_until(pilot, lambda: [e.path.name for e in pane.presets] == ["added.yaml", "tiny.yaml"], timeout=10.0)
        assert pane.selected().path.name == "tiny.yaml"  # where the cursor was
        (folders / "presets" / "added.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": "renamed"}), sort_keys=False))
        await wait_until(pilot, lambda: pane.presets[0].name == "renamed", timeout=10.0)
        (folders / "presets" / "tiny.yaml").unlink()
        await wait_until(pilot, lambda: [e.path.name for e in pane.presets] == ["added.yaml"], timeout=10.0)
        assert "added.yaml" in screen_text(app)


@sync
async def test_why_a_preset_could_not_be_opened_is_taken_back_once_its_file_is_repaired(folders, registry):
    path = folders / "presets" / "tiny.yaml"
    path.write_text("name: [broken\n")
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "enter")
        assert "Cannot open tiny.yaml: not valid YAML" in status_text(app)
        (folders / "presets" / "other.yaml").write_text(yaml.safe_dump(merge(TINY, {"name": "other"})))
        await wait_until(pilot, lambda: len(app.query_one("PresetsPane").presets) == 2, timeout=10.0)
        assert "Cannot open tiny.yaml" in status_text(app)  # another file: still so
        path.write_text(yaml.safe_dump(TINY, sort_keys=False))  # repaired by another program
        await wait_until(pilot, lambda: status_text(app) == "", timeout=10.0)
        await press_settled(pilot, "enter")  # the cursor stayed on it: it opens now
        assert app.draft_path == Path("presets/tiny.yaml") and not status_text(app)
