"""The chart widget: xi against f (log axis) in braille dots, drawn by ``tui.chart``."""

from __future__ import annotations

from rich.text import Text
from textual.widget import Widget

from ..chart import NO_DATA, Series, render_chart


class Chart(Widget):
    """xi against f (log axis), braille dots; redrawn when ``series`` is set."""

    DEFAULT_CSS = "Chart { height: 1fr; min-height: 6; }"

    def __init__(self, empty: str = NO_DATA, **kwargs):
        super().__init__(**kwargs)
        self.series: list[Series] = []
        self.empty = empty  # what it says with no point to plot

    def show(self, series: list[Series], empty: str = NO_DATA) -> None:
        self.series, self.empty = series, empty
        self.refresh()

    def render(self) -> Text:
        text = Text(no_wrap=True, overflow="crop")
        rows = render_chart(self.series, self.size.width, self.size.height, self.empty)
        for i, row in enumerate(rows):
            for chunk, style in row:
                text.append(chunk, style=style or None)
            if i < len(rows) - 1:
                text.append("\n")
        return text
