"""Small modal dialogs: confirm, ask for a path (save as, duplicate), a new preset."""

from __future__ import annotations

from pathlib import Path

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, Select, Static


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
