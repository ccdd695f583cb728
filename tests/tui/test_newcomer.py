"""What a first-time user trips over (issue 36), each read from the screen: keys that do
what the footer says, every run listed as it starts, damaged folders named, resume
offered wherever a run can be resumed."""

import subprocess
import shutil
import sys
import time

import pytest
import yaml

from frictionlab.runs.detached import start_detached
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.runs.rundir import new_run_folder
from frictionlab.tui.widgets import ResultsPane

from ..conftest import merge
from .conftest import (
    LONG, SIZE, TINY, interrupted_long_run, long_run_going, make_app, make_runs, numbers_in, press_settled,
    record_said, runs_app, screen_text, started, status_text, sync, wait_until,
)


@pytest.mark.long
@sync
async def test_damaged_run_folders_are_listed_with_their_reason(folders, registry):
    make_runs(folders, registry)
    runs = folders / "runs"
    shutil.copytree(runs / "seed1", runs / "seed3")  # a completed run whose manifest is then cut short
    (runs / "seed3" / "run.json").write_text('{"format": 2, "status": "compl')
    (runs / "seed1" / "summary.json").write_text("{junk")
    (runs / "seed2" / "summary.json").unlink()
    (runs / "seed2" / "summary.json").symlink_to(folders / "presets" / "tiny.yaml")
    (runs / "sw").mkdir()
    (runs / "sw" / "sweep.json").write_text("not a sweep")
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "f5")
        pane = app.query_one(ResultsPane)
        assert {e.path.name: e.status for e in pane.runs} == {"seed1": "damaged", "seed2": "damaged", "seed3": "damaged", "sw": "damaged"}
        screen = screen_text(app)
        for name in ("seed1", "seed2", "sw"):
            line = next(line for line in screen.splitlines() if f" {name} " in line)
            assert "✗" in line and "damaged" in line, line
        row = [e.path.name for e in pane.runs].index("seed2")
        await press_settled(pilot, *["down"] * row, "enter")
        assert "seed2 is damaged: summary.json" in status_text(app) and "link" in status_text(app)
        junk = (runs / "seed1" / "summary.json").read_bytes()
        for name in ("seed1", "seed2", "seed3"):  # u refuses, naming the damage; nothing is rewritten, no link replaced
            row = [e.path.name for e in pane.runs].index(name)
            await press_settled(pilot, "f5", "home", *["down"] * row, "u")
            said = status_text(app)
            assert said.startswith("Cannot resume") and f"{name} is damaged" in said and app.followed is None, said
    assert (runs / "seed1" / "summary.json").read_bytes() == junk and (runs / "seed2" / "summary.json").is_symlink()


@pytest.mark.long
@pytest.mark.parametrize("route", ["command line", "list"])
@sync
async def test_q_on_a_freshly_opened_preset_quits_and_never_types(folders, registry, route):
    """Opened either way, the form has the focus, not its `name` field: q quits (it typed
    `smallq` into the name before); the footer offers Enter into the fields."""
    app = make_app(registry, preset="presets/tiny.yaml" if route == "command line" else None)
    async with started(app) as pilot:
        if route == "list":
            await press_settled(pilot, "enter")
        await wait_until(pilot, lambda: "Edit" in screen_text(app).splitlines()[-1], 10)  # the footer, once refreshed
        screen = screen_text(app)
        await press_settled(pilot, "q")
        quit_by_q = not app.is_running
    assert "(saved)" in screen and "smallq" not in screen
    assert "Enter or Tab: into the fields" in screen
    assert "⏎ Edit" in screen.splitlines()[-1] or "enter Edit" in screen.splitlines()[-1]
    assert quit_by_q


