"""run.lock: an exclusive lock a run holds on its folder while it writes there.

On POSIX it is a plain ``flock`` (the kernel drops it when its holder dies, even on kill -9);
elsewhere filelock's. Not filelock on POSIX too: its import is about 19 ms of every run's
start, for one call of ``fcntl.flock``.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path
from typing import Callable

from ..errors import RunFolderError, shown_name
from ..io.files import written_through

try:
    import fcntl
except ImportError:  # Windows: filelock's LockFileEx
    fcntl = None


class LockHeld(Exception):
    """Another process holds the lock."""


_HELD: set[int] = set()  # descriptors of the locks this process holds


def _forget_in_child() -> None:
    """A forked worker closes its copy of each held lock's descriptor (closing, never
    unlocking: the lock belongs to the parent's open file): a worker that outlives a
    killed main process must not keep the folder locked."""
    for fd in _HELD:
        try:
            os.close(fd)
        except OSError:
            pass
    _HELD.clear()


if fcntl is not None and hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_in_child)


class RunLock:
    """The lock file ``path``, taken at once or not at all (``LockHeld``). ``on_acquired(fd)``
    runs once it is held (to write who holds it). An OSError of the file system (ENOLCK,
    ENOSYS, ...: some network file systems keep no locks) is raised as it is."""

    def __init__(self, path: str | Path, on_acquired: Callable[[int], None]):
        self.path = Path(path)
        self.on_acquired = on_acquired
        self._fd: int | None = None
        self._fallback = None  # filelock's lock, where there is no flock

    def acquire(self) -> None:
        if fcntl is None:
            self._acquire_elsewhere()
            return
        flags = os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
        while True:
            fd = os.open(self.path, flags, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno in (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK):
                    raise LockHeld(str(self.path)) from None
                raise
            if self._still_the_file(fd):
                break
            os.close(fd)  # the holder removed the file we opened as it let go: lock the new one
        if (why := written_through(os.fstat(fd))) is not None:  # who holds it is written into it
            fcntl.flock(fd, fcntl.LOCK_UN)
            os.close(fd)
            raise RunFolderError(f"{shown_name(self.path)} is {why}: a run's lock is never written through; "
                                 "remove it (no run holds it)")
        self._fd = fd
        _HELD.add(fd)
        try:
            self.on_acquired(fd)
        except BaseException:
            self.release()
            raise

    def _still_the_file(self, fd: int) -> bool:
        try:
            return os.path.samestat(os.fstat(fd), os.stat(self.path, follow_symlinks=False))
        except FileNotFoundError:
            return False

    def _acquire_elsewhere(self) -> None:
        from filelock import FileLock, Timeout

        self._fallback = FileLock(self.path, timeout=0, mode=0o644, thread_local=False, on_acquired=self.on_acquired)
        try:
            self._fallback.acquire()
        except Timeout:
            self._fallback = None
            raise LockHeld(str(self.path)) from None

    def release(self) -> None:
        if self._fallback is not None:
            self._fallback.release()
            self._fallback = None
        if self._fd is not None:
            _HELD.discard(self._fd)
            fcntl.flock(self._fd, fcntl.LOCK_UN)
            os.close(self._fd)
            self._fd = None
