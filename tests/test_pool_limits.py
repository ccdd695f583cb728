"""A pool refused its workers says which limit refused them: a control group's pids.max
(a container, a batch job) is not ``ulimit -u``, which then names no cause of the refusal."""

from __future__ import annotations

import errno

from frictionlab.compute import pool


def _cgroup(tmp_path, own: str, folder: str, limit: str, current: int):
    (tmp_path / "cgroup").write_text(own)
    where = tmp_path / "fs" / folder
    where.mkdir(parents=True)
    (where / "pids.max").write_text(f"{limit}\n")
    (where / "pids.current").write_text(f"{current}\n")
    return str(tmp_path / "fs"), str(tmp_path / "cgroup")


def test_a_reached_pids_limit_of_cgroup_v1_is_found(tmp_path):
    root, own = _cgroup(tmp_path, "8:pids:/job7\n4:memory:/x\n", "pids/job7", "4", 4)
    assert pool.cgroup_pids_limit(root, own) == 4


def test_a_reached_pids_limit_of_cgroup_v2_is_found(tmp_path):
    root, own = _cgroup(tmp_path, "0::/user.slice/job7\n", "user.slice/job7", "12", 12)
    assert pool.cgroup_pids_limit(root, own) == 12


def test_a_pids_limit_not_reached_or_unset_is_not_named(tmp_path):
    root, own = _cgroup(tmp_path, "8:pids:/a\n", "pids/a", "40", 3)
    assert pool.cgroup_pids_limit(root, own) is None
    (tmp_path / "v2").mkdir()
    root, own = _cgroup(tmp_path / "v2", "0::/b\n", "b", "max", 3)
    assert pool.cgroup_pids_limit(root, own) is None
    assert pool.cgroup_pids_limit(root, str(tmp_path / "absent")) is None


def test_a_fork_refused_by_a_pids_limit_names_it_not_ulimit_u(monkeypatch):
    monkeypatch.setattr(pool, "cgroup_pids_limit", lambda: 4, raising=False)
    reason = pool.start_failure(OSError(errno.EAGAIN, "Resource temporarily unavailable"))
    assert reason == "Resource temporarily unavailable; the control group's process limit (pids.max) is 4 here"


def test_a_second_interrupt_during_the_pools_stop_leaves_no_worker_waiting(monkeypatch):
    """A second Ctrl-C lands while the pool waits for its first idle worker to stop: every
    worker was told to stop before that wait, so none waits on for a job (workers ignore
    SIGTERM; the command's exit would wait for them forever)."""
    import multiprocessing
    import threading

    import pytest

    from frictionlab.compute.executors import pool_context

    def interrupted_wait(self, timeout=2.0):
        raise KeyboardInterrupt  # the second Ctrl-C, at the first wait

    monkeypatch.setattr(pool._Worker, "stop", interrupted_wait)
    workers = pool.WorkerPool(2, pool_context(), abs)
    with pytest.raises(KeyboardInterrupt) as caught:  # holds the pool's frame, as an exiting command does
        for _ in workers.run({key: -key for key in range(8)}, threading.Event()):
            pass
    children = multiprocessing.active_children()
    for child in children:
        child.join(10)
    waiting = [child for child in children if child.is_alive()]
    for child in waiting:  # the old way's leftovers: killed, or pytest's own exit waits for them
        child.kill()
        child.join()
    assert caught.value is not None and not waiting
