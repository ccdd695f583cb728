"""Parameter sweeps: one full ensemble per point of a preset's ``sweep`` section.

A point is the preset with the swept dotted paths set (``preset.apply_overrides``, then the usual two-phase
validation) and the ``sweep`` section removed; the seed is the preset's, so a point is reproducible on its own::

    frictionlab run PRESET --set sweep=null --set spectrum.params.hurst=0.7

Every point runs through ``runner.run_to_folder`` (the single run path) into ``<out>/points/<NN>-<label>/``.
``sweep.csv`` (a row per point, rewritten atomically as points finish), ``sweep.json``, ``sweep.png`` sit in ``<out>``.

Front ends follow a sweep through ``listeners.SweepListener``s; each point's run tells the run listeners that
``SweepListener.run_listeners(point)`` gives.
"""

from __future__ import annotations

import os
import re
import threading
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from ..compute.dask_session import one_dask_cluster
from ..errors import (FrictionlabError, OutputRefused, PresetError, RunError, RunFolderError, command_word, counted,
                      short_repr, shown_name)  # fmt: skip
from ..compute.fit import LogFit, json_safe
from ..plugin.listeners import SweepListener
from ..options import RunOptions
from ..plugin import KINDS
from ..preset import Preset, Scene, SweepSettings, apply_overrides, build_scene, read_preset, yaml_scalar
from ..preset.schema import ensemble_settings, first_repeat
from ..preset.problems import fold_point_problems
from ..plugin.registry import Registry, default_registry
from .import_ahead import PLOT_MODULE, imported
from .figures import write_figure
from .rundir import STATE_FILE, RunDirectory
from .runfolder import make_subfolder, refuse_nothing_to_resume
from .sweepfiles import RESULT_COLUMNS, check_sweep_folder, completed_rows, stored_sweep, write_tables
from .sweeprecord import combinations, folder_name, read_sweep_record
from ..compute.memory import estimate
from .runner import check_memory, read_back, run_to_folder

UNFINISHED = ("pending", "interrupted", "cancelled")  # a point's statuses that do not count it as done


# ------------------------------------------------------------------ planning


@dataclass(frozen=True)
class SweepPoint:
    """One point: its 1-based number, the swept values and the validated scene."""

    number: int
    values: dict[str, Any]
    folder_name: str
    scene: Scene

    @property
    def assignments(self) -> list[str]:
        """The ``--set`` options that reproduce this point from the preset."""
        return [f"{path}={yaml_scalar(v)}" for path, v in self.values.items()]

    def describe(self) -> str:
        """Its assignments as messages and tables show them, each cut past 80 characters (a swept
        description of pages said them whole, in each message naming the point)."""
        return ", ".join(a if len(a) <= 80 else a[:77] + "..." for a in self.assignments)

    def __repr__(self) -> str:  # its scene, every default filled in, is too long to read
        return f"<SweepPoint {self.number}: {self.describe()}, folder {self.folder_name!r}>"


