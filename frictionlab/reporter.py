"""The CLI's listener: progress on stderr while a run goes on.

On a terminal it redraws one progress line at most ten times a second; into a
file or pipe it prints a plain line every tenth of the run, so logs of
headless runs stay short.
"""

from __future__ import annotations

import sys
import time

from .hookspecs import hookimpl


def _duration(seconds: float) -> str:
    if seconds < 60:
        return f"{seconds:.1f} s"
    minutes, seconds = divmod(int(seconds), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{seconds:02d}" if hours else f"{minutes}:{seconds:02d}"


class ProgressReporter:
    def __init__(self, stream=None, interactive: bool | None = None, width: int = 30):
        self.stream = stream or sys.stderr
        self.interactive = self.stream.isatty() if interactive is None else interactive
        self.width = width
        self.started = 0.0
        self.last_draw = 0.0
        self.next_tenth = 1  # integer tenths: repeated += 0.1 drifts and skips lines
        self.failed = 0
        self.resumed = 0  # restored on a resume: done before this process started

    def _line(self, done: int, total: int) -> str:
        elapsed = time.perf_counter() - self.started
        rate = (done - self.resumed) / elapsed if elapsed > 0 else 0.0
        left = (total - done) / rate if rate > 0 else float("nan")
        eta = _duration(left) if rate > 0 else "?"
        failed = f", {self.failed} failed" if self.failed else ""
        return f"{done}/{total} realizations{failed}, {rate:.1f}/s, elapsed {_duration(elapsed)}, left {eta}"

    @hookimpl
    def run_started(self, run):
        self.started = time.perf_counter()
        self.resumed = getattr(run, "resumed", 0)
        preset = run.scene.preset
        retried = getattr(run, "retried", 0)
        restored = ", ".join(
            [f"{self.resumed} restored from the run folder"] * bool(self.resumed)
            + [f"{retried} failed ones retried"] * bool(retried)
        )
        restored = f" ({restored})" if restored else ""
        self.stream.write(
            f"{preset.name}: {run.total} realizations of {run.scene.spectrum.name} lines{restored}, "
            f"{preset.loading.steps} {preset.loading.control} steps, {run.workers} worker(s)\n"
        )
        self.stream.flush()

    def _progress(self, done: int, total: int) -> None:
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
