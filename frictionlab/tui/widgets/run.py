"""The Run tab: a run's (or a sweep's) progress, the live mean curve with its
interim fit, and at the end the fit with its bootstrap intervals; for a sweep also
the point running and a table row per finished point."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.content import Content
from textual.widgets import ProgressBar, Static

from ...errors import shown
from ...compute.fit import ci_label, format_estimate
from ...plugin.listeners import format_duration, progress_text
from ...runs.figures import shown_caveats
from ..chart import Series
from ..hiddenkeys import SaysWhyUnavailable, said_when_hidden
from ..live import Snapshot
from ..sweepview import point_line, sweep_confidence
from ..text import failure_message, format_count, shorten_middle
from .chart import Chart
from .pathline import PathLine
from .sweeptable import SweepTable


def fit_lines(fit, *, final: bool, f_formula: str = "", short: bool = False) -> list[str]:
    """The coefficients as the Run tab and Results tab show them, with what f is; ``short``:
    the interval's level on the first line, without the bootstrap's count (a plot of 6 rows)."""
    what = [f"  f = {f_formula}"] if f_formula else []
    if fit is None:  # at the end, no law could be fitted (the reason is under the plot)
        return ["xi = a + b ln f", *what, "  (no fit)" if final else "  (no realization yet)"]
    head = "xi = a + b ln f" + ("" if final else "  (interim)")
    lines = [head, *what, f"  a = {fit.a:.4f}", f"  b = {fit.b:.4f}"]
    if final:
        level = ci_label(fit.confidence)
        about = [f"  {level}, bootstrap {fit.bootstrap}"] if fit.bootstrap else [
            "  no CI (bootstrap off,", "  or < 2 realizations)"]  # either; two lines: the panel is as wide as its longest
        if short:
            head, about = head + (f", {level}" if fit.bootstrap else ""), []
        lines = [
            head,
            *what,
            f"  a = {format_estimate(fit.a, fit.a_ci, missing='')}",
            f"  b = {format_estimate(fit.b, fit.b_ci, missing='')}",
            *about,
        ]
    lines.append(f"  R^2 = {fit.r2:.4f}")
    return lines


def fit_series(f: np.ndarray, a: float, b: float, style: str) -> Series:
    """The fitted line a + b ln f over the range of ``f``."""
    f = np.asarray(f, float)
    f = f[np.isfinite(f) & (f > 0)]
    if f.size < 2:
        return Series(np.empty(0), np.empty(0), style, line=True)
    ends = np.array([f.min(), f.max()])
    return Series(ends, a + b * np.log(ends), style, line=True)


def contact_lines(count, room: int | None = None) -> list[str]:
    """The mean points in contact at the first and the last load in the ``room`` rows left
    under the fit (None: all it takes): four, two or one line, never cut."""
    if count is None or not np.size(count):
        return []
    first, last = float(count[0]), float(count[-1])
    forms = (
        ["", "points in contact", f"  {first:.2f} at first load", f"  {last:.2f} at last load"],
        ["points in contact", f"  {first:.2f} first .. {last:.2f} last"],
        [f"contacts {format_count(first)}..{format_count(last)}"],  # as the sweep table's column
    )
    return next((form for form in forms if room is None or len(form) <= room), forms[-1])


class FitPanel(Static):
    """The fit beside the plot, then the points in contact in the rows it leaves: a sweep's
    plot at 60x20 has 6, and the last lines were cut below the panel."""

    def show(self, lines: list[str], count=None, short: list[str] | None = None) -> None:
        """``lines``, or the ``short`` ones where the panel has no room for them and the contacts."""
        self._lines, self._count, self._short = lines, count, short
        self._fill()

    def on_resize(self) -> None:
        if hasattr(self, "_lines"):
            self._fill()

    def _fill(self) -> None:
        lines = self._lines
        if self._short and self.size.height and len(lines) + bool(contact_lines(self._count)) > self.size.height:
            lines = self._short
        room = self.size.height - len(lines) if self.size.height else None
        text = "\n".join(lines + contact_lines(self._count, room))
        if text != getattr(self, "_text", None):
            self._text = text
            self.update(Content(text))


class PlotAndFit(Horizontal):
    """The plot and the fit beside it, 1fr of the tab: a part above or below it that grows or
    shrinks (the progress line's second row, an error) resizes it, and a sweep's table is fitted
    again then (``RunPane._fit_table``). Fitted only when the line changed, a table fitted to
    sizes read before a layout kept them: 3 of 8 points at 60x20 where 4 fit."""

    def on_resize(self) -> None:
        pane = self.parent
        if isinstance(pane, RunPane):
            pane.call_after_refresh(pane._fit_table)


R_ON_RUN_TAB = "r reloads the lists on the Presets and Results tabs; Ctrl+R runs the open preset."
PLOT_ROWS = 10  # a sweep's plot keeps its whole legend (final fit and contacts): #run-body's min-height
PLOT_FLOOR = 6  # where the tab is short: the fit's short lines and its contacts (FitPanel)
TABLE_ROWS = 5  # a sweep's table keeps its header and four points before the plot its PLOT_ROWS


class RunPane(SaysWhyUnavailable, Vertical, can_focus=True):
    BINDINGS = [
        # r reloads a list on the Presets and Results tabs: here it says so, and starts no run (Ctrl+R does)
        Binding("r", "not_run", show=False, system=True),
        Binding("c", "cancel", "Cancel", tooltip="the run: what finished is kept and saved"),
        Binding("u", "resume", "Resume", tooltip="the last run: only the missing realizations are computed"),
        # under 12 rows (30x8) the fit is below the progress, out of sight: the tab scrolls (app.tcss)
        Binding("up", "scroll_up", "Scroll up", tooltip="the tab, where it is taller than the screen (30x8)", show=False),
        Binding("down", "scroll_down", "Scroll down", tooltip="the tab, where it is taller than the screen (30x8)", show=False),
        # the same keys where they cannot act now (check_action hides those above): the status line says why
        *said_when_hidden(("c", "cancel"), ("u", "resume")),
    ]

    def compose(self) -> ComposeResult:
        yield Static("No run yet: open a preset and press Ctrl+R (F5 lists the runs made before; u resumes one).",
                     id="run-title")
        yield PathLine(id="run-folder")
        yield Static("", id="sweep-point")
        yield ProgressBar(id="run-bar", show_eta=False)
        yield Static("", id="run-stats")
        with PlotAndFit(id="run-body"):
            yield Chart(id="run-chart")
            yield FitPanel("", id="run-fit")
        with VerticalScroll(id="run-caveats-box", can_focus=False):  # wrapped, whole; scrolls at 60x20
            yield Static("", id="run-caveats")
        yield SweepTable(id="sweep-table", zebra_stripes=True, cursor_type="row")
        yield Static("", id="run-error")

    def check_action(self, action: str, parameters) -> bool:
        """The footer offers only what applies now: cancel while a run goes, resume when none
        does (only a run that ended before it completed)."""
        app = self.app
        if action == "cancel":  # not once its last event came (its process is only closing), nor twice
            return app.running and not app.followed.ended and not app.followed.cancelling
        if action == "resume":
            return not app.running and app.last_resumable
        return True

    def on_data_table_row_selected(self, event) -> None:
        """Enter on a finished point of the sweep: its run on the Results tab, the sweep's points beside it."""
        event.stop()
        app = self.app
        folder = app.followed.folder if app.running else app.last_out_dir  # the latter is the last run's once it ends
        if folder is not None:
            app.action_show_tab("results")
            app.query_one("ResultsPane").open_point(folder, int(event.row_key.value))

    def action_not_run(self) -> None:
        self.app.say(R_ON_RUN_TAB)

    def action_cancel(self) -> None:
        self.app.action_cancel_run()

    def action_resume(self) -> None:
        self.app.resume_run(self.app.last_out_dir)

    def _show_bar(self, total: int, done: int) -> None:
        """The progress bar, there once a run is shown: before, with no total, it pulsed as if one ran."""
        bar = self.query_one("#run-bar", ProgressBar)
        bar.update(total=total, progress=done)
        bar.display = True

    def _set(self, widget_id: str, text: str | Content) -> None:
        """Show ``text`` as it is: names, values and errors are never read as markup."""
        line = self.query_one(f"#{widget_id}", Static)
        line.update(Content(text) if isinstance(text, str) else text)
        if widget_id == "run-error":  # no error: no blank row the sweep's table could use
            line.display = bool(str(text))
        if widget_id in ("run-stats", "run-error", "run-caveats"):  # one line or two: the table's room changes
            self.call_after_refresh(self._fit_table)
        if widget_id == "run-stats":
            self.call_after_refresh(self._stats_in_sight)

    _stats_rows = 0  # the rows the progress line took when last laid out

    def _stats_in_sight(self) -> None:
        """The progress line grew (``starting``, then its counts on three rows at 30x12): the tab
        scrolled to it as it started shows it whole, as long as the tab scrolls (``_progress_in_sight``)."""
        rows = self.query_one("#run-stats").outer_size.height
        if rows != self._stats_rows:
            self._stats_rows = rows
            self._progress_in_sight()

    def on_resize(self) -> None:
        self.call_after_refresh(self._fit_table)
        self.call_after_refresh(self._progress_in_sight)

    def _fit_table(self) -> None:
        """A sweep's table of points is as tall as its rows, up to 40 % of the tab and no more
        than the plot's PLOT_ROWS leave: taller, its last rows lay below the tab, out of sight
        and out of its own scroll's reach (rows 5 to 8 of 8 points at 80x24); it scrolls instead.
        Where the tab has not that room (60x20), the table keeps TABLE_ROWS, the plot PLOT_FLOOR."""
        table = self.query_one("#sweep-table", SweepTable)
        body = self.query_one("#run-body")
        if not table.display:
            body.styles.min_height = None  # a single run: the stylesheet's (none)
        if not table.display or not self.size.height:
            return
        others = sum(child.outer_size.height for child in self.children
                     if child.display and child is not table and child.id != "run-body")  # fmt: skip
        room = self.size.height - others
        height = max(3, min(room - PLOT_FLOOR, max(TABLE_ROWS, min(self.size.height * 2 // 5, room - PLOT_ROWS))))
        if table.styles.max_height is None or table.styles.max_height.value != height:
            table.styles.max_height = height
        # the plot's min-height pushed the table's rows below the tab, only its header in sight (60x20)
        plot_rows = max(1, min(PLOT_ROWS, room - height))
        if body.styles.min_height is None or body.styles.min_height.value != plot_rows:
            body.styles.min_height = plot_rows

    def _caveats(self, caveats: list[str]) -> None:
        """Under the plot, the width of the tab: beside the fit, a caveat's line set the panel's
        width, the plot gone and the caveat cut at the edge."""
        self.query_one("#run-caveats-box").display = bool(caveats)
        self._set("run-caveats", "\n".join(caveats))

    def _error(self, text: str) -> None:
        self._set("run-error", Content.styled(shown(text), "red"))  # a run's error may quote a file

    # ------------------------------------------------------------ a run starts

    def start(self, scene, sweep, out_dir: Path) -> None:
        """Clear the tab for the run of ``scene`` (or of ``sweep``, when not None) into ``out_dir``."""
        self.set_class(sweep is not None, "-sweep")
        preset = scene.preset
        if sweep is None:
            what = f": {preset.realizations} realizations, {preset.loading.steps} {preset.loading.control} steps"
            self._set("run-title", Content.assemble((self._fitted(preset.name, what), "bold"), what))
        else:
            preset = sweep.points[0].scene.preset
            what = f": {len(sweep.points)} points x {preset.realizations} realizations"
            self._set("run-title", Content.assemble((self._fitted(sweep.name, what), "bold"), what))
            self._set("sweep-point", f"{sweep.spec.mode} over {', '.join(sweep.paths)}")
            self._set("run-stats", "")
            self.query_one("#sweep-table", SweepTable).show_points(sweep.paths, (), sweep_confidence(sweep))
        self.query_one("#run-folder", PathLine).show("into ", str(out_dir))
        self._show_bar(preset.realizations, 0)
        self._set("run-error", "")
        self._set("run-stats", "starting")
        self._clear_fit()
        self.call_after_refresh(self._progress_in_sight)

    def _progress_in_sight(self) -> None:
        """Under 12 rows (30x8) the title and the folder took the rows the status line left, the
        progress below them: the tab starts at the progress (a sweep's at its point), Up shows them."""
        if self.screen.has_class("-tiny") or self.max_scroll_y > 0:
            first = self.query_one("#sweep-point" if self.has_class("-sweep") else "#run-bar")
            self.scroll_to_widget(first, top=True, animate=False)

    def _fitted(self, name: str, rest: str) -> str:
        """``name`` cut in its middle so that the line with ``rest`` fits the tab's width."""
        width = self.size.width or 80
        return shorten_middle(name, max(12, width - len(rest)))

    def _clear_fit(self) -> None:
        """No curve nor fit of an earlier run under this one's count."""
        self.query_one("#run-chart", Chart).show([])
        self.query_one("#run-fit", FitPanel).show(fit_lines(None, final=False))
        self._caveats([])

    # ------------------------------------------------------------ while it runs

    def show_progress(self, snap: Snapshot, cancelling: bool) -> None:
        self._show_bar(snap.total, snap.done)
        if not cancelling:
            stats = progress_text(snap.done, snap.total, snap.failed, snap.elapsed, restored=snap.restored)
            self._set("run-stats", f"{stats}\n{snap.solving}" if snap.solving else stats)
        if snap.f is not None:
            series = [Series(snap.f, snap.xi, "cyan")]
            if snap.fit is not None:
                series.append(fit_series(snap.f, snap.fit.a, snap.fit.b, "yellow"))
            self.query_one("#run-chart", Chart).show(series)
            lines = fit_lines(snap.fit, final=False, f_formula=snap.f_formula)
            self.query_one("#run-fit", FitPanel).show(lines, snap.contact_count)
        if snap.first_error:
            self._error(snap.first_error)

    def show_stored_count(self, done: int, total: int, resuming: bool = False) -> None:
        """The count the run folder's chunks hold (when there is no progress file to read, or
        as a resume begins, before its process says what it restored)."""
        self._show_bar(total, done)
        what = "resuming" if resuming else "read from the run's chunks"
        self._set("run-stats", f"{done}/{total} realizations stored ({what})")

    def show_stored_sweep(self, sweep, rows: list[dict], point, done: int, total: int, resuming: bool = True) -> None:
        """A sweep's resume as it begins (or a sweep that writes no progress file, as it goes): the
        rows of its points that are done (sweep.json's), and ``point``, which it goes on with, at the
        count its chunks hold."""
        table = self.query_one("#sweep-table", SweepTable)
        for row in rows:
            table.put_point(row)
        self._set("sweep-point", point_line(sweep, point))
        self.show_stored_count(done, total, resuming=resuming)

    def show_cancelling(self) -> None:
        self._set("run-stats", "cancelling: the solves running stop; what finished is kept")

    def show_point(self, sweep, kind: str, point, result) -> None:
        """A sweep point started (``result`` None) or finished."""
        table = self.query_one("#sweep-table", SweepTable)
        if kind == "started":
            self._set("sweep-point", point_line(sweep, point))
            self._show_bar(point.scene.preset.realizations, 0)
            table.mark_running(str(point.number))  # an interrupted point, running again
            return
        table.put_point(result.row())  # one row a point: a resume tells again of the points it had
        if result.error:
            self._error(f"point {result.point.number}: {result.error}")

    # ------------------------------------------------------------ at the end

    def show_outcome(self, run, point: str = "") -> str:
        """Show a finished run (``FinishedRun``, read back from its folder), ``point`` the sweep's point it
        is ('point 3/3: ', said before its bar's line); return the line the app notifies."""
        result = run.result
        done, requested = result.realizations
        self._show_bar(requested, done)
        self._set("run-stats", f"{point}{result.status}: {done}/{requested} realizations in "
                               f"{format_duration(result.elapsed)}, {run.workers} worker"
                               f"{'s' if run.workers != 1 else ''}")  # fmt: skip
        f, xi = result.table["f"], result.table["xi"]
        series = [Series(f, xi, "cyan")]  # without a fit, the curve alone: not the last interim line
        if result.fit is not None:
            series.append(fit_series(f, result.fit.a, result.fit.b, "yellow"))
        self.query_one("#run-chart", Chart).show(series)
        lines, short = (fit_lines(result.fit, final=True, f_formula=run.f_formula, short=s) for s in (False, True))
        self.query_one("#run-fit", FitPanel).show(lines, result.table["contact_count"], short)
        self._caveats([f"caveat: {caveat}" for caveat in shown_caveats(result.caveats)])  # as frictionlab run prints them
        if run.failures:  # a realization's own error, told as the user can act on it (the summary quotes it raw)
            index, reason = run.failures[0]
            self._error(f"{run.failed} realization(s) failed; #{index}: {failure_message(reason)}")
        elif run.error and run.error not in result.caveats:  # a run's own error (no law) is a caveat above already
            self._error(f"error: {run.error}")
        return f"Run {result.status}: {done}/{requested} realizations"

    def show_sweep_outcome(self, sweep) -> str:
        """Show a finished sweep (``FinishedSweep``, read back from its folder); return the line the app notifies."""
        if sweep.last is not None:  # the last point as it ended (a short one may have been over before it was read)
            self.show_outcome(sweep.last, f"point {sweep.last_point}/{sweep.total}: ")  # its bar, not the sweep's
        self._set("sweep-point", f"{sweep.status}: {sweep.finished}/{sweep.total} points in "
                                 f"{format_duration(sweep.elapsed)} (sweep.csv, sweep.png)")  # fmt: skip
        return f"Sweep {sweep.status}: {sweep.finished}/{sweep.total} points"

    def show_crash(self, error: str, interrupted: bool = False) -> None:
        self._error(f"run {'interrupted' if interrupted else 'failed'}: {error}")
