"""A key the footer hides where it cannot act (``check_action``) is still caught: its action
runs anyway and says in the status line why it cannot act, never a key that does nothing."""

from __future__ import annotations

from textual.binding import Binding


def said_when_hidden(*pairs: tuple[str, str], priority: bool = False) -> list[Binding]:
    """Unlisted bindings of each ``(key, action)`` to ``unavailable(action)``, for the keys whose
    listed binding ``check_action`` hides."""
    return [Binding(key, f"unavailable('{action}')", show=False, system=True, priority=priority) for key, action in pairs]


SIDEWAYS = frozenset({"scroll_left", "scroll_right", "page_left", "page_right", "cursor_left", "cursor_right"})


def idle_sideways(widget, action: str) -> bool:
    """Whether ``action`` would move ``widget`` sideways where it fits its width: F1 listed Left,
    Right, Ctrl+PgUp and Ctrl+PgDn there, and they did nothing (narrow, a list scrolls to its a, b)."""
    return action in SIDEWAYS and widget.max_scroll_x == 0


class SaysWhyUnavailable:
    """``action_unavailable`` for an app or widget with ``said_when_hidden`` bindings."""

    def action_unavailable(self, action: str) -> None:
        """A key pressed where its action cannot act: the action runs anyway, to say why."""
        getattr(self, f"action_{action}")()
