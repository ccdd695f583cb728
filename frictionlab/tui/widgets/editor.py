"""The Edit tab: the preset form with the draft's name and state, the focused field's
help, and the headless validator's problems."""

from __future__ import annotations

from pathlib import Path

from textual.app import ComposeResult
from textual.containers import Vertical, VerticalScroll
from textual.content import Content
from textual.widgets import Static

from ...errors import shown
from .form import PresetForm, flow_text
from .pathline import PathLine


FORM_HINT = "Enter or Tab: into the fields (Esc comes back out); arrows scroll; q quits"


class EditPane(Vertical):
    def __init__(self, registry, **kwargs):
        super().__init__(**kwargs)
        self.registry = registry
        self._shown: tuple[list[str], str] | None = None  # the problems the panel shows, and what was read

    def compose(self) -> ComposeResult:
        yield PathLine(id="edit-title")
        yield PresetForm(self.registry, id="form")
        yield Static("", id="field-help")
        with VerticalScroll(id="problems-box", can_focus=False):
            yield Static("", id="problems")

    def show_title(self, path: Path | None, modified: bool, problems: list[str]) -> None:
        title = self.query_one("#edit-title", PathLine)
        if path is None:
            title.show("No preset open")
            return
        state = "modified" if modified else "saved"
        count = f", {len(problems)} problem{'s' if len(problems) != 1 else ''}" if problems else ""
        title.show("", str(path), f"  ({state}{count})")

    def show_problems(self, problems: list[str], read: str = "") -> None:
        """The validator's problems, or that the draft is valid with what it read from a file."""
        if (problems, read) == self._shown:
            return  # unchanged: no new layout for a keystroke that changes nothing here
        self._shown = (list(problems), read)
        panel = self.query_one("#problems", Static)
        if problems:
            count = len(problems)
            head = (f"{count} problem{'s' if count != 1 else ''}", "bold")
            panel.update(Content.assemble(head, " (as frictionlab validate says):\n", "\n".join(problems)))
            panel.set_class(True, "-invalid")
        else:
            # text, never markup: what was read names the file ('[b]scan.npy' lost its '[b]')
            panel.update(Content(shown("valid: Ctrl+R runs it, Ctrl+S saves it" + (f"\n{read}" if read else ""))))
            panel.set_class(False, "-invalid")

    def on_preset_form_field_focused(self, event: PresetForm.FieldFocused) -> None:
        spec = event.spec
        form = self.query_one(PresetForm)
        if spec is not None:
            text = f"{spec.dotted}: {spec.help_line()}"
            if spec.dotted in form.swept:
                text = f"{spec.dotted} is swept ({flow_text(form.swept[spec.dotted])}): this value is only the base; {spec.help_line()}"
        elif form.has_focus and form.data is not None:
            text = FORM_HINT
        else:
            text = ""
        self.query_one("#field-help", Static).update(Content(text))
