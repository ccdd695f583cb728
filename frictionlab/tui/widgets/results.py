"""The Results tab: runs and sweeps on the left, the open runs' curves on the right;
an open sweep's table of points below them (Enter on a point opens its run)."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
from rich.text import Text
from textual import events
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.content import Content
from textual.widgets import DataTable, Static

from ...errors import FrictionlabError, shown, shown_name
from ...io.files import real_path
from ...compute.fit import ci_label, format_interval
from ...runs.detached import RESUMABLE
from ..chart import NO_DATA, Series
from ...runs.figures import SHOWN_LABEL_CHARS, cut
from ...runs.results import read_curve
from ..folders import RunEntry, SweepEntry, list_runs, read_run
from ..hiddenkeys import SaysWhyUnavailable, said_when_hidden
from ..sweepview import STATUS_MARKS
from ..text import format_count, packed, shorten_run_name
from .chart import Chart
from .run import fit_series
from .sweeptable import SweepList
from .tables import ListTable

OVERLAY_STYLES = ("cyan", "magenta", "green", "yellow")
HINT = "Enter opens a run; Space adds it to the overlay.\n" + ", ".join(  # what the list's marks are
    f"{mark} {' or '.join(s for s, m in STATUS_MARKS.items() if m == mark)}" for mark in dict.fromkeys(STATUS_MARKS.values()))
NO_RUN_OPEN = "no run open"
NO_RUNS = "No runs yet: Ctrl+R runs the open preset (F2 lists the presets)."
FIXED_COLUMNS = (1, 7, 7)  # the status mark, a, b; the name takes the rest of the list's width
# the list's width: its share of the pane, at least LIST_MIN; the plot keeps CHART_MIN
LIST_SHARE, LIST_MIN, CHART_MIN = 0.45, 40, 40


class InfoBox(VerticalScroll):
    """The box under the plot; under 60 columns, under the list (app.tcss), where it may have the
    tab's rows alone (30x8): Tab goes to it there and the arrows scroll it. Wider, beside the list,
    the list keeps the keys."""

    def allow_focus(self) -> bool:
        return self.screen.has_class("-narrow")


class ResultsPane(SaysWhyUnavailable, Vertical):
    BINDINGS = [
        Binding("space", "compare", "Compare", tooltip="(add the run to the overlay, or remove it)"),
        Binding("r", "reload", "Reload", tooltip="the list of runs"),
        Binding("u", "resume", "Resume", tooltip="the highlighted run: only the missing realizations are computed"),
        Binding("escape", "back_to_list", "Back", tooltip="to the runs from the open sweep's points"),  # short: the footer fits 80
        # the same keys on a row where they cannot act (check_action hides those above): the status line says why
        *said_when_hidden(("space", "compare"), ("u", "resume")),
    ]

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.runs: list[RunEntry | SweepEntry] = []
        self.overlay: list[RunEntry] = []  # the runs drawn, at most one per style
        self.open_sweep: SweepEntry | None = None  # the sweep whose points are listed
        self._shown: list[Path] = []  # the folders the list shows, in its order
        self._footer_row: tuple | None = None  # the (folder, status) the footer's keys were for
        self._info_about: Path | None = None  # the damaged run whose reason the info box shows
        self._visited = False  # the list has had the focus: the row highlighted there is the user's

    def compose(self) -> ComposeResult:
        with Horizontal(id="results-top"):
            yield ListTable(id="runs-table", cursor_type="row", zebra_stripes=True, empty=NO_RUNS)
            with Vertical(id="results-body"):
                yield Chart(empty=NO_RUN_OPEN, id="results-chart")  # not "no data yet": the runs have theirs
                with InfoBox(id="results-info-box"):  # at 60x20 a run's lines need 9 rows
                    yield Static(HINT, id="results-info")
        yield SweepList(id="results-sweep", cursor_type="row", zebra_stripes=True)

    def _name_width(self) -> int:
        """Size the list to the width the pane has: its share, more when a name needs
        it as long as the plot keeps CHART_MIN columns; the name column gets the rest."""
        table = self.query_one("#runs-table", DataTable)
        others = sum(FIXED_COLUMNS) + 2 * table.cell_padding * (len(FIXED_COLUMNS) + 1)
        if self.size.width == 0:  # not laid out yet: filled again once it is (on_resize)
            return 12
        overflows = len(self.runs) + 1 > table.size.height  # the header row, then the runs
        gutter = table.styles.scrollbar_size_vertical if overflows else 0
        longest = max((len(shown_name(entry.path.name)) for entry in self.runs), default=0)
        share = max(LIST_MIN, int(self.size.width * LIST_SHARE))
        width = max(share, min(longest + others + gutter, self.size.width - CHART_MIN))
        if self._narrow():  # the plot goes under the list: the list takes the width (app.tcss)
            width, table.styles.width = self.size.width, None
        else:
            table.styles.width = width
        return max(12, width - others - gutter)

    def on_descendant_focus(self, event: events.DescendantFocus) -> None:
        self._visited = True

    def _narrow(self) -> bool:
        return self.screen.has_class("-narrow")

    def _keep_list_rows(self) -> None:
        """Under 60 columns the list has half the rows above the plot (app.tcss), and at least
        its header and the row highlighted: at 40x12 an open sweep's points left the list three,
        its header alone in sight. Under 12 rows (30x8) the stylesheet's two stand."""
        table = self.query_one("#runs-table", DataTable)
        top = self.query_one("#results-top").size.height
        rows = max(2, top // 2) if top and self._narrow() and not self.screen.has_class("-tiny") else None
        if rows != (table.styles.max_height and table.styles.max_height.value):
            table.styles.max_height = rows

    def on_resize(self, event: events.Resize) -> None:
        self.call_after_refresh(self._fill)  # the list's width is known once laid out
        self.call_after_refresh(self._keep_list_rows)
        if self.overlay and self._info_about is None and self.open_sweep is None:
            self.call_after_refresh(self._show_overlay)  # its lines broken to the box's new width

    def highlighted(self) -> RunEntry | SweepEntry | None:
        row = self.query_one("#runs-table", DataTable).cursor_row
        return self.runs[row] if 0 <= row < len(self.runs) else None

    def check_action(self, action: str, parameters) -> bool:
        """The footer offers what the highlighted row allows: Resume on a run or sweep that ended
        before it completed, Compare on a run with a curve (one with its results written; or on a sweep's point)."""
        if action == "back_to_list":
            return self.open_sweep is not None and self.query_one("#results-sweep").has_focus
        if action not in ("resume", "compare"):
            return True
        entry = self.highlighted()
        if action == "compare" and self.open_sweep is not None and self.query_one("#results-sweep").has_focus:
            return True
        if entry is None:
            return False
        if action == "resume":  # not a run (nor a sweep's points) failed with every realization finished: it would fail so again
            return entry.status in RESUMABLE and not entry.failed_for_good
        return not isinstance(entry, SweepEntry) and entry.status not in ("damaged", "running") and bool(entry.summary)

    def action_back_to_list(self) -> None:
        self.query_one("#runs-table").focus()

    def _close_sweep(self) -> None:
        """The open sweep's points are no longer listed (another row was opened)."""
        self.open_sweep = None
        self.set_class(False, "-sweep")
        self.query_one("#results-sweep", SweepList).clear_points()
        self.call_after_refresh(self._keep_list_rows)

    def _refresh_footer(self) -> None:
        """The footer again when what the highlighted row allows may differ (another row, a status
        changed), not at each reload: the footer is rebuilt each time."""
        entry = self.highlighted()
        now = (entry.path, entry.status) if entry is not None else None
        if now != self._footer_row:
            self._footer_row = now
            self.app.refresh_bindings()

    def on_data_table_row_highlighted(self, event: DataTable.RowHighlighted) -> None:
        self._refresh_footer()  # what this row allows
        if event.data_table.id == "runs-table":
            entry = self.highlighted()
            self.app.row_highlighted(entry.path if entry is not None else None)
            if self._info_about is not None and (entry is None or entry.path != self._info_about):
                self._show_overlay()  # the damaged row's reason goes with it: the overlay's lines again
        elif self.open_sweep is not None:  # a point of the open sweep
            self.app.row_highlighted(self.open_sweep.path / f"point {event.cursor_row}")

    def action_compare(self) -> None:
        self.open_selected(overlay=True)

    def action_reload(self) -> None:
        self.app.reload_runs()

    def action_resume(self) -> None:
        row = self.query_one("#runs-table", DataTable).cursor_row
        if not 0 <= row < len(self.runs):
            self.app.say(NO_RUNS, "warning")
            return
        self.app.resume_run(self.runs[row].path)

    def on_data_table_row_selected(self, event: DataTable.RowSelected) -> None:
        event.stop()
        self.open_selected(overlay=False)

    def reload(self, runs_dir: Path) -> None:
        self.runs = list_runs(runs_dir)
        self._fill()
        self._drop_removed()

    def _drop_removed(self) -> None:
        """A plotted run or the open sweep whose folder was removed (by hand, another program) is
        taken off the plot or the table, and said in the box under the plot: they were drawn on as
        if still there."""
        gone = [entry for entry in self.overlay if not os.path.lexists(entry.path)]
        sweep_gone = self.open_sweep is not None and not os.path.lexists(self.open_sweep.path)
        if not gone and not sweep_gone:
            return
        removed = [entry.path.name for entry in gone] + ([self.open_sweep.path.name] if sweep_gone else [])
        if sweep_gone:
            if self.query_one("#results-sweep").has_focus:
                self.query_one("#runs-table").focus()
            self._close_sweep()
        self.overlay = [entry for entry in self.overlay if entry not in gone]
        self._show_overlay(note=f"Removed from disk since opened: {', '.join(map(shown_name, removed))}.")

    def _fill(self) -> None:
        """The list of runs, each name shortened from the middle to the width the list has."""
        table = self.query_one("#runs-table", DataTable)
        row = table.cursor_row
        was = self._shown[row] if 0 <= row < len(self._shown) else None
        # the run highlighted stays so as rows are added above it; until the list is first shown, the
        # newest stays first (a run made, then F5: Enter opened the run before it, not the one just made)
        if self._visited and was is not None and was in [entry.path for entry in self.runs]:
            row = [entry.path for entry in self.runs].index(was)
        self._shown = [entry.path for entry in self.runs]
        width = self._name_width()
        table.clear(columns=True)
        table.add_column("", width=FIXED_COLUMNS[0], key="status")
        table.add_column("run", width=width)
        table.add_column("a", width=FIXED_COLUMNS[1])
        table.add_column("b", width=FIXED_COLUMNS[2])
        for entry in self.runs:
            if isinstance(entry, SweepEntry):
                a, b = "sweep", f"{len(entry.points)} pts"
            elif entry.status == "damaged":
                a, b = "damaged", ""
            else:
                a = f"{entry.a:.4f}" if math.isfinite(entry.a) else "-"
                b = f"{entry.b:.4f}" if math.isfinite(entry.b) else "-"
            name = Text(shorten_run_name(shown_name(entry.path.name), width))  # Text: never markup
            table.add_row(STATUS_MARKS.get(entry.status, "?"), name, a, b)
        if self.runs:
            table.move_cursor(row=min(max(row, 0), len(self.runs) - 1), animate=False)
        self._refresh_footer()  # the highlighted row's status may have changed (a run ended)

    def open_selected(self, overlay: bool) -> None:
        """Enter/Space on the list of runs, or on the open sweep's table of points."""
        points = self.query_one("#results-sweep", DataTable)
        if points.has_focus and self.open_sweep is not None:
            row = points.cursor_row
            if not 0 <= row < len(self.open_sweep.points) or (entry := self._point_run(row)) is None:
                return
        else:
            row = self.query_one("#runs-table", DataTable).cursor_row
            if not 0 <= row < len(self.runs):
                self.app.say(NO_RUNS, "warning")
                return
            entry = self.runs[row]
            if entry.status == "damaged":  # nothing to show but why: no sweep's points or curves beside it
                self._close_sweep()
                self.query_one("#results-chart", Chart).show([])
                self.app.say(f"{shown_name(entry.path.name)} is damaged: {entry.reason}", "warning", about=entry.path)
                self._inform(Content(f"{shown_name(entry.path.name)}: damaged\n{entry.reason}"))
                self._info_about = entry.path
                return
            if entry.status == "running" and overlay:  # Space is not listed there: say why, as a hidden key does
                self.app.say(f"{shown_name(entry.path.name)} is running: it has no curve to compare until it ends; "
                             "Enter shows it live on the Run tab", "warning", about=entry.path)  # fmt: skip
                return
            if entry.status == "running":  # its process goes on: shown live (a sweep too)
                self.app.show_running(entry.path)
                return
            if not isinstance(entry, SweepEntry) and not entry.summary:  # ended before its results (killed): no curve
                self._say_no_results(entry, shown_alone=not overlay)
                return
            if isinstance(entry, SweepEntry):
                if overlay:
                    self.app.say(f"{shown_name(entry.path.name)} is a sweep: Enter lists its points, Space on a point overlays it.",
                                 "warning", about=entry.path)
                else:
                    self._show_sweep(entry)
                return
            if not overlay:  # Enter: this run alone (Space adds it beside the sweep's points)
                self._close_sweep()
        hidden = None
        if overlay:
            paths = [e.path for e in self.overlay]
            if entry.path in paths:
                self.overlay = [e for e in self.overlay if e.path != entry.path]
                hidden = entry
            else:
                self.overlay = (self.overlay + [entry])[-len(OVERLAY_STYLES):]
        else:
            self.overlay = [entry]
        self._show_overlay()
        if hidden is not None and not self.overlay:  # its data is there: "no data yet" said otherwise
            name = shown_name(hidden.path.name)
            self.query_one("#results-chart", Chart).show([], empty="run hidden")
            self._inform(
                Content(f"{name} is hidden from the plot: Space on its row shows it again; Enter opens a run.")
            )

    def _point_run(self, row: int) -> RunEntry | None:
        """The run of the open sweep's point ``row``; None, said why, where it has none to show."""
        try:
            return read_run(self.open_sweep.point_folder(self.open_sweep.points[row]))
        except (OSError, FrictionlabError) as exc:
            self.app.say(f"this point has no finished run to show ({exc})", "warning",
                         about=self.open_sweep.path / f"point {row}")  # fmt: skip
            return None

    def open_point(self, sweep: Path, point: int) -> None:
        """Enter on a point of the Run tab's sweep: the sweep open here, that point's run shown."""
        self.app.reload_runs()
        entry = next((e for e in self.runs if isinstance(e, SweepEntry) and real_path(e.path) == real_path(sweep)), None)
        numbers = [row.get("point") for row in entry.points] if entry is not None else []
        if point not in numbers:
            self.app.say(f"point {point} of {shown(sweep)} has no finished run to show yet", "warning")
            return
        self.query_one("#runs-table", DataTable).move_cursor(row=self.runs.index(entry), animate=False)
        self._show_sweep(entry)
        row = numbers.index(point)
        self.query_one("#results-sweep", SweepList).move_cursor(row=row, animate=False)
        if (run := self._point_run(row)) is not None:
            self.overlay = [run]
            self._show_overlay()

    def _say_no_results(self, entry: RunEntry, shown_alone: bool) -> None:
        """A run that ended before it wrote its results (its process killed) has no curve: Enter and
        Space said "no curve (... no such curve.csv)", as of a damaged folder, not how it ended."""
        why = (f"{shown_name(entry.path.name)}: {entry.status} before its results were written, "
               f"{entry.done}/{entry.requested} realizations stored" + ("; u resumes it" if entry.status in RESUMABLE else ""))  # fmt: skip
        self.app.say(why, "warning", about=entry.path)
        if shown_alone:  # Enter: the plot and the box speak of it alone
            self._close_sweep()
            self.overlay = []
            self.query_one("#results-chart", Chart).show([], empty="no curve yet")
            self._inform(Content(why))
            self._info_about = entry.path

    def _show_sweep(self, entry: SweepEntry) -> None:
        """The sweep's table of points, formatted as the Run tab formats a live sweep."""
        self.open_sweep = entry
        table = self.query_one("#results-sweep", SweepList)
        table.show_points(entry.paths, entry.points, entry.confidence)
        self.set_class(True, "-sweep")
        self.call_after_refresh(self._keep_list_rows)
        self._inform(
            Content(
                f"sweep {entry.name}: {entry.status}, {len(entry.points)} points.\n"
                "Enter on a point opens its run; Space adds it to the overlay; Esc goes back to the list."
            )
        )
        table.focus()

    def _show_overlay(self, note: str = "") -> None:
        """The overlay's runs drawn, and their lines in the box under the plot (after ``note``)."""
        self._info_about = None
        series, lines = [], [Content(note)] if note else []
        for style, entry in zip(OVERLAY_STYLES, self.overlay):
            try:
                curve = read_curve(entry.path)
            except (OSError, FrictionlabError) as exc:
                lines.append(Content.assemble((shown_name(entry.path.name), style), f": no curve ({shown(str(exc))})"))
                continue
            f, xi = np.array(curve.get("f", []), float), np.array(curve.get("xi", []), float)
            series.append(Series(f, xi, style))
            if math.isfinite(entry.a):
                series.append(fit_series(f, entry.a, entry.b, f"dim {style}"))
            lines += _entry_lines(entry, style, self._info_width())
        for definition in dict.fromkeys(entry.definition for entry in self.overlay if entry.definition):
            # what each symbol of f is, once under the runs (their lines give the formula alone)
            words = shown(cut(definition, SHOWN_LABEL_CHARS)).split()
            lines += [Content.styled(line, "dim") for line in packed(words, self._info_width(), indent="")]
        self.query_one("#results-chart", Chart).show(series, empty="run removed" if note else NO_DATA)
        self._inform(Content("\n").join(lines) if lines else HINT)

    def _info_width(self) -> int:
        """The columns of the box under the plot, less its scroll bar's (unknown before it is laid out: as if wide)."""
        box = self.query_one("#results-info-box")
        return box.size.width - box.styles.scrollbar_size_vertical if box.size.width else 200

    def _inform(self, text: Content | str) -> None:
        """The info box under the plot says ``text``, from its first line (the box scrolls where
        it is taller than the room the plot leaves)."""
        self.query_one("#results-info", Static).update(text)
        self.query_one("#results-info-box").scroll_home(animate=False)


def _entry_lines(entry: RunEntry, style: str, width: int) -> list[Content]:
    """What the overlay says of one run: f, its status and contacts, its fit; in ``width``
    columns, broken between its parts (at 60x20 the box has 20)."""
    counts = entry.contact_counts
    formula = f"f = {entry.formula}" if entry.formula else ""
    name = f"■ {shown_name(entry.path.name)}"
    if len(name) + 1 + len(formula) <= width or not formula:
        lines = [Content.assemble((shorten_run_name(name, width), style), f" {formula}" if formula else "")]
    else:
        lines = [Content.styled(shorten_run_name(name, width), style), *packed([formula], width)]
    status = [entry.status, f"{entry.done}/{entry.requested}"]
    if math.isfinite(counts[0]):
        status = [status[0], f"{status[1]},", "contacts", f"{format_count(counts[0])}..{format_count(counts[1])}"]
    lines += packed(status, width)
    error = entry.summary.get("error")
    if isinstance(error, str) and error:  # why it failed (no law, say): the advice that comes with it
        # broken between words as the rest of the box is, each line indented (wrapped, it went on at the edge)
        lines += [Content.assemble(line[:2], (line[2:], "red")) for line in packed(shown(error).split(), width)]
    if entry.fit is not None:
        interval = lambda key: format_interval(entry.interval(key) or (None, None), missing="")  # noqa: E731
        lines += packed([f"a={entry.a:.4f}", interval("a_ci"), f"R^2={entry.r2:.4f}"], width)
        lines += packed([f"b={entry.b:.4f}", interval("b_ci")], width)
        level = entry.confidence if entry.interval("a_ci") is not None else None
        # what a and b are, and the intervals' level, as the Run tab says them; after the numbers: a short box shows them first
        lines += packed(["in", "xi = a + b ln f"] if level is None else ["in", "xi = a + b ln f,", ci_label(level)], width)
    return [Content(line) if isinstance(line, str) else line for line in lines]
