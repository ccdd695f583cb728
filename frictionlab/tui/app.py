"""The frictionlab terminal UI: presets, edit form, live run, past results.

The app holds what the tabs share: the draft preset (open, edit, save), the run
going on, and the keys that work everywhere. Each tab's pane shows its part
(``widgets``). A run, or a sweep (a preset with a ``sweep`` section), is a process
of its own (``detached``: it goes on when the TUI or its terminal goes away),
followed by reading its folder (``following``), as a TUI opened later follows it;
starting, resuming and following one is ``running.RunControl``'s part of the app.
The first screen, the Presets tab, is drawn before the rest is built (the plugins, the
other panes, a run to follow): a run's modules are imported only once they are used.
"""

from __future__ import annotations

import copy
import functools
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING

from textual import events
from textual.app import App, ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.content import Content
from textual.css.query import NoMatches
from textual.widgets import Static, TabPane

from ..errors import PresetError, shown, shown_name
from ..options import RunOptions
from ..preset import load_preset_file
from ..preset.builtin import preset_folders
from ..plugin.registry import default_registry
from ..runs.rundir import DEFAULT_RUNS_DIR
from .folders import (
    copy_name,
    copy_target,
    file_stamp,
    preset_from_template,
    presets_signature,
    runs_signature,
    save_folder,
    templates,
)
from .hiddenkeys import SaysWhyUnavailable, said_when_hidden
from .keyorder import answer_focus_key, unjoined
from .keyshelp import KeysHelp
from .tabs import Tabs, TabSwitching
from .running import NO_PRESET, RunControl
from .saving import PresetSaving
from .screens import ConfirmScreen, Dialog, NewPresetScreen, PathScreen
from .text import problems_text
from .widgets.footer import KeysFooter
from .widgets.presets import NO_PRESETS, PresetsPane

if TYPE_CHECKING:
    from .following import FollowedRun
    from .widgets import PresetForm
    from .widgets.keyinput import KeyInput

FOLLOW_SECONDS = 0.25  # how often a run in its own process is read: progress moves at least this often
WATCH_SECONDS = 0.5  # how often the runs and presets folders and the open preset's file are looked at: a run or
#   preset file made anywhere is listed within this, another program's write to the preset said
REREAD_SECONDS = 2.0  # the list read again at most this often while only runs' files change
DRAFT_KEYS = frozenset({"ctrl+s", "ctrl+o", "ctrl+r"})  # save or run the draft


