"""Runs that outlive their front end: a detached run finishes after the session that
started it is gone, a run whose process died reads as interrupted, its progress
file is followed as untrusted input and tells what the run computed."""

import json
import os
import signal
import subprocess
import sys

import numpy as np
import pytest

from frictionlab.runs.detached import lock_held, process_alive, run_state, start_detached, stored_count, wait_started
from frictionlab.plugin.hookspecs import hookimpl
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.runs.progresslog import PROGRESS_FILE, Follower, ProgressLog, ProgressReader
from frictionlab.runs.rundir import LOCK_FILE, RunDirectory
from frictionlab.runs.runner import run_to_folder

from .conftest import SMALL_PRESET, merge
from .sessions import start_then_hang_up, wait_for

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="sessions and signals are POSIX")


class Collect:
    """A run listener that keeps what it hears."""

    def __init__(self):
        self.results, self.started = [], None

    @hookimpl
    def run_started(self, run):
        self.started, self.results = run, []

    @hookimpl
    def realization_done(self, result, done, total):
        self.results.append((result, done, total))


@pytest.mark.long
def test_a_detached_run_completes_after_the_session_that_started_it_is_killed(tmp_path):
    data = merge(SMALL_PRESET, {"realizations": 60, "spectrum": {"params": {"points": 2048}}})
    out = tmp_path / "run"
    run_pid = start_then_hang_up(data, out, resolve=True)
    assert run_state(out).status == "running" and run_state(out).pid == run_pid  # not done yet when the session died
    wait_for(lambda: run_state(out).status != "running")
    state = run_state(out)
    assert (state.status, state.done, state.total) == ("completed", 60, 60)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["realizations"]["done"] == 60
    # the same numbers as a run in this process (same preset, same seed)
    whole, _ = run_to_folder(build_scene(data), tmp_path / "here", RunOptions(workers=1))
    assert summary["fit"]["a"] == whole.fit.a and summary["fit"]["b"] == whole.fit.b


def test_a_run_whose_process_was_killed_reads_as_interrupted_and_resumes(tmp_path):
    data = merge(SMALL_PRESET, {"realizations": 100_000})
    out = tmp_path / "run"
    process = start_detached(build_scene(data).resolved(), out, RunOptions(workers=1))
    wait_started(process, out)
    assert run_state(out).done is not None  # 0 before the first realization: a count, not unknown
    wait_for(lambda: (run_state(out).done or 0) >= 2)
    assert run_state(out).status == "running"
    process.kill()  # kill -9: no chance to write anything
    process.wait()
    assert json.loads((out / "run.json").read_text())["status"] == "running"  # what the dead run left
    state = run_state(out)
    assert state.status == "interrupted" and state.pid is None and state.resumable
    assert state.done == stored_count(out)[0] < 100_000  # what its chunks hold, which a resume restores


def test_a_lock_naming_a_dead_or_unrelated_process_is_not_a_running_run(tmp_path):
    scene = build_scene(SMALL_PRESET)
    with RunDirectory(tmp_path) as run_dir:  # a run that began and was never finished
        run_dir.start(scene, resume=False)
        assert run_state(tmp_path).status == "running"  # this process holds the lock
    (tmp_path / LOCK_FILE).write_text("pid 999999999, started 2025-01-01 00:00:00\n")  # left by kill -9
    assert not process_alive(999999999)
    assert run_state(tmp_path).status == "interrupted"
    (tmp_path / LOCK_FILE).write_text(f"pid {os.getpid()}, started 2025-01-01 00:00:00\n")  # a reused pid
    assert process_alive(os.getpid()) and not lock_held(tmp_path)
    assert run_state(tmp_path).status == "interrupted"


def test_sigterm_ends_a_detached_run_interrupted_keeping_what_finished(tmp_path):
    data = merge(SMALL_PRESET, {"realizations": 100_000})
    out = tmp_path / "run"
    process = start_detached(build_scene(data).resolved(), out, RunOptions(workers=1), plot=False)
    wait_started(process, out)
    wait_for(lambda: (run_state(out).done or 0) >= 3)
    os.kill(process.pid, signal.SIGTERM)
    assert process.wait(timeout=60) == 143
    state = run_state(out)
    summary = json.loads((out / "summary.json").read_text())
    assert state.status == summary["status"] == "interrupted"
    assert 3 <= summary["realizations"]["done"] == state.done < 100_000
    with np.load(out / "realizations.npz") as arrays:
        assert arrays["xi"].shape[0] == state.done


