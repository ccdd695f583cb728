"""The CLI's listeners: progress on stderr while a run or a sweep goes on.

On a terminal ``ProgressReporter`` redraws one progress line at most ten times
a second; into a file or pipe it prints a plain line every tenth of the run, so
logs of headless runs stay short.
"""

from __future__ import annotations

import sys
import time

from ..hookspecs import hookimpl
from ..listeners import SweepListener, progress_text


LOAD_LINE_SECONDS = 30.0


class ProgressReporter:
    """A ``listeners.RunListener``: one run's progress on ``stream`` (stderr)."""

    def __init__(self, stream=None, interactive: bool | None = None, width: int = 30):
        self.stream = stream or sys.stderr
        self.interactive = self.stream.isatty() if interactive is None else interactive
        self.width = width
        self.started = 0.0
        self.last_draw = 0.0
        self.next_tenth = 1  # integer tenths: repeated += 0.1 drifts and skips lines
        self.failed = 0
        self.resumed = 0  # restored on a resume: done before this process started
        self.done, self.total = 0, 1
        self.last_load_line = 0.0  # into a file: a load line at most every LOAD_LINE_SECONDS

    def _line(self, done: int, total: int) -> str:
        return progress_text(done, total, self.failed, time.perf_counter() - self.started, restored=self.resumed)

    @hookimpl
    def run_started(self, run):
        self.started = time.perf_counter()
        self.resumed = run.resumed
        preset = run.scene.preset
        restored = ", ".join(
            [f"{self.resumed} restored from the run folder"] * bool(self.resumed)
            + [f"{run.retried} failed ones retried"] * bool(run.retried)
        )
        restored = f" ({restored})" if restored else ""
        self.stream.write(
            f"{preset.name}: {run.total} realizations of {run.scene.generator.name} lines{restored}, "
            f"{preset.loading.steps} {preset.loading.control} steps, {run.workers} worker(s)\n"
        )
        self.stream.flush()

    def _progress(self, done: int, total: int) -> None:
        self.done, self.total = done, total
        now = time.perf_counter()
        if self.interactive:
            if done == total or now - self.last_draw >= 0.1:
                filled = int(self.width * done / total)
                bar = "#" * filled + "-" * (self.width - filled)
                self.stream.write(f"\r[{bar}] {self._line(done, total)}\x1b[K")
                self.stream.flush()
                self.last_draw = now
        elif done == total or 10 * done >= self.next_tenth * total:
            self.stream.write(self._line(done, total) + "\n")
            self.stream.flush()
            while self.next_tenth * total <= 10 * done:
                self.next_tenth += 1

    @hookimpl
    def realization_done(self, done, total):
        self._progress(done, total)

    @hookimpl
    def load_done(self, index, done, total):
        """A long solve's loads: on the progress line (a terminal), or a line now and then (a file)."""
        now = time.perf_counter()
        text = f"realization {index}: load {done}/{total}"
        if self.interactive:
            if now - self.last_draw >= 0.1:
                self.stream.write(f"\r{self._line(self.done, self.total)}, {text}\x1b[K")
                self.stream.flush()
                self.last_draw = now
        elif now - max(self.last_load_line, self.started) >= LOAD_LINE_SECONDS:
            self.stream.write(text + "\n")
            self.stream.flush()
            self.last_load_line = now

    @hookimpl
    def realization_failed(self, result, done, total):
        self.failed += 1
        if self.failed == 1:  # the first error says what is wrong; the rest only count
            self.stream.write(f"{chr(10) if self.interactive else ''}realization {result.index} failed: {result.error}\n")
        self._progress(done, total)

    @hookimpl
    def run_finished(self, outcome):
        if self.interactive:
            self.stream.write("\n")
        if outcome.status != "completed":
            self.stream.write(f"run {outcome.status}: {outcome.done} of {outcome.requested} realizations finished\n")
        self.stream.flush()


class SweepProgress(SweepListener):
    """One counter line per point on stderr; each point's run reports its own
    realizations through a ``ProgressReporter``."""

    def __init__(self, stream=None):
        self.stream = stream or sys.stderr

    def sweep_started(self, sweep):
        mode = sweep.spec.mode
        self.stream.write(f"{sweep.name}: sweep of {len(sweep.points)} points ({mode} over {', '.join(sweep.paths)})\n")
        self.stream.flush()

    def point_started(self, sweep, point):
        self.stream.write(f"point {point.number}/{len(sweep.points)}: {point.describe()}\n")
        self.stream.flush()

    def run_listeners(self, point):
        return [ProgressReporter(self.stream)]

    def point_finished(self, sweep, point, result):
        if result.status == "error":
            self.stream.write(f"point {point.number} failed: {result.error}\n")
            self.stream.flush()
