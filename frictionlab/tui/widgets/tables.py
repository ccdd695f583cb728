"""Row lists of the Presets and Results tabs."""

from __future__ import annotations

from textual.binding import Binding
from textual.widgets import DataTable

from ..hiddenkeys import SaysWhyUnavailable, idle_sideways, said_when_hidden


class ListTable(SaysWhyUnavailable, DataTable):
    """A row list whose Enter is shown in the footer as Open while it has a row; Enter on an
    empty list says what to do instead (``empty``)."""

    BINDINGS = [
        Binding("enter", "select_cursor", "Open", tooltip="the highlighted row"),
        # a list has no columns to scroll to: Home/End go to its first/last row (as Ctrl+Home/End do)
        Binding("home", "scroll_top", "First row", show=False),
        Binding("end", "scroll_bottom", "Last row", show=False),
        *said_when_hidden(("enter", "select_cursor")),
    ]

    def __init__(self, *args, empty: str = "Nothing here.", **kwargs):
        super().__init__(*args, **kwargs)
        self.empty = empty

    def check_action(self, action: str, parameters) -> bool:
        if idle_sideways(self, action):
            return False
        return action != "select_cursor" or self.row_count > 0  # an empty list: nothing to open

    def action_select_cursor(self) -> None:
        if self.row_count == 0:
            self.app.say(self.empty, "warning")
            return
        super().action_select_cursor()