@pytest.mark.long
@sync
async def test_q_after_a_refused_run_quits_and_never_types_into_the_field_at_fault(folders, registry):
    """Ctrl+R refused for a bad seed pointed at the seed field by focusing it: q then typed
    `q` into it (an outsider's tmux check). The form keeps the focus; Enter goes in."""
    (folders / "presets" / "tiny.yaml").write_text(yaml.safe_dump(merge(TINY, {"seed": -5})))
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "ctrl+r")
        said = status_text(app)
        await press_settled(pilot, "q")
        quit_by_q = not app.is_running
    assert said.startswith("Cannot run: 1 problem: seed")
    assert quit_by_q and yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())["seed"] == -5


@sync
async def test_ctrl_r_refused_in_a_field_leaves_the_keys_typed_next_in_the_field(folders, registry):
    """In tmux at 80x24: realizations typed as -5, Ctrl+R refused, then Ctrl+U and 20 typed to
    fix it: the focus had gone to the form, Ctrl+U did nothing and 2 switched to the Presets tab."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        app.query_one("#field--realizations").focus()
        await press_settled(pilot, "ctrl+u", "minus", "5")
        await press_settled(pilot, "ctrl+r")
        said = status_text(app)
        await press_settled(pilot, "ctrl+u", "2", "0")
        tab, focused = app.query_one("#tabs").active, app.focused.id
        value = app.query_one("#field--realizations").value
    assert said.startswith("Cannot run: 1 problem: realizations: must be >= 1, got -5"), said
    assert (tab, focused, value) == ("edit", "field--realizations", "20")


@pytest.mark.long
@sync
async def test_esc_leaves_a_field_so_that_q_quits(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await pilot.press("enter", "x")  # into name, typed
        await pilot.pause()
        typed = app.query_one("#field--name").value
        footer_in_field = screen_text(app).splitlines()[-1]
        await press_settled(pilot, "escape")
        left = app.focused.id
        await press_settled(pilot, "ctrl+s")  # saved: q quits without a question
        await press_settled(pilot, "q")
        quit_by_q = not app.is_running
    assert typed == "smallx" and "Leave field" in footer_in_field
    assert left == "form" and quit_by_q


@pytest.mark.long
@sync
async def test_a_run_started_elsewhere_is_listed_in_results_without_a_reload(folders, registry):
    """A run started by another TUI (here its detached process, as that TUI starts it) is
    listed while it runs, without r: the runs folder is watched. The highlighted run stays
    highlighted as rows are added above it."""
    app = runs_app(folders, registry)
    async with started(app) as pilot:
        await pilot.press("f5")
        pane = app.query_one(ResultsPane)
        await press_settled(pilot, "down")
        highlighted = pane.runs[app.query_one("#runs-table").cursor_row].path
        scene = build_scene(merge(TINY, {"name": "elsewhere", "realizations": 100_000}), registry=registry)
        out = new_run_folder("elsewhere", "runs")
        process = start_detached(scene.resolved(), out, RunOptions(workers=1), plot=False)
        try:
            await wait_until(pilot, lambda: any(e.path.name == out.name and e.status == "running" for e in pane.runs), 30)
            screen = screen_text(app)
            cursor = pane.runs[app.query_one("#runs-table").cursor_row].path
        finally:
            process.terminate()
            process.wait()
        await wait_until(pilot, lambda: any(e.path.name == out.name and e.status != "running" for e in pane.runs), 30)
    assert any("▶" in line and "elsew" in line for line in screen.splitlines()), screen  # its name cut to fit
    assert cursor == highlighted


def _footer(app) -> str:
    return screen_text(app).splitlines()[-1]


@pytest.mark.long
@sync
async def test_after_a_run_killed_mid_way_the_run_tab_offers_u_and_u_resumes_it(folders, registry):
    """A run that ended without its results (a full disk, kill -9) can be resumed: the Run
    tab offered no u and said "No run to resume" while Results' u resumed it."""
    (folders / "presets" / "long.yaml").write_text(yaml.safe_dump(LONG))
    app = make_app(registry, preset="presets/long.yaml", workers=1)
    async with started(app) as pilot:
        await pilot.press("ctrl+r")
        await wait_until(pilot, lambda: app.last_snapshot is not None and app.last_snapshot.done >= 2)
        folder = app.followed.folder
        app.followed.process.kill()  # as the disk filled: no summary written
        await wait_until(pilot, lambda: app.followed is None)
        await pilot.pause()
        footer, said = _footer(app), status_text(app)
        said_since = record_said(app)  # the resumed process's own warning (chunks it recomputes) may follow at once
        await press_settled(pilot, "u")
        resumed = app.followed is not None and app.followed.folder == folder
        pid = app.followed.pid if resumed else None
        said_after = said_since[0] if said_since else ""
        if resumed:
            app.followed.cancel()
            await wait_until(pilot, lambda: app.followed is None)
    assert "u Resume" in footer and "u resumes it" in said
    assert said.startswith("Run interrupted: ")  # as Results and frictionlab runs list it, not "Run failed"
    assert resumed and said_after.startswith("Resuming long") and f"pid {pid}" in said_after


