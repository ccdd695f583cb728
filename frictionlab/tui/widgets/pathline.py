"""A one-line label whose path is shortened from the middle to fit its width."""

from __future__ import annotations

from textual.content import Content
from textual.widget import Widget

from ...errors import shown
from ..text import shorten_middle


class PathLine(Widget):
    """``head`` (bold), a path cut from the middle to the room left, then ``tail``;
    all shown as text, never markup. Redrawn at every width."""

    DEFAULT_CSS = "PathLine { height: 1; }"

    def __init__(self, head: str = "", path: str = "", tail: str = "", **kwargs):
        super().__init__(**kwargs)
        self.head, self.path, self.tail = head, path, tail

    def show(self, head: str = "", path: str = "", tail: str = "") -> None:
        self.head, self.path, self.tail = head, path, tail
        self.refresh()

    def render(self) -> Content:
        room = max(self.size.width - len(self.head) - len(self.tail), 12)
        return Content.assemble((self.head, "bold"), shorten_middle(shown(self.path), room), self.tail)  # a name's escape codes as text
