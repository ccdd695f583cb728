"""The Presets tab: the presets of the project and user folders, with a line about each."""

from __future__ import annotations

from pathlib import Path

from rich.text import Text
from textual import events
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical, VerticalScroll
from textual.content import Content
from textual.widgets import DataTable, Static

from ...errors import shown, shown_name
from ...io.files import real_path
from ..folders import PresetEntry, list_presets
from ..hiddenkeys import SaysWhyUnavailable, said_when_hidden
from ..text import shorten_middle
from .pathline import PathLine
from .tables import ListTable

NO_PRESETS = "No preset to open here: n makes a new one."


class PresetsPane(SaysWhyUnavailable, Vertical):
    BINDINGS = [
        Binding("d", "duplicate", "Duplicate", tooltip="the preset (asks for a file name)"),
        Binding("n", "new", "New", tooltip="preset from a listed one (asks its name and file)"),
        Binding("r", "reload", "Reload", tooltip="the list of presets"),
        *said_when_hidden(("d", "duplicate")),  # on an empty list (check_action hides d): says why
    ]

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.presets: list[PresetEntry] = []

    def compose(self) -> ComposeResult:
        yield ListTable(id="preset-table", cursor_type="row", zebra_stripes=True, empty=NO_PRESETS)
        yield PathLine(id="preset-path")
        with VerticalScroll(id="preset-info-box", can_focus=False):
            yield Static("", id="preset-info")

    def on_resize(self, event: events.Resize) -> None:
        self.call_after_refresh(self._fill)  # the names are cut to the width the list has

    def _widths(self, table: DataTable) -> tuple[int, int, int]:
        """The name, folder and file columns' widths: all three on screen, a long name or file
        name cut in its middle, the name given at least half of what the folder leaves. Under
        60 columns no file column (0), and no folder column where the name needs its room: the
        line under the list names the file; at 30 columns the name kept 8 (``ben…fig2``)."""
        names = max((len(shown_name(e.name)) for e in self.presets), default=4)
        labels = max((len(e.label) for e in self.presets), default=6)
        files = max((len(shown_name(e.path.name)) for e in self.presets), default=4)
        if self.size.width == 0:  # not laid out yet: filled again once it is (on_resize)
            return names, labels, files
        padding = 2 * table.cell_padding  # a column's
        room = self.size.width - table.styles.scrollbar_size_vertical
        if self.screen.has_class("-narrow"):  # the name first; the folder where it fits whole beside it
            folder = labels if names + labels + 2 * padding <= room else 0
            return max(4, room - padding - (folder + padding if folder else 0)), folder, 0
        room -= 3 * padding
        folder = min(labels, max(6, room // 5))
        room -= folder
        name = min(names, max(room // 2, room - files))
        return max(4, name), folder, max(4, min(files, room - name))

    def _fill(self) -> None:
        table = self.query_one("#preset-table", DataTable)
        row = table.cursor_row
        name, folder, file = self._widths(table)
        table.clear(columns=True)
        columns = [("name", name), ("folder", folder), ("file", file)]
        for label, width in columns:
            if width:  # under 60 columns the file's, and the folder's, may be left out (_widths)
                table.add_column(label, width=width)
        for entry in self.presets:  # Text: never markup
            cells = zip((entry.name, entry.label, entry.path.name), (width for _, width in columns), strict=True)
            table.add_row(*(Text(shorten_middle(shown_name(text), width)) for text, width in cells if width))
        if self.presets:
            table.move_cursor(row=min(max(row, 0), len(self.presets) - 1), animate=False)

    def check_action(self, action: str, parameters) -> bool:
        return action != "duplicate" or bool(self.presets)  # listed only with a preset to duplicate

    def reload(self, folders: list) -> None:
        """List the presets of ``folders`` (``folders.preset_folders``); the highlighted preset
        stays highlighted where it is still listed (a file added above it moved the cursor off it)."""
        chosen = self.selected()
        self.presets = list_presets(folders)
        self._fill()
        if chosen is not None:
            self.highlight(chosen.path)
        self.app.refresh_bindings()  # Open and Duplicate are listed only on a list with a row
        if not self.presets:
            shown = ", ".join(str(f) for _, f in folders)
            self.query_one("#preset-path", PathLine).show("")
            self.query_one("#preset-info", Static).update(Content(f"No presets in {shown}. n makes a new one."))
        else:
            self._show_info(self.query_one("#preset-table", DataTable).cursor_row)

    def highlight(self, path: Path) -> bool:
        """Move the list's cursor to the preset in ``path``, if it is listed; whether it is."""
        rows = [i for i, entry in enumerate(self.presets) if real_path(entry.path) == real_path(path)]
        if rows:
            self.query_one("#preset-table", DataTable).move_cursor(row=rows[0], animate=False)
        return bool(rows)

    def selected(self) -> PresetEntry | None:
        row = self.query_one("#preset-table", DataTable).cursor_row
        return self.presets[row] if 0 <= row < len(self.presets) else None

    def _show_info(self, row: int) -> None:
        if 0 <= row < len(self.presets):
            entry = self.presets[row]
            text = entry.error or entry.description or "(no description)"
            self.query_one("#preset-path", PathLine).show("", str(entry.path))
            self.query_one("#preset-info", Static).update(Content(shown(text)))  # an escape sequence in the file: text
            self.query_one("#preset-info-box").scroll_home(animate=False)  # a description is read from its start

    def on_data_table_row_highlighted(self, event: DataTable.RowHighlighted) -> None:
        self._show_info(event.cursor_row)
        entry = self.selected()
        self.app.row_highlighted(entry.path if entry is not None else None)

    def on_data_table_row_selected(self, event: DataTable.RowSelected) -> None:
        event.stop()
        self.app.open_selected_preset()

    def action_duplicate(self) -> None:
        self.app.duplicate_selected_preset()

    def action_new(self) -> None:
        self.app.new_preset()

    def action_reload(self) -> None:
        self.app.reload_presets()