@pytest.mark.long
@sync
async def test_a_resume_that_another_process_began_first_is_followed_and_said_in_full(folders, registry):
    """Two TUIs pressing u on one interrupted run: the one that loses the folder's lock
    follows the run that won, and says so whole (it said "Run failed: … in use by another
    run (pid …): wait for it to end, or give another", cut, advice it could not follow)."""
    out = interrupted_long_run(folders, registry)
    # the winner: a process that holds the folder's lock, as a resume does before its manifest says "running"
    holder = subprocess.Popen([sys.executable, "-c", HOLD_LOCK, str(out / "run.lock")], stdout=subprocess.PIPE)
    try:
        assert holder.stdout.readline().strip() == b"held"
        app = make_app(registry)
        async with started(app) as pilot:
            await press_settled(pilot, "f5", "u")
            following = app.followed is not None and app.followed.folder.resolve() == out.resolve()
            tab = app.query_one("#tabs").active
            screen = " ".join(screen_text(app).split())
            said = status_text(app)
    finally:
        holder.kill()
        holder.wait()
    assert following and tab == "run", said
    assert said == (f"long was resumed by another process first (pid {holder.pid}): "
                    "this TUI follows that run; c cancels it")  # fmt: skip
    assert said in screen  # whole on the screen, not cut
    assert "in use" not in said and "output folder" not in said


@pytest.mark.long
@sync
async def test_a_resume_that_loses_the_race_after_its_process_began_follows_the_winner(folders, registry, monkeypatch):
    """Two TUIs pressing u at the same instant: both see the folder free and start a resume;
    the loser's process finds the lock taken and ends with nothing of its own left in the
    progress file (the winner rewrites it). The loser read the old summary and showed
    "Run interrupted" with no c, no u, following nothing, until a second u."""
    import frictionlab.runs.detached as detached

    out = interrupted_long_run(folders, registry)
    holders = []

    def the_loser_starts(*args, **kwargs):  # the winner takes the lock just after this TUI's check
        holder = subprocess.Popen([sys.executable, "-c", HOLD_LOCK, str(out / "run.lock")], stdout=subprocess.PIPE)
        holders.append(holder)
        assert holder.stdout.readline().strip() == b"held"
        return subprocess.Popen([sys.executable, "-c", "raise SystemExit(5)"])  # in use: its word lost

    monkeypatch.setattr(detached, "start_detached", the_loser_starts)
    try:
        app = make_app(registry)
        async with started(app) as pilot:
            await press_settled(pilot, "f5", "u")
            await wait_until(pilot, lambda: app.followed is None or app.followed.process is None)
            await pilot.pause(0.3)
            following = app.followed is not None and app.followed.folder.resolve() == out.resolve()
            said, footer = status_text(app), _footer(app)
    finally:
        for holder in holders:
            holder.kill()
            holder.wait()
    assert following, said
    assert said == (f"long was resumed by another process first (pid {holders[0].pid}): "
                    "this TUI follows that run; c cancels it")  # fmt: skip
    assert "c Cancel" in footer, footer


