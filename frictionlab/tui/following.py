"""A run (or sweep) the TUI shows that goes on in a process of its own
(``frictionlab.runs.detached``), started here or found running in the runs folder; and a
finished run (or sweep) read back from its folder. No Textual here: the app polls
``FollowedRun`` (``FollowedSweep``) on a timer."""

from __future__ import annotations

import os
import stat
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

from ..api import Result, load
from ..runs.detached import cancel, lock_held, lock_holder, stored_count
from ..errors import FrictionlabError, RunFolderError, shown
from ..runs.progresslog import PROGRESS_FILE, Follower, NoProgressFile
from ..runs.sweeplog import SweepFollower
from .folders import read_run, read_sweep
from .live import LiveListener
from .sweepview import SweepPoster


class FollowedRun:
    """The run in ``folder`` of ``scene``, read from its progress file; ``post`` gets the
    ``Snapshot``s of a ``LiveListener`` (elapsed and rate in the run's own times).
    ``process``: the run's process when this TUI started it (reaped here), else None."""

    def __init__(self, folder: Path, scene, post, process: subprocess.Popen | None = None, pid: int | None = None):
        self.folder = Path(folder)
        self.scene = scene
        self.process = process
        self._pid = pid
        self.live = LiveListener(post)
        self.follower = Follower(folder, scene, [self.live], pid=process.pid if process is not None else None)
        self.live.clock = self.follower.now
        self.cancelling = False
        self.refusal: str | None = None  # why a cancel signalled nothing
        self.said_progress_problem = False  # that its progress file cannot be written (said once)
        self.no_progress_file = NoProgressFile(self.follower.reader)

    @property
    def pid(self) -> int | None:
        """The run's process: the one started here, else the folder's lock holder as the
        kernel says (never the pid its progress file names: anyone may have written that)."""
        if self.process is not None:
            return self.process.pid
        return lock_holder(self.folder)

    @property
    def error(self) -> str | None:
        """Why the run could not begin or go on, as it said (None if it did not)."""
        finished = self.follower.finished
        return finished.error if finished is not None and finished.exit_code is not None else None

    @property
    def ended(self) -> bool:
        """Whether the run's last event came (how it ended, or why it could not go on): its
        process may still be writing its files and closing, with nothing left to cancel. Of a
        run another process holds, only if that process wrote it: a resume that has the folder
        but has not yet rewritten its progress file leaves the last run's end there."""
        if self.follower.finished is None:
            return False
        return self.process is not None or (self.follower.pid is not None and self.follower.pid == self.pid)

    def poll(self) -> bool:
        """Read what the run wrote since the last call (a snapshot even when nothing came:
        the elapsed time moves); True once its process has ended."""
        if not self.follower.poll() and self.live is not None and self.count_from_chunks() is None:
            self.live.tick()  # the elapsed time moves (not over the count read from the chunks instead)
        if self.process is not None:
            over = self.process.poll() is not None  # also reaps it: no zombie reads as alive
        else:
            over = not lock_held(self.folder)
        if over:
            self.follower.poll()  # what it wrote last
        return over

    def progress_problem(self) -> str | None:
        """Why this TUI cannot read what the run writes to its progress file: it is a link or not
        a regular file, which is never written or read through, or it was removed once read (its
        folder removed by hand: the run writes on into the file it has open, its chunks into the
        folder made again); None if it is fine or not there yet."""
        path = self.folder / PROGRESS_FILE
        try:
            mode = os.lstat(path).st_mode
        except OSError:  # the progress froze at what was read, the time left growing, without a word
            read = self.follower.reader.offset > 0
            return f"{PROGRESS_FILE} in {shown(self.folder)} was removed while the run goes on" if read else None
        if stat.S_ISREG(mode):
            return None
        what = "a symbolic link" if stat.S_ISLNK(mode) else "not a regular file"
        return f"{PROGRESS_FILE} in {shown(self.folder)} is {what}, never written through"

    def count_from_chunks(self) -> str | None:
        """Why this run's count is read from its chunks rather than its progress file: the file
        cannot be read (``progress_problem``), or a run not started here writes none; None if not."""
        return self.progress_problem() or (None if self.process is not None else self.no_progress_file.reason())

    def stored_count(self) -> tuple[int | None, int | None]:
        """(done, total) realizations as the run folder's manifest says (its chunks)."""
        try:
            return stored_count(self.folder)
        except (OSError, FrictionlabError):
            return None, None

    def cancel(self) -> bool:
        """SIGTERM: the run keeps what finished and ends interrupted. False if it is gone, or
        (``refusal`` says why) no process could be verified as the one that holds its folder.
        Signalled: the process started here (not yet reaped: its pid is its own), else only
        the folder's lock holder (``detached.cancel``). Signalled once: a second SIGTERM stops the
        run's process at once, before it has written what finished (c pressed again, c on quitting)."""
        self.refusal = None
        if self.cancelling:
            return True
        if self.process is not None:
            if self.process.poll() is None:
                self.process.terminate()
                self.cancelling = True
            return self.cancelling
        try:
            cancel(self.folder)
            self.cancelling = True
        except RunFolderError as exc:
            self.refusal = str(exc)
        return self.cancelling


