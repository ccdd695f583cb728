"""The help screen: every key binding of the app, grouped by where it works."""

from __future__ import annotations

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Label, Static


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
