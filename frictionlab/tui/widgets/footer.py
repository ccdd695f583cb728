"""The footer, fitted to the terminal's width: Textual's cuts its keys at the right edge, and at
60 columns ``^s Save`` and ``^r Run`` were lost there. Keys that would run past the edge are
drawn closer together, and where they still do not fit the least needed are left out, first
those in ``LEFT_OUT_FIRST``; F1's key panel lists them all, as it lists every key."""

from __future__ import annotations

from rich.cells import cell_len
from textual import events
from textual.widgets import Footer

# the actions whose keys go first where the footer is short (in this order): another key does
# the same (q quits, Tab leaves a sweep's points), or a list that is seldom reloaded or copied;
# F1 Keys, Save, Run and the focused part's own Open, Compare, Resume, Cancel stay; narrower
# than these (30 columns) the last keys go, whole, but F1's: Textual cut one at the edge to a stray ^
LEFT_OUT_FIRST = ("reload", "duplicate", "quit", "back_to_list", "new")


class KeysFooter(Footer):
    """Textual's footer, its keys fitted to the width it has (``LEFT_OUT_FIRST``)."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._fitted_to = 0  # the width the keys were last fitted to
        self._drawn: tuple | None = None  # what the keys were last composed from (_keys_shown)
        self._check_queued = False

    def compose(self):
        if self._bindings_ready:
            self._drawn = self._keys_shown()
        keys = list(super().compose())  # FooterKeys: this app's bindings have no groups
        width = self._fitted_to = self.app.size.width
        self.compact = drawn_width(keys, compact=False) > width  # no padding around a key, one space after it
        for action in LEFT_OUT_FIRST:
            if drawn_width(keys, self.compact) <= width:
                break
            keys = [key for key in keys if key.action != action]
        while drawn_width(keys, self.compact) > width and any(key.action != "help" for key in keys):
            last = max(i for i, key in enumerate(keys) if key.action != "help")
            keys = keys[:last] + keys[last + 1 :]
        yield from keys

    def _keys_shown(self) -> tuple:
        """What the footer draws its keys from: the width and each shown binding's key, action,
        description, state and tooltip (Textual's footer reads nothing else)."""
        return (self.app.size.width, *(
            (binding.key, binding.action, binding.description, enabled, tooltip)
            for _, binding, enabled, tooltip in self.screen.active_bindings.values()
            if binding.show
        ))  # fmt: skip

    def bindings_changed(self, screen) -> None:
        # Textual recomposes the footer (a dozen widgets mounted and styled) whenever the focus
        # moves, most often to keys it already shows: recompose once a refresh, and only for new keys
        self._bindings_ready = True
        if screen.app.app_focus and self.is_attached and screen is self.screen and not self._check_queued:
            self._check_queued = True
            self.call_after_refresh(self._recompose_if_new)

    async def _recompose_if_new(self) -> None:
        self._check_queued = False
        if self.is_attached and self._keys_shown() != self._drawn:
            await self.recompose()

    def on_resize(self, event: events.Resize) -> None:
        if event.size.width != self._fitted_to:
            self.call_after_refresh(self.recompose)


def drawn_width(keys, compact: bool) -> int:
    """The columns ``keys`` take in a row: a key and its description, with Textual's padding
    (one column each side of the key, one after the description) or, compact, a space between
    them and one after (a key without a description: the key, and compact, a space after it)."""
    if compact:
        return sum(cell_len(key.key_display) + (cell_len(key.description) + 1 if key.description else 0) + 1 for key in keys)
    return sum(cell_len(key.key_display) + (cell_len(key.description) + 3 if key.description else 0) for key in keys)