@dataclass(frozen=True)
class Sweep:
    """A planned sweep: the base preset data (overrides applied), its spec and every point."""

    name: str
    spec: SweepSettings
    base: dict
    points: list[SweepPoint]
    source: str | None = None

    @classmethod
    def recorded(cls, out_dir: Path) -> Sweep:
        """The sweep that the sweep.json in ``out_dir`` records, without its points: its name, spec
        and base preset, what names and scales sweep.png's axes (read as untrusted input:
        ``read_sweep_record``, a RunFolderError naming the file and the field); its name cut as a
        title is (``figures.SHOWN_LABEL_CHARS``: one of 300000 characters took 40 s to draw)."""
        from .figures import SHOWN_LABEL_CHARS, cut

        summary, record = read_sweep_record(out_dir)
        spec = SweepSettings.model_validate(summary["sweep"])
        return cls(cut(record.name, SHOWN_LABEL_CHARS), spec, summary["base_preset"], points=[])

    @property
    def paths(self) -> list[str]:
        return list(self.spec.parameters)

    @property
    def preset_data(self) -> dict:
        """The preset data this sweep is planned from (``plan_sweep`` takes it), as sweep.json stores it."""
        return {**self.base, "sweep": self.spec.model_dump(mode="json", exclude_none=True)}

    def axis_label(self, path: str) -> str:
        """What a swept ``path`` is, for a figure: the head of its field's description
        (``spectrum.params.hurst``: "Hurst exponent H"), else its last key."""
        keys = path.split(".")
        field = None
        if len(keys) == 3 and keys[1] == "params":
            params = self._params_model(keys[0])
            field = params.model_fields.get(keys[2]) if params is not None else None
        else:
            model = Preset
            for key in keys:
                field = model.model_fields.get(key) if model is not None else None
                model = _model_of(field.annotation) if field is not None else None
        head = re.split(r"[:;(,]", (field.description or "") if field is not None else "")[0].strip()
        return head if 0 < len(head) <= 40 else keys[-1].replace("_", " ")

    def _params_model(self, section: str) -> type[BaseModel] | None:
        """The Params of the plugin in ``section``: a point's, else (a sweep read back
        from its folder, without points) the installed plugin the base preset names."""
        if self.points:
            plugin = self.points[0].scene.plugins().get(section)
            return type(plugin.params) if plugin is not None else None
        chosen = self.base.get(section)
        name = chosen.get("name") if isinstance(chosen, dict) else None  # a sweep.json's base preset: untrusted
        try:
            return default_registry().get(section, name).Params if isinstance(name, str) else None
        except FrictionlabError:  # not installed (any more): the figure names the field by its key
            return None


def _model_of(annotation) -> type[BaseModel] | None:
    for arg in (annotation, *getattr(annotation, "__args__", ())):  # Model, or Optional[Model]
        if isinstance(arg, type) and issubclass(arg, BaseModel):
            return arg
    return None


def path_problem(path: str, data: dict, spec: SweepSettings, registry: Registry) -> str | None:
    """Why ``path`` cannot be swept (unknown field, a section, ``sweep`` itself), or None."""
    where = f"sweep.parameters.{path}"
    keys = path.split(".")
    if not all(k.strip() for k in keys):
        return f"{where}: must be a dotted path like spectrum.params.hurst"
    if keys[0] == "sweep":
        return f"{where}: a sweep cannot sweep its own sweep section"
    model: type[BaseModel] | None = Preset
    for depth, key in enumerate(keys):
        done = ".".join(keys[:depth]) or "the preset"
        if model is None:
            return f"{where}: {done} is a value, not a section"
        if key not in model.model_fields:
            allowed = ", ".join(sorted(k for k in model.model_fields if k != "sweep"))
            return f"{where}: {done} has no field {key!r}; allowed: {allowed}"
        if depth == 1 and keys[0] in KINDS and key == "params":
            return _plugin_param_problem(where, keys, data, spec, registry)
        model = _model_of(model.model_fields[key].annotation)
    if model is not None:
        return f"{where}: {path} is a section; sweep one of its values ({', '.join(model.model_fields)})"
    return None


def _plugin_param_problem(where, keys, data, spec, registry) -> str | None:
    slot = keys[0]
    if len(keys) != 3:
        return f"{where}: must name one parameter, like {slot}.params.<name>"
    names = {(data.get(slot) or {}).get("name")} if isinstance(data.get(slot), dict) else set()
    swept = spec.parameters.get(f"{slot}.name")
    if swept is not None:
        names = set(swept.points())
    known: set[str] = set()
    for name in names:
        try:
            known |= set(registry.get(slot, str(name)).Params.model_fields)
        except Exception:  # an unknown plugin name is reported when the points are validated
            return None
    if keys[2] not in known:
        return f"{where}: the {slot} plugin has no parameter {keys[2]!r}; allowed: {', '.join(sorted(known))}"
    return None


