"""Small modal dialogs: confirm, ask for a path (save as, duplicate), a new preset."""

from __future__ import annotations

import re
from pathlib import Path

from textual import events
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.content import Content
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, Select, Static

from ...errors import shown, shown_name
from ...io.inputs import expand_user
from ...preset.problems import shown_value
from ...preset.schema import NAME_PATTERN, NAME_RULE
from ..folders import is_builtin, made_when_saved, new_preset_path
from ..widgets.footer import KeysFooter
from ..widgets.keyinput import KeyInput


WAIT_FOR_DIALOG = "A dialog is open: {answers}; then Ctrl+S, Ctrl+O, Ctrl+R and F2 to F5 act."
WAITING_KEYS = frozenset({"ctrl+s", "ctrl+o", "ctrl+r", "f2", "f3", "f4", "f5"})  # the app's keys that pass a dialog


class Dialog(ModalScreen):
    """A modal dialog with a footer of its own: the one behind lists the keys of the screen
    behind (Open, Duplicate, New), none of which acts while the dialog is up.

    Keys typed before it is mounted (n then a name, read together) wait for it (``hold``): they
    went to the screen, no field of it focused yet, and were lost. They are answered in the app's
    queue, in the order typed, once its first field has the focus.

    Taller than the screen (30x8), it scrolls with the arrows: nothing in it takes them, and its
    answers (the hint, last) were out of reach below the screen's edge."""

    BINDINGS = [
        Binding("down", "scroll_dialog(1)", show=False),
        Binding("up", "scroll_dialog(-1)", show=False),
        Binding("pagedown", "scroll_dialog(5)", show=False),
        Binding("pageup", "scroll_dialog(-5)", show=False),
    ]

    ANSWERS = "Enter answers it, Esc closes it"  # the keys that answer it, as the status line says them

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._held: list[events.Key] | None = []  # None once the keys held are answered

    @property
    def waiting(self) -> str:
        """What the status line says of a key that waits for the dialog to close."""
        return WAIT_FOR_DIALOG.format(answers=self.ANSWERS)

    @property
    def answered_by(self) -> str:
        """What Enter on a question that Enter does not answer (y or n) says."""
        return f"This question is answered by its keys: {self.ANSWERS}."

    def action_say_answers(self) -> None:
        self.app.say(self.answered_by, "warning")

    def hold(self, key: events.Key) -> bool:
        """Keep ``key`` for the dialog until it is mounted; False once it takes keys itself."""
        if self._held is None:
            return False
        self._held.append(key)
        return True

    def on_mount(self) -> None:
        self.app.call_later(self._answer_held)  # after the keys the app's queue holds now

    async def _answer_held(self) -> None:
        held, self._held = self._held, None
        for key in held or ():
            await self.app.on_event(key)

    def answers_first(self, key: events.Key) -> bool:
        """Whether the dialog answers ``key`` itself, before any binding: Ctrl+S, Ctrl+O, Ctrl+R and
        F2 to F5 wait for it to close, and say so (each opened another dialog over it, ran the
        preset, or switched the tab behind it, the dialog left up over another tab).
        (Esc closes the keys panel over it first: ``KeysHelp.esc_closed_keys``.)"""
        if key.key in WAITING_KEYS:
            self.app.say(self.waiting, "warning")
            return True
        return False

    def on_unmount(self) -> None:
        status = self.app.query("#status")
        if status and str(status.first().render()) in (self.waiting, self.answered_by):
            self.app.say("")  # the dialog is closed: those keys act again

    def on_key_input_left_out(self, event: KeyInput.LeftOut) -> None:
        """What a paste left out, in the dialog's error line: the status line may be under it (30x8)."""
        event.stop()  # it comes after the Changed the paste posted, which clears that line
        show_error(self.query_one(".field-error", Static), event.text)

    def action_scroll_dialog(self, lines: int) -> None:
        self.query_one(".dialog").scroll_relative(y=lines, animate=False)

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog"):
            yield from self.body()
        yield KeysFooter()  # its keys drawn closer together where the width is short

    def body(self) -> ComposeResult:
        raise NotImplementedError


