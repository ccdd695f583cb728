"""The preset edit form, built from the models: ``Preset`` for the scene and
each plugin's ``Params`` for its section. Numbers become inputs checked by the
headless validator (so the message is the same text ``frictionlab validate``
prints), literals become selects, booleans switches. Choosing another plugin
swaps its parameter section; the old plugin's values are kept in case the
user switches back."""

from __future__ import annotations

import copy
from pathlib import Path

import yaml
from textual.actions import SkipAction
from textual.binding import Binding
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.content import Content
from textual.message import Message
from textual.widget import Widget
from textual.widgets import Input, Label, Select, Static, Switch

from ...errors import shown
from ...plugin import KINDS
from ...preset import MISSING, Preset, get_path, set_path
from ..fields import (FieldSpec, default_plugin_name, display, field_specs, parse, problem_path, problems_for,
                      shared_params, validation_of)  # fmt: skip
from ..hiddenkeys import idle_sideways
from .keyinput import FieldInput


def flow_text(value) -> str:
    text = yaml.safe_dump(value, default_flow_style=True, width=10_000).strip()
    return text if len(text) <= 400 else text[:397] + "..."  # wrapped on the form: a sweep's values whole


def _section_id(path: tuple[str, ...]) -> str:
    return "section--" + "--".join(path)


class FieldSelect(Select):
    """A choice of the form: Enter or Space opens its list; Up and Down go to the field above or
    below, as in a text field (Textual's opened the list: Down through the form stopped there)."""

    BINDINGS = [
        Binding("down", "app.focus_next", "Field below", show=False),
        Binding("up", "app.focus_previous", "Field above", show=False),
    ]