def plan_sweep(data: dict, registry: Registry | None = None, source: str | None = None, before_reading=None) -> Sweep:
    """Expand preset data with a ``sweep`` section into validated points, each checked by ``before_reading``.
    Every problem of every point is reported at once (``sweep point N (path=value): ...``); nothing runs unless
    every point is valid, and no two points are one preset."""
    registry = registry or default_registry()
    base_preset = build_scene(data, registry=registry, source=source).preset  # the base and the spec itself
    spec = base_preset.sweep
    if spec is None:
        raise PresetError(["sweep: the preset has no sweep section"], source=source)
    problems = [p for p in (path_problem(path, data, spec, registry) for path in spec.parameters) if p]
    if problems:
        raise PresetError(problems, source=source)
    base = {k: v for k, v in data.items() if k != "sweep"}
    combos = combinations(spec)
    points, problems = [], []
    for number, values in enumerate(combos, start=1):
        try:
            assignments = [f"{path}={yaml_scalar(v)}" for path, v in values.items()]
            scene = build_scene(apply_overrides(base, assignments), registry=registry, before_reading=before_reading)
        except PresetError as exc:
            problems += [(number, _point_named(number, values), p) for p in exc.problems]
            continue
        except RunError as exc:  # the memory check: the point named, before any point runs
            raise RunError(f"{_point_named(number, values)}: {exc}") from None
        folder = folder_name(number, len(combos), values)
        points.append(SweepPoint(number=number, values=values, folder_name=folder, scene=scene if scene.input_files() else scene.for_pressing()))
    problems = fold_point_problems(problems)
    if not problems and (pair := first_repeat([ensemble_settings(p.scene.resolved()) for p in points])) is not None:
        one, two = (points[i] for i in pair)  # seed 1 and '1': one preset once read, which the values' check cannot see
        problems = [f"sweep points {one.number} ({one.describe()}) and {two.number} ({two.describe()}) are one preset "
                    "once read, name, description and output aside: the same ensemble would run twice; give each value once"]
    if problems:
        raise PresetError(problems, source=source)
    return Sweep(name=base_preset.name, spec=spec, base=base, points=points, source=source)


def _point_named(number: int, values: dict[str, Any]) -> str:
    shown = ", ".join(f"{path}={short_repr(v)}" for path, v in values.items())  # a value may be any length
    return f"sweep point {number} ({shown})"


def check_sweep_memory(sweep: Sweep, options: RunOptions) -> None:
    """Refuse (RunError), before the first point runs, a sweep one of whose points does not fit
    in memory (each point's run checks it again as it starts): not halfway, its first points
    run. The largest point is checked first, so the advice of a refusal fits every point."""
    if not options.memory_check:
        return
    for point in sorted(sweep.points, key=lambda p: -estimate(p.scene, workers=1, executor="serial").total):
        try:
            check_memory(point.scene, options)
        except RunError as exc:
            raise RunError(f"{_point_named(point.number, point.values)}: {exc}") from None


def load_sweep(path: str | Path, overrides: Iterable[str] = (), registry: Registry | None = None) -> Sweep:
    """A preset file, or a built-in's name (``"benad2012-fig5"``), with ``--set`` overrides
    applied -> planned Sweep (the preset must have a sweep section)."""
    from ..preset.builtin import locate_preset

    resolved, source = locate_preset(path)
    return plan_sweep(read_preset(resolved, list(overrides), registry), registry=registry, source=source)


# ------------------------------------------------------------------ running


