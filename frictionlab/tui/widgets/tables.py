"""Row lists of the Presets and Results tabs."""

from __future__ import annotations

from textual.binding import Binding
from textual.widgets import DataTable


class ListTable(DataTable):
    """A row list whose Enter is shown in the footer as Open; Enter on an empty
    list says what to do instead (``empty``)."""

    BINDINGS = [
        Binding("enter", "select_cursor", "Open", tooltip="the highlighted row"),
        # a list has no columns to scroll to: Home/End go to its first/last row (as Ctrl+Home/End do)
        Binding("home", "scroll_top", "First row", show=False),
        Binding("end", "scroll_bottom", "Last row", show=False),
    ]

    def __init__(self, *args, empty: str = "Nothing here.", **kwargs):
        super().__init__(*args, **kwargs)
        self.empty = empty

    def action_select_cursor(self) -> None:
        if self.row_count == 0:
            self.app.say(self.empty, "warning")
            return
        super().action_select_cursor()