class PresetForm(VerticalScroll):
    """Edits ``data`` (the preset as a plain mapping, unknown sections kept).

    A preset opens with the form itself focused, not a field: the app's keys (``q``
    quits) act there, and typing never edits the preset by surprise. Enter (or Tab)
    goes into the fields, Esc leaves one."""

    BINDINGS = [
        Binding("enter", "edit_field", "Edit", tooltip="the fields: Enter or Tab goes in, Esc comes back out"),
        Binding("escape", "leave_field", "Leave field", tooltip="(back to the form: q, ? and the app's keys act again)"),
        # in a field Down scrolled the form a line under the cursor, which stayed where it was
        Binding("down", "arrow(1)", "Scroll Down", tooltip="(the form; in a field: the field below, as Tab)", show=False),
        Binding("up", "arrow(-1)", "Scroll Up", tooltip="(the form; in a field: the field above, as Shift+Tab)", show=False),
    ]

    class Edited(Message):
        """The draft changed (or was loaded): ``problems`` is the headless list; ``read``,
        what a valid draft's spectrum read from its file ("" when none)."""

        def __init__(self, problems: list[str], changed: bool, read: str = "", data: dict | None = None):
            super().__init__()
            self.problems = problems
            self.changed = changed
            self.read = read
            self.data = data  # the draft (the form's, not a copy): compared with the preset's file

    class FieldFocused(Message):
        def __init__(self, spec: FieldSpec | None):
            super().__init__()
            self.spec = spec

    def __init__(self, registry, **kwargs):
        super().__init__(**kwargs)
        self.registry = registry
        self.data: dict | None = None
        self._loaded: dict = {}  # the preset as opened: what its file leaves unsaid
        self.base_dir: Path | None = None  # the preset file's folder: relative input files are taken from it
        self.problems: list[str] = []
        self._specs: dict[str, FieldSpec] = {}
        self._stash: dict[tuple[str, str], dict] = {}  # (slot, plugin) -> params left behind
        # the value each select or switch shows: Textual also posts Changed when one is mounted
        self._seen: dict[str, object] = {}
        self._marked: dict[str, list[str]] = {}  # widget id -> the messages shown under it
        self._last_field: Widget | None = None  # the field Enter goes back into

    def watch_has_focus(self, _has_focus: bool) -> None:
        # Textual restyles a widget and every widget in it when its focus changes; no rule
        # styles a field by the form's focus, so the form alone is restyled, not its hundreds
        # of fields (a tenth of a second each time Enter goes into a field or Esc comes out)
        try:
            app = self.app
        except RuntimeError:  # no app: a focus change as it closes (Textual's own watcher passes too)
            return
        app.stylesheet.update_nodes([self], animate=True)

    # ------------------------------------------------------------ building

    async def load(self, data: dict, base_dir: Path | None = None) -> None:
        self.data = copy.deepcopy(data)
        self._loaded = copy.deepcopy(data)
        self.base_dir = base_dir
        self._stash.clear()
        await self.recompose()
        self.scroll_home(animate=False)  # another preset opens at its top, not where the last one was left
        self.revalidate(changed=False)

    def compose(self):
        self._specs = {}
        self._seen = {}
        self._marked = {}
        if self.data is None:
            yield Static("No preset open. F2 lists the presets: Enter opens one, n makes a new one.")
            return
        sections = []
        yield Label("Scene", classes="heading")
        for spec in field_specs(Preset):
            if spec.kind == "section" and not spec.optional:
                sections.append(spec)
            else:
                yield from self.field_rows(spec)
        for spec in sections:
            if spec.name in KINDS:
                yield from self.plugin_rows(spec.name)
            else:
                yield Label(spec.name.capitalize(), classes="heading")
                for sub in field_specs(spec.model, prefix=spec.path):
                    yield from self.field_rows(sub)
                yield Static("", id=_section_id(spec.path), classes="field-error")
        unknown = [key for key in self.data if key not in Preset.model_fields]
        if unknown:
            yield Static(Content(f"Kept as in the file (edit the YAML to change): {', '.join(shown(k) for k in unknown)}"), classes="note")

    @property
    def swept(self) -> dict[str, object]:
        """The dotted paths the draft's sweep sets, with their values (as the YAML gives them)."""
        sweep = self.data.get("sweep") if isinstance(self.data, dict) else None
        parameters = sweep.get("parameters") if isinstance(sweep, dict) else None
        return {str(k): v for k, v in parameters.items()} if isinstance(parameters, dict) else {}

    def field_rows(self, spec: FieldSpec) -> list[Widget]:
        self._specs[spec.widget_id] = spec
        value = get_path(self.data, spec.path)
        current = spec.default if value is MISSING else value
        if spec.kind == "bool":
            widget = Switch(value=bool(current), id=spec.widget_id)
        elif spec.kind == "choice":
            options = [(Content(str(c)), c) for c in spec.choices]  # text, never markup
            known = current in spec.choices
            widget = FieldSelect(
                options,
                value=current if known else Select.NULL,
                allow_blank=spec.optional or not known,
                prompt=_unset(spec),  # as a text field says it (Textual's "Select" read as the value)
                compact=True,
                id=spec.widget_id,
            )
        elif spec.kind in ("int", "float", "text"):
            placeholder = _unset(spec)
            widget = FieldInput(
                leave=self.action_leave_field,
                value=display(value),
                placeholder=placeholder,
                compact=True,
                validate_on=[],  # the form marks it, from the headless validator's problems (revalidate)
                # a text (a description) is read from its start: selecting it on focus would show its end
                select_on_focus=spec.kind != "text",
                name=spec.dotted,  # as messages name the field
                id=spec.widget_id,
            )
            widget.cursor_position = len(widget.value) if spec.kind == "text" else 0  # typing adds to a name
        else:  # mappings, lists, optional sections (a sweep): shown whole, kept, edited in the YAML
            text = "(none)" if value in (MISSING, None) else shown(flow_text(value))
            # Content, not markup: a shortened value can hold an unclosed "[" (a sweep's list)
            note = Content.assemble(text, "  ", ("(edit in the YAML)", "dim"))
            widget = Static(note, id=spec.widget_id, classes="other")
        if spec.kind == "bool":
            self._seen[spec.widget_id] = bool(current)
        elif spec.kind == "choice":
            self._seen[spec.widget_id] = current if current in spec.choices else Select.NULL
        widget.tooltip = Content(spec.tooltip())  # descriptions are text, never markup
        label = Label(Content(spec.name), classes="field-label")
        label.tooltip = Content(spec.tooltip())
        row = [label, widget]
        if spec.kind == "bool":  # the state in words, not in colour only
            row.append(Static(_on_off(bool(current)), id=spec.widget_id + "--state", classes="switch-state"))
        if spec.dotted in self.swept:  # the sweep sets it: the value here is only the base of the others
            row.append(Static("swept", classes="swept-mark"))
        tall = spec.kind not in ("bool", "choice", "int", "float", "text")  # a sweep, a list: shown whole, wrapped
        return [Horizontal(*row, classes="row -tall" if tall else "row")]  # its messages go under it (_set_error)

    def plugin_rows(self, slot: str) -> list[Widget]:
        name = get_path(self.data, (slot, "name"), default_plugin_name(slot))
        names = self.registry.names(slot)
        known = self._known_name(slot, name)
        select = FieldSelect(
            [(Content(n), n) for n in names],
            value=known if known else Select.NULL,
            allow_blank=known is None,
            prompt="choose one",
            compact=True,
            id=f"plugin--{slot}",
        )
        select.tooltip = Content(f"{slot} plugin: one of {', '.join(names)}")
        self._seen[select.id] = known if known else Select.NULL
        return [
            Label(slot.capitalize(), classes="heading"),
            Horizontal(Label("name", classes="field-label"), select, classes="row"),
            Vertical(*self.param_rows(slot), id=f"params--{slot}", classes="params"),
            Static("", id=_section_id((slot, "params")), classes="field-error"),
        ]

    def _known_name(self, kind: str, name) -> str | None:
        if not isinstance(name, str):
            return None
        try:
            return self.registry.info(kind, name).name
        except Exception:
            return None

    def param_rows(self, slot: str) -> list[Widget]:
        known = self._known_name(slot, get_path(self.data, (slot, "name"), default_plugin_name(slot)))
        if known is None:
            return [Static("(choose a plugin to see its parameters)", classes="note")]
        cls = self.registry.get(slot, known)
        rows: list[Widget] = [Static(Content(cls.summary), classes="summary")]
        for spec in field_specs(cls.Params, prefix=(slot, "params")):
            rows += self.field_rows(spec)
        return rows

    # ------------------------------------------------------------ editing

    def ensure_plugin_name(self, data: dict, path: tuple[str, ...]) -> None:
        """Editing a parameter of a slot the file leaves at its default writes the
        slot out, with the plugin name shown in the form."""
        slot = path[0]
        if slot in KINDS and len(path) > 2 and get_path(data, (slot, "name")) is MISSING:
            set_path(data, (slot, "name"), default_plugin_name(slot), replace_values=True)

    def rename(self, name: str) -> None:
        """The draft named ``name`` (a copy saved under it), its field showing it."""
        spec = next(spec for spec in self._specs.values() if spec.path == ("name",))
        self.query_one(f"#{spec.widget_id}", Input).value = name  # not typed: Changed stores nothing
        self._store(spec, name)

    def _store(self, spec: FieldSpec, value) -> None:
        unsaid = get_path(self._loaded, spec.path) is MISSING
        if spec.kind in ("bool", "choice") and unsaid and value == spec.default:
            value = MISSING  # back to the default the file left unsaid: no change to save
        if get_path(self.data, spec.path) == value:
            return
        self.ensure_plugin_name(self.data, spec.path)
        set_path(self.data, spec.path, value, replace_values=True)
        if value is MISSING:
            self._prune(spec.path[:-1])
        self.revalidate(changed=True)

    def _prune(self, path: tuple[str, ...]) -> None:
        """Drop the mappings along ``path`` left empty that the file had not (``output: {}``)."""
        while path and get_path(self.data, path) == {} and get_path(self._loaded, path) is MISSING:
            set_path(self.data, path, MISSING)
            path = path[:-1]

    def _is_new(self, widget_id: str, value) -> bool:
        if widget_id in self._seen and self._seen[widget_id] == value:
            return False
        self._seen[widget_id] = value
        return True

    def on_input_changed(self, event: Input.Changed) -> None:
        spec = self._specs.get(event.input.id or "")
        # only typing is an edit: the Changed that mounting an input posts is not. The field typed
        # into may have lost the focus since (Tab and Esc act at once, before the keys typed before them)
        if spec is not None and self.data is not None and getattr(event.input, "typed", False):
            event.stop()
            self._store(spec, parse(spec, event.value))

    def on_switch_changed(self, event: Switch.Changed) -> None:
        state = self.query(f"#{event.switch.id}--state")
        if state:
            state.first().update(_on_off(event.value))
        spec = self._specs.get(event.switch.id or "")
        if spec is not None and self.data is not None and self._is_new(spec.widget_id, event.value):
            event.stop()
            self._store(spec, bool(event.value))

    async def on_select_changed(self, event: Select.Changed) -> None:
        if self.data is None:
            return
        select_id = event.select.id or ""
        event.stop()
        if not self._is_new(select_id, event.value):
            return
        if select_id.startswith("plugin--"):
            await self._switch_plugin(select_id.removeprefix("plugin--"), event.value)
            return
        spec = self._specs.get(select_id)
        if spec is not None:
            self._store(spec, MISSING if event.value is Select.NULL else event.value)

    async def _switch_plugin(self, slot: str, new_name) -> None:
        old_name = get_path(self.data, (slot, "name"), default_plugin_name(slot))
        old_known = self._known_name(slot, old_name)
        if new_name is Select.NULL or new_name == old_known:
            return
        old_params = get_path(self.data, (slot, "params"), {})
        if old_known is not None:
            self._stash[(slot, old_known)] = copy.deepcopy(old_params if isinstance(old_params, dict) else {})
        params = self._stash.get((slot, new_name))
        if params is None and isinstance(old_params, dict):  # a typo's were meant for the one chosen now; else those it shares
            params = old_params if old_known is None else shared_params(self.registry, slot, old_known, new_name, old_params)
        self.data[slot] = {"name": new_name, "params": params or {}}
        for spec_id in [i for i, s in self._specs.items() if s.path[0] == slot]:
            del self._specs[spec_id]
            self._marked.pop(spec_id, None)  # its new row starts unmarked
        container = self.query_one(f"#params--{slot}", Vertical)
        await container.remove_children()
        await container.mount_all(self.param_rows(slot))
        self.revalidate(changed=True)

    # ------------------------------------------------------------ messages

    def revalidate(self, changed: bool) -> None:
        """Run the headless validator on the draft and mark every field whose
        messages changed (only those: each change lays the form out again, and
        that, not the validator, is what a keystroke costs)."""
        self.problems, read = [], ""
        if self.data is not None:
            self.problems, read = validation_of(self.data, self.registry, self.base_dir)
        placed = set()  # problems shown under a field
        for widget_id, spec in self._specs.items():
            messages = problems_for(self.problems, spec.dotted)
            placed.update(messages)
            self._set_error(widget_id, messages)
        for slot in KINDS:
            messages = problems_for(self.problems, f"{slot}.name")
            placed.update(messages)
            self._set_error(f"field--{slot}--name", messages, field_id=f"plugin--{slot}")
        for section in self.query(".field-error"):
            if section.id and section.id.startswith("section--"):
                dotted = section.id.removeprefix("section--").replace("--", ".")
                messages = [p for p in self.problems if p not in placed and problem_path(p) == dotted]
                if self._marked.get(section.id, []) != messages:
                    self._marked[section.id] = messages
                    section.update(Content("\n".join(messages)))
                    section.display = bool(messages)
        self.post_message(self.Edited(self.problems, changed, read, self.data))

    def _set_error(self, widget_id: str, messages: list[str], field_id: str | None = None) -> None:
        """Show ``messages`` under the row of the field ``field_id`` (by default ``widget_id``, which
        is then marked invalid). The line under a row is mounted the first time it has something
        to say: a form of some 40 fields opened a tenth of a second sooner without them."""
        if self._marked.get(widget_id, []) == messages:
            return
        self._marked[widget_id] = messages
        try:
            field = self.query_one(f"#{field_id or widget_id}")
        except Exception:  # a plugin's row swapped out meanwhile
            return
        if field_id is None:
            field.set_class(bool(messages), "-invalid")
        if existing := self.query(f"#{widget_id}--error"):
            label = existing.first(Static)
        elif messages:  # under its row, in the form or in a plugin's parameters
            label = Static(id=f"{widget_id}--error", classes="field-error")
            field.parent.parent.mount(label, after=field.parent)
        else:
            return
        label.update(Content("\n".join(messages)))
        label.display = bool(messages)

    def focus_problem(self, problems: list[str]) -> None:
        """Point at the field of the first problem that has one (else the first field): scrolled
        into view and the one Enter goes into, while the focus stays on the form, so that a
        key the footer lists (q, ?) acts and never types into the field. Pressed in a field,
        the focus goes into that one: the keys typed next were meant for a field (a value's
        digit 2 switched to the Presets tab)."""
        for problem in problems:
            dotted = problem_path(problem)
            slot, _, rest = dotted.partition(".")
            # a section's problem that names its field first ("loading: stop must be > start"): that field
            named = f"{dotted}.{problem.partition(': ')[2].split(' ', 1)[0]}".replace(".", "--")
            for widget_id in ("field--" + dotted.replace(".", "--"), "field--" + named,
                              f"plugin--{slot}" if rest == "name" else ""):  # fmt: skip
                widgets = self.query(f"#{widget_id}") if widget_id else []
                if widgets and widgets.first().focusable:
                    self._point_at(widgets.first())
                    return
        fields = [w for w in self.query("Input, Select, Switch") if w.focusable]
        if fields:
            self._point_at(fields[0])

    def _point_at(self, field) -> None:
        self._last_field = field
        focused = self.screen.focused
        if focused is not None and focused is not self and self in focused.ancestors:
            field.focus(scroll_visible=False)
        else:
            self.focus(scroll_visible=False)
        field.scroll_visible()

    def check_action(self, action: str, parameters) -> bool:
        """Enter goes into a field from the form; Esc leaves one (the footer shows the one that applies).
        The screen's focus, not ``has_focus``: that follows once the Focus message is handled, and Enter,
        Esc, q typed fast found the form still focused on Esc, which then came late, after the q typed."""
        focused = self.screen.focused is self
        if action == "edit_field":
            return focused and self.data is not None
        if action == "leave_field":
            return not focused
        return not idle_sideways(self, action)

    def action_edit_field(self) -> None:
        fields = [w for w in self.query("Input, Select, Switch") if w.focusable]
        last = self._last_field if self._last_field in fields else None
        if last is not None or fields:
            self.screen.set_focus(last or fields[0])  # now, not after the keys already queued (focus() waits)

    def action_leave_field(self) -> None:
        self.screen.set_focus(self, scroll_visible=False)  # the next key (q) is the app's, never the field's

    # Up, Down, PageUp, PageDown: scrolled now, each from where the one before went. Textual's
    # scroll waits for a screen refresh and starts from where the form was: 20 Downs typed fast (a
    # key held down) scrolled it one line.
    def action_arrow(self, step: int) -> None:
        """Up or Down: in a field, the field above or below, as Shift+Tab and Tab go (a choice's
        own: ``FieldSelect``); on the form itself, a line of scroll."""
        if self.screen.focused is self or self.screen.focused is None:
            self._scroll_by(step)
        elif step > 0:
            self.screen.focus_next()
        else:
            self.screen.focus_previous()

    def action_scroll_down(self) -> None:
        self._scroll_by(1)

    def action_scroll_up(self) -> None:
        self._scroll_by(-1)

    def action_page_down(self) -> None:
        self._scroll_by(self.scrollable_content_region.height)

    def action_page_up(self) -> None:
        self._scroll_by(-self.scrollable_content_region.height)

    def _scroll_by(self, lines: int) -> None:
        if not self.allow_vertical_scroll:
            raise SkipAction()  # the form fits: the key goes on to the app
        self.scroll_to(y=self.scroll_target_y + lines, animate=False, immediate=True)

    def on_focus(self, event) -> None:
        self.post_message(self.FieldFocused(None))

    def on_key(self, event) -> None:
        """A letter typed in a choice or a switch (which take none) is not the app's: q quit, 2 went to Presets."""
        focused = self.screen.focused
        if event.is_printable and focused is not self and event.key not in focused._bindings.key_to_bindings:
            event.stop()
            self.app.say(f"{event.character!r} types nothing in this field: Enter or Space changes it, Esc leaves it "
                         "(then q, ? and the app's keys act)", "warning")  # fmt: skip

    def on_resize(self, event) -> None:
        """The help under the form grows as a field is focused: the form keeps that field in sight."""
        focused = self.screen.focused
        if focused is not None and focused is not self and self in focused.ancestors:
            focused.scroll_visible(animate=False)

    def on_descendant_focus(self, event) -> None:
        # keys typed fast (Shift+Tab held) move the focus on before each field's message comes, in
        # no set order: the field focused now is the one (the help spoke of hurst, seed focused)
        focused = self.screen.focused
        widget = focused if focused is not None and self in focused.ancestors else event.widget
        self._last_field = widget
        spec = self._specs.get(widget.id or "")
        if spec is None and (widget.id or "").startswith("plugin--"):
            slot = widget.id.removeprefix("plugin--")
            spec = FieldSpec(
                (slot, "name"), "choice", f"{slot} plugin ({slot})", False, default_plugin_name(slot),
                choices=tuple(self.registry.names(slot)),
            )
        self.post_message(self.FieldFocused(spec))


def _unset(spec: FieldSpec) -> str:
    """What a field with no value shows: that it must be given, or what it is left at."""
    return "required" if spec.required else f"default: {display(spec.default) or 'not set'}"


def _on_off(value: bool) -> str:
    return "on" if value else "off"
