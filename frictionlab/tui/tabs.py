"""Switching tabs: F2..F5 (or 2..5) and a tab clicked with the mouse (``FrictionlabApp``'s, a mixin)."""

from __future__ import annotations

import contextlib

from textual.css.query import NoMatches
from textual.widgets import TabbedContent, TabPane

FOCUS = {"presets": "#preset-table", "edit": "#form", "run": "#run-pane", "results": "#runs-table"}


class Tabs(TabbedContent):
    """Textual's tabs, where a widget focused in a pane shows that pane only while it still has
    the focus: Esc in a field then Ctrl+R typed fast focused the form, then showed the Run tab,
    and the form's late message took the screen back to the Edit tab."""

    def _on_tab_pane_focused(self, event: TabPane.Focused) -> None:
        focused = self.screen.focused
        if focused is not None and event.tab_pane not in focused.ancestors_with_self:
            event.prevent_default()  # the focus has moved on since: Textual's handler leaves the tab shown since


class TabSwitching:
    """Each tab shown gives the keys to its part: a list, the form (not a field, so a listed
    key never types into the preset), the Run pane."""

    def action_show_tab(self, tab: str) -> None:
        self.query_one("#tabs", TabbedContent).active = tab
        self._focus_tab(tab)
        self.call_after_refresh(self.refresh_bindings)  # the footer, for the part now focused

    def _focus_tab(self, tab: str) -> None:
        with contextlib.suppress(NoMatches):  # a pane not mounted yet (a tab clicked as the app starts)
            widget = self.query_one(FOCUS[tab])
            widget.screen.set_focus(widget)  # now: the Focused message of the tab left is then out of date

    def on_tabbed_content_tab_activated(self, event: TabbedContent.TabActivated) -> None:
        if not self.screen_stack:  # not once the app has closed (a late message)
            return
        # a tab clicked with the mouse left the focus in the tab it hid (nowhere, so Enter did nothing
        # on the list shown): its part takes the keys, as F2..F5 give them (not for a tab since left:
        # the first tab's message comes after a preset given on the command line is open)
        focused, pane = self.focused, event.pane
        shown = pane.id == event.tabbed_content.active and self.screen is pane.screen
        if shown and (focused is None or pane not in focused.ancestors):
            self._focus_tab(pane.id)
        self.refresh_bindings()
