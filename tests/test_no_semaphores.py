"""A system whose worker processes cannot start: without a usable /dev/shm (some containers and
batch nodes) Python makes no POSIX semaphore, and a process pool's first one fails with ENOSYS.
The default run goes on in its own process, saying so; an executor asked for by name is refused,
naming the cause. Such a run once ended 'error: cannot write: Function not implemented'."""

from __future__ import annotations

import _multiprocessing
import errno
import os
import subprocess
import sys

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