@dataclass
class PointResult:
    """What one point gave: its status, fit and contact counts (from the run's outcome)."""

    point: SweepPoint
    status: str  # completed | cancelled | interrupted | failed | error | pending
    folder: Path
    outcome: Any = None  # ensemble.RunOutcome
    error: str | None = None
    recorded: dict[str, Any] | None = None  # a row read back (a followed sweep's): stands for ``outcome``

    @property
    def failure(self) -> str:
        """Why this point makes its sweep failed, "" where it does not: its error (a point failed
        or in error), or its realizations that failed (a point completed without them)."""
        if self.status in ("failed", "error") or (self.recorded is not None and self.error):  # a kept row: its point's error
            return self.error or self.status
        failures = self.outcome.failures if self.outcome is not None else ()
        return f"{counted(len(failures), 'realization')} failed, the first: {failures[0][1]}" if failures else ""

    @property
    def fit(self) -> LogFit | None:
        """The point's fit of xi = a + b ln f; None where it has none (or only a row read back)."""
        return None if self.outcome is None else self.outcome.fit

    def held(self) -> PointResult:
        """This result as a sweep holds it till its end: without each realization's curves (they are
        in the point's realizations.npz), else a sweep's memory grows by them at every point."""
        return self if self.outcome is None else replace(self, outcome=replace(self.outcome, per_realization={}))

    def row(self) -> dict[str, Any]:
        if self.recorded is not None:
            return {**self.recorded, "point": self.point.number, "label": self.point.folder_name, **self.point.values}
        row: dict[str, Any] = {"point": self.point.number, "label": self.point.folder_name}
        row.update(self.point.values)
        row.update({k: None for k in RESULT_COLUMNS})
        row.update(status=self.status, folder=f"points/{self.point.folder_name}")
        o = self.outcome
        if o is not None:
            row.update(done=o.done, elapsed_s=round(o.elapsed, 3))
            if o.fit is not None:
                f = o.fit
                row.update(a=f.a, a_lo=f.a_ci[0], a_hi=f.a_ci[1], b=f.b, b_lo=f.b_ci[0], b_hi=f.b_ci[1], r2=f.r2)
            if o.done:
                row.update(contact_first=float(o.contact_count[0]), contact_last=float(o.contact_count[-1]))
        return {k: json_safe(v) if isinstance(v, float) else v for k, v in row.items()}


def row_fit(row: dict[str, Any]) -> LogFit | None:
    """The fit of a point from its row (``PointResult.row()``, or a row of sweep.json), None without one."""
    if row["a"] is None:
        return None
    return LogFit.from_dict({"a": row["a"], "b": row["b"], "a_ci": [row["a_lo"], row["a_hi"]],
                             "b_ci": [row["b_lo"], row["b_hi"]], "r2": row["r2"]})  # fmt: skip


@dataclass
class SweepOutcome:
    status: str  # running (until it ends) | completed | interrupted | failed (some point failed)
    results: list[PointResult]
    elapsed: float
    files: dict[str, Path] = field(default_factory=dict)

    @property
    def rows(self) -> list[dict[str, Any]]:
        return [r.row() for r in self.results]


def point_folder(out_dir: str | Path, point: SweepPoint) -> Path:
    """Where ``point`` runs in the sweep's folder ``out_dir``."""
    return Path(out_dir) / "points" / point.folder_name


def _run_points(
    sweep: Sweep, out_dir: Path, options: RunOptions, listeners: list[SweepListener], cancel, plot: bool = True
) -> Iterator[PointResult]:
    """Run the points in order, yielding each PointResult as it finishes.

    Stops after a point that was cancelled or interrupted (what finished is
    written); a point that raises a FrictionlabError is recorded as ``error``
    and the sweep goes on.
    """
    for point in sweep.points:
        folder = point_folder(out_dir, point)
        if cancel.is_set():
            return
        for listener in listeners:
            listener.point_started(sweep, point)
        try:  # points/ and the point's folder: made here, never a link to elsewhere
            make_subfolder(out_dir, f"points/{point.folder_name}")
        except RunFolderError as exc:
            yield PointResult(point, "error", folder, error=f"{exc}: remove the link, then resume the sweep")
            continue
        run_listeners = [each for listener in listeners for each in listener.run_listeners(point)]
        started = (folder / STATE_FILE).exists()  # a resumed sweep starts afresh the points it never reached
        finished = read_back(point.scene, folder, run_listeners, plot) if started and options.resume else None
        if finished is not None:
            yield PointResult(point, finished.status, folder, outcome=finished, error=finished.error)
            continue
        point_options = options if started or not options.resume else replace(options, resume=False)
        try:
            outcome, _ = run_to_folder(
                point.scene, folder, point_options, listeners=run_listeners, cancel=cancel, plot=plot
            )
        except FrictionlabError as exc:  # a folder not this point's run's: a resume meets it again unless moved
            hint = f"; move {shown_name(folder)} aside, then resume the sweep to compute the point afresh" if isinstance(
                exc, (RunFolderError, OutputRefused)) else ""  # fmt: skip
            yield PointResult(point, "error", folder, error=f"{exc}{hint}")
            continue
        yield PointResult(point, outcome.status, folder, outcome=outcome, error=outcome.error)
        if outcome.status in ("cancelled", "interrupted"):
            return


