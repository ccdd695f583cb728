"""Progress of a run and of a sweep, as people read it: a rich
progress bar on a terminal or in a Jupyter notebook with ipywidgets (the ``notebook``
extra), plain lines elsewhere (a log file, a pipe, a notebook without ipywidgets:
rich would draw nothing there but a warning), one every tenth of the work so that
logs stay short.

The CLI, the Python API (``frictionlab.run``) and the studies use these; rich is
imported only when a bar is drawn. ``NO_COLOR`` is honoured by rich itself.
"""

from __future__ import annotations

import math
import sys
import threading
import time

from .errors import counted, shown
from .plugin.hookspecs import hookimpl
from .plugin.listeners import SweepListener, progress_text, solve_text


def _in_notebook() -> bool:
    shell = sys.modules.get("IPython")
    try:
        return shell is not None and type(shell.get_ipython()).__name__ == "ZMQInteractiveShell"
    except AttributeError:
        return False


def wants_bar(stream) -> bool:
    """A live bar on a terminal or in a notebook that can draw one; plain lines anywhere else."""
    try:
        return bool(stream.isatty()) or (_in_notebook() and _has_widgets())
    except (AttributeError, ValueError):
        return False


def _has_widgets() -> bool:
    """ipywidgets is installed: rich draws its bar in a notebook with it."""
    import importlib.util

    return importlib.util.find_spec("ipywidgets") is not None


NOTEBOOK_REDRAWS_PER_SECOND = 1


def _thread_starts() -> bool:
    """Whether a thread can start here (a container's pids limit may refuse one): rich redraws a
    bar from a thread of its own, else the bar is redrawn as it moves."""
    try:
        thread = threading.Thread(target=lambda: None, daemon=True)
        thread.start()
    except RuntimeError:
        return False
    thread.join()
    return True


class _Bar:
    """A rich progress bar of one task on ``stream`` (imported when first drawn)."""

    def __init__(self, stream, description: str, total: int, completed: int = 0, started: float | None = None,
                 clock=time.perf_counter):
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

        console = Console(file=stream, highlight=False)
        # in a notebook each redraw is a new output (cleared, displayed again), sent whether or not
        # anything changed: once a second, as often as the elapsed time it shows moves
        rate = NOTEBOOK_REDRAWS_PER_SECOND if console.is_jupyter else 10
        self.every = 1.0 / rate
        self.redrawn = None if _thread_starts() else -math.inf  # None: rich's own thread redraws
        self.progress = Progress(
            TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TextColumn("{task.fields[note]}"),
            TimeElapsedColumn(), TextColumn("left"), TimeRemainingColumn(), console=console, refresh_per_second=rate,
            get_time=clock, auto_refresh=self.redrawn is None,
        )  # fmt: skip
        self.task = self.progress.add_task(description, total=total, completed=completed, note="")
        if started is not None:  # drawn late (a run shows its bar after 2 s): the clock is the run's
            self.progress.tasks[0].start_time = started
        self.progress.start()

    def update(self, completed: int, note: str = "") -> None:
        due = self.redrawn is not None and time.perf_counter() - self.redrawn >= self.every  # drawn here, without a thread
        self.progress.update(self.task, completed=completed, note=note, refresh=due)
        if due:
            self.redrawn = time.perf_counter()

    def print(self, text: str) -> None:
        self.progress.console.print(text, markup=False)

    def stop(self) -> None:
        console = self.progress.console
        if not console.is_jupyter:
            self.progress.stop()
            return
        # in a notebook rich's stop draws no last state (the bar stayed at its last refresh) and
        # shows the console's empty buffer: a blank output under each bar. Drawn, then stopped quietly.
        self.progress.refresh()
        console.quiet = True
        try:
            self.progress.stop()
        finally:
            console.quiet = False


SHOW_AFTER = 2.0  # seconds: a run shorter than this shows no progress beyond its first line
LOAD_LINE_SECONDS = 1.5  # in a log: a long solve's load or iteration at most this often (movement every 2 s)


def _flush_stdout(stream) -> None:
    """What the caller printed before (a notebook cell's ``print`` above a run) goes out
    before progress on stderr: stdout is buffered (a kernel sends it every 0.2 s, a pipe
    when full), stderr is flushed at once, so a line printed first showed after."""
    out = sys.stdout
    if out is not None and out is not stream:
        try:
            out.flush()
        except (OSError, ValueError):  # closed, or its reader gone: it says so where it is written
            pass


