"""A run's progress as a file in its folder, so that whoever comes later can follow it.

A run writes ``progress.jsonl``: one JSON object a line, appended as things happen
(``started``; ``realizations`` for the realizations finished since the last such line,
with the sums of their curves (``progresslines``); ``load`` and ``iteration`` within a long
solve; ``finished``; ``error`` when the run could not start). A TUI
opened later, ``frictionlab follow`` or ``tail -f`` read it; ``Follower`` replays
it to ``listeners.RunListener``s, the same ones that hear a run in this process.

The file is rewritten from the start when a run (or its resume) starts; a resume
first lists the realizations it restored, so a follower's sums cover them all.
It is read as the rest of a run folder is: untrusted, a regular file only (never
through a link), capped in size, a line that is not an event skipped.
"""

from __future__ import annotations

import json
import math
import os
import stat
import time
from dataclasses import dataclass, replace
from pathlib import Path

from ..errors import shown
from ..plugin.hookspecs import hookimpl
from ..compute.realization import RealizationResult
from ..io.files import written_through
from ..io.values import number_or_nan, whole_or
from .progresslines import MAX_BATCH, Batch, batch_results, fitted_line, result_of
from .progressevents import checked_event

PROGRESS_FILE = "progress.jsonl"
MAX_PROGRESS_BYTES = 256 * 1024 * 1024  # far above what a run writes (tens of bytes a realization): beyond that it is not ours
READ_BLOCK = 4 * 1024 * 1024  # read at most this much at a time: a follower stays responsive
FLUSH_SECONDS = 1.0  # realizations finished together are written as one line at most this often,
FLUSH_SHARE = 0.01  # or this share of the run's time so far if longer (a long run's log grows slower than its time),
MAX_FLUSH_SECONDS = 60.0  # but at least this often while realizations finish: a follower is never a minute behind
SOLVE_SECONDS = 0.5  # a solve's load events, at most this often (a fast solver reports every load)


class ProgressLog:
    """A ``listeners.RunListener`` that writes the run's events to ``folder/progress.jsonl``.
    Realizations are written together (``progresslines.Batch``): the first at once, then at
    most every ``FLUSH_SECONDS`` (``FLUSH_SHARE`` of the run's time so far, if longer, up to
    ``MAX_FLUSH_SECONDS``), the last with it, and what is pending before any other event.
    Progress is never worth a run: a write that fails stops the log, not the run."""

    def __init__(self, folder: str | Path, clock=time.time):
        self.path = Path(folder) / PROGRESS_FILE
        self.clock = clock
        self._fd: int | None = None
        self._batch = Batch()
        self._started = self._flushed = self._solve_said = -math.inf
        self._held: list[dict] = []  # warnings given before the file was begun: written once it is

    def _open(self, truncate: bool) -> None:
        self.close()
        flags = os.O_WRONLY | os.O_CREAT | os.O_APPEND | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
        try:
            self._fd = os.open(self.path, flags, 0o644)
            if written_through(os.fstat(self._fd)):  # emptied only once known to be the folder's own file
                self.close()
            elif truncate:
                os.ftruncate(self._fd, 0)
        except OSError:
            self._fd = None

    def close(self) -> None:
        self.flush()
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def write(self, event: dict) -> None:
        """Append one event (with the wall-clock ``time``) as one line of at most
        ``MAX_LINE_BYTES`` (``fitted_line``), written at once."""
        if self._fd is None:
            return
        line = fitted_line({**event, "time": self.clock()})
        try:
            written = os.write(self._fd, line)
            if written < len(line):  # a full disk: the part written goes, so that no later line (the error) is glued to it
                os.ftruncate(self._fd, os.lseek(self._fd, 0, os.SEEK_CUR) - written)
                self.close()
        except OSError:
            self.close()

    def flush(self) -> None:
        """Write the realizations not yet written, if any."""
        batch, self._batch = self._batch, Batch()
        if len(batch):
            self._flushed = self.clock()
            self.write(batch.event())

    def _due(self) -> bool:
        now = self.clock()
        elapsed = now - self._started if math.isfinite(self._started) else 0.0
        return now - self._flushed >= max(FLUSH_SECONDS, min(FLUSH_SHARE * elapsed, MAX_FLUSH_SECONDS))

    def error(self, message: str, exit_code: int) -> None:
        """The run could not start, or stopped with an error: what a follower shows."""
        if self._fd is None:
            self._batch = Batch()  # none of its realizations are told after another run's events
            self._open(truncate=False)  # appended: the log may be another live run's (a folder in use)
            self._write_held()
        self.flush()
        self.write({"event": "error", "pid": os.getpid(), "message": message, "exit_code": int(exit_code)})

    def warning(self, message: str) -> None:
        """A warning of the run's process (a detached one's stderr is no one's): what a follower shows."""
        event = {"event": "warning", "pid": os.getpid(), "message": message}
        if self._fd is None:
            self._held.append(event)
        else:
            self.write(event)

    def _write_held(self) -> None:
        held, self._held = self._held, []
        for event in held:
            self.write(event)

    def begin(self, event: dict) -> None:
        """Start the file afresh (a new run, or its resume) with ``event``."""
        self._open(truncate=True)
        self.write(event)
        self._write_held()

    @hookimpl
    def run_started(self, run):
        self.begin({"event": "started", "pid": os.getpid(), "name": run.scene.preset.name, "total": run.total,
                    "workers": run.workers, "executor": run.executor, "resumed": run.resumed, "retried": run.retried})  # fmt: skip
        self._batch = Batch(restored=True)
        for done, result in enumerate(run.restored, start=1):
            self._batch.add(result, done, run.total)
            if len(self._batch) >= MAX_BATCH:
                self.flush()
                self._batch = Batch(restored=True)
        self.flush()
        self._started, self._flushed, self._solve_said = self.clock(), -math.inf, -math.inf  # the first is written at once

    @hookimpl
    def realization_done(self, result, done, total):
        self._batch.add(result, done, total)
        if done >= total or len(self._batch) >= MAX_BATCH or self._due():
            self.flush()

    @hookimpl
    def realization_failed(self, result, done, total):
        self.realization_done(result, done, total)

    def _solve_note(self, event: dict) -> None:
        """A long solve's event (the realizations due first): an iteration's always (the run
        sends them at most every ``ITERATION_EVENT_SECONDS``), a load's if none was for ``SOLVE_SECONDS``."""
        if self._due():
            self.flush()
        if event["event"] == "iteration" or self.clock() - self._solve_said >= SOLVE_SECONDS:
            self._solve_said = self.clock()
            self.write(event)

    @hookimpl
    def load_done(self, index, done, total):
        self._solve_note({"event": "load", "index": index, "done": done, "total": total})

    @hookimpl
    def iteration_done(self, index, load, iteration, residual):
        self._solve_note({"event": "iteration", "index": index, "load": load, "iteration": iteration, "residual": residual})

    @hookimpl
    def run_finished(self, outcome):
        self.flush()
        self.write({"event": "finished", "status": outcome.status, "done": outcome.done,
                    "failed": len(outcome.failures), "requested": outcome.requested, "error": outcome.error})  # fmt: skip
        self.close()  # a sweep's child writes one log per point: none stays open


