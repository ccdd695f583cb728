"""Keys that move the focus act before the next key is handed on.

Textual hands a key to the focused widget and runs a binding of a widget above it (Tab's
focus_next, the form's Enter and Esc) only once the key has bubbled back up, one message
queue at a time; keys typed meanwhile (fast typing, or the keys held while the app was
built) are handed to the widget focused before. Tab then ``abc`` lost the letters on the
form, and Esc then ``q`` in a field typed the q there, though q quits outside a field.
Such a key's binding is run here, at once, in the app's queue, so each key after it goes
where the focus now is. A list's cursor keys are run at once too: n and d (run at once) read the
highlighted row, and Down Down d typed fast duplicated the row the cursor was on before the arrows.

Esc then a key within the terminal's escape delay (0.1 s: a fast typist, or keystrokes that
SSH sends joined) reaches the app as one Alt+key, and a field typed its letter: this app
binds no Alt key, so such a key is read as the two keys typed. Esc joined to a control key
(Ctrl+S, Ctrl+R, Enter) lost the Esc in Textual's parser itself: ``keep_escape_before_control_keys``;
an ESC inside a paste made the rest of it keys: ``paste_keeps_escapes``.
"""

from __future__ import annotations

from textual import events
from textual.widgets import DataTable, Input, Select, Switch

# the actions that only move the focus, or open a dialog (which holds the keys after it until its field
# has the focus): run at once, they change nothing else than Textual's own order would
FOCUS_ACTIONS = frozenset(
    {"app.focus_next", "app.focus_previous", "focus_next", "focus_previous", "edit_field", "leave_field", "new", "duplicate",
     "arrow(1)", "arrow(-1)",  # the form's Up and Down: a field's neighbour (a line of scroll on the form itself)
     # q, and the digits that switch tabs (as F2..F5 do, at once): q then n on the Presets list opened New, not quit
     "quit", "show_tab('presets')", "show_tab('edit')", "show_tab('run')", "show_tab('results')"}
)

# a list's own cursor moves: nothing else handles these keys on a list, so at once is Textual's order
LIST_CURSOR_ACTIONS = frozenset(
    {"cursor_up", "cursor_down", "page_up", "page_down", "scroll_home", "scroll_end", "scroll_top", "scroll_bottom"}
)


def unjoined(key: events.Key) -> list[events.Key]:
    """``key``, or Esc and the key typed after it where the terminal joined them as Alt+key."""
    if key.key.startswith("alt+") and key.character is not None and len(key.character) == 1:
        return [events.Key("escape", "\x1b"), events.Key(key.key.removeprefix("alt+"), key.character)]
    return [key]


async def answer_focus_key(app, key: events.Key) -> bool:
    """Run ``key``'s binding now if the binding it would reach (the first from the focused
    widget up) moves the focus, opens a dialog or moves a list's cursor; True if it did. A printable key is the
    focused text field's (n and d open dialogs from the Presets list)."""
    if key.is_forwarded or (key.is_printable and _in_a_field(app.focused)):
        return False
    for namespace, bindings in app.screen._modal_binding_chain:
        for binding in bindings.key_to_bindings.get(key.key, ()):
            if binding.priority:
                continue  # the app ran those before
            if isinstance(namespace, Input) and binding.action in ("scroll_up", "scroll_down"):
                continue  # a field of one line scrolls nothing: the key is the form's (or a dialog's)
            moves_cursor = isinstance(namespace, DataTable) and binding.action in LIST_CURSOR_ACTIONS
            if binding.action not in FOCUS_ACTIONS and not moves_cursor:
                return False  # another binding comes first: Textual's order
            return await app.run_action(binding.action, namespace)
    return False


def _in_a_field(widget) -> bool:
    """Whether ``widget`` is a field, whose printable keys are never the app's: a text field, or a
    choice or switch of the preset form (q there quit at once, the footer saying "Leave field")."""
    from .widgets.form import PresetForm

    return isinstance(widget, Input) or (isinstance(widget, Select | Switch)
                                         and any(isinstance(a, PresetForm) for a in widget.ancestors))  # fmt: skip