class BestEffort:
    """A stream whose failed writes are dropped from then on: progress is never worth a
    run (stderr closed under it, or full: ``2>/dev/full``)."""

    def __init__(self, stream):
        self.stream, self.broken = stream, False

    def write(self, text: str) -> int:
        if not self.broken:
            _flush_stdout(self.stream)
            try:
                return self.stream.write(text)
            except (OSError, ValueError):  # ValueError: written after it was closed
                self.broken = True
        return len(text)

    def flush(self) -> None:
        if not self.broken:
            try:
                self.stream.flush()
            except (OSError, ValueError):
                self.broken = True

    def isatty(self) -> bool:
        try:
            return self.stream.isatty()
        except (AttributeError, ValueError):
            return False

    def __getattr__(self, name):  # what else a console asks of its file: encoding, fileno, ...
        return getattr(self.stream, name)


class ProgressReporter:
    """A ``listeners.RunListener``: one run's progress on ``stream`` (stderr): a bar
    when ``interactive`` (default: a terminal or a notebook), else a plain line per tenth;
    either only once the run has gone on ``after`` seconds (a short run shows its first
    line and, in a log, its last). A spectrum read from a file says what was read under
    the first line (``io.inputs.input_lines``), once for the reporters sharing ``inputs_said``
    (a sweep's points, a study's runs: the same file read alike is said once)."""

    def __init__(self, stream=None, interactive: bool | None = None, after: float = SHOW_AFTER, clock=time.perf_counter,
                 inputs_said: set[str] | None = None):  # fmt: skip
        self.stream = BestEffort(stream or sys.stderr)
        self.interactive = wants_bar(self.stream) if interactive is None else interactive
        self.after = after
        self.clock = clock  # a followed run's (progresslog.Follower.now): its times are the run's
        self.total = 0
        self.bar: _Bar | None = None
        self.started = 0.0
        self.next_tenth = 1  # integer tenths: repeated += 0.1 drifts and skips lines
        self.failed = 0
        self.resumed = 0  # restored on a resume: done before this process started
        self.done = 0
        self.loads = 0  # load steps of each realization
        self.last_load_line = 0.0
        self.inputs_said = set() if inputs_said is None else inputs_said

    def _line(self, done: int, total: int) -> str:
        return progress_text(done, total, self.failed, self.clock() - self.started, restored=self.resumed)

    def _write(self, text: str) -> None:
        if self.bar is not None:
            self.bar.print(text)
        else:
            self.stream.write(text + "\n")
            self.stream.flush()

    @hookimpl
    def run_started(self, run):
        self.started = self.clock()
        self.resumed = self.done = run.resumed
        self.total = run.total
        self.loads = len(run.scene.loads)
        preset = run.scene.preset
        restored = ", ".join(
            [f"{self.resumed} restored from the run folder"] * bool(self.resumed)
            + [f"{run.retried} failed ones retried"] * bool(run.retried)
        )
        restored = f" ({restored})" if restored else ""
        crowded = (  # a pool larger than the cores it may use: said, since it is no faster
            f" on {run.cores} core(s): they take turns, no faster than {run.cores}"
            if run.executor == "processes" and 0 < run.cores < run.workers else ""
        )  # fmt: skip
        self._write(
            f"{preset.name}: {run.total} realization{'s' if run.total != 1 else ''} of {run.scene.pressed}{restored}, "
            f"{preset.loading.steps} {preset.loading.control} steps, {'up to ' * run.sized}{run.workers} worker(s){crowded}"
        )
        self._say_input(run.scene.spectrum.input_summary())

    def _say_input(self, summary: dict | None) -> None:
        """What a measured file gave (its channel, unit, levelling), once: a run headless shows it too."""
        from .io.inputs import input_lines

        said = "\n".join(f"  {shown(line)}" for line in input_lines(summary)) if summary is not None else ""
        if said and said not in self.inputs_said:
            self.inputs_said.add(said)
            self._write(said)

    def _pass_tenths(self, done: int, total: int) -> None:
        """Count the tenths of ``total`` that ``done`` passed as said (computed, not looped:
        a followed run's numbers come from a file)."""
        if total > 0:
            self.next_tenth = max(self.next_tenth, 10 * min(done, total) // total + 1)

    def _progress(self, done: int, total: int) -> None:
        done = max(0, min(done, total))  # a followed run's numbers come from a file
        self.done, self.total = done, total
        if self.clock() - self.started < self.after and not (done == total and not self.interactive):
            self._pass_tenths(done, total)  # tenths passed before: not printed late
            return
        if self.interactive and self.bar is None:
            self.bar = _Bar(self.stream, "realizations", total, completed=done, started=self.started, clock=self.clock)
        if self.bar is not None:
            self.bar.update(done, f"{self.failed} failed" if self.failed else "")
        elif done == total or 10 * done >= self.next_tenth * total:
            self._write(self._line(done, total))
            self._pass_tenths(done, total)

    @hookimpl
    def realization_done(self, done, total):
        self._progress(done, total)

    @hookimpl
    def load_done(self, index, done, total):
        """A long solve's loads: the bar's note, or a line now and then in a log."""
        self._solve_note(solve_text(index, done, total))

    @hookimpl
    def iteration_done(self, index, load, iteration, residual):
        """Within a long load: its iteration and residual, as ``load_done``."""
        self._solve_note(solve_text(index, load, self.loads, iteration, residual))

    def _solve_note(self, text: str) -> None:
        now = self.clock()
        if now - self.started < self.after or not self.total:
            return
        if self.interactive:
            if self.bar is None:
                self.bar = _Bar(self.stream, "realizations", self.total, completed=self.done, started=self.started, clock=self.clock)
            self.bar.update(self.done, text)
        elif now - max(self.last_load_line, self.started) >= LOAD_LINE_SECONDS:
            self._write(text)
            self.last_load_line = now

    @hookimpl
    def realization_failed(self, result, done, total):
        self.failed += 1
        if self.failed == 1:  # the first error says what is wrong; the rest only count
            self._write(f"realization {result.index} failed: {shown(result.error)}")
        self._progress(done, total)

    def close(self) -> None:
        """End the bar, if one shows, on a line of its own: what is written next goes below it."""
        if self.bar is not None:
            self.bar.stop()
            self.bar = None

    @hookimpl
    def run_finished(self, outcome):
        self.close()
        if outcome.status != "completed":
            self._write(shown(f"run {outcome.status}: {outcome.done} of {outcome.requested} realizations finished"))


class SweepProgress(SweepListener):
    """One line per point on ``stream`` (stderr); each point's run reports its own
    realizations through a ``ProgressReporter``. ``fits``: a line with each point's fit
    as it ends, too (where no table follows the sweep: ``frictionlab follow``)."""

    def __init__(self, stream=None, interactive: bool | None = None, after: float = SHOW_AFTER, clock=time.perf_counter,
                 fits: bool = False):  # fmt: skip
        self.fits = fits
        self.stream = BestEffort(stream or sys.stderr)
        self.interactive = interactive
        self.after = after
        self.clock = clock  # a followed sweep's (sweeplog.SweepFollower.now): its times are the run's
        self.reporter: ProgressReporter | None = None  # the point's running now
        self.inputs_said: set[str] = set()  # a file every point reads alike is said once

    def _write(self, text: str) -> None:
        if self.reporter is not None:  # above its bar, if one shows
            self.reporter._write(text)
        else:
            self.stream.write(text + "\n")
            self.stream.flush()

    def close(self) -> None:
        """End the bar of the point running, if one shows (``ProgressReporter.close``)."""
        if self.reporter is not None:
            self.reporter.close()

    def sweep_started(self, sweep):
        mode = sweep.spec.mode
        self._write(f"{sweep.name}: sweep of {counted(len(sweep.points), 'point')} ({mode} over {', '.join(sweep.paths)})")

    def point_started(self, sweep, point):
        self._write(f"point {point.number}/{len(sweep.points)}: {point.describe()}")

    def run_listeners(self, point):
        self.close()
        self.reporter = ProgressReporter(self.stream, self.interactive, self.after, clock=self.clock,
                                         inputs_said=self.inputs_said)  # fmt: skip
        return [self.reporter]

    def point_finished(self, sweep, point, result):
        if result.status == "error":
            self._write(f"point {point.number} failed: {shown(result.error)}")
        elif self.fits:
            self._write(point_result_line(sweep, point, result.row()))


def point_result_line(sweep, point, row: dict) -> str:
    """``    2  hurst=0.7: a = ..., b = ..., R^2 = ..., contacts ..``: how a point ended."""
    from .compute.fit import format_estimate
    from .preset import yaml_scalar
    from .runs.sweep import row_fit

    values = ", ".join(f"{p.rsplit('.', 1)[-1]}={yaml_scalar(point.values[p])}" for p in sweep.paths)
    fit = row_fit(row)
    reason = row["error"] if isinstance(row.get("error"), str) and row["error"] else ""  # what to do: a point in error, a kept row's
    if fit is None:
        return shown(f"  {point.number:>3}  {values}: {row['status']}{reason and ': '}{reason}")
    first, last = row.get("contact_first"), row.get("contact_last")  # an edited sweep.json may hold one
    contacts = "" if first is None or last is None else f", contacts {first:.2f} .. {last:.2f}"
    return shown(f"  {point.number:>3}  {values}: a = {format_estimate(fit.a, fit.a_ci)}, "
            f"b = {format_estimate(fit.b, fit.b_ci)}, R^2 = {fit.r2:.3f}{contacts}"
            + ("" if row["status"] == "completed" else f" ({row['status']})")
            + (f"; error: {reason}" if reason else ""))  # fmt: skip
