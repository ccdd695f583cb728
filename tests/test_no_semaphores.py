"""A system whose worker processes cannot start: without a usable /dev/shm (some containers and
batch nodes) Python makes no POSIX semaphore, and a process pool's first one fails with ENOSYS.
The default run goes on in its own process, saying so; an executor asked for by name is refused,
naming the cause. Such a run once ended 'error: cannot write: Function not implemented'."""

from __future__ import annotations

import _multiprocessing
import errno
import os
import re
import subprocess
import sys
import warnings

import numpy as np
import pytest

from frictionlab.compute import engine
from frictionlab.errors import RunError
from frictionlab.options import RunOptions

REFUSING = """
import _multiprocessing, errno
class _Refused(_multiprocessing.SemLock):
    def __new__(cls, *args, **keys):
        raise OSError(errno.ENOSYS, "Function not implemented")
_multiprocessing.SemLock = _Refused
"""


class _Refused(_multiprocessing.SemLock):
    def __new__(cls, *args, **keys):
        raise OSError(errno.ENOSYS, "Function not implemented")


@pytest.fixture
def no_semaphores(monkeypatch):
    monkeypatch.setattr(_multiprocessing, "SemLock", _Refused)


@pytest.fixture
def scene(make_scene):
    return make_scene({"realizations": 6})


def test_the_default_pool_gives_way_to_this_process_saying_why(scene, no_semaphores, monkeypatch):
    from frictionlab.compute import executors

    monkeypatch.setattr(executors, "POOL_START_SECONDS", 0.0)  # else a short run skips the pool anyway
    with pytest.warns(UserWarning, match=r"2 worker processes cannot start here \(.*POSIX semaphore.*Function not "
                                         r"implemented; is /dev/shm missing or read-only\?\): the run goes on in this process"):
        outcome = engine.run(scene, RunOptions(workers=2))
    assert (outcome.status, outcome.done, outcome.extra["executor"], outcome.workers) == ("completed", 6, "serial", 1)
    monkeypatch.undo()
    alone = engine.run(scene, RunOptions(workers=1))
    assert outcome.fit == alone.fit


def test_a_pool_asked_for_by_name_is_refused_naming_the_cause(scene, no_semaphores):
    with pytest.raises(RunError, match=r"executor 'processes' cannot start here: .*Function not implemented"):
        engine.run(scene, RunOptions(workers=2, executor="processes"))


def test_an_own_dask_cluster_is_refused_before_it_starts(scene, no_semaphores):
    pytest.importorskip("distributed", reason='dask is not installed: pip install "frictionlab[dask]"')
    with pytest.raises(RunError, match=r"executor 'dask' cannot start its local cluster here: .*semaphore"):
        engine.run(scene, RunOptions(workers=2, executor="dask"))


def test_a_local_dask_cluster_that_does_not_start_is_refused_naming_why(monkeypatch):
    distributed = pytest.importorskip("distributed", reason='dask is not installed: pip install "frictionlab[dask]"')
    from frictionlab.compute.dask_security import start_local_cluster

    def failing(*args, **keys):
        try:
            raise OSError(errno.ENOSPC, "No space left on device")
        except OSError as exc:
            raise RuntimeError("Nanny failed to start.") from exc

    monkeypatch.setattr(distributed, "LocalCluster", failing)
    with pytest.raises(RunError, match=r"^the local Dask cluster did not start: Nanny failed to start\. "
                                       r"\(OSError: \[Errno 28\] No space left on device\)$"):
        start_local_cluster(2)


def test_the_command_finishes_in_its_own_process_on_such_a_system(tmp_path):
    (tmp_path / "site").mkdir()
    (tmp_path / "site" / "sitecustomize.py").write_text(REFUSING)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path / "site"), *sys.path])}
    done = subprocess.run([sys.executable, "-m", "frictionlab", "run", "quickstart", "--workers", "2",
                           "--set", "realizations=40", "--out", str(tmp_path / "out"), "--no-plot"],
                          capture_output=True, text=True, env=env, cwd=tmp_path)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "warning: 2 worker processes cannot start here" in done.stderr and "Traceback" not in done.stderr
    assert "40/40 realizations in" in done.stdout and "(1 worker)" in done.stdout
    assert (tmp_path / "out" / "summary.json").is_file()


# ------------------------------------------------------------------ out of descriptors or processes


class _Starts(list):
    refused = 0  # starts refused


def _failing_starts(monkeypatch, after: int):
    """Worker starts fail, as under ``ulimit -n`` (EMFILE), once ``after`` have started."""
    from frictionlab.compute import executors, pool

    monkeypatch.setattr(executors, "POOL_START_SECONDS", 0.0)  # a short run would skip the pool anyway
    real, started = pool.WorkerPool._start, _Starts()

    def start(self, stop):
        if len(started) >= after:
            started.refused += 1
            raise OSError(errno.EMFILE, "Too many open files")
        started.append(real(self, stop))
        return started[-1]

    monkeypatch.setattr(pool.WorkerPool, "_start", start)
    return started


def test_a_pool_of_which_no_worker_starts_runs_here_saying_why(scene, monkeypatch):
    alone = engine.run(scene, RunOptions(workers=1))
    _failing_starts(monkeypatch, after=0)
    with pytest.warns(UserWarning, match=r"^worker processes could not start \(Too many open files; ulimit -n is \d+ "
                                         r"here\): the run goes on in this process$"):
        outcome = engine.run(scene, RunOptions(workers=2))
    assert (outcome.status, outcome.done, outcome.extra["executor"], outcome.workers) == ("completed", 6, "serial", 1)
    assert outcome.fit == alone.fit


