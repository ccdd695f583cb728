"""A sweep's progress as files, so that whoever comes later can follow it.

A sweep writes ``progress.jsonl`` in its folder (``progresslog.ProgressLog``: the same
file handling, one JSON object a line): ``sweep_started``, ``point_started`` (its
number and folder), ``point_finished`` (its row of sweep.json: status, fit, contact
counts), ``sweep_finished``; ``error`` when it could not start. Each point's run writes
its own ``progress.jsonl`` in its folder, as any run does. ``SweepFollower`` replays
both to ``listeners.SweepListener``s: the sweep's events, and the running point's
realizations to the run listeners they give for it.
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path

from ..errors import RunFolderError
from ..plugin.listeners import SweepListener
from ..io.values import number_or_nan, whole_or
from .progresslog import Finished, Follower, HeardWarnings, ProgressLog, ProgressReader, StartOf, told_by
from .runfolder import checked
from .sweep import UNFINISHED, PointResult, Sweep, SweepPoint, point_folder
from .sweeprecord import PointRecord


class SweepProgressLog(SweepListener):
    """A ``SweepListener`` that writes the sweep's events to ``out_dir/progress.jsonl``
    and gives each point's run a ``ProgressLog`` of its own folder."""

    def __init__(self, out_dir: str | Path):
        self.out_dir = Path(out_dir)
        self.log = ProgressLog(out_dir)

    def sweep_started(self, sweep: Sweep) -> None:
        self.log.begin({"event": "sweep_started", "pid": os.getpid(), "name": sweep.name, "total": len(sweep.points)})

    def point_started(self, sweep: Sweep, point: SweepPoint) -> None:
        self.log.write({"event": "point_started", "number": point.number, "total": len(sweep.points),
                        "folder": f"points/{point.folder_name}"})  # fmt: skip

    def run_listeners(self, point: SweepPoint) -> list[object]:
        return [ProgressLog(point_folder(self.out_dir, point))]

    def warning(self, message: str) -> None:
        self.log.warning(message)

    def point_finished(self, sweep: Sweep, point: SweepPoint, result: PointResult) -> None:
        self.log.write({"event": "point_finished", "number": point.number, "row": {**result.row(), "error": result.error}})

    def sweep_finished(self, sweep: Sweep, outcome) -> None:
        done = sum(r.status not in UNFINISHED for r in outcome.results)
        self.log.write({"event": "sweep_finished", "status": outcome.status, "done": done, "total": len(outcome.results)})
        self.log.close()

    def error(self, message: str, exit_code: int) -> None:
        self.log.error(message, exit_code)

    def close(self) -> None:
        self.log.close()


class SweepFollower:
    """Replays a sweep folder's progress.jsonl to ``listeners`` (``SweepListener``s) as it
    grows: ``sweep_started``, ``point_started``, ``point_finished`` (a ``PointResult`` whose
    row is the one the sweep wrote, checked as sweep.json's rows are), and, for the point
    running, its realizations to the ``run_listeners(point)`` they give (read from the
    point's own progress.jsonl; points that finished before following began are not
    replayed realization by realization). Call ``poll()`` now and then; ``finished`` is
    set once the sweep's last event came. ``pid``: the sweep's process, when known (it was
    started here); only its events are replayed (``progresslog.StartOf``)."""

    def __init__(self, folder: str | Path, sweep: Sweep, listeners=(), pid: int | None = None):
        self.folder = Path(folder)
        self.sweep = sweep
        self.listeners = list(listeners)
        self.reader = ProgressReader(folder)
        self.pid = pid
        self.awaited = StartOf(pid, "sweep_started")
        self.finished: Finished | None = None
        self.point: SweepPoint | None = None  # the point running
        self.run: Follower | None = None  # its run's follower, once made
        self.done = 0  # points finished
        self._points = {point.number: point for point in sweep.points}
        self.warnings = HeardWarnings()

    @property
    def total(self) -> int:
        return len(self.sweep.points)

    def now(self) -> float:
        """The clock of the point's run being replayed (``progresslog.Follower.now``)."""
        return self.run.now() if self.run is not None else time.time()

    def poll(self) -> int:
        """Replay the events written since the last call; return how many."""
        events = self.reader.new_events()
        count = len(events)
        if self.reader.restarted:
            self.finished, self.point, self.run = None, None, None
        for event in self.awaited.after(events, self.reader.restarted):
            kind = event["event"]
            if kind == "sweep_started":
                self.pid = whole_or(event.get("pid")) or None
                self.finished, self.point, self.run, self.done = None, None, None, 0
                self._tell("sweep_started", self.sweep)
            elif kind == "point_started":
                point = self._points.get(whole_or(event.get("number"), -1))
                if point is not None:
                    self.point, self.run = point, None
                    self._tell("point_started", self.sweep, point)
            elif kind == "point_finished":
                self._point_finished(event)
            elif kind == "sweep_finished":
                self._finish_point_run()
                self.finished = Finished(str(event.get("status")), whole_or(event.get("done")), whole_or(event.get("total")))
                self.point = None
            elif kind == "warning":
                self.warnings.hear(event, self.pid)
            elif kind == "error" and told_by(event, self.pid):
                self._finish_point_run()
                self.finished = Finished("failed", self.done, self.total, str(event.get("message")),
                                         whole_or(event.get("exit_code"), 1))  # fmt: skip
        if self.point is not None and self.finished is None:
            if self.run is None:  # made for the point running now only: earlier points are not replayed
                listeners = [each for listener in self.listeners for each in listener.run_listeners(self.point)]
                self.run = Follower(point_folder(self.folder, self.point), self.point.scene, listeners, pid=self.pid)
            count += self.run.poll()
        return count

    def _finish_point_run(self) -> None:
        if self.run is not None:
            self.run.poll()  # its last events: written before the sweep's
            self.run = None

    def _point_finished(self, event: dict) -> None:
        point = self._points.get(whole_or(event.get("number"), -1))
        row = event.get("row")
        if point is None or not isinstance(row, dict):
            return
        try:
            record = checked(PointRecord, row, self.reader.path)
        except RunFolderError:
            return  # not a row a sweep writes: skipped, as any line that is not an event
        if self.point is not None and self.point.number == point.number:
            self._finish_point_run()
            self.point = None
        values = record.model_dump(include=set(PointRecord.model_fields))
        error = row.get("error") if isinstance(row.get("error"), str) else None
        elapsed = number_or_nan(row.get("elapsed_s"))
        values.update(elapsed_s=elapsed if math.isfinite(elapsed) else None)
        result = PointResult(point, record.status, point_folder(self.folder, point), error=error, recorded=values)
        self.done += 1
        self._tell("point_finished", self.sweep, point, result)

    def _tell(self, hook: str, *args) -> None:
        for listener in self.listeners:
            getattr(listener, hook)(*args)
