"""The frictionlab terminal UI: presets, edit form, live run, past results.

The engine runs in a thread worker through ``runner.run_to_folder`` (the path
``frictionlab run`` takes, so the same files are written); a preset with a
``sweep`` section runs through ``sweep.run_sweep`` the same way. The ``LiveListener``
hands snapshots over with ``post_message`` (thread safe); ``RunProgress``
messages coalesce in the queue, so a fast run cannot flood the UI.
"""

from __future__ import annotations

import math
import threading
from functools import partial
from pathlib import Path

import numpy as np
from textual.app import App, ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.widgets import DataTable, Footer, ProgressBar, Static, TabbedContent, TabPane

from ..errors import FrictionlabError, PresetError
from ..preset import build_scene, load_preset_file, resolve_input_paths
from ..registry import default_registry
from ..reporter import _duration
from ..runner import run_to_folder
from ..sweep import plan_sweep, run_sweep
from .chart import Series
from .fields import preset_from_defaults
from .folders import (
    default_runs_dir,
    list_presets,
    list_runs,
    new_run_folder,
    preset_folders,
    SweepEntry,
    read_curve,
    read_run,
    save_preset,
    writable_folder,
)
from .form import PresetForm
from .live import LiveListener, Snapshot
from .screens import Chart, ConfirmScreen, HelpScreen, NewPresetScreen, PathScreen
from .sweepview import STATUS_MARKS, SweepPoster, point_line, row_cells, table_cells, table_columns

OVERLAY_STYLES = ("cyan", "magenta", "green", "yellow")


# ------------------------------------------------------------------ messages from the run thread


class RunProgress(Message):
    """A cumulative snapshot: a newer one supersedes any still queued."""

    def __init__(self, snapshot: Snapshot):
        super().__init__()
        self.snapshot = snapshot

    def can_replace(self, message: Message) -> bool:
        return isinstance(message, RunProgress)


class RunDone(Message):
    def __init__(self, scene, outcome, out_dir: Path):
        super().__init__()
        self.scene = scene
        self.outcome = outcome
        self.out_dir = out_dir


class SweepEvent(Message):
    """A sweep point started (``result`` None) or finished."""

    def __init__(self, sweep, kind: str, point, result):
        super().__init__()
        self.sweep, self.kind, self.point, self.result = sweep, kind, point, result


class SweepDone(Message):
    def __init__(self, sweep, outcome, out_dir: Path):
        super().__init__()
        self.sweep = sweep
        self.outcome = outcome
        self.out_dir = out_dir


class RunCrashed(Message):
    def __init__(self, error: str):
        super().__init__()
        self.error = error


# ------------------------------------------------------------------ formatting


def _interval(ci) -> str:
    low, high = ci
    return "" if low is None or not math.isfinite(low) else f"[{low:.4f}, {high:.4f}]"


def fit_lines(fit, *, final: bool, f_formula: str = "") -> list[str]:
    """The coefficients as the Run tab and Results tab show them, with what f is."""
    what = [f"  f = {f_formula}"] if f_formula else []
    if fit is None:
        return ["xi = a + b ln f", *what, "  (no realization yet)"]
    head = "xi = a + b ln f" + ("" if final else "  (interim)")
    lines = [head, *what, f"  a = {fit.a:.4f}", f"  b = {fit.b:.4f}"]
    if final:
        level = f"{100 * fit.confidence:g}%"
        lines = [
            head,
            *what,
            f"  a = {fit.a:.4f} {_interval(fit.a_ci)}",
            f"  b = {fit.b:.4f} {_interval(fit.b_ci)}",
            f"  {level} CI, bootstrap {fit.bootstrap}",
        ]
    lines.append(f"  R^2 = {fit.r2:.4f}")
    return lines


def _fit_series(f: np.ndarray, a: float, b: float, style: str) -> Series:
    f = np.asarray(f, float)
    f = f[np.isfinite(f) & (f > 0)]
    if f.size < 2:
        return Series(np.empty(0), np.empty(0), style, line=True)
    ends = np.array([f.min(), f.max()])
    return Series(ends, a + b * np.log(ends), style, line=True)