def run_sweep(
    sweep: Sweep,
    out_dir: str | Path,
    options: RunOptions = RunOptions(),
    *,
    listeners: Iterable[SweepListener] = (),
    cancel=None,
    plot: bool = True,
) -> SweepOutcome:
    """Run every point as ``options`` say, telling ``listeners`` (``listeners.SweepListener``), and
    keep ``sweep.csv``/``sweep.json`` current; draw ``sweep.png`` at the end (and each point's plot.png)
    unless ``plot`` is False. ``out_dir`` must be new, empty or a folder of this same sweep unless
    ``options.force``. It holds the folder's lock (``run.lock``) while it runs, and its sweep.json says
    "running" until the end: a sweep whose process died reads as interrupted (``detached.run_state``)."""
    out_dir = Path(out_dir)
    if options.resume:
        refuse_nothing_to_resume(out_dir)
    check_sweep_folder(sweep, out_dir, options.force, options.resume)
    check_sweep_memory(sweep, options)
    listeners = list(listeners)
    cancel = threading.Event() if cancel is None else cancel
    started = time.perf_counter()
    results = {p.number: PointResult(p, "pending", point_folder(out_dir, p)) for p in sweep.points}
    outcome = SweepOutcome(status="running", results=list(results.values()), elapsed=0.0)
    with RunDirectory(out_dir):  # its lock: one sweep at a time here, and a dead one reads as interrupted
        kept = completed_rows(out_dir) if options.resume else {}  # a finished row stays so where its point is not read back
        try:  # every point's folder is in points/: a file or a link there refuses the sweep, not each point
            make_subfolder(out_dir, "points")
        except RunFolderError as exc:
            then = "resume the sweep" if options.resume else "run again"
            raise (RunFolderError if options.resume else OutputRefused)(f"{exc}: move it aside, then {then}") from None
        write_tables(sweep, outcome, out_dir)  # first: a sweep that is heard of has its sweep.json
        for listener in listeners:
            listener.sweep_started(sweep)
        interrupted = False
        try:
            with one_dask_cluster(options):  # on Dask, every point's run uses one client and cluster
                for result in _run_points(sweep, out_dir, options, listeners, cancel, plot):
                    number = result.point.number  # the listeners hear it whole, and its error
                    results[number] = result.held() if result.status != "error" or number not in kept else replace(
                        result, status="completed", recorded=kept[number])
                    outcome.results = list(results.values())
                    outcome.elapsed = time.perf_counter() - started
                    write_tables(sweep, outcome, out_dir)
                    for listener in listeners:
                        listener.point_finished(sweep, result.point, result)
        except KeyboardInterrupt:  # Ctrl-C between two points
            interrupted = True
        outcome.elapsed = time.perf_counter() - started
        _finish(sweep, outcome, out_dir, plot, interrupted)
        for listener in listeners:  # before the lock goes: a follower that sees it gone has heard this
            listener.sweep_finished(sweep, outcome)
    return outcome