class SubmitInput(KeyInput):
    """A dialog's text field whose Enter the footer lists, as what it does (``submit``):
    a field's own Enter binding is hidden, and it comes before the dialog's in the footer."""

    def __init__(self, value: str, submit: str, **kwargs):
        super().__init__(value, **kwargs)
        self._bindings = self._bindings.copy()  # this field's, not every Input's
        self._bindings.key_to_bindings["enter"] = [Binding("enter", "submit", submit, key_display="⏎")]


class ConfirmScreen(Dialog, ModalScreen[bool]):
    ANSWERS = "y answers yes, n or Esc no"
    BINDINGS = [
        Binding("y", "answer(True)", "Yes"),
        Binding("n,escape", "answer(False)", "No"),
        Binding("enter", "say_answers", show=False),  # it did nothing, unsaid: never a yes (a discard) by habit
    ]

    def __init__(self, question: str):
        super().__init__()
        self.question = question

    def body(self) -> ComposeResult:
        yield Static(Content(shown(self.question)))  # it quotes problems and paths: text, never markup nor escape codes
        yield Label("y: yes    n / Esc: no", classes="hint")

    def action_answer(self, value: bool) -> None:
        self.dismiss(value)


class QuitUnsavedScreen(ConfirmScreen):
    """Quit with unsaved changes? (A screen of its own kind: Ctrl+Q again while it is up asks nothing more.)"""

    def __init__(self):
        super().__init__("The open preset has unsaved changes. Quit anyway?")


class QuitRunEndedScreen(ConfirmScreen):
    """Quit? asked again when the run ended while ``QuitDuringRunScreen`` was up: its question
    still said the run was going, l and c to leave running or cancel what had ended."""


class QuitDuringRunScreen(Dialog, ModalScreen[str | None]):
    """Quit while a run goes on: leave it running ("leave"), cancel it ("cancel"), or stay (None)."""

    ANSWERS = "l leaves the run going and quits, c cancels it and quits, Esc stays"
    BINDINGS = [
        Binding("l", "answer('leave')", "Leave it running"),
        Binding("c", "answer('cancel')", "Cancel it"),
        Binding("escape,n", "answer(None)", "Stay"),
        Binding("enter", "say_answers", show=False),
    ]

    def __init__(self, question: str):
        super().__init__()
        self.question = question

    def body(self) -> ComposeResult:
        yield Static(Content(shown(self.question)))
        yield Label("l: leave it running and quit    c: cancel it and quit    Esc: stay", classes="hint")

    def action_answer(self, value: str | None) -> None:
        self.dismiss(value)


def preset_path_problem(text: str, folder: Path | None = None) -> tuple[Path | None, str]:
    """The path a user typed for a preset (``.yaml`` added), or why it cannot be one;
    ``folder`` (the presets folder) and the user folder, made when first saved into, need not exist yet."""
    text = text.strip()
    if not text:
        return None, "path: must not be empty"
    try:
        path = Path(expand_user(text))
    except ValueError as exc:  # ~user of no user here
        return None, f"path: {exc}"
    try:
        return _checked_path(path, folder)
    except (OSError, ValueError) as exc:  # a name past the system's limits, a folder not to be read: no traceback
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        return None, f"path: {shown_value(text)} cannot be a file here ({reason}); give another"


def _checked_path(path: Path, folder: Path | None) -> tuple[Path | None, str]:
    if path.is_dir():  # before .yaml is added: a folder typed was saved as <folder>.yaml beside it
        return None, f"path: {shown_name(path)} is a folder; give a file name"
    if path.suffix not in (".yaml", ".yml"):
        path = path.with_name(path.name + ".yaml")
    if path.is_dir():
        return None, f"path: {shown_name(path)} is a folder; give a file name"
    if not path.parent.is_dir() and not (folder is not None and made_when_saved(path.parent, folder)):
        return None, f"path: the folder {shown_name(path.parent)} does not exist"
    if is_builtin(path):  # shipped with frictionlab: read and copied, never replaced
        return None, f"path: {shown_name(path)} is a built-in preset, never written; give a file of your own"
    return path, ""


def show_error(line: Static, text: str) -> None:
    """A dialog's error line (hidden, as the form's are, until it has something to say)."""
    line.update(Content(text))
    line.display = bool(text)


