"""A text input whose editing keys act in the order they were typed."""

from __future__ import annotations

import re
from collections.abc import Callable

from textual import events
from textual.binding import Binding
from textual.message import Message
from textual.widgets import Input

from ...errors import shown

# what a paste may bring that a field must not hold: C0 controls, DEL and C1 (an ESC, a BEL, a
# terminal's colour codes copied along) are no text, and a YAML file cannot hold them raw
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f]")


def pasted_text(text: str) -> tuple[str, list[str]]:
    """A paste as a one-line field takes it: its lines and tabs joined by spaces, its other
    control characters left out; and those left out, as ``shown`` writes them (``\\x1b``)."""
    lines = [line.strip() for line in text.splitlines()]
    joined = " ".join(line for line in lines if line) if len(lines) > 1 else text
    joined = joined.replace("\t", " ")
    dropped = sorted({shown(c) for c in _CONTROL.findall(joined)})
    return _CONTROL.sub("", joined), dropped


LINES_KEYS = ("up", "down")  # Input's own bindings scroll it by lines, and it has one


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

    class LeftOut(Message):
        """A paste's control characters were left out; ``text`` says which, naming the field (the
        app says it in the status line, a dialog, which may cover that line at 30x8, in its own)."""

        def __init__(self, text: str):
            super().__init__()
            self.text = text

    async def _on_key(self, event: events.Key) -> None:
        self.typed = True
        bindings = self._bindings.key_to_bindings.get(event.key)
        if event.key in LINES_KEYS:  # a field of one line scrolls no lines: the form's or the dialog's Up/Down act
            bindings = None
        if bindings and not event.is_printable:
            event.stop()
            event.prevent_default()
            await self.run_action(bindings[0].action)
            return
        await super()._on_key(event)

    def _on_paste(self, event: events.Paste) -> None:
        """Input's own kept a paste's first line only (the rest dropped unsaid) and its control
        characters raw, saved so into the preset: a paragraph is joined, the controls left out, said."""
        self.typed = True
        event.prevent_default()
        event.stop()
        text, dropped = pasted_text(event.text)
        if text:
            if self.selection.is_empty:
                self.insert_text_at_cursor(text)
            else:
                self.replace(text, *self.selection)
        if dropped:  # after the Changed the insertion posted: a dialog clears its error line on that
            self.post_message(self.LeftOut(f"{self.name or self.id or 'field'}: the paste's control characters "
                                           f"{', '.join(dropped)} were left out (a field holds text only)"))  # fmt: skip

    def action_copy(self) -> None:
        """Ctrl+C copies here, and says (as it does elsewhere) what quits."""
        try:
            super().action_copy()  # SkipAction when nothing is selected
        finally:
            say_quit = getattr(self.app, "action_help_quit", None)
            if say_quit is not None:
                say_quit(in_field=True)


class FieldInput(KeyInput):
    """A text field of the preset form. Enter leaves it, back to the form, as Esc does: Input's
    own Enter (Submit, so F1 listed it) did nothing there. Up and Down go to the field above or
    below (the form's keys), which F1 listed as a scroll of this one-line field."""

    def __init__(self, *args, leave: Callable[[], None], **kwargs):
        super().__init__(*args, **kwargs)
        self._leave = leave  # the form's Esc: back to the form
        self._bindings = self._bindings.copy()  # this field's, not every Input's
        keys = self._bindings.key_to_bindings
        # F1 lists them; the footer keeps Esc's Leave field, as before
        keys["enter"] = [Binding("enter", "leave_field", "Done", tooltip="leave the field (back to the form), as Esc", show=False)]
        keys["down"] = [Binding("down", "app.focus_next", "Field below", tooltip="as Tab", show=False)]
        keys["up"] = [Binding("up", "app.focus_previous", "Field above", tooltip="as Shift+Tab", show=False)]

    def action_leave_field(self) -> None:
        self._leave()