# ------------------------------------------------------------------ reading


REALIZATIONS = ("realization", "realizations")  # one realization's event (as written before), several's
HEAD_BYTES = 4096  # of the first line, kept to tell a rewritten file (its ``started`` names a new pid and time)


def progress_file_problem(folder: str | Path) -> str | None:
    """Why the progress file in ``folder`` would not be written (``written_through``; a symbolic
    link, never followed); None if it is fine or not there."""
    path = Path(folder) / PROGRESS_FILE
    try:
        status = os.lstat(path)
    except FileNotFoundError:
        return None
    why = "a symbolic link" if stat.S_ISLNK(status.st_mode) else written_through(status)
    return None if why is None else f"{PROGRESS_FILE} in {shown(Path(folder))} is {why}, never written through"


NO_PROGRESS_FILE_WAIT = 2.0  # seconds a run found running may go without a progress file before it is said to write none


class NoProgressFile:
    """Whether a run found running writes no progress file (``frictionlab run`` in a terminal
    writes none): none there, nothing read from one, for NO_PROGRESS_FILE_WAIT seconds. Its
    count is then read from its chunks (``detached.run_state``)."""

    def __init__(self, reader: ProgressReader):
        self.reader = reader
        self._missing_since: float | None = None

    def reason(self) -> str | None:
        """Why the run's count comes from its chunks; None while it has (or may yet write) a progress file."""
        if self.reader.offset > 0 or os.path.lexists(self.reader.path):
            self._missing_since = None
            return None
        now = time.monotonic()
        self._missing_since = self._missing_since or now
        if now - self._missing_since < NO_PROGRESS_FILE_WAIT:
            return None
        return (f"the run in {shown(self.reader.path.parent)} writes no {PROGRESS_FILE} (frictionlab run in a "
                "terminal writes none; frictionlab run --detach and the terminal UI do)")


