"""The tables of a sweep's points on the Run and Results tabs (their own module: the first
screen's lists, ``tables``, do without the sweep's modules)."""

from __future__ import annotations

from rich.cells import cell_len
from rich.text import Text
from textual.binding import Binding
from textual.widgets import DataTable

from ..hiddenkeys import idle_sideways
from ..sweepview import row_cells, table_columns
from .tables import ListTable


class SweepRows:
    """A sweep's table of points (a ``DataTable`` mixin) that fits its width: where the a and b
    intervals would push R^2 and the contacts out of sight (60 columns), they are left out
    (sweep.csv, the plot's fit and each point's run have them)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._paths: list[str] = []
        self._points: dict[str, dict] = {}  # sweep.json's points (PointResult.row()), by point number
        self._intervals: bool | None = None  # the form shown; None: no sweep's columns
        self._confidence: float | None = None  # the intervals' level (None: the points' differ)

    def show_points(self, paths: list[str], rows, confidence: float | None) -> None:
        """The columns of a sweep over ``paths`` and its ``rows`` (sweep.json's points), keyed by point
        number; ``confidence``, the level of its intervals (None where its points differ in it)."""
        self._paths, self._points, self._intervals = list(paths), {str(row["point"]): row for row in rows}, None
        self._confidence = confidence
        self._refill()

    def clear_points(self) -> None:
        """No sweep's points (its sweep closed): none come back on a resize."""
        self._paths, self._points, self._intervals = [], {}, None
        self.clear(columns=True)

    def put_point(self, row: dict) -> None:
        """A point's row (``PointResult.row()``) added, or updated in place (a resumed point)."""
        key = str(row["point"])
        self._points[key] = row
        if self._fits_intervals() != self._intervals:
            self._refill()
        elif key in self.rows:
            for column, cell in zip(self.columns, row_cells(self._paths, row, self._intervals)):
                self.update_cell(key, column, Text(cell))
        else:
            self.add_row(*map(Text, row_cells(self._paths, row, self._intervals)), key=key)

    def mark_running(self, key: str) -> None:
        """A point that was interrupted runs again: its status mark."""
        if key in self._points:
            self.put_point({**self._points[key], "status": "running"})

    def on_resize(self) -> None:
        if self._intervals is not None and self._fits_intervals() != self._intervals:
            self._refill()

    def _fits_intervals(self) -> bool:
        """Whether every column fits with the intervals (beside the vertical scroll bar); not
        laid out yet, they are assumed to (a resize checks again)."""
        columns = [table_columns(self._paths, True, self._confidence), *(row_cells(self._paths, row) for row in self._points.values())]
        needed = sum(max(map(cell_len, cells)) + 2 * self.cell_padding for cells in zip(*columns))
        return not self.size.width or needed <= self.size.width - self.styles.scrollbar_size_vertical

    def _refill(self) -> None:
        """All the rows again, in the form that fits; the cursor stays on its row."""
        row = self.cursor_row
        self._intervals = self._fits_intervals()
        self.clear(columns=True)
        self.add_columns(*table_columns(self._paths, self._intervals, self._confidence))
        for key, point in self._points.items():
            self.add_row(*map(Text, row_cells(self._paths, point, self._intervals)), key=key)
        if self.row_count:
            self.move_cursor(row=min(row, self.row_count - 1))


class SweepTable(SweepRows, DataTable):
    """The Run tab's table of a sweep's finished points: Enter opens a point's run on the Results
    tab (F1 listed Enter as Select, and it did nothing); Left, Right and Ctrl+PgUp/PgDn are listed
    only where the table is wider than the screen."""

    BINDINGS = [Binding("enter", "select_cursor", "Open", tooltip="the point's run on the Results tab")]

    def check_action(self, action: str, parameters) -> bool:
        return not idle_sideways(self, action)


class SweepList(SweepRows, ListTable):
    """The Results tab's points of the open sweep: Enter opens a point's run."""