def test_a_pool_short_of_workers_goes_on_with_those_that_started(scene, monkeypatch):
    alone = engine.run(scene, RunOptions(workers=1))
    started = _failing_starts(monkeypatch, after=1)
    with pytest.warns(UserWarning, match=r"^1 of 3 worker processes started \(Too many open files.*\): the run goes on with 1$"):
        outcome = engine.run(scene, RunOptions(workers=3))
    assert (outcome.status, outcome.done, outcome.extra["executor"], outcome.workers) == ("completed", 6, "processes", 1)
    assert len(started) == 1 and outcome.fit == alone.fit


@pytest.mark.skipif(not hasattr(__import__("resource"), "RLIMIT_NOFILE") or sys.platform == "win32", reason="POSIX limits")
def test_the_command_under_a_low_ulimit_n_finishes_saying_so(tmp_path):
    import resource

    def low_limit():
        resource.setrlimit(resource.RLIMIT_NOFILE, (16, 16))

    done = subprocess.run([sys.executable, "-m", "frictionlab", "run", "quickstart", "--workers", "8",
                           "--set", "realizations=400", "--out", str(tmp_path / "out"), "--no-plot"],
                          capture_output=True, text=True, cwd=tmp_path, preexec_fn=low_limit)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and "cannot write" not in done.stderr
    assert "ulimit -n is 16 here" in done.stderr and "400/400 realizations in" in done.stdout


@pytest.mark.parametrize("workers, starts", [(1, 1), (2, 2)])
def test_a_worker_that_dies_and_cannot_be_replaced_leaves_its_chunks_to_the_others_or_to_this_process(
    make_scene, tmp_path, monkeypatch, workers, starts
):
    """A worker dies (its chunk runs again); no new one can start: with one worker the chunks not
    yet done run here, with two the one left takes them. Every realization once, the same numbers."""
    from .faults import CrashingPowerLaw, with_spectrum

    scene = make_scene({"realizations": 24})
    alone = engine.run(scene, RunOptions(workers=1))
    flag = tmp_path / "crashed"
    crashing = with_spectrum(scene, CrashingPowerLaw, flag=str(flag), parent=os.getpid())
    started = _failing_starts(monkeypatch, after=starts)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        outcome = engine.run(crashing, RunOptions(workers=workers, executor="processes"))
    assert flag.exists(), "no worker died: the test did not test anything"
    # a replacement is started only where no worker is idle as the dead one's chunk comes back:
    # with one worker always; with two, as the other's chunk goes (it may have ended first)
    assert started.refused >= (1 if workers == 1 else 0)
    said = [w for w in caught if "worker processes" in str(w.message)]
    assert len(said) == (1 if started.refused else 0), [str(w.message) for w in caught]
    assert (outcome.status, outcome.done, outcome.failures) == ("completed", 24, [])
    np.testing.assert_array_equal(outcome.per_realization["xi"], alone.per_realization["xi"])
    assert outcome.fit == alone.fit


def test_a_run_where_no_thread_can_start_is_solved_in_the_main_thread(tmp_path, monkeypatch, cli):
    """A container's pids limit refuses new threads ("can't start new thread"): the serial
    solve and the plotting import ahead run without one, to the same numbers and files."""
    import threading

    here = cli("run", "quickstart", "--workers", "1", "--out", tmp_path / "with-threads")

    def refused(self):
        raise RuntimeError("can't start new thread")

    monkeypatch.setattr(threading.Thread, "start", refused)
    done = cli("run", "quickstart", "--workers", "1", "--out", tmp_path / "no-threads")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "no-threads" / "plot.png").is_file()
    timeless = lambda out: re.sub(r"in [\d.]+ s", "", out.replace("no-threads", "with-threads"))  # noqa: E731
    assert timeless(done.stdout) == timeless(here.stdout) and "xi = a + b ln f" in done.stdout


def test_a_progress_bar_is_drawn_where_no_thread_can_start(monkeypatch):
    """rich redraws its bar from a thread of its own; without one the bar is redrawn as it moves."""
    import io
    import threading

    from frictionlab.progress import _Bar

    def refused(self):
        raise RuntimeError("can't start new thread")

    monkeypatch.setattr(threading.Thread, "start", refused)
    stream = io.StringIO()
    bar = _Bar(stream, "realizations", 10)
    bar.update(7)
    bar.stop()
    assert "7/10" in stream.getvalue()


@pytest.mark.skipif(sys.platform == "win32", reason="flock is POSIX")
@pytest.mark.parametrize("code", [errno.ENOLCK, errno.ENOSYS])
def test_a_folder_on_a_file_system_without_locks_is_refused_naming_it(tmp_path, monkeypatch, cli, code):
    """Some network file systems keep no locks: a run without its folder's lock could share the
    folder with another and mix their chunks. It ended 'error: cannot write: No locks available'."""
    import fcntl

    def no_locks(fd, operation):
        raise OSError(code, os.strerror(code))

    monkeypatch.setattr(fcntl, "flock", no_locks)
    done = cli("run", "quickstart", "--out", tmp_path / "out")
    assert done.returncode not in (0, 70) and "Traceback" not in done.stderr
    assert f"run.lock cannot be locked ({os.strerror(code)})" in done.stderr
    assert "does not keep locks" in done.stderr and "give an output folder on a local disk" in done.stderr
    assert not (tmp_path / "out" / "summary.json").exists()