class FollowedSweep(FollowedRun):
    """The sweep in ``folder`` (a planned ``sweep.Sweep``), read from its progress files:
    ``post_point(kind, point, result)`` hears each point start and finish (``SweepPoster``),
    ``post`` the ``Snapshot``s of the point running."""

    def __init__(self, folder: Path, sweep, post, post_point, process: subprocess.Popen | None = None):
        self.folder = Path(folder)
        self.sweep = sweep
        self.scene = sweep.points[0].scene
        self.process = process
        self._pid = None
        self.live: LiveListener | None = None  # the point running's, made as it starts
        self._post = post
        self.follower = SweepFollower(folder, sweep, [SweepPoster(post_point, self._listeners_of)],
                                      pid=process.pid if process is not None else None)  # fmt: skip
        self.said_progress_problem = False
        self.no_progress_file = NoProgressFile(self.follower.reader)
        self.cancelling = False
        self.refusal: str | None = None

    def progress_problem(self) -> str | None:
        return None  # a sweep's count is its points', never read from chunks: its live tick goes on

    def count_from_chunks(self) -> str | None:
        """Why its points' count comes from sweep.json and the chunks of the one going on: it writes
        no progress file (a sweep started in a terminal); None if not."""
        return None if self.process is not None else self.no_progress_file.reason()

    def _listeners_of(self, point) -> list[object]:
        self.live = LiveListener(self._post)
        self.live.clock = self.follower.now
        return [self.live]


@dataclass
class FinishedRun:
    """A finished run as its folder holds it: the numbers (``api.Result``) and what the Run tab adds."""

    result: Result
    workers: int
    f_formula: str
    failures: list[tuple[int, str]] = field(default_factory=list)
    failed: int = 0
    error: str | None = None

    @property
    def status(self) -> str:
        return self.result.status

    @property
    def done(self) -> int:
        return self.result.realizations[0]

    @property
    def fit(self):
        return self.result.fit


@dataclass
class FinishedSweep:
    """A finished sweep as its folder holds it: how it ended, and its last finished point's run."""

    status: str
    finished: int  # points that ended
    total: int
    elapsed: float
    last: FinishedRun | None  # None when no point wrote its results
    last_point: int | None = None  # its number, from 1


def read_finished_sweep(folder: Path) -> FinishedSweep:
    """The sweep in ``folder`` read back (RunFolderError, OSError if its sweep.json is unreadable)."""
    from ..runs.detached import sweep_state
    from ..errors import FrictionlabError

    entry, state = read_sweep(folder), sweep_state(folder)
    last, number = None, None
    for number, row in reversed(list(enumerate(entry.points, start=1))):
        try:
            last = read_finished(entry.point_folder(row))
            break
        except (FrictionlabError, OSError, ValueError, TypeError, KeyError):
            continue
    return FinishedSweep(state.status, state.done or 0, state.total or 0, entry.elapsed, last,
                         number if last is not None else None)  # fmt: skip


def read_finished(folder: Path) -> FinishedRun:
    """The run in ``folder`` read back (RunFolderError, OSError, ValueError if it wrote no results)."""
    result = load(folder)
    entry = read_run(folder)
    counts = entry.summary.get("realizations") if isinstance(entry.summary.get("realizations"), dict) else {}
    failures = [(f.get("index"), str(f.get("error"))) for f in counts.get("failures") or [] if isinstance(f, dict)]
    workers = entry.summary.get("workers")
    error = entry.summary.get("error")
    return FinishedRun(
        result=result,
        workers=workers if isinstance(workers, int) and workers > 0 else 1,
        f_formula=entry.formula,
        failures=failures,
        failed=counts.get("failed") if isinstance(counts.get("failed"), int) else len(failures),
        error=error if isinstance(error, str) else None,
    )
