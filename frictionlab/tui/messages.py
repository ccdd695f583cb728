"""What the run thread tells the app (``post_message`` is thread safe). ``RunProgress``
messages coalesce in the queue, so a fast run cannot flood the UI."""

from __future__ import annotations

from pathlib import Path

from textual.message import Message

from .live import Snapshot


class RunProgress(Message):
    """A cumulative snapshot of the running ensemble: a newer one supersedes any still queued."""

    def __init__(self, snapshot: Snapshot):
        super().__init__()
        self.snapshot = snapshot

    def can_replace(self, message: Message) -> bool:
        return isinstance(message, RunProgress)


class SweepPointEvent(Message):
    """A sweep point started (``result`` None) or finished."""

    def __init__(self, sweep, kind: str, point, result):
        super().__init__()
        self.sweep, self.kind, self.point, self.result = sweep, kind, point, result


class RunFinished(Message):
    """The run ended: ``outcome`` is its ``RunOutcome``, or a sweep's ``SweepOutcome``."""

    def __init__(self, outcome, out_dir: Path):
        super().__init__()
        self.outcome = outcome
        self.out_dir = out_dir


class RunCrashed(Message):
    """The run could not go on (a refused folder, a full disk, a bug): ``error`` says why."""

    def __init__(self, error: str):
        super().__init__()
        self.error = error