def _xterm_parser():
    """Textual's terminal parser, or None: a private part of Textual, which a later Textual may
    not have (its keys and pastes are then read as that Textual reads them)."""
    try:
        from textual._xterm_parser import XTermParser
    except ImportError:
        return None
    return XTermParser


def keep_escape_before_control_keys() -> None:
    """Esc then a control key, joined by the terminal (as above; on a busy machine keys typed
    0.15 s apart are read together), reached the app as the control key alone: Textual's
    parser reads ESC and a control character as Alt+key and drops the Alt of a control key
    (ESC Ctrl+S is Ctrl+S), so Esc then Ctrl+S in a field saved and stayed in it. The parser
    hands the Esc on first instead. The sequences Textual maps whole (ESC Tab: Shift+Tab,
    ESC Backspace: Ctrl+W) are not this path and stay as they are."""
    XTermParser = _xterm_parser()
    parse = getattr(XTermParser, "_sequence_to_key_events", None)
    if parse is None or getattr(parse, "keeps_escape", False):
        return

    def sequence_to_key_events(self, sequence: str, alt: bool = False):
        for key in parse(self, sequence, alt):
            if alt and key.key != "escape" and not key.key.startswith("alt+"):
                yield events.Key("escape", "\x1b")  # the Esc the Alt stood for
            yield key

    sequence_to_key_events.keeps_escape = True
    XTermParser._sequence_to_key_events = sequence_to_key_events


PASTE_START, PASTE_END = "\x1b[200~", "\x1b[201~"
PASTED_ESC = "\ufdd0"  # a noncharacter: stands for an ESC inside a paste until the paste is whole


def paste_keeps_escapes() -> None:
    """An ESC inside a paste (text copied with its colour codes) ended the paste there for
    Textual's parser: the paste stopped at it and the rest arrived as keys before it, typed
    (``^[31m``), or acting where no field has the focus (q quits, c cancels a run). The
    parser is handed such an ESC as a stand-in character, given back in the paste's text
    (where the field leaves it out, saying so)."""
    XTermParser = _xterm_parser()
    feed = getattr(XTermParser, "feed", None)
    if feed is None or getattr(feed, "keeps_pasted_escapes", False):
        return

    def feed_pastes_whole(self, data: str):
        text = _escapes_in_pastes_replaced(self, data)
        chunks = [text] if text else []  # never "" for a read all held: "" is the input's end
        if not data:
            chunks.append("")  # the end, after what was held
        for chunk in chunks:
            for token in feed(self, chunk):
                if isinstance(token, events.Paste):
                    token.text = token.text.replace(PASTED_ESC, "\x1b")
                yield token

    feed_pastes_whole.keeps_pasted_escapes = True
    XTermParser.feed = feed_pastes_whole


def _escapes_in_pastes_replaced(parser, data: str) -> str:
    """``data`` with each ESC inside a paste but the one of its end marker as ``PASTED_ESC``;
    what may begin the end marker at the end of ``data`` is held for the next read (``""``: the end)."""
    text = getattr(parser, "_held_in_paste", "") + data
    pasting, recent = getattr(parser, "_pasting", False), getattr(parser, "_recent", "")
    out: list[str] = []
    at = 0
    while at < len(text):
        rest = text[at : at + len(PASTE_END)]
        if pasting and text[at] == "\x1b" and rest != PASTE_END:
            if data and PASTE_END.startswith(rest) and at + len(rest) == len(text):
                break  # the marker may go on in the next read
            out.append(PASTED_ESC)
            at += 1
            continue
        if pasting and rest == PASTE_END:
            out.append(rest)
            at += len(rest)
            pasting, recent = False, ""
            continue
        out.append(text[at])
        recent = (recent + text[at])[-len(PASTE_START) :]
        pasting = pasting or recent == PASTE_START
        at += 1
    parser._held_in_paste, parser._pasting, parser._recent = text[at:], pasting, recent
    return "".join(out)
