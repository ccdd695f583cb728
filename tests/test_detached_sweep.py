"""Sweeps that outlive their front end: a detached sweep finishes every point after the
session that started it is gone, SIGTERM leaves it interrupted and resumable to the
same numbers, and its folder and progress file are read as untrusted input."""

import json
import os
import signal
import sys

import pytest

from frictionlab.runs.detached import list_run_states, run_state, start_detached, wait_started
from frictionlab.errors import RunFolderError
from frictionlab.plugin.listeners import SweepListener
from frictionlab.options import RunOptions
from frictionlab.runs.progresslog import PROGRESS_FILE
from frictionlab.runs.sweep import plan_sweep, run_sweep
from frictionlab.runs.sweeplog import SweepFollower

from .conftest import SMALL_PRESET, merge
from .sessions import start_then_hang_up, wait_for

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="sessions and signals are POSIX")

SWEEP = merge(SMALL_PRESET, {"realizations": 12, "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.7, 0.9]}}}})


def fits(folder):
    return [(p["status"], p["a"], p["b"]) for p in json.loads((folder / "sweep.json").read_text())["points"]]


@pytest.mark.long
def test_a_detached_sweep_completes_every_point_after_the_session_that_started_it_is_killed(tmp_path):
    data = merge(SWEEP, {"realizations": 40})
    out = tmp_path / "sweep"
    sweep_pid = start_then_hang_up(data, out, resolve=False, plot=False)
    wait_for(lambda: run_state(out).status != "running")
    state = run_state(out)
    assert (state.kind, state.status, state.done, state.total) == ("sweep", "completed", 3, 3)
    assert all(json.loads((out / "points" / p["folder"].split("/")[-1] / "summary.json").read_text())
               ["realizations"]["done"] == 40 for p in json.loads((out / "sweep.json").read_text())["points"])  # fmt: skip
    here = run_sweep(plan_sweep(data), tmp_path / "here", RunOptions(workers=1), plot=False)
    assert fits(out) == [("completed", r.outcome.fit.a, r.outcome.fit.b) for r in here.results]  # the same numbers
    assert sweep_pid > 0 and not (out / "run.lock").exists()


@pytest.mark.long
def test_sigterm_leaves_a_detached_sweep_interrupted_and_resume_detach_completes_it_to_the_same_numbers(tmp_path):
    from frictionlab.cli.main import main

    data = merge(SWEEP, {"realizations": 3000, "spectrum": {"params": {"points": 512}}})
    out = tmp_path / "sweep"
    process = start_detached(data, out, RunOptions(workers=1), plot=False)
    wait_started(process, out)
    second = out / "points" / "02-hurst-0.7"
    wait_for(lambda: (second / "run.json").exists() and (run_state(second).done or 0) >= 2)  # the second point going
    os.kill(process.pid, signal.SIGTERM)
    assert process.wait(timeout=60) == 143
    state = run_state(out)
    statuses = [status for status, _, _ in fits(out)]
    assert state.status == "interrupted" and 1 <= state.done < 3 and statuses[0] == "completed"
    assert statuses[state.done:] in (["interrupted", "pending"], ["interrupted"], ["pending"])  # stopped in a point, or between two
    assert main(["resume", str(out), "--detach", "--workers", "1", "--no-plot"]) == 0
    wait_for(lambda: run_state(out).status != "running", timeout=300)
    here = run_sweep(plan_sweep(data), tmp_path / "here", RunOptions(workers=1), plot=False)
    assert fits(out) == [("completed", r.outcome.fit.a, r.outcome.fit.b) for r in here.results]


class Heard(SweepListener):
    def __init__(self):
        self.events = []

    def point_started(self, sweep, point):
        self.events.append(("started", point.number))

    def point_finished(self, sweep, point, result):
        self.events.append(("finished", point.number, result.status, result.row()["a"]))


def test_the_follower_hears_each_point_with_its_fit_and_skips_what_a_sweep_does_not_write(tmp_path):
    sweep = plan_sweep(SWEEP)
    out = tmp_path / "sweep"
    process = start_detached(SWEEP, out, RunOptions(workers=1), plot=False)
    wait_started(process, out)
    assert process.wait(timeout=120) == 0
    heard = Heard()
    follower = SweepFollower(out, sweep, [heard])
    follower.poll()
    rows = json.loads((out / "sweep.json").read_text())["points"]
    assert heard.events == [e for n, row in enumerate(rows, 1) for e in (("started", n), ("finished", n, "completed", row["a"]))]
    assert follower.finished.status == "completed" and follower.done == 3
    # junk lines, an unknown point, a row of the wrong kind: skipped, never a traceback
    log = out / PROGRESS_FILE
    with open(log, "a") as fh:
        fh.write('not json\n{"event": "point_finished", "number": 99, "row": {}}\n')
        fh.write('{"event": "point_finished", "number": 1, "row": {"folder": "../../etc", "status": "completed"}}\n')
        fh.write('{"event": "point_finished", "number": 2, "row": {"folder": "points/x", "status": "completed", "a": "1"}}\n')
    later = Heard()
    SweepFollower(out, sweep, [later]).poll()
    assert later.events == heard.events
    log.rename(tmp_path / "elsewhere.jsonl")
    log.symlink_to(tmp_path / "elsewhere.jsonl")
    never = Heard()
    assert SweepFollower(out, sweep, [never]).poll() == 0 and never.events == []  # never through a link


def test_a_sweep_json_that_is_a_link_or_damaged_is_refused_and_listed_as_damaged(tmp_path):
    runs = tmp_path / "runs"
    real = runs / "real"
    run_sweep(plan_sweep(SWEEP), real, RunOptions(workers=1), plot=False)
    assert [(s.kind, s.status, s.done) for s in list_run_states(runs)] == [("sweep", "completed", 3)]
    linked = runs / "linked"
    linked.mkdir()
    (linked / "sweep.json").symlink_to(real / "sweep.json")
    damaged = runs / "damaged"
    damaged.mkdir()
    (damaged / "sweep.json").write_text(json.dumps({**json.loads((real / "sweep.json").read_text()), "points": [{"folder": 3}]}))
    for folder in (linked, damaged):
        with pytest.raises(RunFolderError):
            run_state(folder)
    listed = {s.folder.name: s for s in list_run_states(runs)}
    assert listed["real"].status == "completed" and listed["real"].reason is None
    for name in ("linked", "damaged"):  # never hidden, never shown as completed: damaged, with the reason
        assert (listed[name].kind, listed[name].status) == ("sweep", "damaged")
        assert "sweep.json" in listed[name].reason and str(runs) not in listed[name].reason


def test_a_sweep_that_says_running_with_no_live_process_reads_as_interrupted(tmp_path):
    out = tmp_path / "sweep"
    run_sweep(plan_sweep(SWEEP), out, RunOptions(workers=1), plot=False)
    record = json.loads((out / "sweep.json").read_text())
    (out / "sweep.json").write_text(json.dumps({**record, "status": "running"}))  # what a killed sweep leaves
    (out / "run.lock").write_text("pid 999999999, started 2025-01-01 00:00:00\n")
    state = run_state(out)
    assert (state.status, state.pid, state.resumable) == ("interrupted", None, True)


def test_follow_of_a_sweep_that_ended_on_a_full_disk_says_why(tmp_path, capsys):
    """A detached sweep stopped by a full disk logs its error; `follow` afterwards listed its
    points and said nothing of why it stopped."""
    from frictionlab.cli import main
    from frictionlab.runs.progresslog import ProgressLog

    out = tmp_path / "sweep"
    assert main(["run", "benad2012-fig5", "--set", "realizations=2", "--set", "loading.steps=5", "--set", "fit.bootstrap=20",
                 "--out", str(out), "--workers", "1", "--quiet", "--no-plot"]) == 0  # fmt: skip
    data = json.loads((out / "sweep.json").read_text())
    data["status"] = "interrupted"  # as a sweep stopped by the disk leaves it
    (out / "sweep.json").write_text(json.dumps(data))
    said = f"cannot write results to {out}/points/02-hurst-0.4/curve.csv: No space left on device"
    ProgressLog(out).error(said, 1)  # as the detached process says it
    capsys.readouterr()
    assert main(["follow", str(out)]) == 1
    assert capsys.readouterr().err == f"error: {said}\n"
