"""The keys panel and the quit hint: the app's actions that show what the keys are
(``FrictionlabApp``'s, a mixin)."""

from __future__ import annotations

from textual.actions import SkipAction


class KeysHelp:
    """F1, ``?``, Esc on the keys panel, and Ctrl+C's hint (``FrictionlabApp``'s)."""

    def action_help(self) -> None:
        """Textual's key panel: the keys of the focused widget and of the app, as they change.
        Pressed again it shows the next page of a panel taller than the screen (it takes no
        focus, so no other key scrolls it), and hides it after the last."""
        panels = self.screen.query("HelpPanel KeyPanel")
        if not panels:
            self.action_show_help_panel()
            return
        keys = panels.first()
        if keys.scroll_y < keys.max_scroll_y:
            keys.scroll_page_down(animate=False)
        else:
            self.action_hide_help_panel()

    def action_show_help_panel(self) -> None:
        """Textual's panel, with a line on top that says how to close it."""
        from .widgets import KeysPanel

        if not self.screen.query("HelpPanel"):
            self.screen.mount(KeysPanel())

    def action_toggle_keys(self) -> None:
        """? shows the key panel, or hides it (F1 pages through it)."""
        if self.screen.query("HelpPanel"):
            self.action_hide_help_panel()
        else:
            self.action_show_help_panel()

    def esc_closed_keys(self, key) -> bool:
        """Esc with the panel up closes it, before the focused part's own Esc (a sweep's points went
        back to the runs, the panel left up; a dialog's Esc closed both); a field's Esc, run
        before, leaves the field first."""
        if key.key != "escape" or not self.screen.query("HelpPanel"):
            return False
        self.action_hide_help_panel()
        return True

    def action_hide_keys(self) -> None:
        if self.screen.query("HelpPanel"):
            self.action_hide_help_panel()
        else:
            raise SkipAction()  # Esc means nothing here: another part may take it

    def action_cancel_where(self) -> None:
        """c outside the Run tab (whose own c cancels) and a text field: while a run goes, say where
        it cancels (pressed on the Edit tab, say, it did nothing, unsaid)."""
        if self.running and not self.followed.ended:
            self.say("c cancels the run on the Run tab (F4), where it shows; here it does nothing.", "warning")

    def action_help_quit(self, in_field: bool = False) -> None:
        """Ctrl+C (copy, in a text field) does not quit: where the status line says what does."""
        where = "Ctrl+C copies in a text field. " if in_field else ""
        if self.running and not self.followed.ended:  # Ctrl+C stops a program in a shell: say what stops this run
            where += "Ctrl+C does not stop the run: c on the Run tab (F4) cancels it, keeping what finished. "
        self.say(f"{where}Ctrl+Q quits (q too, outside a text field: Esc leaves one); "
                 "a run goes on after you quit unless you cancel it.")  # fmt: skip
