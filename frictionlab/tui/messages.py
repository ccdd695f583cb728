"""How a followed run (or sweep) ended, as the app tells its panes."""

from __future__ import annotations

from pathlib import Path

from textual.message import Message



class RunFinished(Message):
    """The run ended: ``outcome`` is its ``FinishedRun``, or a sweep's ``FinishedSweep`` (``following``)."""

    def __init__(self, outcome, out_dir: Path):
        super().__init__()
        self.outcome = outcome
        self.out_dir = out_dir


class RunCrashed(Message):
    """The run could not go on (a refused folder, a full disk, a bug): ``error`` says why;
    ``interrupted``: its process ended without a word (killed) and its folder can be resumed."""

    def __init__(self, error: str, interrupted: bool = False):
        super().__init__()
        self.error = error
        self.interrupted = interrupted