@pytest.mark.long
def test_the_follower_hears_every_realization_as_the_run_computed_it_and_a_resume_lists_the_restored(tmp_path):
    data = merge(SMALL_PRESET, {"realizations": 12})
    scene = build_scene(data)
    here = Collect()
    cancel = __import__("threading").Event()

    class StopAfterFive:
        @hookimpl
        def realization_done(self, done):
            if done >= 5:
                cancel.set()

    run_to_folder(scene, tmp_path, RunOptions(workers=1), listeners=[ProgressLog(tmp_path), StopAfterFive()], cancel=cancel)
    first = Collect()
    Follower(tmp_path, scene, [first]).poll()
    assert 5 <= len(first.results) < 12
    run_to_folder(scene, tmp_path, RunOptions(workers=1, resume=True), listeners=[ProgressLog(tmp_path), here])
    heard = Collect()
    follower = Follower(tmp_path, scene, [heard])
    follower.poll()
    resumed = len(first.results)
    assert follower.finished.status == "completed" and heard.started.resumed == resumed
    restored = list(heard.started.restored)  # as the run's own listeners have them: not as realizations done now
    assert sorted(r.index for r in restored) == sorted(r.index for r, _, _ in first.results)
    assert sorted(r.index for r in restored + [r for r, _, _ in heard.results]) == list(range(12))
    assert [done for _, done, _ in heard.results] == list(range(resumed + 1, 13))
    computed = [r for r, _, _ in here.results]
    followed = restored + [r for r, _, _ in heard.results]
    with np.load(tmp_path / "realizations.npz") as arrays:  # the sums a mean curve needs, never each curve
        np.testing.assert_allclose(sum(r.xi for r in followed), arrays["xi"].sum(axis=0), rtol=1e-12)
    heard_counts = sum(r.contact_count for r, _, _ in heard.results)
    np.testing.assert_allclose(heard_counts, sum(r.contact_count for r in computed), rtol=1e-12)


def test_the_progress_file_is_read_as_untrusted_input(tmp_path, monkeypatch):
    reader = ProgressReader(tmp_path)
    path = tmp_path / PROGRESS_FILE
    path.write_bytes(b'{"event": "started", "total": 3}\nnot json\n[1, 2]\n{"no_event": 1}\n{"event": "realiz')
    assert [e["event"] for e in reader.new_events()] == ["started"]  # bad lines skipped, a cut last line waits
    with open(path, "ab") as fh:
        fh.write(b'ation", "index": 0}\n')
    assert [e["event"] for e in reader.new_events()] == ["realization"]
    path.write_bytes(b'{"event": "started"}\n')  # rewritten by a new start: read again from the top
    assert [e["event"] for e in reader.new_events()] == ["started"] and reader.restarted
    path.unlink()
    target = tmp_path / "elsewhere.jsonl"
    target.write_bytes(b'{"event": "started"}\n')
    path.symlink_to(target)
    assert ProgressReader(tmp_path).new_events() == []  # never through a link
    path.unlink()
    path.write_bytes(b'{"event": "started"}\n' * 100)
    monkeypatch.setattr("frictionlab.runs.progresslog.MAX_PROGRESS_BYTES", 1000)
    capped = ProgressReader(tmp_path)
    assert capped.new_events() == [] and capped.too_large


def test_a_realization_event_of_the_wrong_shape_is_skipped(tmp_path):
    scene = build_scene(SMALL_PRESET)
    steps = scene.loads.size
    lines = [
        {"event": "started", "total": 2, "pid": 1},
        {"event": "realization", "index": 0, "done": 1, "ok": True, "xi": [1.0] * (steps - 1), "contact_count": [1] * steps},
        {"event": "realization", "index": "one", "done": 1, "ok": True},
        {"event": "realization", "index": 1, "done": 1, "ok": True, "xi": [0.5] * steps, "contact_count": [2] * steps},
    ]
    (tmp_path / PROGRESS_FILE).write_text("".join(json.dumps(line) + "\n" for line in lines))
    heard = Collect()
    Follower(tmp_path, scene, [heard]).poll()
    assert [(r.index, done) for r, done, _ in heard.results] == [(1, 1)]


def test_iterations_within_a_load_reach_the_follower(tmp_path):
    from frictionlab.compute.engine import RunInfo

    scene = build_scene(SMALL_PRESET)
    log = ProgressLog(tmp_path)
    log.run_started(RunInfo(scene=scene, total=2, workers=1))
    log.load_done(index=0, done=2, total=16)
    log.iteration_done(index=0, load=3, iteration=40, residual=3.1e-5)
    log.close()
    heard = []

    class Hear:
        @hookimpl
        def load_done(self, index, done, total):
            heard.append(("load", index, done, total))

        @hookimpl
        def iteration_done(self, index, load, iteration, residual):
            heard.append(("iteration", index, load, iteration, residual))

    Follower(tmp_path, scene, [Hear()]).poll()
    assert heard == [("load", 0, 2, 16), ("iteration", 0, 3, 40, 3.1e-5)]