# ------------------------------------------------------------------ panes


class ListTable(DataTable):
    """A row list whose Enter is shown in the footer as Open."""

    BINDINGS = [Binding("enter", "select_cursor", "Open", tooltip="Open the highlighted row")]


class PresetsPane(Vertical):
    BINDINGS = [
        Binding("d", "duplicate", "Duplicate", tooltip="Duplicate the preset (asks for a file name)"),
        Binding("n", "new", "New", tooltip="New preset from a spectrum plugin's defaults"),
        Binding("r", "reload", "Reload", tooltip="Reload the list of presets"),
    ]

    def compose(self) -> ComposeResult:
        yield ListTable(id="preset-table", cursor_type="row", zebra_stripes=True)
        yield Static("", id="preset-info")

    def action_duplicate(self) -> None:
        self.app.duplicate_selected_preset()

    def action_new(self) -> None:
        self.app.new_preset()

    def action_reload(self) -> None:
        self.app.reload_presets()


class EditPane(Vertical):
    def __init__(self, registry, **kwargs):
        super().__init__(**kwargs)
        self.registry = registry

    def compose(self) -> ComposeResult:
        yield Static("", id="edit-title")
        yield PresetForm(self.registry, id="form")
        yield Static("", id="field-help")
        yield Static("", id="problems")


class RunPane(Vertical, can_focus=True):
    BINDINGS = [
        Binding("r", "start", "Run", tooltip="Run the open preset (again)"),
        Binding("c", "cancel", "Cancel", tooltip="Cancel the run: what finished is kept and saved"),
    ]

    def compose(self) -> ComposeResult:
        yield Static("No run yet: open a preset and press Ctrl+R.", id="run-title")
        yield Static("", id="sweep-point")
        yield ProgressBar(id="run-bar", show_eta=False)
        yield Static("", id="run-stats")
        with Horizontal(id="run-body"):
            yield Chart(id="run-chart")
            yield Static("", id="run-fit")
        yield DataTable(id="sweep-table", zebra_stripes=True, cursor_type="none")
        yield Static("", id="run-error")

    def action_start(self) -> None:
        self.app.action_start_run()

    def action_cancel(self) -> None:
        self.app.action_cancel_run()


class ResultsPane(Vertical):
    """Runs and sweeps on the left, the open runs' curves on the right; an open
    sweep's table of points below them (Enter on a point opens its run)."""

    BINDINGS = [
        Binding("space", "compare", "Compare", tooltip="Compare: add the run to the overlay, or remove it"),
        Binding("r", "reload", "Reload", tooltip="Reload the list of runs"),
    ]

    def compose(self) -> ComposeResult:
        with Horizontal(id="results-top"):
            yield ListTable(id="runs-table", cursor_type="row", zebra_stripes=True)
            with Vertical(id="results-body"):
                yield Chart(id="results-chart")
                yield Static("Enter opens a run; Space adds it to the overlay.", id="results-info")
        yield ListTable(id="results-sweep", cursor_type="row", zebra_stripes=True)

    def action_compare(self) -> None:
        self.app.open_selected_run(overlay=True)

    def action_reload(self) -> None:
        self.app.reload_runs()


# ------------------------------------------------------------------ the app


