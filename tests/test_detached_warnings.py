"""A detached run's warnings: its stderr is no one's, so they go to its progress log, where a
follower (the TUI, ``frictionlab follow``) hears each once. They used to go to /dev/null."""

import json
import os
import sys

import pytest

from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.runs.detached import start_detached
from frictionlab.runs.progresslog import PROGRESS_FILE, Follower, ProgressLog

from .conftest import SMALL_PRESET, merge
from .sessions import wait_for
from .test_no_semaphores import REFUSING

STARTED = {"event": "started", "pid": os.getpid(), "name": "x", "total": 1}


def test_a_warning_given_before_the_log_began_is_written_after_its_start_and_heard_once(tmp_path):
    log = ProgressLog(tmp_path)
    log.warning("the run goes on in this process")  # before the run started: no file yet
    assert not (tmp_path / PROGRESS_FILE).exists()
    log.begin(STARTED)
    log.warning("a second one")
    log.close()
    kinds = [json.loads(line)["event"] for line in (tmp_path / PROGRESS_FILE).read_text().splitlines()]
    assert kinds == ["started", "warning", "warning"]  # the file's first line still tells its run
    follower = Follower(tmp_path, build_scene(SMALL_PRESET))
    follower.poll()
    assert follower.warnings.take() == ["the run goes on in this process", "a second one"]
    assert follower.warnings.take() == []


def test_a_warning_logged_with_an_error_before_the_run_began_is_kept(tmp_path):
    log = ProgressLog(tmp_path)
    log.warning("said first")
    log.error("could not start", 2)
    log.close()
    follower = Follower(tmp_path, build_scene(SMALL_PRESET))
    follower.poll()
    assert follower.warnings.take() == ["said first"] and follower.finished.error == "could not start"


@pytest.mark.parametrize("forged", [{"message": ["not", "text"]}, {"message": "another run's", "pid": 1}])
def test_a_forged_warning_or_another_process_s_is_not_heard(tmp_path, forged):
    lines = [STARTED, {"event": "warning", "pid": os.getpid(), **forged}]
    (tmp_path / PROGRESS_FILE).write_text("".join(json.dumps(line) + "\n" for line in lines))
    follower = Follower(tmp_path, build_scene(SMALL_PRESET))
    follower.poll()
    assert follower.warnings.take() == []


@pytest.mark.skipif(sys.platform == "win32", reason="a detached run is a POSIX session")
def test_a_detached_run_s_warning_reaches_its_follower(tmp_path, monkeypatch):
    (tmp_path / "site").mkdir()
    (tmp_path / "site" / "sitecustomize.py").write_text(REFUSING)  # its worker processes cannot start
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(tmp_path / "site"), *sys.path]))
    data = merge(SMALL_PRESET, {"realizations": 8})
    out = tmp_path / "run"
    process = start_detached(build_scene(data).resolved(), out, RunOptions(workers=2), plot=False)
    wait_for(lambda: process.poll() is not None)
    assert process.returncode == 0
    follower = Follower(out, build_scene(data))
    follower.poll()
    assert follower.finished.status == "completed"
    [warning] = follower.warnings.take()
    assert warning.startswith("2 worker processes cannot start here (") and "POSIX semaphore" in warning


@pytest.mark.skipif(sys.platform == "win32", reason="a detached run is a POSIX session")
def test_follow_of_a_run_that_ended_says_its_warnings_and_not_another_process_s(tmp_path, capsys):
    """The run ended before anyone followed it: its warnings are in its log alone."""
    from frictionlab.cli.main import main

    data = merge(SMALL_PRESET, {"realizations": 4})
    out = tmp_path / "run"
    assert main(["run", str(write_preset(tmp_path, data)), "--out", str(out), "--quiet", "--no-plot"]) == 0
    process = start_detached(build_scene(data).resolved(), out, RunOptions(workers=1), plot=False)  # runs again
    wait_for(lambda: process.poll() is not None)
    with open(out / PROGRESS_FILE, "a") as log:  # a second run, refused the folder, logged this
        log.write(json.dumps({"event": "warning", "pid": process.pid + 1, "message": "another run's"}) + "\n")
    capsys.readouterr()
    assert main(["follow", str(out)]) == 0
    said = capsys.readouterr()
    assert "completed, 4/4 realizations" in said.out
    warnings = [line for line in said.err.splitlines() if line.startswith("warning: ")]
    assert len(warnings) == 1 and "holds a completed run of this preset: it runs again" in warnings[0]


def write_preset(folder, data):
    import yaml

    path = folder / "preset.yaml"
    path.write_text(yaml.safe_dump(data))
    return path
