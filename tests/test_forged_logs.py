"""A run folder's files are anyone's: a forged run.lock or progress.jsonl makes frictionlab
signal no process but the one the kernel says holds the folder's lock, show no number it
did not check, spin no loop, and a folder swapped or deleted under a run is said as it is."""

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import frictionlab

from frictionlab.cli.main import main
from frictionlab.runs.detached import lock_held, lock_holder, run_state, start_detached, wait_started
from frictionlab.errors import FrictionlabError, RunFolderError
from frictionlab.plugin.hookspecs import hookimpl
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.progress import ProgressReporter
from frictionlab.runs.progresslines import MAX_LINE_BYTES
from frictionlab.runs.progresslog import PROGRESS_FILE, READ_BLOCK, Follower, ProgressLog, ProgressReader
from frictionlab.compute.realization import RealizationResult
from frictionlab.runs.rundir import LOCK_FILE, RunDirectory
from frictionlab.runs.runfolder import _not_to_signal
from frictionlab.runs.sweep import plan_sweep, run_sweep

from .conftest import SMALL_PRESET, merge
from .sessions import wait_for

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the kernel's lock table is Linux's /proc/locks")

STEPS = SMALL_PRESET["loading"]["steps"]


def hold(folder, data=SMALL_PRESET, own_session=True) -> subprocess.Popen:
    """A process (in a session of its own, as a detached run) that holds ``folder``'s lock,
    its run started and "running", until its stdin closes."""
    script = textwrap.dedent(f"""
        import sys
        from frictionlab.preset import build_scene
        from frictionlab.runs.rundir import RunDirectory
        with RunDirectory({str(folder)!r}) as run_dir:
            run_dir.start(build_scene({data!r}), resume=False)
            print("held", flush=True)
            sys.stdin.read()
    """)
    process = subprocess.Popen([sys.executable, "-c", script], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                               start_new_session=own_session)  # fmt: skip
    assert process.stdout.readline().strip() == "held"
    return process