@pytest.mark.long
@sync
async def test_space_on_a_running_row_says_why_it_cannot_compare(folders, registry):
    """Space, not listed on a running row of Results, switched to the Run tab without a word."""
    with long_run_going(folders, registry):
        app = make_app(registry)
        async with started(app) as pilot:
            await press_settled(pilot, "f5")
            pane = app.query_one(ResultsPane)
            await wait_until(pilot, lambda: [(e.path.name, e.status) for e in pane.runs] == [("long", "running")])
            footer = _footer(app)
            await press_settled(pilot, "space")
            tab, said = app.query_one("#tabs").active, status_text(app)
    assert "Compare" not in footer, footer
    assert tab == "results", said
    assert said == "long is running: it has no curve to compare until it ends; Enter shows it live on the Run tab"


HOLD_LOCK = """
import fcntl, os, sys
fd = os.open(sys.argv[1], os.O_RDWR | os.O_CREAT)
os.ftruncate(fd, 0)
os.write(fd, f"pid {os.getpid()}, started now\\n".encode())
fcntl.flock(fd, fcntl.LOCK_EX)
print("held", flush=True)
import time; time.sleep(600)
"""


@pytest.mark.long
@sync
async def test_a_resume_whose_progress_file_is_a_link_is_refused_in_words_and_writes_nothing(folders, registry):
    out = interrupted_long_run(folders, registry, done=1)  # at least one chunk stored
    (out / "progress.jsonl").unlink()
    (folders / "elsewhere.jsonl").write_text("")
    (out / "progress.jsonl").symlink_to(folders / "elsewhere.jsonl")
    stored = sorted(path.name for path in out.iterdir())
    app = make_app(registry)
    said = []
    async with started(app) as pilot:
        original = app.say
        app.say = lambda text, *a, **k: (said.append(text), original(text, *a, **k))
        await pilot.press("f5", "u")
        await wait_until(pilot, lambda: any("progress.jsonl" in text for text in said))
        await pilot.pause(0.5)
        assert app.followed is None  # no run started that would go on unseen
    told = [text for text in said if "progress.jsonl" in text and "symbolic link" in text]
    assert len(told) == 1 and "remove it" in told[0]
    assert (folders / "elsewhere.jsonl").read_text() == ""  # never written through the link
    assert sorted(path.name for path in out.iterdir()) == stored  # nothing computed is lost


@pytest.mark.long
@sync
async def test_a_preset_that_is_not_yaml_says_what_is_wrong_in_words_at_its_line(folders, registry):
    (folders / "presets" / "bad.yaml").write_text("name: bad\nseed: 1\nrealizations: [1, 2\n")
    app = make_app(registry)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        listed = screen_text(app)
        await pilot.press("enter")  # bad.yaml is listed first
        await pilot.pause()
        said = status_text(app)
    assert "cannot be read: not valid YAML at line 3" in listed and "YamlProblem" not in listed
    assert said.startswith("Cannot open bad.yaml: not valid YAML at line 3, column 15: a [ list opened here is not closed")
    assert "(file)" not in said


@pytest.mark.long
@sync
async def test_the_keys_panel_is_readable_at_80x24_and_tabs_are_reached_without_f_keys(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "question_mark")
        panel = app.screen.query("HelpPanel")
        width = panel.first().size.width if panel else 0
        await press_settled(pilot, "escape")
        closed_by_esc = not app.screen.query("HelpPanel")
        await press_settled(pilot, "question_mark", "question_mark")
        toggled = not app.screen.query("HelpPanel")
        tabs = []
        for key in ("5", "4", "2", "3"):
            await press_settled(pilot, key)
            tabs.append(app.query_one("#tabs").active)
        await press_settled(pilot, "4")
        run_footer = screen_text(app).splitlines()[-1]
    assert width >= 44 and closed_by_esc and toggled  # Textual's was 29 wide: every key wrapped
    assert tabs == ["results", "run", "presets", "edit"]
    assert "^r Run" in run_footer and " r Run" not in run_footer


