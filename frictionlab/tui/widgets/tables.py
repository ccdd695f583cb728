"""Row lists of the Presets and Results tabs."""

from __future__ import annotations

from textual.binding import Binding
from textual.widgets import DataTable


class ListTable(DataTable):
    """A row list whose Enter is shown in the footer as Open."""

    BINDINGS = [Binding("enter", "select_cursor", "Open", tooltip="Open the highlighted row")]