def _finish(sweep: Sweep, outcome: SweepOutcome, out_dir: Path, plot: bool, interrupted: bool = False) -> None:
    """The sweep's status from its points' (``interrupted``: stopped between two points), its tables
    written, and sweep.png drawn where ``plot`` and some point has a fit."""
    statuses = {r.status for r in outcome.results}
    if interrupted or statuses & {"interrupted", "cancelled"} or "pending" in statuses:
        outcome.status = "interrupted"
    elif any(result.failure for result in outcome.results):
        outcome.status = "failed"
    else:
        outcome.status = "completed"
    outcome.files = write_tables(sweep, outcome, out_dir)
    if plot and any(r.fit is not None or (r.recorded or {}).get("a") is not None for r in outcome.results):
        write_sweep_figure(out_dir / "sweep.png", sweep, outcome.rows)
        outcome.files["plot"] = out_dir / "sweep.png"
        write_tables(sweep, outcome, out_dir)


def write_sweep_figure(path: Path, sweep: Sweep, rows: list[dict[str, Any]], **written) -> None:
    """sweep.png of ``rows`` (a row per point, as sweep.json holds them), drawn in this process
    (``written``: ``write_figure``'s devices and kept); matplotlib imported only as it draws."""
    write_figure(path, lambda fh: imported(PLOT_MODULE).plot_sweep(sweep, rows, fh), **written)


def sweep_of_point(folder: str | Path) -> Path | None:
    """The folder of the sweep whose point ``folder`` is (``SWEEP/points/NN``: its sweep.json
    beside points/), else None."""
    folder = Path(folder) if Path(folder).name not in ("", ".", "..") else Path(os.path.abspath(folder))  # no link followed
    if folder.parent.name == "points" and os.path.lexists(folder.parent.parent / "sweep.json"):
        return folder.parent.parent
    return None


def refresh_point_tables(folder: str | Path, plot: bool = True) -> tuple[bool, str] | None:
    """After one point of a sweep (``folder``) ran on its own (``frictionlab resume SWEEP/points/NN``),
    the sweep's sweep.csv and sweep.json (and sweep.png, with ``plot``) written again: each completed
    point read back, the others' rows as they were; nothing is computed. None where ``folder`` is no
    sweep's point; else whether they were written, and what to tell the user."""
    out_dir = sweep_of_point(folder)
    if out_dir is None:
        return None
    resume = f"`frictionlab resume {command_word(out_dir)}` writes them (and runs what is unfinished)"
    try:
        with RunDirectory(out_dir):  # the sweep's lock: not while the sweep itself runs
            data, record = read_sweep_record(out_dir)
            sweep = plan_sweep(stored_sweep(out_dir), source=str(out_dir / "sweep.json"))  # as `resume SWEEP` plans it
            if Path(os.path.abspath(folder)).name not in [p.folder_name for p in sweep.points]:  # a folder of its own
                return None
            results = [_as_it_is(point, out_dir, row) for point, row in zip(sweep.points, data["points"], strict=True)]
            outcome = SweepOutcome(status="running", results=results, elapsed=record.elapsed_seconds)
            _finish(sweep, outcome, out_dir, plot)
    except (FrictionlabError, OSError) as exc:
        return False, f"the tables of the sweep in {shown_name(out_dir)}/ are not updated with this point ({exc}): {resume}"
    return True, f"sweep.csv and sweep.json of the sweep in {shown_name(out_dir)}/ updated with this point (sweep {outcome.status})"


def _as_it_is(point: SweepPoint, out_dir: Path, row: dict) -> PointResult:
    """``point``'s result read back from its folder where it completed, else its ``row`` of sweep.json."""
    folder = point_folder(out_dir, point)
    done = read_back(point.scene, folder, (), plot=False) if (folder / STATE_FILE).exists() else None
    if done is not None:
        return PointResult(point, done.status, folder, outcome=done, error=done.error).held()
    return PointResult(point, row["status"], folder, error=row.get("error"), recorded=row)