class FrictionlabApp(KeysHelp, TabSwitching, SaysWhyUnavailable, RunControl, PresetSaving, App):
    CSS_PATH = "app.tcss"
    TITLE = "frictionlab"
    ENABLE_COMMAND_PALETTE = False  # every action has a key; the footer needs the room
    # narrow: the keys panel takes the width; roomy: half of it; wide: 60 % (app.tcss)
    HORIZONTAL_BREAKPOINTS = [(0, "-narrow"), (60, "-roomy"), (80, "-wide")]
    # short: a dialog as tall as the screen at most; tiny (30x8): the Edit tab's form keeps rows (app.tcss)
    VERTICAL_BREAKPOINTS = [(0, "-tiny"), (12, "-short"), (22, "-tall")]
    BINDINGS = [
        Binding("f1", "help", "Keys", tooltip="(show, next page, hide): those of the focused part and the app's", priority=True),
        Binding("question_mark", "toggle_keys", "Keys", tooltip="(show or hide), outside a text field", show=False),
        Binding("escape", "hide_keys", show=False, system=True),  # closes the keys panel (a field's Esc leaves it first)
        Binding("f2", "show_tab('presets')", "Presets tab", show=False, priority=True),
        Binding("f3", "show_tab('edit')", "Edit tab", show=False, priority=True),
        Binding("f4", "show_tab('run')", "Run tab", show=False, priority=True),
        Binding("f5", "show_tab('results')", "Results tab", show=False, priority=True),
        # the same tabs where the F-keys are the terminal's (GNOME's F1, a Mac without fn): the F-key's digit
        Binding("2", "show_tab('presets')", "Presets tab", tooltip="(as F2), outside a text field", show=False),
        Binding("3", "show_tab('edit')", "Edit tab", tooltip="(as F3), outside a text field", show=False),
        Binding("4", "show_tab('run')", "Run tab", tooltip="(as F4), outside a text field", show=False),
        Binding("5", "show_tab('results')", "Results tab", tooltip="(as F5), outside a text field", show=False),
        Binding("ctrl+s", "save", "Save", tooltip="the preset (asks first if it has problems)", priority=True),
        Binding("ctrl+o", "save_as", "Save a copy", tooltip="in another file, under a name of its own", show=False, priority=True),
        Binding("ctrl+r", "start_run", "Run", tooltip="the open preset", priority=True),
        Binding("ctrl+q", "quit", "Quit", tooltip="(asks if the preset has unsaved changes, or a run goes on)", priority=True),
        Binding("q", "quit", "Quit", tooltip="outside a text field, as Ctrl+Q", show=False),
        Binding("ctrl+c", "help_quit", show=False, system=True),  # in the status line, not a pop-up over it
        Binding("c", "cancel_where", show=False, system=True),  # outside the Run tab: says where c cancels a run
        Binding("ctrl+z", "suspend_process", "Suspend", tooltip="to the shell, as Ctrl+Z in a shell (fg brings the TUI back)", show=False),
        # the same keys where they cannot act (check_action hides those above): the status line says why
        *said_when_hidden(("ctrl+s", "save"), ("ctrl+o", "save_as"), ("ctrl+r", "start_run"), priority=True),
    ]

    def __init__(
        self,
        preset: str | Path | None = None,
        *,
        presets_dir: str | Path | None = None,
        runs_dir: str | Path | None = None,
        options: RunOptions | None = None,
        registry=None,
    ):
        super().__init__()
        self.preset_path = Path(preset) if preset else None
        self.presets_dir = Path(presets_dir) if presets_dir else None
        self.runs_dir = Path(runs_dir) if runs_dir else DEFAULT_RUNS_DIR
        self.run_options = options or RunOptions()
        self._plugins = registry  # the plugins, loaded when first needed (not for the first screen)
        self.draft_path: Path | None = None
        self.draft_source: Path | None = None  # the file the draft was read from: its comments are kept
        self.modified = False
        self._saved: dict | None = None  # the draft as its file holds it (None: not saved yet)
        self.disk_stamp: tuple | None = None  # the draft's file as read or written here (folders.file_stamp)
        self.said_stamp: tuple | None = None  # the file's change the status line said last
        self.problems: list[str] = []
        self.blocked_by: str | None = None  # why the status line says Ctrl+R refused ("" once taken back)
        self.said_valid = False  # the status line says the preset is valid (taken back on a new problem)
        self.said_about: Path | None = None  # the row the status line speaks of (taken back on leaving it)
        self.taken_back_on = ""  # "open": the status line says no preset is open; "edit": why a run could not start
        self.followed: FollowedRun | None = None  # the run (FollowedSweep: sweep) in its own process shown on the Run tab
        self.farewell: str | None = None  # said on the shell once the app has quit (a run left going)
        # what the Run tab shows: the last snapshot, and the last finished run's (or sweep's) outcome and folder
        self.last_snapshot = None
        self.last_outcome = None
        self.last_out_dir: Path | None = None
        self.last_resumable = False  # the last run shown ended before it completed, and can go on (u)
        self._runs_seen: tuple = ()  # the runs folder as last listed (runs_signature)
        self._presets_seen: tuple = ()  # the presets folders as last listed (presets_signature)
        self._runs_read_at = 0.0  # when it was (time.monotonic)
        self._early_keys: list[events.Key] | None = []  # keys typed before the app is built (None: it is)
        self.quitting = False  # set once it exits: the keys still on their way are dropped, as at the shell
        self._terminated = 0  # the exit code of a SIGTERM (SIGHUP) that came before it was built: it quits once it is

    # ------------------------------------------------------------ layout

    def compose(self) -> ComposeResult:
        # the first screen is the Presets tab: the other panes are mounted just after it is drawn
        with Tabs(initial="presets", id="tabs"):
            with TabPane("F2 Presets", id="presets"):
                yield PresetsPane(id="presets-pane")
            yield TabPane("F3 Edit", id="edit")
            yield TabPane("F4 Run", id="run")
            yield TabPane("F5 Results", id="results")
        with VerticalScroll(id="status-box", can_focus=False):
            yield Static("", id="status")
        yield KeysFooter()

    def on_mount(self) -> None:
        # F2..F5 switch tabs: the tab bar as a Tab stop would only take focus where nothing shows it
        self.query_one("ContentTabs").can_focus = False
        # back from Ctrl+Z (fg): Textual re-enters the screen but draws nothing until something changes
        self.app_resume_signal.subscribe(self, lambda _app: self.refresh(layout=True))
        self.reload_presets()
        self.query_one("#preset-table").focus()

    def exit(self, *args, **kwargs) -> None:
        self.quitting = True
        super().exit(*args, **kwargs)

    async def on_event(self, event: events.Event) -> None:
        if isinstance(event, events.Key) and self.quitting:
            return  # typed after the quit (q then ?): a panel or dialog mounted on screens going away failed
        if isinstance(event, events.Key):
            if len(keys := unjoined(event)) > 1:  # Esc and a key the terminal joined as Alt+key
                for key in keys:
                    await self.on_event(key)
                return
            if self._early_keys is not None:
                self._early_keys.append(event)  # typed before the first frame: answered once every pane is there
                return
            if isinstance(self.screen, Dialog) and (self.screen.hold(event) or self.screen.answers_first(event)):
                return  # typed as a dialog opens (answered once it is up), or a key the dialog answers itself
            if await answer_focus_key(self, event):  # Tab, the form's Enter and Esc: before the next key
                return
            if self.esc_closed_keys(event):  # before a list's Esc (Back): the panel says Esc closes it
                return
            if event.key in DRAFT_KEYS and self._mounted("EditPane") is not None:
                await self.form_settled()  # what was typed before the key is in the draft it saves or runs
        await super().on_event(event)

    async def on_ready(self) -> None:
        """The first frame is on the screen: now the panes and the work it does not show (the
        form, the runs, a run to follow). This runs in the app's own queue, as the keys do, so a
        key pressed meanwhile waits for it (as it waited for the whole start before)."""
        from ..runs.detached import list_run_states
        from .widgets import EditPane, ResultsPane, RunPane

        await self.query_one("#edit", TabPane).mount(EditPane(self.registry, id="edit-pane"))
        await self.query_one("#run", TabPane).mount(RunPane(id="run-pane"))
        await self.query_one("#results", TabPane).mount(ResultsPane(id="results-pane"))
        self.reload_runs()
        self._show_edit_state()
        for seconds, tick in ((FOLLOW_SECONDS, self._follow_tick), (WATCH_SECONDS, self._watch_runs),
                              (WATCH_SECONDS, self._watch_preset_file), (WATCH_SECONDS, self._watch_presets)):
            # a tick as the app shuts down (a run ending as it quits) would find its widgets gone
            self.set_interval(seconds, functools.partial(self._unless_closing, tick))
        going = [state for state in list_run_states(self.runs_dir) if state.status == "running"]
        if going:  # started earlier (by a TUI that went away, or frictionlab run --detach): shown live
            self.follow_run(going[0].folder)
        if self.preset_path is not None:
            await self.open_preset(self.preset_path)
        elif going:
            self.action_show_tab("run")
        self.refresh_bindings()  # the footer: the keys of the tabs now mounted
        # the keys typed so far once the tab shown and its focus have settled (a key typed meanwhile
        # is held too, after them), in the app's queue, as a key is answered
        self.call_after_refresh(self.call_later, self._answer_early_keys)

    async def _answer_early_keys(self) -> None:
        early, self._early_keys = self._early_keys, None
        if self._terminated:
            self.terminate()
            return
        for key in early:  # in the order typed
            if key.key == "ctrl+j":  # Enter typed before the terminal was raw: the tty made it a line feed
                key = events.Key("enter", "\r")
            await self.on_event(key)

    def terminate(self, code: int | None = None) -> None:
        """SIGTERM (or SIGHUP: ``code`` 129): quit without a question (a run goes on: it is a
        process of its own), exit code 143; while the panes are being mounted, once they are
        (an exit then fails their mount)."""
        from ..errors import ExitCode

        self._terminated = code or self._terminated or int(ExitCode.TERMINATED)
        if self.built:
            self.exit(return_code=self._terminated)

    @property
    def built(self) -> bool:
        """Whether every pane is there, and the keys typed before are answered (the Presets tab
        is drawn first, the rest just after)."""
        return self._early_keys is None

    @property
    def registry(self):
        """The plugins (``Registry``): loaded when first used, after the first screen."""
        if self._plugins is None:
            self._plugins = default_registry()
        return self._plugins

    @property
    def folders(self):
        return preset_folders(self.presets_dir)

    @property
    def save_folder(self) -> Path:
        """Where New and a built-in preset's copy are saved by default: a listed folder."""
        return save_folder(self.presets_dir)

    @property
    def running(self) -> bool:
        return self.followed is not None

    def check_action(self, action: str, parameters) -> bool:
        """The footer offers Save with a preset open, Run with one open, without problems, and
        no run going (Ctrl+R pressed anyway says why, and points at the field at fault)."""
        if action in ("save", "save_as"):
            return self.draft_path is not None
        return action != "start_run" or (self.draft_path is not None and not self.running and not self.problems)

    # ------------------------------------------------------------ navigation and help

    def row_highlighted(self, path: Path | None) -> None:
        """A list's cursor is on ``path``'s row: a message about another row is taken back."""
        if self.said_about is not None and self.said_about != path:
            self.say("")

    # ------------------------------------------------------------ the status line

    def _unless_closing(self, tick) -> None:
        if self.is_running:
            tick()

    def say(self, text: str, severity: str = "information", title: str = "", about: Path | None = None, until_open=False) -> None:
        """Show ``text`` in the status line above the footer (never over the data); it stays
        until the next message, or (``about``: the run or preset folder or file it speaks of)
        until another row of a list is highlighted, or (``until_open``: it speaks of the open
        preset) until another preset opens. ``text`` is shown as it is, never as markup."""
        line = Content.assemble((f"{shown(title)}: ", "bold") if title else "", shown(text))  # no escape code from a folder
        self.blocked_by = None  # a newer message: no longer one to take back when a problem is fixed
        self.said_valid = False
        self.said_about = about
        self.taken_back_on = "open" if until_open or text == NO_PRESET else ""
        status = self.query_one("#status", Static)
        status.update(line)
        self.query_one("#status-box").scroll_home(animate=False)  # a message read from its start
        for name in ("information", "warning", "error"):
            status.set_class(name == severity, f"-{name}")

    def on_key_input_left_out(self, event: KeyInput.LeftOut) -> None:
        self.say(event.text, "warning")

    # ------------------------------------------------------------ presets

    def reload_presets(self) -> None:
        folders = self.folders
        self._presets_seen = presets_signature(folders)
        self.query_one(PresetsPane).reload(folders)

    def _watch_presets(self) -> None:
        """The Presets list follows its folders: a preset file added, removed or rewritten
        there (an editor, a shell, another TUI) is listed as it is now, without r."""
        pane = self._mounted("PresetsPane")
        if pane is None or presets_signature(self.folders) == self._presets_seen:  # or the app is closing
            return
        before = {entry.path: entry for entry in pane.presets}
        self.reload_presets()
        about = self.said_about
        if about in before and before[about] not in pane.presets:  # why it could not be opened: out of date
            self.say("")

    def open_selected_preset(self) -> None:
        entry = self.query_one(PresetsPane).selected()
        if entry is None:
            self.say(NO_PRESETS, "warning")
            return
        self.run_worker(self._open_or_show(entry.path), exclusive=True, group="open")

    async def _open_or_show(self, path: Path) -> None:
        """Enter on a preset: opened; the one already open with unsaved changes is shown as it is
        (asked whether to discard them, Enter on the row it came from threw them away)."""
        if path == self.draft_source and await self.unsaved():
            self.action_show_tab("edit")
            self.say(f"{shown_name(path.name)} is open, with unsaved changes: Ctrl+S saves them")
            return
        await self._open_after_confirm(path)

    async def _open_after_confirm(self, path: Path, data: dict | None = None, *, modified: bool = False) -> bool:
        """Open a preset in place of the draft, asking first when the draft has unsaved changes
        (Enter on the list, New, Duplicate); whether it was opened."""
        if await self.unsaved() and not await self.push_screen_wait(
            ConfirmScreen("The open preset has unsaved changes. Discard them?")
        ):
            return False
        await self.open_preset(path, data, modified=modified)
        return True

    async def open_preset(self, path: Path, data: dict | None = None, *, modified: bool = False) -> None:
        if data is None:
            stamp = file_stamp(path)  # before reading it: a write meanwhile is seen as a change, never missed
            try:
                data = load_preset_file(path)
            except PresetError as exc:
                self.say(problems_text(exc.problems), "error", title=f"Cannot open {shown_name(path.name)}", about=path)
                return
            self.draft_source, self.disk_stamp = path, stamp
        else:
            self.draft_source, self.disk_stamp = None, None
        self.draft_path = path
        with self.batch_update():  # the new form and its tab drawn once, not as each part of them is built
            await self.query_one("#form").load(data, base_dir=path.parent)
            if self.query_one("#status").has_class("-error") or self.taken_back_on == "open":  # not this one
                self.say("")
            self.modified = modified
            self._saved = None if modified else copy.deepcopy(self._draft())
            self._show_edit_state()
            self.action_show_tab("edit")

    def duplicate_selected_preset(self) -> None:
        entry = self.query_one(PresetsPane).selected()
        if entry is None:
            self.say("No preset to duplicate here: n makes a new one.", "warning")
            return
        try:
            data = load_preset_file(entry.path)
        except PresetError as exc:
            self.say(problems_text(exc.problems), "error", title="Cannot duplicate", about=entry.path)
            return
        # in the folder where n and Ctrl+S save too
        name, default = copy_target(str(data.get("name") or entry.path.stem), entry.path.stem, self.save_folder, self.names_listed())

        def done(path: Path | None) -> None:
            if path is not None:
                data["name"] = copy_name(name, path, default, self.names_listed(replaced=path))
                self._write(path, data, then_open=True, template=entry.path)

        self.push_screen(PathScreen(f"Duplicate {shown_name(entry.path.name)} as", default, self.save_folder), done)

    def new_preset(self) -> None:
        """A new preset from a template that runs (a listed preset; a plugin's
        defaults only when there is none), saved where the user says."""
        choices = templates(self.query_one(PresetsPane).presets)  # the built-in presets first

        def done(answer) -> None:
            if answer is None:
                return
            name, template, path = answer
            try:
                if template is None:
                    from .fields import default_spectrum, preset_from_defaults

                    data = preset_from_defaults(name, default_spectrum(self.registry), self.registry)
                else:
                    data = preset_from_template(template, name, path, self.registry)
            except PresetError as exc:
                self.say(problems_text(exc.problems), "error", title="Cannot read the template")
                return
            self.run_worker(self._open_new(path, data, template), group="open")

        self.push_screen(NewPresetScreen(choices, self.save_folder), done)

    async def _open_new(self, path: Path, data: dict, template: Path | None) -> None:
        if not await self._open_after_confirm(path, data, modified=True):
            return
        self.draft_source = template  # its comments are kept when the new preset is saved
        self.say(f"New preset {shown_name(path.name)}: Ctrl+S saves it as {shown_name(path)}.", until_open=True)

    # ------------------------------------------------------------ editing and saving

    def on_preset_form_edited(self, event: PresetForm.Edited) -> None:
        if bool(self.problems) != bool(event.problems):
            self.call_after_refresh(self.refresh_bindings)  # Run is listed for a valid preset only
        self.problems = event.problems
        if event.changed:  # against the file, not the last save: an edit's message may come after a save
            self.modified = self._saved is None or event.data != self._saved
        if self.blocked_by is not None and self.blocked_by not in event.problems:
            # the status said why Ctrl+R refused: that problem is gone, so is the message;
            # once no problem is left (a field is empty while retyped), it says so
            if event.problems:
                self.say("")
                self.blocked_by = ""
            else:
                self.say("The preset is valid: Ctrl+R runs it.")
                self.said_valid = True
        elif (self.said_valid and event.problems) or (self.taken_back_on == "edit" and event.changed):
            self.say("")  # no longer valid (the title counts the problem), or edited since a run could not start
        self._show_edit_state()
        if (pane := self._mounted("EditPane")) is not None:
            pane.show_problems(event.problems, event.read)

    def _show_edit_state(self) -> None:
        if (pane := self._mounted("EditPane")) is not None:
            pane.show_title(self.draft_path, self.modified, self.problems)

    def _mounted(self, pane_class: str):
        """The app's pane of that class (named: the panes are imported once the first screen is drawn),
        or None before it is mounted, or once the app is closing: its widgets are gone while a late
        message or a follow tick still arrives."""
        try:
            pane = self.query_one(pane_class)
        except NoMatches:
            return None
        # closing: exit() asked (is_attached is then False) or the shutdown begun (not running), the
        # panes' children removed one by one while a watch tick still arrives
        return pane if pane.children and pane.is_attached and self.is_running else None

    def _draft(self) -> dict | None:
        return self.query_one("#form").data

    # ------------------------------------------------------------ results

    def reload_runs(self) -> None:
        self.query_one("ResultsPane").reload(self.runs_dir)
        if self.last_resumable and not os.path.lexists(self.last_out_dir):  # removed: u leaves the Run tab's footer
            self.last_resumable = False
            self.refresh_bindings()
        self._runs_read_at = time.monotonic()
        self._runs_seen = self._runs_signature()

    def _runs_signature(self) -> tuple:
        running = [entry.path for entry in self.query_one("ResultsPane").runs if entry.status == "running"]
        return runs_signature(self.runs_dir, running)

    def _watch_runs(self) -> None:
        """Results lists every run the moment it starts, from any TUI or the CLI: the runs
        folder's names and times are looked at, and the list read again only when they changed."""
        if self._mounted("ResultsPane") is None:
            return
        now, seen = self._runs_signature(), self._runs_seen
        if now == seen:
            return
        names = lambda signature: [name for name, _ in signature[1]] if signature else None  # noqa: E731
        # a run started, removed or ended, or a folder not yet listed written (its run.json): at once;
        # a listed run's files written (a chunk): coalesced, the list read at most every REREAD_SECONDS
        listed = {entry.path.name for entry in self._mounted("ResultsPane").runs}
        unlisted_changed = set(now[1]) - set(seen[1]) if now and seen else set()  # a new folder's run.json, say
        if (
            names(now) != names(seen)
            or now[2:] != seen[2:]
            or any(name not in listed for name, _ in unlisted_changed)
            or time.monotonic() - self._runs_read_at >= REREAD_SECONDS
        ):
            self.reload_runs()