def test_a_progress_file_rewritten_larger_by_a_resume_is_read_again_from_its_start(tmp_path):
    path = tmp_path / PROGRESS_FILE
    path.write_bytes(b'{"event": "started", "pid": 1}\n{"event": "finished"}\n')
    reader = ProgressReader(tmp_path)
    assert [e["event"] for e in reader.new_events()] == ["started", "finished"]
    path.write_bytes(b'{"event": "started", "pid": 22}\n' + b'{"event": "realization", "restored": true}\n' * 3)
    assert [e["event"] for e in reader.new_events()] == ["started"] + ["realization"] * 3 and reader.restarted
    with open(path, "ab") as fh:
        fh.write(b'{"event": "finished"}\n')
    assert [e["event"] for e in reader.new_events()] == ["finished"] and not reader.restarted


def test_a_follower_of_a_process_it_started_skips_the_file_of_the_run_that_process_continues(tmp_path):
    scene = build_scene(SMALL_PRESET)
    steps = scene.loads.size
    done = {"event": "realization", "index": 0, "done": 1, "ok": True, "xi": [1.0] * steps, "contact_count": [2] * steps}
    old = [{"event": "started", "total": 2, "pid": 1}, done, {"event": "finished", "status": "interrupted"}]
    path = tmp_path / PROGRESS_FILE
    path.write_text("".join(json.dumps(line) + "\n" for line in old))
    heard = Collect()
    follower = Follower(tmp_path, scene, [heard], pid=22)
    follower.poll()  # the cancelled run's file, not yet rewritten by the resume (pid 22)
    assert heard.started is None and heard.results == [] and follower.finished is None
    new = [{"event": "started", "total": 2, "pid": 22, "resumed": 1}, {**done, "restored": True},
           {**done, "index": 1, "done": 2}]  # fmt: skip
    path.write_text("".join(json.dumps(line) + "\n" for line in new))
    follower.poll()
    assert heard.started.resumed == 1 and [r.index for r in heard.started.restored] == [0]
    assert [(r.index, n) for r, n, _ in heard.results] == [(1, 2)]
    refused = Follower(tmp_path, scene, pid=33)
    path.write_text(json.dumps(old[0]) + "\n" + json.dumps({"event": "error", "pid": 33, "message": "in use", "exit_code": 4}) + "\n")
    refused.poll()  # a process that could not start: its error is heard
    assert (refused.finished.error, refused.finished.exit_code) == ("in use", 4)


def test_wait_started_waits_for_its_own_process_not_the_run_a_resume_continues(tmp_path):
    from frictionlab.errors import FrictionlabError

    (tmp_path / PROGRESS_FILE).write_text(json.dumps({"event": "started", "pid": 1, "total": 2}) + "\n")  # the cancelled run's
    silent = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(0.3)"])  # never writes a start
    with pytest.raises(FrictionlabError, match="ended at once"):
        wait_started(silent, tmp_path, timeout=30)


def test_a_log_line_cut_by_a_full_disk_is_taken_back_so_the_error_after_it_is_read(tmp_path, monkeypatch):
    """A full disk cut a line of progress.jsonl: the run's error event was appended to the cut
    line, which no reader parses, so `follow` never heard why the run stopped."""
    import errno

    log = ProgressLog(tmp_path)
    log.begin({"event": "started", "pid": os.getpid(), "name": "x", "total": 3})
    real_write = os.write

    calls = []

    def half_then_full(fd, data):  # as write(2) does at the disk's last block, then on a full disk
        calls.append(data)
        if len(calls) == 1:
            return real_write(fd, data[: len(data) // 2])
        if b'"error"' not in data:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_write(fd, data)  # the error: room enough again (the cut line's blocks, or a file deleted)

    monkeypatch.setattr(os, "write", half_then_full)
    log.write({"event": "load", "index": 0, "done": 1, "total": 3})
    log.write({"event": "load", "index": 0, "done": 2, "total": 3})  # not written: the log stopped at the cut
    log.error("cannot write results to x: No space left on device", 1)
    events = ProgressReader(tmp_path).new_events()
    assert [event["event"] for event in events] == ["started", "error"]
    assert events[-1]["message"] == "cannot write results to x: No space left on device"


def test_follow_of_a_run_that_ended_on_a_full_disk_says_why(tmp_path, capsys):
    """A detached run stopped by a full disk logs its error; `follow` afterwards said only
    'interrupted' (it read the error of summary.json alone, which a full disk did not let be written)."""
    from frictionlab.cli import main

    scene = build_scene(merge(SMALL_PRESET, {"realizations": 12}))
    cancel = __import__("threading").Event()
    cancel.set()  # stopped as it began: an interrupted folder, as the disk left it
    run_to_folder(scene, tmp_path, RunOptions(workers=1), listeners=[ProgressLog(tmp_path)], cancel=cancel)
    said = f"cannot write results to {tmp_path}/chunks/00000000-00000011.npz: No space left on device"
    ProgressLog(tmp_path).error(said, 1)  # as the detached process says it
    assert main(["follow", str(tmp_path)]) == 1
    assert capsys.readouterr().err == f"error: {said}\n"