class PathScreen(Dialog, ModalScreen[Path | None]):
    """Ask for a file path (save as, duplicate); replacing a file asks a second Enter."""

    BINDINGS = [Binding("escape", "dismiss(None)", "Cancel")]

    def __init__(self, title: str, default: Path, folder: Path | None = None):
        super().__init__()
        self.title_text = title
        self.default = default
        self.folder = folder  # the presets folder: made on saving if it does not exist yet
        self.confirmed: Path | None = None  # an existing file the user pressed Enter on once

    def body(self) -> ComposeResult:
        yield Label(Content(shown(self.title_text)), classes="heading")
        yield SubmitInput(str(self.default), "Save", name="path", id="path-input")
        yield Static("", id="path-error", classes="field-error")
        yield Label("Enter: save    Esc: cancel", classes="hint")

    def on_input_changed(self, event: Input.Changed) -> None:
        """Another file typed: what was said of the one before (it exists, Enter again replaces it) is taken back."""
        if self.query_one("#path-error", Static).display:
            self.confirmed = None
            show_error(self.query_one("#path-error", Static), "")

    def on_input_submitted(self, event: Input.Submitted) -> None:
        path, problem = preset_path_problem(event.value, self.folder)
        error = self.query_one("#path-error", Static)
        if path is None:
            show_error(error, problem)
            return
        if path.exists() and path != self.confirmed:
            self.confirmed = path
            show_error(error, f"{shown_name(path)} exists: Enter again replaces it, Esc keeps it")
            return
        self.dismiss(path)


class NewPresetScreen(Dialog, ModalScreen[tuple[str, Path | None, Path] | None]):
    """A new preset: its name, the preset it starts from (one that runs), and where it
    is saved (the presets folder the list shows unless the user says otherwise)."""

    BINDINGS = [Binding("escape", "dismiss(None)", "Cancel")]

    def __init__(self, templates: list[tuple[str, Path]], folder: Path):
        super().__init__()
        self.templates = templates
        self.folder = folder
        self.path_edited = False  # the file follows the name until the user types a path

    def body(self) -> ComposeResult:
        yield Label("New preset", classes="heading")
        with Horizontal(classes="row"):
            yield Label("name", classes="field-label")
            yield SubmitInput("my-scene", "Create", name="name", id="new-name", compact=True)
        with Horizontal(classes="row"):
            yield Label("start from", classes="field-label")
            if self.templates:
                yield Select(
                    [(Content(label), path) for label, path in self.templates],
                    value=self.templates[0][1], allow_blank=False, compact=True, id="new-template",
                )
            else:
                yield Static("a plugin's defaults (no preset listed to start from)", id="new-template")
        with Horizontal(classes="row"):
            yield Label("save as", classes="field-label")
            default = str(new_preset_path("my-scene", self.folder))
            yield SubmitInput(default, "Create", name="path", id="new-path", compact=True)
        yield Static("", id="new-error", classes="field-error")
        yield Button("Create", id="new-create", compact=True)
        yield Label("Tab: next field    Enter: create    Esc: cancel", classes="hint")

    def on_input_changed(self, event: Input.Changed) -> None:
        if event.input.id == "new-name" or event.input.has_focus:  # not the file following the name
            show_error(self.query_one("#new-error", Static), "")  # it quoted what was typed before
        if event.input.id == "new-name" and not self.path_edited:
            name = event.value.strip() or "my-scene"
            self.query_one("#new-path", Input).value = str(new_preset_path(name, self.folder))
        elif event.input.id == "new-path" and event.input.has_focus:
            self.path_edited = True

    def _create(self) -> None:
        error = self.query_one("#new-error", Static)
        name = self.query_one("#new-name", Input).value.strip()
        if not name:
            show_error(error, "name: must not be empty")
            return
        if not re.fullmatch(NAME_PATTERN, name):  # as the form would say at once, and Ctrl+R refuse
            show_error(error, f"name: {NAME_RULE}, got {shown_value(name)}")
            return
        path, problem = preset_path_problem(self.query_one("#new-path", Input).value, self.folder)
        if path is None:
            show_error(error, problem)
            return
        if path.exists():
            show_error(error, f"{shown_name(path)} exists: give another file (a new preset never replaces one)")
            return
        template = self.query_one("#new-template", Select).value if self.templates else None
        self.dismiss((name, template, path))

    def on_input_submitted(self, event: Input.Submitted) -> None:
        self._create()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        self._create()
