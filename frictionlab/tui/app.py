"""The frictionlab terminal UI: presets, edit form, live run, past results.

The app holds what the tabs share: the draft preset (open, edit, save), the run
going on, and the keys that work everywhere. Each tab's pane shows its part
(``widgets``). A run, or a sweep (a preset with a ``sweep`` section), is a process
of its own (``detached``: it goes on when the TUI or its terminal goes away),
followed by reading its folder (``following``), as a TUI opened later follows it.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from textual.actions import SkipAction
from textual.app import App, ComposeResult
from textual.binding import Binding
from textual.content import Content
from textual.css.query import NoMatches
from textual.widgets import Footer, Static, TabbedContent, TabPane

from ..detached import (
    check_startable,
    check_sweep_startable,
    list_run_states,
    lock_held,
    lock_holder,
    run_state,
    start_detached,
)
from ..errors import FrictionlabError, PresetError, RunFolderError, shown
from ..files import output_path_problem
from ..options import RunOptions
from ..preset import build_scene, load_preset_file, resolve_input_paths
from ..registry import default_registry
from ..rundir import DEFAULT_RUNS_DIR, RunDirectory, new_run_folder
from ..sweep import plan_sweep, stored_sweep
from .fields import default_spectrum, preset_from_defaults
from .folders import (
    is_builtin,
    new_preset_path,
    preset_folders,
    preset_from_template,
    read_run,
    runs_signature,
    save_folder,
    save_preset,
    templates,
    user_presets_dir,
    writable_folder,
)
from .following import FinishedSweep, FollowedRun, FollowedSweep, read_finished, read_finished_sweep
from .messages import RunCrashed, RunFinished
from .screens import ConfirmScreen, NewPresetScreen, PathScreen, QuitDuringRunScreen
from .text import failure_message, problems_text
from .widgets import EditPane, PresetForm, PresetsPane, ResultsPane, RunPane
from .widgets.presets import NO_PRESETS

NO_PRESET = "No preset open: F2 lists them (Enter opens one, n makes a new one)."
FOLLOW_SECONDS = 0.25  # how often a run in its own process is read: progress moves at least this often
WATCH_SECONDS = 0.5  # how often the runs folder is looked at: a run started anywhere is listed within this


class FrictionlabApp(App):
    CSS_PATH = "app.tcss"
    TITLE = "frictionlab"
    ENABLE_COMMAND_PALETTE = False  # every action has a key; the footer needs the room
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
        Binding("ctrl+o", "save_as", "Save as", tooltip="another file", show=False, priority=True),
        Binding("ctrl+r", "start_run", "Run", tooltip="the open preset", priority=True),
        Binding("ctrl+q", "quit", "Quit", tooltip="(asks if the preset has unsaved changes, or a run goes on)", priority=True),
        Binding("q", "quit", "Quit", tooltip="outside a text field, as Ctrl+Q", show=False),
        Binding("ctrl+c", "help_quit", show=False, system=True),  # in the status line, not a pop-up over it
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
        self.registry = registry or default_registry()
        self.draft_path: Path | None = None
        self.draft_source: Path | None = None  # the file the draft was read from: its comments are kept
        self.modified = False
        self.problems: list[str] = []
        self.blocked_by: str | None = None  # why the status line says Ctrl+R refused ("" once taken back)
        self.said_valid = False  # the status line says the preset is valid (taken back on a new problem)
        self.followed: FollowedRun | None = None  # the run (FollowedSweep: sweep) in its own process shown on the Run tab
        # what the Run tab shows: the last snapshot, and the last finished run's (or sweep's) outcome and folder
        self.last_snapshot = None
        self.last_outcome = None
        self.last_out_dir: Path | None = None
        self.last_resumable = False  # the last run shown ended before it completed, and can go on (u)
        self._runs_seen: tuple = ()  # the runs folder as last listed (runs_signature)

    # ------------------------------------------------------------ layout

    def compose(self) -> ComposeResult:
        with TabbedContent(initial="presets", id="tabs"):
            with TabPane("F2 Presets", id="presets"):
                yield PresetsPane(id="presets-pane")
            with TabPane("F3 Edit", id="edit"):
                yield EditPane(self.registry, id="edit-pane")
            with TabPane("F4 Run", id="run"):
                yield RunPane(id="run-pane")
            with TabPane("F5 Results", id="results"):
                yield ResultsPane(id="results-pane")
        yield Static("", id="status")
        yield Footer()

    async def on_mount(self) -> None:
        # F2..F5 switch tabs: the tab bar as a Tab stop would only take focus where nothing shows it
        self.query_one("ContentTabs").can_focus = False
        self.reload_presets()
        self.reload_runs()
        self._show_edit_state()
        self.set_interval(FOLLOW_SECONDS, self._follow_tick)
        self.set_interval(WATCH_SECONDS, self._watch_runs)
        going = [state for state in list_run_states(self.runs_dir) if state.status == "running"]
        if going:  # started earlier (by a TUI that went away, or frictionlab run --detach): shown live
            self.follow_run(going[0].folder)
        if self.preset_path is not None:
            await self.open_preset(self.preset_path)
        elif going:
            self.action_show_tab("run")
        else:
            self.query_one("#preset-table").focus()

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

    # ------------------------------------------------------------ navigation and help

    def action_show_tab(self, tab: str) -> None:
        self.query_one("#tabs", TabbedContent).active = tab
        focus = {"presets": "#preset-table", "edit": "#form", "run": "#run-pane", "results": "#runs-table"}[tab]
        self.query_one(focus).focus()  # the form, not a field: a listed key never types into the preset
        self.call_after_refresh(self.refresh_bindings)  # the footer, for the part now focused

    def on_tabbed_content_tab_activated(self, event: TabbedContent.TabActivated) -> None:
        if self.screen_stack:  # not once the app has closed (a late message)
            self.refresh_bindings()

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

    def action_toggle_keys(self) -> None:
        """? shows the key panel, or hides it (F1 pages through it)."""
        if self.screen.query("HelpPanel"):
            self.action_hide_help_panel()
        else:
            self.action_show_help_panel()

    def action_hide_keys(self) -> None:
        if self.screen.query("HelpPanel"):
            self.action_hide_help_panel()
        else:
            raise SkipAction()  # Esc means nothing here: another part may take it

    def action_help_quit(self, in_field: bool = False) -> None:
        """Ctrl+C (copy, in a text field) does not quit: where the status line says what does."""
        where = "Ctrl+C copies in a text field. " if in_field else ""
        self.say(f"{where}Ctrl+Q quits (q too, outside a text field: Esc leaves one); "
                 "a run goes on after you quit unless you cancel it.")  # fmt: skip

    # ------------------------------------------------------------ the status line

    def say(self, text: str, severity: str = "information", title: str = "") -> None:
        """Show ``text`` in the status line above the footer (never over the data); it
        stays until the next message. ``text`` is shown as it is, never as markup."""
        line = Content.assemble((f"{title}: ", "bold") if title else "", text)
        self.blocked_by = None  # a newer message: no longer one to take back when a problem is fixed
        self.said_valid = False
        status = self.query_one("#status", Static)
        status.update(line)
        for name in ("information", "warning", "error"):
            status.set_class(name == severity, f"-{name}")

    # ------------------------------------------------------------ presets

    def reload_presets(self) -> None:
        self.query_one(PresetsPane).reload(self.folders)

    def open_selected_preset(self) -> None:
        entry = self.query_one(PresetsPane).selected()
        if entry is None:
            self.say(NO_PRESETS, "warning")
            return
        self.run_worker(self._open_after_confirm(entry.path), exclusive=True, group="open")

    async def _open_after_confirm(self, path: Path) -> None:
        if self.modified and not await self.push_screen_wait(
            ConfirmScreen("The open preset has unsaved changes. Discard them?")
        ):
            return
        await self.open_preset(path)

    async def open_preset(self, path: Path, data: dict | None = None, *, modified: bool = False) -> None:
        if data is None:
            try:
                data = load_preset_file(path)
            except PresetError as exc:
                self.say(problems_text(exc.problems), "error", title=f"Cannot open {path.name}")
                return
            self.draft_source = path
        else:
            self.draft_source = None
        self.draft_path = path
        await self.query_one("#form", PresetForm).load(data, base_dir=path.parent)
        if self.query_one("#status").has_class("-error"):  # about the preset open before: not this one
            self.say("")
        self.modified = modified
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
            self.say(problems_text(exc.problems), "error", title="Cannot duplicate")
            return
        data["name"] = f"{data.get('name') or entry.path.stem}-copy"
        default = writable_folder(self.folders) / f"{entry.path.stem}-copy.yaml"

        def done(path: Path | None) -> None:
            if path is not None:
                self._write(path, data, then_open=True, template=entry.path)

        self.push_screen(PathScreen(f"Duplicate {entry.path.name} as", default), done)

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
                    data = preset_from_defaults(name, default_spectrum(self.registry), self.registry)
                else:
                    data = preset_from_template(template, name, path, self.registry)
            except PresetError as exc:
                self.say(problems_text(exc.problems), "error", title="Cannot read the template")
                return
            self.run_worker(self._open_new(path, data, template), group="open")

        self.push_screen(NewPresetScreen(choices, self.save_folder), done)

    async def _open_new(self, path: Path, data: dict, template: Path | None) -> None:
        await self.open_preset(path, data, modified=True)
        self.draft_source = template  # its comments are kept when the new preset is saved
        self.say(f"New preset {path.name}: Ctrl+S saves it as {path}.")

    # ------------------------------------------------------------ editing and saving

    def on_preset_form_edited(self, event: PresetForm.Edited) -> None:
        self.problems = event.problems
        if event.changed:
            self.modified = True
        if self.blocked_by is not None and self.blocked_by not in event.problems:
            # the status said why Ctrl+R refused: that problem is gone, so is the message;
            # once no problem is left (a field is empty while retyped), it says so
            if event.problems:
                self.say("")
                self.blocked_by = ""
            else:
                self.say("The preset is valid: Ctrl+R runs it.")
                self.said_valid = True
        elif self.said_valid and event.problems:  # it is no longer: the title counts the problem
            self.say("")
        self._show_edit_state()
        if (pane := self._mounted(EditPane)) is not None:
            pane.show_problems(event.problems, event.read)

    def _show_edit_state(self) -> None:
        if (pane := self._mounted(EditPane)) is not None:
            pane.show_title(self.draft_path, self.modified, self.problems)

    def _mounted(self, pane_class):
        """The app's pane of that class, or None once the app is closing: its widgets are
        gone while a late message or a follow tick still arrives."""
        try:
            pane = self.query_one(pane_class)
        except NoMatches:
            return None
        return pane if pane.children else None  # the app is closing: the panes' children go first

    def _draft(self) -> dict | None:
        return self.query_one("#form", PresetForm).data

    def action_save(self) -> None:
        if self.draft_path is None or self._draft() is None:
            self.say(NO_PRESET, "warning")
            return
        if is_builtin(self.draft_path):  # shipped with frictionlab: saved as a copy, where the user says
            self.say(f"{self.draft_path.name} is a built-in preset: save your version as a new file.", "warning")
            self.push_screen(
                PathScreen(
                    "Save the built-in preset's changes as",
                    new_preset_path(self.draft_path.stem, self.save_folder),
                    self.save_folder,
                ),
                lambda path: path is not None and self._save_checked(path),
            )
            return
        if self.draft_source != self.draft_path and self.draft_path.exists():
            # a new preset whose file appeared since the New dialog: replaced only if the user says so
            self.push_screen(
                PathScreen(f"{self.draft_path} exists now: save the new preset as", self.draft_path, self.save_folder),
                lambda path: path is not None and self._save_checked(path),
            )
            return
        self._save_checked(self.draft_path)

    def action_save_as(self) -> None:
        if self.draft_path is None or self._draft() is None:
            self.say(NO_PRESET, "warning")
            return
        self.push_screen(
            PathScreen("Save preset as", self.draft_path),
            lambda path: path is not None and self._save_checked(path),
        )

    def _save_checked(self, path: Path) -> None:
        data = self._draft()
        if not self.problems:
            self._write(path, data, template=self.draft_source)
            return
        count = len(self.problems)
        question = (
            f"This preset has {count} problem{'s' if count != 1 else ''}; frictionlab run will refuse it:\n"
            + "\n".join(self.problems[:6])
            + "\n\nSave it anyway?"
        )
        self.push_screen(
            ConfirmScreen(question), lambda yes: yes and self._write(path, data, template=self.draft_source)
        )

    def _write(self, path: Path, data: dict, then_open: bool = False, template: Path | None = None) -> None:
        try:
            if not path.parent.exists() and path.parent.resolve() == self.save_folder.resolve():
                path.parent.mkdir(parents=True)  # the presets folder, made when first saved into
            save_preset(path, data, template=template)
        except OSError as exc:  # a read-only folder, not the user's, a file in the way
            elsewhere = user_presets_dir() / path.name
            self.say(f"{shown(path)} cannot be written ({exc.strerror or exc}): Ctrl+O saves it elsewhere, "
                     f"e.g. {shown(elsewhere)}", "error", title="Not saved")  # fmt: skip
            return
        self.say(f"Saved {path}")
        self.reload_presets()
        self.query_one(PresetsPane).highlight(path)  # a listed folder: the preset is there
        if then_open:
            self.run_worker(self.open_preset(path), group="open")
        else:
            self.draft_path = self.draft_source = path
            self.modified = False
            self._show_edit_state()

    # ------------------------------------------------------------ running

    def action_start_run(self) -> None:
        if self.running:
            self.say("A run is going; c on the Run tab cancels it.", "warning")
            return
        data = self._draft()
        if data is None:
            self.say(NO_PRESET, "warning")
            return
        try:
            if self.draft_path is not None:  # relative input files are the preset file's neighbours
                data = resolve_input_paths(data, self.draft_path.parent, self.registry)
            scene = build_scene(data, registry=self.registry)
            sweep = None
            if scene.preset.sweep is not None:  # every point is checked before any runs
                source = str(self.draft_path) if self.draft_path else None
                sweep = plan_sweep(data, registry=self.registry, source=source)
        except PresetError as exc:
            count = len(exc.problems)
            self.say(exc.problems[0], "error", title=f"Cannot run: {count} problem{'s' if count != 1 else ''}")
            self.blocked_by = exc.problems[0]
            self.query_one("#tabs", TabbedContent).active = "edit"
            form = self.query_one("#form", PresetForm)
            form.revalidate(changed=False)  # a file may have gone since the last keystroke: mark it now
            form.focus_problem(exc.problems)
            return
        try:
            out_dir = new_run_folder(scene.preset.name, self.runs_dir)  # made now: it claims the name
        except FrictionlabError as exc:  # the runs folder is a file
            self.say(output_path_problem(self.runs_dir) or str(exc), "error", title="Run failed")
            return
        except OSError as exc:  # it cannot be made: read-only, not the user's
            self.say(f"no run folder can be made in {shown(self.runs_dir)} ({exc.strerror or exc}): quit and start "
                     "the TUI in a folder you can write in, or give one: frictionlab tui --runs DIR", "error",
                     title="Cannot run")  # fmt: skip
            return
        self._start(scene, sweep, out_dir, self.run_options)

    def resume_run(self, folder: Path | None) -> None:
        """Continue a cancelled or interrupted run in ``folder`` with the preset stored
        there (``frictionlab resume``): only the missing realizations are computed."""
        if self.running:
            self.say("A run is going; c on the Run tab cancels it.", "warning")
            return
        if folder is None:
            self.say("No run to resume: F5 lists the runs (u there resumes the highlighted one).", "warning")
            return
        try:
            state = run_state(folder)
            if state.status == "running":
                if self.followed is None:
                    self._follow_the_winner(folder, state.pid)
                else:
                    self.show_running(folder)
                return
            if state.kind == "sweep" and state.status == "completed":
                self.say(f"{folder.name} is complete: nothing to resume.", "warning")
                return
        except FrictionlabError:
            pass  # not a run folder (yet): said below
        try:
            if read_run(folder).status == "completed":
                self.say(f"{folder.name} is complete: nothing to resume.", "warning")
                return
        except (OSError, RunFolderError):
            pass  # no summary yet (a run killed early): the stored preset says whether it can go on
        stored = self._stored_or_say(folder, "resume")
        if stored is not None:
            self._start(*stored, folder, replace(self.run_options, resume=True))

    def _follow_the_winner(self, folder: Path, pid: int | None = None) -> None:
        """A resume that another process (a TUI, the CLI) began first: follow that one, and say so."""
        self.follow_run(folder)
        if self.followed is None:
            return  # the status line says why it cannot be followed
        self.action_show_tab("run")
        pid = pid or lock_holder(folder)
        self.say(f"{shown(folder.name)} was resumed by another process first (pid {pid or 'unknown'}): "
                 "this TUI follows that run; c cancels it", "warning")  # fmt: skip

    def _stored(self, folder: Path):
        """(scene, sweep) of the run stored in ``folder`` (sweep None), or of the sweep (scene
        its first point's); RunFolderError or PresetError if it holds none that can run."""
        if run_state(folder).kind == "sweep":
            sweep = plan_sweep(stored_sweep(folder), registry=self.registry, source=str(folder / "sweep.json"))
            return sweep.points[0].scene, sweep
        return build_scene(RunDirectory(folder).stored_preset(), registry=self.registry), None

    def _stored_or_say(self, folder: Path, verb: str):
        """``_stored(folder)``, or None once the status line has said why it cannot ``verb`` it."""
        try:
            return self._stored(folder)
        except RunFolderError as exc:
            self.say(str(exc), "error", title=f"Cannot {verb}")
        except PresetError as exc:
            self.say(exc.problems[0], "error", title=f"Cannot {verb} {folder.name}")
        return None

    def _start(self, scene, sweep, out_dir: Path, options: RunOptions) -> None:
        self.last_outcome = None
        self.last_resumable = False
        self.refresh_bindings()
        try:  # refused here, at once, what the run would refuse as it begins
            if sweep is None:
                check_startable(scene, out_dir, options)
            else:
                check_sweep_startable(sweep, out_dir, options)
        except FrictionlabError as exc:
            if options.resume and lock_held(out_dir):  # another TUI (or the CLI) resumed it first
                self._follow_the_winner(out_dir)
                return
            self.say(str(exc), "error", title="Cannot resume" if options.resume else "Cannot run")
            return
        try:
            preset = scene.resolved() if sweep is None else sweep.preset_data
            process = start_detached(preset, out_dir, options, source=sweep.source if sweep is not None else None)
        except OSError as exc:  # no process can be started (out of processes, memory)
            self.say(f"cannot start the run: {exc.strerror or exc}", "error", title="Run failed")
            return
        self.followed = self._follower(out_dir, scene, sweep, process)
        self.refresh_bindings()  # the Run tab's keys: cancel now, not run nor resume
        self.query_one(RunPane).start(scene, sweep, out_dir)
        self.action_show_tab("run")
        verb = "Resuming" if options.resume else "Running"
        name = scene.preset.name if sweep is None else f"the sweep {sweep.name}"
        self.say(f"{verb} {name} into {out_dir} as a process of its own "
                 f"(pid {self.followed.pid}): it goes on if you quit")  # fmt: skip

    def _follower(self, folder: Path, scene, sweep, process=None) -> FollowedRun:
        if sweep is None:
            return FollowedRun(folder, scene, self._show_snapshot, process=process)
        show_point = lambda kind, point, result: self._show_point(sweep, kind, point, result)  # noqa: E731
        return FollowedSweep(folder, sweep, self._show_snapshot, show_point, process=process)

    def show_running(self, folder: Path) -> None:
        """The Run tab, following the run going on in ``folder`` (if it is not the one shown)."""
        if self.followed is None or self.followed.folder.resolve() != folder.resolve():
            if self.running:
                self.say("A run is shown: it goes on when you quit; follow this one after it (or from another TUI).", "warning")
                return
            self.follow_run(folder)
        self.action_show_tab("run")

    def follow_run(self, folder: Path) -> None:
        """Show the run (or sweep) going on in ``folder`` (another process's) live on the Run tab."""
        stored = self._stored_or_say(folder, "follow")
        if stored is None:
            return
        scene, sweep = stored
        self.last_outcome = None
        self.last_resumable = False
        self.query_one(RunPane).start(scene, sweep, folder)  # before the first poll: that fills its table
        self.followed = self._follower(folder, scene, sweep)
        self.refresh_bindings()
        name = scene.preset.name if sweep is None else f"The sweep {sweep.name}"
        self.say(f"{name} is running in {folder} (a process of its own): F4 shows it, c cancels it")
        self._follow_tick()

    def _show_point(self, sweep, kind: str, point, result) -> None:
        if (pane := self._mounted(RunPane)) is not None:
            pane.show_point(sweep, kind, point, result)

    def _show_snapshot(self, snapshot) -> None:
        self.last_snapshot = snapshot
        if (pane := self._mounted(RunPane)) is not None:
            pane.show_progress(snapshot, self.followed is not None and self.followed.cancelling)

    def _follow_tick(self) -> None:
        followed = self.followed
        if followed is not None and not isinstance(followed, FollowedSweep) and followed.progress_problem():
            self._count_from_chunks(followed)
        if followed is None or not followed.poll():
            return
        self.followed = None
        self.last_out_dir = followed.folder
        self.last_resumable = _resumable(followed.folder)  # however it ended: u offered when it can go on
        self.refresh_bindings()
        if followed.error:
            if lock_held(followed.folder) and followed.process is not None:  # ours lost the folder to another's resume
                self._follow_the_winner(followed.folder)
                return
            self.on_run_crashed(RunCrashed(followed.error))
            self.reload_runs()
            return
        try:
            read = read_finished_sweep if isinstance(followed, FollowedSweep) else read_finished
            finished = read(followed.folder)
        except (FrictionlabError, OSError, ValueError, TypeError, KeyError):
            resume = "u resumes it" if self.last_resumable else "it cannot be resumed"
            error = f"the run's process ended without writing its results ({resume}: {followed.folder})"
            self.on_run_crashed(RunCrashed(error))
            self.reload_runs()
            return
        self.on_run_finished(RunFinished(finished, followed.folder))

    def _count_from_chunks(self, followed: FollowedRun) -> None:
        """A run whose progress file cannot be written: said once; its count read from its chunks."""
        if not followed.said_progress_problem:
            followed.said_progress_problem = True
            self.say(f"{followed.progress_problem()}: the count comes from the run's chunks, without a live plot", "warning")
        done, total = followed.stored_count()
        if total and (pane := self._mounted(RunPane)) is not None:
            pane.show_stored_count(done or 0, total)

    def action_cancel_run(self) -> None:
        if not self.running:
            self.say("No run is going: Ctrl+R starts one.", "warning")
            return
        if not self.followed.cancel():
            return  # its process is gone: the next tick shows how it ended
        self.query_one(RunPane).show_cancelling()

    def on_run_finished(self, message: RunFinished) -> None:
        outcome = message.outcome
        self.last_outcome, self.last_out_dir = outcome, message.out_dir
        self.refresh_bindings()  # resume, if it ended before it completed
        pane = self.query_one(RunPane)
        if isinstance(outcome, FinishedSweep):
            self.say(pane.show_sweep_outcome(outcome))
        else:
            line = pane.show_outcome(outcome)
            if outcome.done == 0 and outcome.failures:  # nothing to show: say why, as the user can fix it
                self.say(failure_message(outcome.failures[0][1]), "error", title="Run failed: no realization finished")
            elif outcome.failures:
                self.say(f"{line}; {outcome.failed} failed: {failure_message(outcome.failures[0][1])}", "warning")
            else:
                self.say(line)
        self.reload_runs()

    def on_run_crashed(self, message: RunCrashed) -> None:
        self.query_one(RunPane).show_crash(message.error)
        self.say(message.error, "error", title="Run failed")

    def action_quit(self) -> None:
        """Quit at once; while a run goes on, ask first whether to leave it running or cancel it."""
        followed = self.followed
        if followed is not None:
            def answered(choice: str | None) -> None:
                if choice is None:
                    return
                if choice == "cancel":
                    followed.cancel()  # SIGTERM: it keeps what finished; no need to wait for it
                self._quit_unless_unsaved()

            what = "sweep" if isinstance(followed, FollowedSweep) else "run"
            question = (f"A {what} is going in {followed.folder} (pid {followed.pid}), a process of its own.\n"
                        "Leave it running (a TUI opened later shows it, u resumes it if it stops), or cancel it "
                        "(what finished is kept)?")  # fmt: skip
            self.push_screen(QuitDuringRunScreen(question), answered)
            return
        self._quit_unless_unsaved()

    def _quit_unless_unsaved(self) -> None:
        if self.modified:
            self.push_screen(
                ConfirmScreen("The open preset has unsaved changes. Quit anyway?"),
                lambda yes: yes and self.exit(),
            )
            return
        self.exit()

    # ------------------------------------------------------------ results

    def reload_runs(self) -> None:
        self.query_one(ResultsPane).reload(self.runs_dir)
        self._runs_seen = self._runs_signature()

    def _runs_signature(self) -> tuple:
        running = [entry.path for entry in self.query_one(ResultsPane).runs if entry.status == "running"]
        return runs_signature(self.runs_dir, running)

    def _watch_runs(self) -> None:
        """Results lists every run the moment it starts, from any TUI or the CLI: the runs
        folder's names and times are looked at, and the list read again only when they changed."""
        if self._mounted(ResultsPane) is not None and self._runs_signature() != self._runs_seen:
            self.reload_runs()


def _resumable(folder: Path) -> bool:
    """Whether the run (or sweep) in ``folder`` ended before it completed and can go on."""
    try:
        return run_state(folder).resumable
    except (OSError, FrictionlabError):
        return False
