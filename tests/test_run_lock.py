"""run.lock's flock (``runs.runlock``): held once, retaken on the file that is there, let go on failure."""

from __future__ import annotations

import os

import pytest

from frictionlab.runs import runlock
from frictionlab.runs.runlock import LockHeld, RunLock

pytestmark = pytest.mark.skipif(runlock.fcntl is None, reason="flock is POSIX's (filelock's lock is used elsewhere)")


def wrote_pid(fd: int) -> None:
    os.pwrite(fd, f"pid {os.getpid()}\n".encode(), 0)


def test_a_second_lock_on_the_file_is_refused_until_the_first_lets_go(tmp_path):
    path = tmp_path / "run.lock"
    first = RunLock(path, wrote_pid)
    first.acquire()
    assert path.read_text() == f"pid {os.getpid()}\n"
    with pytest.raises(LockHeld):
        RunLock(path, wrote_pid).acquire()
    first.release()
    second = RunLock(path, wrote_pid)
    second.acquire()
    second.release()


def test_a_file_removed_by_its_holder_as_it_let_go_is_not_the_one_locked(tmp_path, monkeypatch):
    """The waiter opened run.lock; the holder then removed it and let go: a lock on the
    removed file would lock nothing that a third run could see."""
    path = tmp_path / "run.lock"
    path.write_text("old holder\n")
    real_open, opened = os.open, []

    def open_then_removed(name, flags, mode=0o777):
        fd = real_open(name, flags, mode)
        if not opened:
            os.unlink(name)  # as the old holder does, after this open
        opened.append(fd)
        return fd

    monkeypatch.setattr(runlock.os, "open", open_then_removed)
    lock = RunLock(path, wrote_pid)
    lock.acquire()
    try:
        assert len(opened) == 2
        assert os.fstat(opened[1]).st_ino == os.stat(path).st_ino
        monkeypatch.setattr(runlock.os, "open", real_open)
        with pytest.raises(LockHeld):  # the file now at the path is the one held
            RunLock(path, wrote_pid).acquire()
    finally:
        lock.release()


def test_a_holder_that_cannot_say_who_it_is_lets_the_lock_go(tmp_path):
    path = tmp_path / "run.lock"

    def fails(fd):
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space"):
        RunLock(path, fails).acquire()
    again = RunLock(path, wrote_pid)
    again.acquire()  # not held by the failed one
    again.release()
    assert not runlock._HELD