class FrictionlabApp(App):
    CSS_PATH = "app.tcss"
    TITLE = "frictionlab"
    ENABLE_COMMAND_PALETTE = False  # every action has a key; the footer needs the room
    BINDINGS = [
        Binding("f1", "help", "Help", tooltip="This list of keys", priority=True),
        Binding("question_mark", "help", "Help", tooltip="This list of keys (outside a text field)", show=False),
        Binding("f2", "show_tab('presets')", "Presets tab", show=False, priority=True),
        Binding("f3", "show_tab('edit')", "Edit tab", show=False, priority=True),
        Binding("f4", "show_tab('run')", "Run tab", show=False, priority=True),
        Binding("f5", "show_tab('results')", "Results tab", show=False, priority=True),
        Binding("ctrl+s", "save", "Save", tooltip="Save the preset (asks first if it has problems)", priority=True),
        Binding("ctrl+o", "save_as", "Save as", tooltip="Save the preset under another name", priority=True),
        Binding("ctrl+r", "start_run", "Run", tooltip="Run the open preset", priority=True),
        Binding("ctrl+q", "quit", "Quit", tooltip="Quit (asks if the preset has unsaved changes)", priority=True),
    ]

    def __init__(
        self,
        preset: str | Path | None = None,
        *,
        presets_dir: str | Path | None = None,
        runs_dir: str | Path | None = None,
        workers: int | None = None,
        registry=None,
    ):
        super().__init__()
        self.preset_path = Path(preset) if preset else None
        self.presets_dir = Path(presets_dir) if presets_dir else None
        self.runs_dir = Path(runs_dir) if runs_dir else default_runs_dir()
        self.run_workers = workers
        self.registry = registry or default_registry()
        self.draft_path: Path | None = None
        self.draft_source: Path | None = None  # the file the draft was read from: its comments are kept
        self.modified = False
        self.problems: list[str] = []
        self.presets = []
        self.runs = []
        self.overlay: list = []
        self.cancel_event: threading.Event | None = None
        self.last_outcome = None
        self.last_out_dir: Path | None = None
        self.run_error: str | None = None
        self.last_snapshot: Snapshot | None = None
        self.last_sweep = None  # sweep.SweepOutcome of the last sweep run here
        self.open_sweep: SweepEntry | None = None  # the sweep whose points the Results tab shows

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
        yield Footer()

    async def on_mount(self) -> None:
        table = self.query_one("#preset-table", DataTable)
        table.add_columns("name", "folder", "file")
        runs = self.query_one("#runs-table", DataTable)
        runs.add_column("", width=1, key="status")
        runs.add_column("run", width=17)
        runs.add_column("a", width=7)
        runs.add_column("b", width=7)
        self.reload_presets()
        self.reload_runs()
        self._show_edit_title()
        if self.preset_path is not None:
            await self.open_preset(self.preset_path)
        else:
            table.focus()

    @property
    def folders(self):
        return preset_folders(self.presets_dir)

    @property
    def running(self) -> bool:
        return self.cancel_event is not None

    # ------------------------------------------------------------ navigation and help

    def action_show_tab(self, tab: str) -> None:
        self.query_one("#tabs", TabbedContent).active = tab
        focus = {
            "presets": "#preset-table",
            "edit": "#form",
            "run": "#run-pane",
            "results": "#runs-table",
        }[tab]
        widget = self.query_one(focus)
        if tab == "edit":
            fields = [w for w in widget.query("Input, Select, Switch") if w.focusable]
            widget = fields[0] if fields else widget
        widget.focus()

    def on_tabbed_content_tab_activated(self, event: TabbedContent.TabActivated) -> None:
        self.refresh_bindings()

    def help_groups(self) -> list[tuple[str, list[tuple[str, str]]]]:
        def rows(bindings):
            out = []
            for binding in bindings:
                for key in binding.key.split(","):
                    description = binding.tooltip or binding.description
                    out.append((self.get_key_display(Binding(key, binding.action)), description))
            return out

        return [
            ("Everywhere", rows(self.BINDINGS)),
            (
                "Presets tab (the list)",
                rows(ListTable.BINDINGS) + rows(PresetsPane.BINDINGS) + [("Up/Down", "Move in the list")],
            ),
            (
                "Edit tab (the form)",
                [
                    ("Tab/Shift+Tab", "Next / previous field"),
                    ("Enter", "Open a choice list (on a select)"),
                    ("Space", "Toggle a switch"),
                ],
            ),
            ("Run tab", rows(RunPane.BINDINGS)),
            ("Results tab (the list)", rows(ListTable.BINDINGS) + rows(ResultsPane.BINDINGS)),
            ("Dialogs", [("Enter", "Confirm"), ("Esc", "Cancel / close"), ("y / n", "Yes / no")]),
        ]

    def action_help(self) -> None:
        if not isinstance(self.screen, HelpScreen):
            self.push_screen(HelpScreen(self.help_groups()))

    # ------------------------------------------------------------ presets

    def reload_presets(self) -> None:
        self.presets = list_presets(self.folders)
        table = self.query_one("#preset-table", DataTable)
        table.clear()
        for entry in self.presets:
            table.add_row(entry.name, entry.label, entry.path.name)
        if not self.presets:
            folders = ", ".join(str(f) for _, f in self.folders)
            self.query_one("#preset-info", Static).update(f"No presets in {folders}. n makes a new one.")
        else:
            self._show_preset_info(0)

    def _show_preset_info(self, row: int) -> None:
        if 0 <= row < len(self.presets):
            entry = self.presets[row]
            text = entry.error or entry.description or "(no description)"
            self.query_one("#preset-info", Static).update(f"{entry.path}\n{text}")

    def on_data_table_row_highlighted(self, event: DataTable.RowHighlighted) -> None:
        if event.data_table.id == "preset-table":
            self._show_preset_info(event.cursor_row)

    def on_data_table_row_selected(self, event: DataTable.RowSelected) -> None:
        if event.data_table.id == "preset-table":
            self.open_selected_preset()
        elif event.data_table.id in ("runs-table", "results-sweep"):
            self.open_selected_run(overlay=False)

    def _selected_preset(self):
        row = self.query_one("#preset-table", DataTable).cursor_row
        return self.presets[row] if 0 <= row < len(self.presets) else None

    def open_selected_preset(self) -> None:
        entry = self._selected_preset()
        if entry is not None:
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
                self.notify("\n".join(exc.problems), title=f"Cannot open {path.name}", severity="error")
                return
            self.draft_source = path
        else:
            self.draft_source = None
        self.draft_path = path
        await self.query_one("#form", PresetForm).load(data)
        self.modified = modified
        self._show_edit_title()
        self.action_show_tab("edit")

    def duplicate_selected_preset(self) -> None:
        entry = self._selected_preset()
        if entry is None:
            return
        try:
            data = load_preset_file(entry.path)
        except PresetError as exc:
            self.notify("\n".join(exc.problems), title="Cannot duplicate", severity="error")
            return
        data["name"] = f"{data.get('name') or entry.path.stem}-copy"
        default = writable_folder(self.folders) / f"{entry.path.stem}-copy.yaml"

        def done(path: Path | None) -> None:
            if path is not None:
                self._write(path, data, then_open=True, template=entry.path)

        self.push_screen(PathScreen(f"Duplicate {entry.path.name} as", default), done)

    def new_preset(self) -> None:
        def done(answer) -> None:
            if answer is None:
                return
            name, spectrum = answer
            data = preset_from_defaults(name, spectrum, self.registry)
            path = writable_folder(self.folders) / f"{name}.yaml"
            self.run_worker(self.open_preset(path, data, modified=True), group="open")

        self.push_screen(NewPresetScreen(self.registry.names("spectrum")), done)

    # ------------------------------------------------------------ editing and saving

    def on_preset_form_edited(self, event: PresetForm.Edited) -> None:
        self.problems = event.problems
        if event.changed:
            self.modified = True
        self._show_edit_title()
        panel = self.query_one("#problems", Static)
        if event.problems:
            count = len(event.problems)
            panel.update(
                f"[b]{count} problem{'s' if count != 1 else ''}[/b] (as frictionlab validate says):\n"
                + "\n".join(event.problems)
            )
            panel.set_class(True, "-invalid")
        else:
            panel.update("valid: Ctrl+R runs it, Ctrl+S saves it")
            panel.set_class(False, "-invalid")
        self.refresh_bindings()

    def on_preset_form_field_focused(self, event: PresetForm.FieldFocused) -> None:
        spec = event.spec
        text = "" if spec is None else f"{spec.dotted}: " + spec.tooltip().replace("\n", "; ")
        self.query_one("#field-help", Static).update(text)

    def _show_edit_title(self) -> None:
        title = self.query_one("#edit-title", Static)
        if self.draft_path is None:
            title.update("No preset open")
            return
        state = "modified" if self.modified else "saved"
        problems = f", {len(self.problems)} problem(s)" if self.problems else ""
        title.update(f"[b]{self.draft_path.name}[/b]  ({state}{problems})")

    def check_action(self, action: str, parameters) -> bool | None:
        if action in ("save", "save_as"):
            # shown on the Edit tab only: the footer has no room for keys that do nothing here
            return self.draft_path is not None and self.query_one("#tabs", TabbedContent).active == "edit"
        if action == "start_run" and self.draft_path is None:
            return None  # shown, dimmed
        return True

    def _draft(self) -> dict | None:
        return self.query_one("#form", PresetForm).data

    def action_save(self) -> None:
        if self.draft_path is None or self._draft() is None:
            self.notify("No preset open: F2 lists them.", severity="warning")
            return
        self._save_checked(self.draft_path)

    def action_save_as(self) -> None:
        if self.draft_path is None or self._draft() is None:
            self.notify("No preset open: F2 lists them.", severity="warning")
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
            save_preset(path, data, template=template)
        except OSError as exc:
            self.notify(f"{path}: {exc.strerror or exc}", title="Not saved", severity="error")
            return
        self.notify(f"Saved {path}")
        self.reload_presets()
        if then_open:
            self.run_worker(self.open_preset(path), group="open")
        else:
            self.draft_path = self.draft_source = path
            self.modified = False
            self._show_edit_title()

    # ------------------------------------------------------------ running

    def action_start_run(self) -> None:
        if self.running:
            self.notify("A run is going; c on the Run tab cancels it.", severity="warning")
            return
        data = self._draft()
        if data is None:
            self.notify("No preset open: F2 lists them.", severity="warning")
            return
        try:
            if self.draft_path is not None:  # relative input files are the preset file's neighbours
                data = resolve_input_paths(data, self.draft_path.parent, self.registry)
            scene = build_scene(data, registry=self.registry)
            sweep = None
            if getattr(scene.preset, "sweep", None) is not None:  # every point is checked before any runs
                source = str(self.draft_path) if self.draft_path else None
                sweep = plan_sweep(data, registry=self.registry, source=source)
        except PresetError as exc:
            count = len(exc.problems)
            self.notify(
                "\n".join(exc.problems[:5]),
                title=f"Cannot run: {count} problem{'s' if count != 1 else ''}",
                severity="error",
            )
            self.action_show_tab("edit")
            return
        out_dir = new_run_folder(self.runs_dir, scene.preset.name)
        self.cancel_event = threading.Event()
        self.run_error = None
        self.last_outcome = self.last_sweep = None
        pane = self.query_one("#run-pane", RunPane)
        pane.set_class(sweep is not None, "-sweep")
        if sweep is not None:
            self._start_sweep(sweep, out_dir, pane)
            return
        preset = scene.preset
        pane.query_one("#run-title", Static).update(
            f"[b]{preset.name}[/b]: {preset.realizations} realizations, {preset.loading.steps} "
            f"{preset.loading.control} steps -> {out_dir.parent.name}/{out_dir.name}"
        )
        pane.query_one("#run-bar", ProgressBar).update(total=preset.realizations, progress=0)
        pane.query_one("#run-error", Static).update("")
        self.action_show_tab("run")
        self.run_worker(
            partial(self._run_in_thread, scene, out_dir, self.cancel_event),
            thread=True,
            group="run",
            exit_on_error=False,
        )

    def _run_in_thread(self, scene, out_dir: Path, cancel: threading.Event) -> None:
        listener = LiveListener(lambda snapshot: self.post_message(RunProgress(snapshot)))
        try:
            outcome, _ = run_to_folder(scene, out_dir, workers=self.run_workers, listeners=[listener], cancel=cancel)
        except FrictionlabError as exc:
            self.post_message(RunCrashed(str(exc)))
        except OSError as exc:
            self.post_message(RunCrashed(f"cannot write results to {out_dir}: {exc}"))
        except Exception as exc:  # an internal error: shown, never a crash of the UI
            self.post_message(RunCrashed(f"internal error: {type(exc).__name__}: {exc}"))
        else:
            self.post_message(RunDone(scene, outcome, out_dir))

    def _start_sweep(self, sweep, out_dir: Path, pane: RunPane) -> None:
        preset = sweep.points[0].scene.preset
        pane.query_one("#run-title", Static).update(
            f"[b]{sweep.name}[/b]: {len(sweep.points)} points x {preset.realizations} realizations"
            f" -> {out_dir.parent.name}/{out_dir.name}"
        )
        pane.query_one("#sweep-point", Static).update(f"{sweep.spec.mode} over {', '.join(sweep.paths)}")
        pane.query_one("#run-bar", ProgressBar).update(total=preset.realizations, progress=0)
        pane.query_one("#run-stats", Static).update("")
        pane.query_one("#run-error", Static).update("")
        table = pane.query_one("#sweep-table", DataTable)
        table.clear(columns=True)
        table.add_columns(*table_columns(sweep.paths))
        self.action_show_tab("run")
        self.run_worker(
            partial(self._sweep_in_thread, sweep, out_dir, self.cancel_event),
            thread=True,
            group="run",
            exit_on_error=False,
        )

    def _sweep_in_thread(self, sweep, out_dir: Path, cancel: threading.Event) -> None:
        poster = SweepPoster(lambda kind, point, result: self.post_message(SweepEvent(sweep, kind, point, result)))

        def point_listeners(point):
            return [LiveListener(lambda snapshot: self.post_message(RunProgress(snapshot)))]

        try:
            outcome = run_sweep(
                sweep,
                out_dir,
                workers=self.run_workers,
                listeners=[poster],
                point_listeners=point_listeners,
                cancel=cancel,
            )
        except OSError as exc:
            self.post_message(RunCrashed(f"cannot write results to {out_dir}: {exc}"))
        except Exception as exc:  # an internal error: shown, never a crash of the UI
            self.post_message(RunCrashed(f"internal error: {type(exc).__name__}: {exc}"))
        else:
            self.post_message(SweepDone(sweep, outcome, out_dir))

    def on_sweep_event(self, message: SweepEvent) -> None:
        pane = self.query_one("#run-pane", RunPane)
        if message.kind == "started":
            total = message.point.scene.preset.realizations
            pane.query_one("#sweep-point", Static).update(point_line(message.sweep, message.point))
            pane.query_one("#run-bar", ProgressBar).update(total=total, progress=0)
            return
        result = message.result
        pane.query_one("#sweep-table", DataTable).add_row(*table_cells(message.sweep, result))
        if result.error:
            pane.query_one("#run-error", Static).update(f"[red]point {result.point.number}: {result.error}[/red]")

    def on_sweep_done(self, message: SweepDone) -> None:
        outcome = message.outcome
        self.cancel_event = None
        self.last_sweep, self.last_out_dir = outcome, message.out_dir
        finished = sum(r.status != "pending" for r in outcome.results)
        pane = self.query_one("#run-pane", RunPane)
        pane.query_one("#sweep-point", Static).update(
            f"{outcome.status}: {finished}/{len(outcome.results)} points in {_duration(outcome.elapsed)}"
            " (sweep.csv, sweep.png)"
        )
        self.notify(f"Sweep {outcome.status}: {finished}/{len(outcome.results)} points")
        self.reload_runs()

    def action_cancel_run(self) -> None:
        if not self.running:
            self.notify("No run is going.", severity="warning")
            return
        self.cancel_event.set()
        self.query_one("#run-stats", Static).update("cancelling: the realizations already running finish and are kept")

    def on_run_progress(self, message: RunProgress) -> None:
        snap = self.last_snapshot = message.snapshot
        pane = self.query_one("#run-pane", RunPane)
        pane.query_one("#run-bar", ProgressBar).update(total=snap.total, progress=snap.done)
        failed = f", {snap.failed} failed" if snap.failed else ""
        left = _duration(snap.seconds_left) if math.isfinite(snap.seconds_left) else "?"
        if not (self.cancel_event is not None and self.cancel_event.is_set()):
            pane.query_one("#run-stats", Static).update(
                f"{snap.done}/{snap.total} realizations{failed}, {snap.rate:.1f}/s, "
                f"elapsed {_duration(snap.elapsed)}, left {left}"
            )
        if snap.f is not None:
            series = [Series(snap.f, snap.xi, "cyan")]
            if snap.fit is not None:
                series.append(_fit_series(snap.f, snap.fit.a, snap.fit.b, "yellow"))
            pane.query_one("#run-chart", Chart).show(series)
            lines = fit_lines(snap.fit, final=False, f_formula=snap.f_formula)
            lines += _contact_lines(snap.contact_count)
            pane.query_one("#run-fit", Static).update("\n".join(lines))
        if snap.first_error:
            pane.query_one("#run-error", Static).update(f"[red]{snap.first_error}[/red]")

    def on_run_done(self, message: RunDone) -> None:
        outcome = message.outcome
        self.cancel_event = None
        self.last_outcome, self.last_out_dir = outcome, message.out_dir
        pane = self.query_one("#run-pane", RunPane)
        pane.query_one("#run-bar", ProgressBar).update(total=outcome.requested, progress=outcome.done)
        pane.query_one("#run-stats", Static).update(
            f"{outcome.status}: {outcome.done}/{outcome.requested} realizations in {_duration(outcome.elapsed)}"
            f", {outcome.workers} worker{'s' if outcome.workers != 1 else ''}"
        )
        if outcome.fit is not None:
            series = [
                Series(outcome.f, outcome.xi, "cyan"),
                _fit_series(outcome.f, outcome.fit.a, outcome.fit.b, "yellow"),
            ]
            pane.query_one("#run-chart", Chart).show(series)
        lines = fit_lines(outcome.fit, final=True, f_formula=outcome.normalisation.formula)
        lines += _contact_lines(outcome.contact_count)
        pane.query_one("#run-fit", Static).update("\n".join(lines))
        if outcome.failures or outcome.error:
            first = outcome.error or f"#{outcome.failures[0][0]}: {outcome.failures[0][1]}"
            pane.query_one("#run-error", Static).update(
                f"[red]{len(outcome.failures)} realization(s) failed; {first}[/red]"
            )
        self.notify(f"Run {outcome.status}: {outcome.done}/{outcome.requested} realizations")
        self.reload_runs()

    def on_run_crashed(self, message: RunCrashed) -> None:
        self.cancel_event = None
        self.run_error = message.error
        self.query_one("#run-error", Static).update(f"[red]run failed: {message.error}[/red]")
        self.notify(message.error, title="Run failed", severity="error")

    async def action_quit(self) -> None:
        if self.running:
            self.cancel_event.set()  # what finished is still written by the run thread
        if self.modified:
            self.push_screen(
                ConfirmScreen("The open preset has unsaved changes. Quit anyway?"),
                lambda yes: yes and self.exit(),
            )
            return
        self.exit()

    # ------------------------------------------------------------ results

    def reload_runs(self) -> None:
        self.runs = list_runs(self.runs_dir)
        table = self.query_one("#runs-table", DataTable)
        table.clear()
        for entry in self.runs:
            if isinstance(entry, SweepEntry):
                a, b = "sweep", f"{len(entry.points)} pts"
            else:
                a = f"{entry.a:.4f}" if math.isfinite(entry.a) else "-"
                b = f"{entry.b:.4f}" if math.isfinite(entry.b) else "-"
            table.add_row(STATUS_MARKS.get(entry.status, "?"), entry.path.name, a, b)

    def open_selected_run(self, overlay: bool) -> None:
        """Enter/Space on the list of runs, or on the open sweep's table of points."""
        points = self.query_one("#results-sweep", DataTable)
        if points.has_focus and self.open_sweep is not None:
            row = points.cursor_row
            if not 0 <= row < len(self.open_sweep.points):
                return
            folder = self.open_sweep.point_folder(self.open_sweep.points[row])
            try:
                entry = read_run(folder)
            except (OSError, ValueError, TypeError):
                self.notify(f"{folder.name}: this point has no finished run", severity="warning")
                return
        else:
            row = self.query_one("#runs-table", DataTable).cursor_row
            if not 0 <= row < len(self.runs):
                return
            entry = self.runs[row]
            if isinstance(entry, SweepEntry):
                if not overlay:
                    self._show_sweep(entry)
                return
        if overlay:
            paths = [e.path for e in self.overlay]
            if entry.path in paths:
                self.overlay = [e for e in self.overlay if e.path != entry.path]
            else:
                self.overlay = (self.overlay + [entry])[-len(OVERLAY_STYLES):]
        else:
            self.overlay = [entry]
        self._show_overlay()

    def _show_sweep(self, entry: SweepEntry) -> None:
        """The sweep's table of points, formatted as the Run tab formats a live sweep."""
        self.open_sweep = entry
        table = self.query_one("#results-sweep", DataTable)
        table.clear(columns=True)
        table.add_columns(*table_columns(entry.paths))
        for row in entry.points:
            table.add_row(*row_cells(entry.paths, row))
        self.query_one("#results-pane", ResultsPane).set_class(True, "-sweep")
        self.query_one("#results-info", Static).update(
            f"sweep {entry.name}: {entry.status}, {len(entry.points)} points.\n"
            "Enter on a point opens its run; Space adds it to the overlay."
        )
        table.focus()

    def _show_overlay(self) -> None:
        series, lines = [], []
        for style, entry in zip(OVERLAY_STYLES, self.overlay):
            try:
                curve = read_curve(entry.path)
            except (OSError, ValueError, KeyError) as exc:
                lines.append(f"[{style}]{entry.path.name}[/]: no curve ({exc})")
                continue
            f, xi = np.array(curve.get("f", []), float), np.array(curve.get("xi", []), float)
            series.append(Series(f, xi, style))
            if math.isfinite(entry.a):
                series.append(_fit_series(f, entry.a, entry.b, f"dim {style}"))
            fit = entry.fit or {}
            counts = entry.summary.get("contact_count_at_first_load"), entry.summary.get("contact_count_at_last_load")
            formula = (entry.summary.get("normalisation") or {}).get("formula")
            lines.append(f"[{style}]■ {entry.path.name}[/]" + (f" f = {formula}" if formula else ""))
            contacts = f", contacts {counts[0]:.3g}..{counts[1]:.3g}" if counts[0] is not None else ""
            lines.append(f"  {entry.status} {entry.done}/{entry.requested}{contacts}")
            if fit:
                lines.append(
                    f"  a={fit.get('a', math.nan):.4f} {_interval(tuple(fit.get('a_ci') or (None, None)))}"
                    f" R^2={fit.get('r2', math.nan):.4f}"
                )
                lines.append(f"  b={fit.get('b', math.nan):.4f} {_interval(tuple(fit.get('b_ci') or (None, None)))}")
        self.query_one("#results-chart", Chart).show(series)
        info = "\n".join(lines) if lines else "Enter opens a run; Space adds it to the overlay."
        self.query_one("#results-info", Static).update(info)


def _contact_lines(count) -> list[str]:
    if count is None or not np.size(count):
        return []
    return ["", "points in contact", f"  {count[0]:.2f} at first load", f"  {count[-1]:.2f} at last load"]
