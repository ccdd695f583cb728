"""The TUI's run listener: running sums and an interim fit, handed on as snapshots.

It hears a followed run's events (``progresslog.Follower``) and never touches the UI: it
calls ``post`` with a ``Snapshot`` at most every ``interval`` seconds (and always at the
start, for the first and the last realization, and at the end). Each snapshot is
cumulative, so the UI may show only the newest one. The
interim fit is least squares of the mean curve so far; the bootstrap intervals
come only with the final ``RunOutcome``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..compute.fit import LogFit, fit_curve
from ..plugin.hookspecs import hookimpl
from ..plugin.listeners import solve_text
from .text import failure_message


@dataclass(frozen=True)
class Snapshot:
    done: int  # finished, ok or failed
    total: int
    failed: int
    elapsed: float
    f: np.ndarray | None  # dimensionless force of the mean curve (None before the first result)
    xi: np.ndarray | None  # mean xi over the finished realizations
    contact_count: np.ndarray | None
    fit: LogFit | None  # least squares of the mean curve so far: no intervals
    first_error: str | None = None
    finished: bool = False
    f_formula: str = ""  # what f is, e.g. "F / (E* h L)"
    restored: int = 0  # of ``done``, restored from the run folder (a resume): not counted in the rate
    solving: str = ""  # where a long solve is: realization, load, iteration, residual


class LiveListener:
    def __init__(self, post: Callable[[Snapshot], None], interval: float = 0.1, clock=time.perf_counter):
        self.post = post
        self.interval = interval
        self.clock = clock  # a followed run's: ``progresslog.Follower.now``
        self._total = 0

    @hookimpl
    def run_started(self, run):
        scene = run.scene
        steps = scene.loads.size
        self._loads = scene.loads.astype(float)
        self._force_control = not scene.forces_vary  # forces the same for every realization: the solver's loads
        if self._force_control:
            self._loads = scene.solver_loads.astype(float)
        self._force_unit = math.nan
        self._f_formula = scene.normalisation.formula
        self._ok = 0
        self._failed = 0
        self._first_error = None
        self._solving = ""
        self._xi_sum = np.zeros(steps)
        self._count_sum = np.zeros(steps)
        self._force_sum = np.zeros(steps)
        self._restored = run.resumed
        self._done, self._total = run.resumed, run.total
        for result in run.restored:  # a resume: the interim fit covers every realization, not only the new ones
            if result.ok:
                self._add(result)
        self._started = self.clock()
        self._all_done_at = self._started if run.resumed >= run.total else None
        self._last_post = self._started
        self.post(self._snapshot(run.resumed, run.total))

    def _add(self, result) -> None:
        self._ok += 1
        self._force_unit = result.force_unit
        self._xi_sum += result.xi
        self._count_sum += result.contact_count
        if result.force is not None:
            self._force_sum += result.force

    @hookimpl
    def realization_done(self, result, done, total):
        self._add(result)
        self._maybe_post(done, total)

    def tick(self) -> None:
        """A snapshot now, nothing new heard: the elapsed time moves on while a realization runs."""
        if self._total:
            self.post(self._snapshot(self._done, self._total))

    @hookimpl
    def realization_failed(self, result, done, total):
        self._failed += 1
        self._first_error = self._first_error or f"realization {result.index}: {failure_message(result.error)}"
        self._maybe_post(done, total)

    @hookimpl
    def load_done(self, index, done, total):
        self._solve_note(solve_text(index, done, total))

    @hookimpl
    def iteration_done(self, index, load, iteration, residual):
        self._solve_note(solve_text(index, load, self._loads.size, iteration, residual))

    def _solve_note(self, text: str) -> None:
        """Movement within a long realization: shown with the next snapshot, posted at once
        if none was for ``interval``."""
        self._solving = text
        now = self.clock()
        if now - self._last_post >= self.interval:
            self._last_post = now
            self.post(self._snapshot(self._done, self._total))

    @hookimpl
    def run_finished(self):
        # the run's own end (a followed run's finished event): its elapsed time, the final line's
        self._all_done_at = self.clock()
        self.post(self._snapshot(self._done, self._total, finished=True))

    def _maybe_post(self, done: int, total: int) -> None:
        self._done, self._total, self._solving = done, total, ""
        now = self.clock()
        if done >= total and self._all_done_at is None:
            self._all_done_at = now
        if done in (1, total) or now - self._last_post >= self.interval:  # the plot appears at once
            self._last_post = now
            self.post(self._snapshot(done, total))

    def _snapshot(self, done: int, total: int, finished: bool = False) -> Snapshot:
        f = xi = count = fit = None
        if self._ok:
            force = self._loads if self._force_control else self._force_sum / self._ok
            f = force / self._force_unit
            xi = self._xi_sum / self._ok
            count = self._count_sum / self._ok
            fit = interim_fit(f, xi)
        # the time the realizations took: it stops with the last one (the rate not falling while
        # the run stores them and ends), then moves to the run's end, the elapsed time of its summary
        end = self.clock() if self._all_done_at is None else self._all_done_at
        return Snapshot(
            done=done,
            total=total,
            failed=self._failed,
            elapsed=end - self._started,
            f=f,
            xi=xi,
            contact_count=count,
            fit=fit,
            first_error=self._first_error,
            finished=finished,
            f_formula=self._f_formula,
            restored=self._restored,
            solving="" if finished else "writing the results" if self._all_done_at is not None else self._solving,
        )


def interim_fit(f: np.ndarray, xi: np.ndarray) -> LogFit | None:
    """The fit of the mean curve so far (None until it can be fitted)."""
    keep = np.isfinite(f) & np.isfinite(xi) & (f > 0)
    try:
        return fit_curve(f[keep], xi[keep])
    except (ValueError, np.linalg.LinAlgError):
        return None
