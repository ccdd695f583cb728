"""A text input whose editing keys act in the order they were typed."""

from __future__ import annotations

from textual import events
from textual.widgets import Input


class KeyInput(Input):
    """An ``Input`` that runs its own key bindings (Ctrl+U, Home, Ctrl+W, ...) at once.

    Textual runs a widget's bindings only after the key has bubbled up to the app,
    one message queue at a time, while a printable key is inserted where it lands.
    Keys a terminal delivers together (fast typing) then act out of order: ``Ctrl+U``
    followed by ``123`` inserted 123 and then cleared it with the late Ctrl+U, and
    ``Home 7`` put the 7 at the end. Run here, a binding acts before the next key.

    ``typed`` says a key or a paste reached it: its Changed is then the user's edit, even where
    the focus has moved on meanwhile (Tab typed just after runs first), and never the one
    mounting it posts.
    """

    typed = False

    async def _on_key(self, event: events.Key) -> None:
        self.typed = True
        bindings = self._bindings.key_to_bindings.get(event.key)
        if bindings and not event.is_printable:
            event.stop()
            event.prevent_default()
            await self.run_action(bindings[0].action)
            return
        await super()._on_key(event)

    def _on_paste(self, event: events.Paste) -> None:
        self.typed = True  # Textual then calls Input's own, which pastes
        lines = event.text.splitlines()
        if len(lines) > 1:  # Input's own keeps the first line, the rest dropped unsaid: a paragraph, joined
            event.prevent_default()
            event.stop()
            text = " ".join(line.strip() for line in lines if line.strip())
            if self.selection.is_empty:
                self.insert_text_at_cursor(text)
            else:
                self.replace(text, *self.selection)

    def action_copy(self) -> None:
        """Ctrl+C copies here, and says (as it does elsewhere) what quits."""
        try:
            super().action_copy()  # SkipAction when nothing is selected
        finally:
            say_quit = getattr(self.app, "action_help_quit", None)
            if say_quit is not None:
                say_quit(in_field=True)