def release(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.stdin.close()
    process.wait(timeout=30)


@pytest.fixture
def victim():
    """A harmless live process that a forged file names."""
    process = subprocess.Popen(["sleep", "300"])
    yield process
    process.kill()
    process.wait()


def forge(folder, *events, lock_text=None) -> None:
    (folder / PROGRESS_FILE).write_text("".join(json.dumps(event) + "\n" for event in events))
    if lock_text is not None:
        (folder / LOCK_FILE).write_text(lock_text)  # the text only: the kernel's lock stays the holder's


def realization(index, done, total, steps=STEPS):
    return {"event": "realization", "index": index, "done": done, "total": total, "ok": True, "seconds": 0.1,
            "xi": [1.0] * steps, "contact_count": [2.0] * steps}  # fmt: skip


# ------------------------------------------------------------------ who is signalled


def test_cancel_signals_the_verified_lock_holder_never_the_pid_a_forged_log_or_lock_names(tmp_path, victim):
    from frictionlab.tui.following import FollowedRun

    holder = hold(tmp_path)
    forge(tmp_path, {"event": "started", "pid": victim.pid, "total": 8}, lock_text=f"pid {victim.pid}, started 2025\n")
    followed = FollowedRun(tmp_path, build_scene(SMALL_PRESET), post=lambda snapshot: None)
    followed.poll()
    before = (followed.follower.pid, followed.pid, lock_holder(tmp_path), run_state(tmp_path).pid)
    cancelled = followed.cancel()
    time.sleep(0.5)
    assert victim.poll() is None  # the process the log and the lock's text named is untouched
    assert before == (victim.pid, holder.pid, holder.pid, holder.pid)  # what the log says is not who is signalled
    assert cancelled and holder.wait(timeout=30) == -signal.SIGTERM
    again = FollowedRun(tmp_path, build_scene(SMALL_PRESET), post=lambda snapshot: None)
    again.poll()  # no one holds the folder now: nothing is signalled, and it says why
    assert not again.cancel() and "nothing was signalled" in again.refusal
    assert victim.poll() is None


def test_a_lock_held_by_this_process_or_its_session_is_never_signalled(tmp_path, victim):
    from frictionlab.runs.detached import cancel

    with RunDirectory(tmp_path) as run_dir:
        run_dir.start(build_scene(SMALL_PRESET), resume=False)
        with pytest.raises(RunFolderError, match="this process"):
            cancel(tmp_path)  # were it signalled, this test run would end here
    same_session = hold(tmp_path, own_session=False)
    try:
        with pytest.raises(RunFolderError, match="in this session"):
            cancel(tmp_path)
        assert same_session.poll() is None
    finally:
        release(same_session)
    assert _not_to_signal(1) == "the system's first process" and _not_to_signal(os.getpid()) == "this process"


def test_runs_shows_the_verified_holder_and_only_checked_counts(tmp_path, capsys):
    held, dead = tmp_path / "held", tmp_path / "dead"
    holder = hold(held)
    try:
        forge(held, {"event": "started", "pid": 1, "total": 8}, realization(0, 10**30, 8), lock_text="pid 1, started 2025\n")
        with RunDirectory(dead) as run_dir:
            run_dir.start(build_scene(merge(SMALL_PRESET, {"realizations": 12})), resume=False)
        forge(dead, {"event": "started", "total": 12}, realization(0, 10**30, 10**31), {"event": "finished", "done": 10**30,
              "requested": 12})  # fmt: skip
        done = tmp_path / "done"
        frictionlab.run(SMALL_PRESET, out=done, workers=1, plot=False, progress=False)
        summary = json.loads((done / "summary.json").read_text())
        summary["realizations"]["done"] = 10**30
        (done / "summary.json").write_text(json.dumps(summary))
        assert main(["runs", str(tmp_path)]) == 0
        out = capsys.readouterr().out
    finally:
        release(holder)
    # summary.json's done beyond its run's: not shown; the folder damaged, as frictionlab.load finds it, and why
    assert f"{done} is damaged: summary.json is damaged: fields 'realizations.done' and 'realizations.failed' add up to more than" in out
    assert "10000000000" not in out and not re.search(r"completed +\d", out)
    assert f"running (pid {holder.pid})" in out and "pid 1)" not in out
    assert "10000000000" not in out and "interrupted" in out and " 0/12" in out  # the started event's count: none done
    assert run_state(dead).done == 0


@pytest.mark.long  # follows for 3 s
def test_follow_of_a_log_with_numbers_out_of_bounds_ends_and_spins_no_loop(tmp_path):
    holder = hold(tmp_path)
    forge(tmp_path, {"event": "started", "pid": holder.pid, "total": -12}, realization(0, 10**30, -12),
          {"event": "started", "pid": holder.pid, "total": 8}, realization(0, 10**30, 8), realization(1, 9, 8))  # fmt: skip
    follow = subprocess.Popen([sys.executable, "-m", "frictionlab", "follow", str(tmp_path)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)  # fmt: skip
    time.sleep(3)
    release(holder)
    try:
        out, err = follow.communicate(timeout=60)  # spun at 100 % CPU for ever before
    except subprocess.TimeoutExpired:
        follow.kill()
        follow.communicate()
        pytest.fail("follow did not end")
    assert follow.returncode == 1 and "interrupted" in out and "10000000000" not in out + err


def test_a_reporter_fed_numbers_out_of_bounds_returns(tmp_path):
    class Run:
        scene = build_scene(SMALL_PRESET)
        total, resumed, retried, workers, executor, cores, sized = -12, 0, 0, 1, "serial", 0, False

    reporter = ProgressReporter(stream=open(os.devnull, "w"), interactive=False, after=0.0)
    reporter.run_started(Run())
    thread = threading.Thread(target=lambda: [reporter.realization_done(done, total) for done, total in
                                              ((10**30, -12), (10**30, 12), (5, 0), (3, 12))], daemon=True)  # fmt: skip
    thread.start()
    thread.join(10)
    assert not thread.is_alive()


# ------------------------------------------------------------------ the size of a line


def test_a_realization_of_the_most_load_steps_is_written_in_a_line_a_follower_reads(tmp_path):
    from frictionlab.compute.engine import RunInfo
    from frictionlab.preset.schema import MAX_STEPS

    scene = build_scene(merge(SMALL_PRESET, {"loading": {"steps": MAX_STEPS, "control": "indentation", "start": 0.01,
                                                         "stop": 0.1}}))  # its forces vary: three curves a line
    steps = scene.loads.size
    rng = np.random.default_rng(3)
    result = RealizationResult(index=0, seconds=1.0, xi=rng.random(steps), contact_count=rng.integers(0, 900, steps) * 1.0,
                               force=rng.random(steps), points=1024, force_unit=2.0, slope_rms_line=0.5)  # fmt: skip
    log = ProgressLog(tmp_path)
    log.run_started(RunInfo(scene=scene, total=1, workers=1))
    log.realization_done(result, 1, 1)
    log.close()
    lines = (tmp_path / PROGRESS_FILE).read_bytes().splitlines(keepends=True)
    assert max(len(line) for line in lines) <= MAX_LINE_BYTES < READ_BLOCK  # 4.7 MiB before: above what a reader takes
    heard = []

    class Hear:
        @hookimpl
        def realization_done(self, result, done, total):
            heard.append((result, done, total))

    Follower(tmp_path, scene, [Hear()]).poll()
    [(got, done, total)] = heard
    stride = json.loads(lines[1])["stride"]
    assert (done, total) == (1, 1) and stride > 1 and got.xi.shape == (steps,)
    assert np.array_equal(got.xi[::stride], result.xi[::stride]) and np.isnan(got.xi[1::stride]).all()


def test_a_line_longer_than_a_read_block_is_skipped_not_waited_on(tmp_path):
    path = tmp_path / PROGRESS_FILE
    path.write_bytes(b'{"event": "started", "total": 2}\n' + b"x" * (READ_BLOCK + 10) + b'\n{"event": "finished"}\n')
    reader, events = ProgressReader(tmp_path), []
    for _ in range(5):
        events += [event["event"] for event in reader.new_events()]
    assert events == ["started", "finished"]


# ------------------------------------------------------------------ what is said


def test_a_second_detached_resume_that_lost_the_folder_says_it_is_in_use_by_the_verified_holder(tmp_path):
    holder = hold(tmp_path)
    try:
        (tmp_path / PROGRESS_FILE).write_text("")  # the winner truncated the log: the loser's "in use" is gone
        loser = subprocess.Popen([sys.executable, "-c", "raise SystemExit(5)"])
        with pytest.raises(RunFolderError, match=f"in use by another run \\(pid {holder.pid}\\)"):
            wait_started(loser, tmp_path, timeout=30)
    finally:
        release(holder)


@pytest.mark.long
def test_follow_of_a_run_whose_folder_is_deleted_says_it_is_gone_and_advises_no_resume(tmp_path):
    out = tmp_path / "run"
    run = start_detached(build_scene(merge(SMALL_PRESET, {"realizations": 100_000})).resolved(), out, RunOptions(workers=1),
                         plot=False)  # fmt: skip
    try:
        wait_started(run, out)
        follow = subprocess.Popen([sys.executable, "-m", "frictionlab", "follow", str(out)],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
        assert "100000 realizations" in follow.stderr.readline()  # it follows the run
        while out.exists():
            shutil.rmtree(out, ignore_errors=True)  # the run writes chunks meanwhile
        out_text, err = follow.communicate(timeout=60)
        alive = run.poll() is None  # alive now, so alive when follow looked (a write racing the delete may end it)
    finally:
        run.kill()
        run.wait()
    assert follow.returncode == 1 and "was deleted or replaced while its run was going" in err
    # it said the process wrote 'nowhere you can see': its next chunk made the folder anew
    said = f"still runs and may write a new {out}/ as it goes on (kill -TERM {run.pid} stops it)" in err
    assert said or not alive
    assert "resume" not in (out_text + err).replace("nothing of that run is left to resume", "")


def test_follow_of_a_sweep_whose_point_folder_was_swapped_says_why_and_advice_that_works(tmp_path, capsys):
    data = merge(SMALL_PRESET, {"realizations": 4, "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.7]}}}})
    out = tmp_path / "sw"
    sweep = plan_sweep(data)
    run_sweep(sweep, out, RunOptions(workers=1), plot=False)
    first, second = (out / "points" / point.folder_name for point in sweep.points)
    shutil.rmtree(first)
    shutil.copytree(second, first)  # another point's run where this point's was
    record = json.loads((out / "sweep.json").read_text())
    record["points"][0]["status"] = "interrupted"
    (out / "sweep.json").write_text(json.dumps(record))
    run_sweep(sweep, out, RunOptions(workers=1, resume=True), plot=False)
    capsys.readouterr()
    assert main(["follow", str(out)]) == 1
    said = capsys.readouterr().out
    line = next(line for line in said.splitlines() if "hurst=0.5" in line)
    assert "error: cannot resume" in line and "started with differs from the one given" in said and f"move {first} aside" in said
    assert "do what the points in error say, then frictionlab resume" in said
    shutil.move(first, tmp_path / "aside")  # what it advises
    assert run_sweep(sweep, out, RunOptions(workers=1, resume=True), plot=False).status == "completed"


@pytest.mark.long  # a process of its own, seconds end to end: pytest -m long
def test_resume_detach_of_a_sweep_whose_point_folder_is_a_link_writes_nothing_outside(tmp_path, capsys):
    data = merge(SMALL_PRESET, {"realizations": 4, "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.7]}}}})
    out, elsewhere = tmp_path / "sw", tmp_path / "elsewhere"
    sweep = plan_sweep(data)
    run_sweep(sweep, out, RunOptions(workers=1), plot=False)
    elsewhere.mkdir()
    first = out / "points" / sweep.points[0].folder_name
    shutil.rmtree(first)
    first.symlink_to(elsewhere)
    record = json.loads((out / "sweep.json").read_text())
    record["points"][0]["status"] = "interrupted"
    (out / "sweep.json").write_text(json.dumps(record))
    assert main(["resume", str(out), "--detach"]) == 0
    wait_for(lambda: not lock_held(out))
    assert list(elsewhere.iterdir()) == []
    row = json.loads((out / "sweep.json").read_text())["points"][0]
    assert row["status"] == "error" and "symbolic link" in row["error"] and first.is_symlink()
    points = tmp_path / "points-elsewhere"
    points.mkdir()
    shutil.rmtree(out / "points")
    (out / "points").symlink_to(points)  # the level above: points/ itself refuses the whole sweep
    with pytest.raises(RunFolderError, match="points is a symbolic link or not a folder"):
        run_sweep(sweep, out, RunOptions(workers=1, resume=True), plot=False)
    assert list(points.iterdir()) == []


def test_result_plot_refuses_an_axes_like_object_naming_what_it_lacks(tmp_path):
    result = frictionlab.run(SMALL_PRESET, out=tmp_path / "run", workers=1, plot=False, progress=False)

    class NotAxes:
        def errorbar(self, *args, **kwargs):
            pass

    with pytest.raises(FrictionlabError, match="got NotAxes, which has no fill_between"):
        result.plot(ax=NotAxes())
