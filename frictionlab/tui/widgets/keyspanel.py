"""The keys panel: Textual's, with a first line that says how to close it (at 30x8 it takes
the whole screen, the footer under it, and nothing there said how to get out)."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.css.query import NoMatches
from textual.widgets import HelpPanel, KeyPanel, Static

MORE = "Esc closes; F1: next page"
LAST = "Esc or F1 closes"


class KeysPanel(HelpPanel):
    """``HelpPanel`` under a line that says which key closes it, and whether F1 pages on or closes."""

    DEFAULT_CSS = "KeysPanel #keys-close { height: auto; text-style: bold; color: $text-accent; }"

    def compose(self) -> ComposeResult:
        yield Static(MORE, id="keys-close")
        yield from super().compose()

    def on_mount(self) -> None:
        self.watch(self.query_one(KeyPanel), "scroll_y", lambda _: self.say_close())  # F1's page, the wheel
        self.call_after_refresh(self.say_close)

    def on_resize(self) -> None:
        self.call_after_refresh(self.say_close)

    def say_close(self) -> None:
        """The first line as F1 would act now: another page, or close the panel after the last.
        Nothing once the panel is closing: a resize or a scroll heard after Esc removed its lines
        (F1 and Esc typed together, a terminal widened as it closes) ended the app in a traceback."""
        try:
            keys, line = self.query_one(KeyPanel), self.query_one("#keys-close", Static)
        except NoMatches:
            return
        line.update(MORE if keys.scroll_y < keys.max_scroll_y else LAST)