@pytest.mark.long
@sync
async def test_a_swept_field_says_so_and_field_help_is_never_cut(folders, registry):
    data = merge(TINY, {"name": "sw", "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.6, 0.7, 0.8, 0.9]}}}})
    (folders / "presets" / "sw.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    app = make_app(registry, preset="presets/sw.yaml")
    async with started(app) as pilot:
        app.query_one("#field--spectrum--params--hurst").focus()
        help_shown = lambda: str(app.query_one("#field-help").render()).startswith("spectrum.params.hurst is swept")  # noqa: E731
        await wait_until(pilot, lambda: help_shown() and "hurst" in screen_text(app), 30)  # a busy machine paints late
        await pilot.pause()
        screen = screen_text(app)
        help_text = str(app.query_one("#field-help").render())
    hurst = next(line for line in screen.splitlines() if line.startswith("hurst"))
    assert "swept" in hurst
    assert help_text.startswith("spectrum.params.hurst is swept ({values: [0.5, 0.6, 0.7, 0.8, 0.9]}): this value is only the base")
    assert "…" not in help_text and " ".join(help_text.split()) in " ".join(screen.split())  # whole on the screen
    assert "0.9]}}}" in screen or "0.9]" in screen  # the sweep row's values, whole (they were cut)


def test_a_one_realization_fit_says_why_it_has_no_interval_and_a_finished_count_no_rate():
    from frictionlab.compute.fit import LogFit
    from frictionlab.plugin.listeners import progress_text
    from frictionlab.tui.widgets.run import fit_lines

    nan = float("nan")
    lines = fit_lines(LogFit(a=0.8, b=0.02, r2=0.99, a_ci=(nan, nan), b_ci=(nan, nan), bootstrap=0), final=True)
    assert "  no CI (bootstrap off,\n  or < 2 realizations)" in "\n".join(lines)  # two lines: the panel is as wide as its longest
    assert not any("bootstrap 0 " in line or line.endswith("bootstrap 0") for line in lines)
    assert progress_text(8, 8, 0, 0.5, restored=8) == "8/8 realizations (8 restored), elapsed 0.5 s"  # a point restored whole
    assert progress_text(3, 8, 0, 0.5, restored=3) == "3/8 realizations (3 restored), elapsed 0.5 s"
    assert "2.0/s" in progress_text(4, 8, 0, 0.5, restored=3) and "left" in progress_text(4, 8, 0, 0.5, restored=3)


@pytest.mark.long
@sync
async def test_a_run_whose_folder_came_before_its_manifest_is_listed_at_the_next_look(folders, registry):
    """A run started elsewhere makes its folder first and its run.json a moment later: the
    list is read again at once for a folder not yet listed, not after the coalescing delay.
    (The watch is called here, between two of its ticks: a loaded machine made a time limit on
    its timer fail.)"""
    make_runs(folders, registry)
    runs = folders / "runs"
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await press_settled(pilot, "f5")
        pane = app.query_one(ResultsPane)
        (runs / "later").mkdir()  # as a run starting elsewhere makes it
        app._watch_runs()  # looked at: nothing to list there yet
        seen_empty = "later" in {name for name, _ in app._runs_seen[1]} and "later" not in {e.path.name for e in pane.runs}
        for item in (runs / "seed1").iterdir():  # its files written (a finished run's, as a run's would be)
            if item.is_file():
                shutil.copy2(item, runs / "later" / item.name)
        app._runs_read_at = time.monotonic()  # the list was just read: a listed run's change would wait REREAD_SECONDS
        app._watch_runs()
        listed = "later" in {e.path.name for e in pane.runs}
    assert seen_empty and listed
