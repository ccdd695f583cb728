"""What the system and well-kept libraries do for frictionlab, checked where it shows:
run.lock (an flock) between real processes, available memory (psutil), the user's config
folder (platformdirs)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest

from frictionlab.compute import memory
from frictionlab.errors import RunFolderError
from frictionlab.runs.rundir import LOCK_FILE, RunDirectory

HOLD = """
import sys, time
from frictionlab.runs.rundir import RunDirectory
with RunDirectory(sys.argv[1]):
    print("held", flush=True)
    time.sleep(60)
"""


def holder(folder):
    process = subprocess.Popen([sys.executable, "-c", HOLD, str(folder)], stdout=subprocess.PIPE, text=True)
    assert process.stdout.readline().strip() == "held"
    return process


def test_a_run_folder_held_by_another_process_is_refused_with_its_pid_until_it_dies(tmp_path):
    folder = tmp_path / "run"
    process = holder(folder)
    try:
        with pytest.raises(RunFolderError, match=rf"in use by another run \(pid {process.pid}, started"):
            RunDirectory(folder).__enter__()
    finally:
        process.send_signal(signal.SIGKILL)  # as kill -9: no clean-up, the kernel drops the lock
        process.wait()
    assert (folder / LOCK_FILE).exists()  # left behind by the killed holder ...
    with RunDirectory(folder):  # ... and taken over
        assert f"pid {os.getpid()}," in (folder / LOCK_FILE).read_text()
    assert not (folder / LOCK_FILE).exists()


FORK_AND_DIE = """
import os, signal, sys, time
from frictionlab.runs.rundir import RunDirectory
with RunDirectory(sys.argv[1]):
    started, ready = os.pipe()
    child = os.fork()
    if child == 0:  # a pool worker that outlives the main process
        os.write(ready, b"1")  # fork has returned here: the at-fork handlers have run
        time.sleep(30)
        os._exit(0)
    os.read(started, 1)
    print(child, flush=True)
    os.kill(os.getpid(), signal.SIGKILL)  # the main process dies holding the lock
"""


def test_a_forked_worker_does_not_keep_the_lock_of_a_dead_main_process(tmp_path):
    folder = tmp_path / "run"
    process = subprocess.Popen([sys.executable, "-c", FORK_AND_DIE, str(folder)], stdout=subprocess.PIPE, text=True)
    child = int(process.stdout.readline())
    process.wait()
    try:
        os.kill(child, 0)  # the worker is still alive, with its copy of the lock's descriptor
        with RunDirectory(folder):  # yet the folder is free
            pass
    finally:
        os.kill(child, signal.SIGKILL)


def test_available_memory_is_psutils_or_less_under_a_cgroup_limit():
    import psutil

    available, source = memory.available_memory()
    assert 0 < available <= psutil.virtual_memory().available * 1.05  # memory moves between the two reads
    assert source


def test_the_user_presets_folder_is_the_platforms_config_folder(monkeypatch):
    from platformdirs import user_config_path

    from frictionlab.preset.builtin import user_presets_dir

    assert user_presets_dir(env={}) == user_config_path("frictionlab") / "presets"
    assert user_presets_dir(env={"XDG_CONFIG_HOME": "/x"}) == __import__("pathlib").Path("/x/frictionlab/presets")