class ProgressReader:
    """Reads the events appended to a folder's progress.jsonl since the last call.
    A file that shrank, or whose first line changed, was rewritten by a new start (a
    resume rewrites it larger than the run it continues): reading begins again (``restarted``)."""

    def __init__(self, folder: str | Path):
        self.path = Path(folder) / PROGRESS_FILE
        self.offset = 0
        self.restarted = False
        self.too_large = False
        self.skipping = False  # inside a line too long to be an event
        self.head = b""  # the start of the first line read (up to HEAD_BYTES)

    def new_events(self) -> list[dict]:
        self.restarted = False
        try:
            fd = os.open(self.path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
        except OSError:
            return []  # not there yet, or a link: nothing to follow
        try:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                return []
            if info.st_size > MAX_PROGRESS_BYTES:
                self.too_large = True
                return []
            if info.st_size < self.offset or (self.head and os.pread(fd, len(self.head), 0) != self.head):
                self.offset, self.restarted, self.head, self.skipping = 0, True, b"", False
            data = os.pread(fd, min(READ_BLOCK, info.st_size - self.offset), self.offset)
        except OSError:  # read next time, if it can be
            return []
        finally:
            os.close(fd)
        if self.skipping:  # the rest of a line longer than any frictionlab writes
            cut = data.find(b"\n") + 1
            self.offset, self.skipping = self.offset + (cut or len(data)), not cut
            data = data[cut:] if cut else b""
        end = data.rfind(b"\n") + 1  # only whole lines: the last one may still be written
        if not end and len(data) == READ_BLOCK:  # no line ends in a whole block: not one of ours, skipped
            self.offset, self.skipping = self.offset + len(data), True
            return []
        if self.offset == 0 and end:
            self.head = data[: min(data.find(b"\n") + 1, HEAD_BYTES)]
        self.offset += end
        return [event for event in map(_parse, data[:end].splitlines()) if event is not None]


def _parse(line: bytes) -> dict | None:
    try:
        event = json.loads(line)
    except (ValueError, RecursionError):
        return None
    return checked_event(event) if isinstance(event, dict) and isinstance(event.get("event"), str) else None


def told_by(event: dict, pid: int | None) -> bool:
    """Whether ``event`` (an ``error`` or ``warning``) is of the followed process ``pid`` (any,
    while it is not known): not of a second run that was refused the folder."""
    return pid is None or event.get("pid") == pid


class HeardWarnings:
    """The warnings a followed process wrote (``warning`` events), each handed out once (``take``)."""

    def __init__(self):
        self._new: list[str] = []

    def hear(self, event: dict, pid: int | None) -> None:
        if told_by(event, pid):
            self._new.append(str(event.get("message")))

    def take(self) -> list[str]:
        new, self._new = self._new, []
        return new


@dataclass
class Finished:
    """How a followed run ended, as its last event says (or ``interrupted`` when its process went without one)."""

    status: str
    done: int
    requested: int
    error: str | None = None
    exit_code: int | None = None  # an ``error`` event's: the run could not start


class StartOf:
    """Where the run of the process ``pid`` begins in a progress file (all of it when ``pid``
    is None): a front end that started a resume may read the file of the run it continues
    before the new process rewrites it, and the old events are not this run's."""

    def __init__(self, pid: int | None, *started: str):
        self.pid, self.started = pid, started
        self.seen = pid is None

    def after(self, events: list[dict], restarted: bool) -> list[dict]:
        """``events`` from this process's start (or its ``error``: it could not start) on."""
        if restarted:
            self.seen = self.pid is None
        if self.seen:
            return events
        for at, event in enumerate(events):
            if (event["event"] in self.started or event["event"] == "error") and event.get("pid") == self.pid:
                self.seen = True
                return events[at:]
        return []


class Follower:
    """Replays a folder's progress.jsonl to ``listeners`` (``RunListener``s) as it grows:
    ``run_started`` (with a ``RunInfo`` of the stored preset's ``scene``), ``realization_done``
    or ``realization_failed``, ``load_done``, ``iteration_done``, ``run_finished`` (its
    outcome a ``Finished``: status, done, requested, error). A resume's restored
    realizations come in ``RunInfo.restored``, as the run's own listeners have them. Call
    ``poll()`` now and then; ``finished`` is set once the run's last event came. ``now()`` is
    the wall-clock time of the event being replayed (the present between events): a
    listener's clock, so that its elapsed time and rate are the run's even when followed
    from the middle. ``pid``: the run's process, when known (it was started here); only its
    events are replayed."""

    def __init__(self, folder: str | Path, scene, listeners=(), pid: int | None = None):
        self.reader = ProgressReader(folder)
        self.scene = scene
        self.listeners = list(listeners)
        self.info = None
        self.pid = pid
        self.awaited = StartOf(pid, "started")
        self.finished: Finished | None = None
        self.done = self.total = 0
        self._event_time: float | None = None
        self._told_at: float | None = None  # the time of the event before the one replayed
        self._hooks = None
        self._resuming = None  # a resume's RunInfo, told once the realizations it restored are read
        self._restored: list[RealizationResult] = []
        self.warnings = HeardWarnings()

    def now(self) -> float:
        return time.time() if self._event_time is None else self._event_time

    def _tell(self, hook: str, **kwargs) -> None:
        from ..compute.engine import listener_manager

        if self._hooks is None:
            self._hooks = listener_manager(self.listeners).hook
        getattr(self._hooks, hook)(**kwargs)

    def _start(self, info) -> None:
        self.info, self._resuming = info, None
        self.done = info.resumed
        self._tell("run_started", run=info)

    def _results(self, event: dict) -> list[RealizationResult] | None:
        """The realizations a ``realization`` or ``realizations`` event tells, None if it holds none."""
        if event["event"] == "realizations":
            return batch_results(event, self.scene.loads.size)
        result = result_of(event, self.scene.loads.size)
        return None if result is None else [result]

    def _realizations(self, event: dict) -> None:
        """Tell each realization of ``event``, counted up to its ``done``; none of another run's."""
        results, done = self._results(event), whole_or(event.get("done"), self.done)
        if not results or done > self.total or done < len(results):  # not realizations of this run
            return
        end = self._event_time
        start = self._told_at if end is not None and self._told_at is not None and self._told_at < end else end
        for k, result in enumerate(results, start=1):  # each at its share of the time since the last event: a rate as the run's
            self.done = done - len(results) + k
            self._event_time = None if end is None else start + (end - start) * k / len(results)
            hook = "realization_done" if result.ok else "realization_failed"
            self._tell(hook, run=self.info, result=result, done=self.done, total=self.total)

    def poll(self) -> int:
        """Replay the events written since the last call; return how many."""
        from ..compute.engine import RunInfo

        events = self.reader.new_events()
        if self.reader.restarted:
            self.info, self.finished, self._resuming = None, None, None
        for event in self.awaited.after(events, self.reader.restarted):
            kind = event["event"]
            at = number_or_nan(event.get("time")) if math.isfinite(number_or_nan(event.get("time"))) else None
            self._event_time = at
            try:
                if self._resuming is not None and kind in REALIZATIONS and event.get("restored") is True:
                    results = self._results(event) or []  # as the run's own listeners have them:
                    self._restored += [result for result in results if result.ok]  # in RunInfo.restored, not done now
                    if len(self._restored) >= self._resuming.resumed:
                        self._start(replace(self._resuming, restored=tuple(self._restored)))
                    continue
                if self._resuming is not None:  # the restored ones are over (some were not readable)
                    self._start(replace(self._resuming, restored=tuple(self._restored)))
                if kind == "started":
                    self.pid = whole_or(event.get("pid")) or None
                    self.total = whole_or(event.get("total"))
                    self.done, self.finished, self.info = 0, None, None
                    info = RunInfo(scene=self.scene, total=self.total, workers=whole_or(event.get("workers"), 1),
                                   executor=str(event.get("executor")), resumed=whole_or(event.get("resumed")))  # fmt: skip
                    if info.resumed:
                        self._resuming, self._restored = info, []
                    else:
                        self._start(info)
                elif kind in REALIZATIONS and self.info is not None:
                    self._realizations(event)
                elif kind == "load" and self.info is not None:
                    self._tell("load_done", run=self.info, index=whole_or(event.get("index")),
                               done=whole_or(event.get("done")), total=whole_or(event.get("total")))  # fmt: skip
                elif kind == "iteration" and self.info is not None:
                    self._tell("iteration_done", run=self.info, index=whole_or(event.get("index")), load=whole_or(event.get("load")),
                               iteration=whole_or(event.get("iteration")), residual=number_or_nan(event.get("residual")))  # fmt: skip
                elif kind == "finished":
                    error = event.get("error")
                    self.finished = Finished(str(event.get("status")), whole_or(event.get("done")),
                                             whole_or(event.get("requested")), error if isinstance(error, str) else None)  # fmt: skip
                    if self.info is not None:  # as the run told its own: a bar ends, a last snapshot goes out
                        self._tell("run_finished", run=self.info, outcome=self.finished)
                elif kind == "error" and told_by(event, self.pid):
                    self.finished = Finished("failed", self.done, self.total, str(event.get("message")),
                                             whole_or(event.get("exit_code"), 1))  # fmt: skip
                elif kind == "warning":
                    self.warnings.hear(event, self.pid)
            finally:
                self._event_time, self._told_at = None, self._told_at if at is None else at
        return len(events)
