"""Small widgets and modal screens of the TUI: the chart, help, confirm, save as, new preset."""

from __future__ import annotations

from pathlib import Path

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.widget import Widget
from textual.widgets import Button, Input, Label, Select, Static

from .chart import Series, render_chart


class Chart(Widget):
    """xi against f (log axis), braille dots; redrawn when ``series`` is set."""

    DEFAULT_CSS = "Chart { height: 1fr; min-height: 6; }"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.series: list[Series] = []

    def show(self, series: list[Series]) -> None:
        self.series = series
        self.refresh()

    def render(self) -> Text:
        text = Text(no_wrap=True, overflow="crop")
        rows = render_chart(self.series, self.size.width, self.size.height)
        for i, row in enumerate(rows):
            for chunk, style in row:
                text.append(chunk, style=style or None)
            if i < len(rows) - 1:
                text.append("\n")
        return text


class HelpScreen(ModalScreen[None]):
    """Every key binding of the app, grouped by where it works."""

    BINDINGS = [
        Binding("escape", "dismiss", "Close"),
        Binding("f1", "dismiss", "Close", show=False),
        Binding("q", "dismiss", "Close", show=False),
    ]

    def __init__(self, groups: list[tuple[str, list[tuple[str, str]]]]):
        super().__init__()
        self.groups = groups

    def compose(self) -> ComposeResult:
        text = Text()
        for title, rows in self.groups:
            text.append(f"{title}\n", style="bold")
            for key, description in rows:
                text.append(f"  {key:<14}", style="bold cyan")
                text.append(f"{description}\n")
        with Vertical(id="help-box"):
            yield Label("Keys  (Esc closes)", classes="heading")
            with VerticalScroll():
                yield Static(text)


class ConfirmScreen(ModalScreen[bool]):
    BINDINGS = [
        Binding("y", "answer(True)", "Yes"),
        Binding("n,escape", "answer(False)", "No"),
    ]

    def __init__(self, question: str):
        super().__init__()
        self.question = question

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield Static(self.question)
            yield Label("y: yes    n / Esc: no", classes="hint")

    def action_answer(self, value: bool) -> None:
        self.dismiss(value)


class PathScreen(ModalScreen[Path | None]):
    """Ask for a file path (save as, duplicate)."""

    BINDINGS = [Binding("escape", "dismiss(None)", "Cancel")]

    def __init__(self, title: str, default: Path):
        super().__init__()
        self.title_text = title
        self.default = default

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield Label(self.title_text, classes="heading")
            yield Input(str(self.default), id="path-input")
            yield Static("", id="path-error", classes="field-error")
            yield Label("Enter: save    Esc: cancel", classes="hint")

    def on_input_submitted(self, event: Input.Submitted) -> None:
        text = event.value.strip()
        error = self.query_one("#path-error", Static)
        if not text:
            error.update("path: must not be empty")
            return
        path = Path(text).expanduser()
        if path.suffix not in (".yaml", ".yml"):
            path = path.with_name(path.name + ".yaml")
        if path.is_dir():
            error.update(f"path: {path} is a folder; give a file name")
            return
        self.dismiss(path)


class NewPresetScreen(ModalScreen[tuple[str, str] | None]):
    """A new preset from a spectrum plugin's defaults: ask its name and spectrum."""

    BINDINGS = [Binding("escape", "dismiss(None)", "Cancel")]

    def __init__(self, spectra: list[str]):
        super().__init__()
        self.spectra = spectra

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield Label("New preset from a plugin's defaults", classes="heading")
            with Horizontal(classes="row"):
                yield Label("name", classes="field-label")
                yield Input("my-scene", id="new-name", compact=True)
            with Horizontal(classes="row"):
                yield Label("spectrum", classes="field-label")
                yield Select(
                    [(s, s) for s in self.spectra], value=self.spectra[0], allow_blank=False,
                    compact=True, id="new-spectrum",
                )
            yield Static("", id="new-error", classes="field-error")
            yield Button("Create", id="new-create", compact=True)
            yield Label("Tab: next field    Enter: create    Esc: cancel", classes="hint")

    def _create(self) -> None:
        name = self.query_one("#new-name", Input).value.strip()
        if not name:
            self.query_one("#new-error", Static).update("name: must not be empty")
            return
        self.dismiss((name, self.query_one("#new-spectrum", Select).value))

    def on_input_submitted(self, event: Input.Submitted) -> None:
        self._create()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        self._create()
