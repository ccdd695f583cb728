"""Parameter sweeps: one full ensemble per point of a preset's ``sweep`` section.

A point is the preset with the swept dotted paths set (``preset.apply_overrides``,
then the usual two-phase validation) and the ``sweep`` section removed; the seed
is the preset's, so a point is reproducible on its own::

    frictionlab run PRESET --set sweep=null --set spectrum.params.hurst=0.7

Every point runs through ``runner.run_to_folder`` (the single run path) into
``<out>/points/<NN>-<label>/``. ``sweep.csv`` (one row per point, rewritten
atomically as points finish), ``sweep.json`` and ``sweep.png`` sit in ``<out>``.

Front ends follow a sweep through listeners: any object with some of the
methods ``sweep_started(sweep)``, ``point_started(sweep, point)``,
``point_finished(sweep, point, result)``, ``sweep_finished(sweep, outcome)``;
each point's run gets the engine listeners that ``point_listeners(point)`` returns.
"""

from __future__ import annotations

import csv
import inspect
import itertools
import json
import math
import re
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel

from . import __version__
from .errors import PresetError
from .fit import json_safe
from .preset import PLUGIN_SLOTS, Preset, Scene, SweepSettings, apply_overrides, build_scene, read_preset
from .registry import Registry, default_registry
from .results import atomic_write

SWEEP_SCHEMA_VERSION = 1
RESULT_COLUMNS = (
    "status", "done", "a", "a_lo", "a_hi", "b", "b_lo", "b_hi", "r2",
    "contact_first", "contact_last", "elapsed_s", "folder",
)  # fmt: skip


# ------------------------------------------------------------------ planning


def yaml_scalar(value: Any) -> str:
    """The ``--set`` spelling of ``value``: YAML that reads back as the same value."""
    if isinstance(value, float) and math.isfinite(value):
        text = repr(value)
        if "e" in text and "." not in text:  # PyYAML reads 1e-05 as text; 1.0e-05 as a float
            text = text.replace("e", ".0e", 1)
        if "e" in text and text.split("e")[1][0] not in "+-":
            text = text.replace("e", "e+", 1)
    else:
        text = yaml.safe_dump(value, default_flow_style=True).removesuffix("\n...\n").strip()
    if yaml.safe_load(text) != value or type(yaml.safe_load(text)) is not type(value):
        raise ValueError(f"cannot spell {value!r} as a YAML scalar")
    return text


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
        return ", ".join(self.assignments)


@dataclass(frozen=True)
class Sweep:
    """A planned sweep: the base preset data (overrides applied), its spec and every point."""

    name: str
    spec: SweepSettings
    base: dict
    points: list[SweepPoint]
    source: str | None = None

    @property
    def paths(self) -> list[str]:
        return list(self.spec.parameters)


def _label(values: dict[str, Any]) -> str:
    parts = []
    for path, value in values.items():
        text = f"{value:.6g}" if isinstance(value, float) else str(value)
        parts.append(f"{path.rsplit('.', 1)[-1]}-{text}")
    return re.sub(r"[^A-Za-z0-9._+=-]+", "-", "_".join(parts))[:80].strip("-") or "point"


def _model_of(annotation) -> type[BaseModel] | None:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in getattr(annotation, "__args__", ()):  # Optional[Model]
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
        if depth == 1 and keys[0] in PLUGIN_SLOTS and key == "params":
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
            known |= set(registry.get(PLUGIN_SLOTS[slot], str(name)).Params.model_fields)
        except Exception:  # an unknown plugin name is reported when the points are validated
            return None
    if keys[2] not in known:
        return f"{where}: the {slot} plugin has no parameter {keys[2]!r}; allowed: {', '.join(sorted(known))}"
    return None


def _combinations(spec: SweepSettings) -> list[dict[str, Any]]:
    paths = list(spec.parameters)
    columns = [spec.parameters[p].points() for p in paths]
    rows = itertools.product(*columns) if spec.mode == "grid" else zip(*columns, strict=True)
    return [dict(zip(paths, row, strict=True)) for row in rows]


def plan_sweep(data: dict, registry: Registry | None = None, source: str | None = None) -> Sweep:
    """Expand preset data with a ``sweep`` section into validated points.

    Every problem of every point is reported at once, each prefixed with
    ``sweep point N (path=value)``; nothing runs unless every point is valid.
    """
    registry = registry or default_registry()
    base_scene = build_scene(data, registry=registry, source=source)  # the base and the spec itself
    spec = base_scene.preset.sweep
    if spec is None:
        raise PresetError(["sweep: the preset has no sweep section"], source=source)
    problems = [p for p in (path_problem(path, data, spec, registry) for path in spec.parameters) if p]
    if problems:
        raise PresetError(problems, source=source)
    base = {k: v for k, v in data.items() if k != "sweep"}
    combos = _combinations(spec)
    width = max(2, len(str(len(combos))))
    points, problems = [], []
    for number, values in enumerate(combos, start=1):
        try:
            assignments = [f"{path}={yaml_scalar(v)}" for path, v in values.items()]
            scene = build_scene(apply_overrides(base, assignments), registry=registry)
        except PresetError as exc:
            shown = ", ".join(f"{path}={v!r}" for path, v in values.items())
            problems += [f"sweep point {number} ({shown}): {p}" for p in exc.problems]
            continue
        folder = f"{number:0{width}d}-{_label(values)}"
        points.append(SweepPoint(number=number, values=values, folder_name=folder, scene=scene))
    if problems:
        raise PresetError(problems, source=source)
    return Sweep(name=base_scene.preset.name, spec=spec, base=base, points=points, source=source)


def load_sweep(path: str | Path, overrides: Iterable[str] = (), registry: Registry | None = None) -> Sweep:
    """File -> overrides -> planned Sweep (the preset must have a sweep section)."""
    return plan_sweep(read_preset(path, list(overrides), registry), registry=registry, source=str(path))


# ------------------------------------------------------------------ running


@dataclass
class PointResult:
    """What one point gave: its status, fit and contact counts (from the run's outcome)."""

    point: SweepPoint
    status: str  # completed | cancelled | interrupted | failed | error | pending
    folder: Path
    outcome: Any = None  # ensemble.RunOutcome
    error: str | None = None

    def row(self) -> dict[str, Any]:
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


@dataclass
class SweepOutcome:
    status: str  # completed | interrupted | failed (some point failed)
    results: list[PointResult]
    elapsed: float
    files: dict[str, Path] = field(default_factory=dict)

    @property
    def rows(self) -> list[dict[str, Any]]:
        return [r.row() for r in self.results]


def _notify(listeners, method: str, **kwargs) -> None:
    for listener in listeners:
        handler = getattr(listener, method, None)
        if handler is not None:
            handler(**kwargs)


def _run_options(options: dict) -> dict:
    """Pass ``executor=``/``resume=`` etc. on only when run_to_folder accepts them."""
    from .runner import run_to_folder

    accepted = inspect.signature(run_to_folder).parameters
    return {k: v for k, v in options.items() if v is not None and k in accepted}


def iter_sweep(
    sweep: Sweep,
    out_dir: str | Path,
    *,
    workers: int | None = None,
    point_listeners: Callable[[SweepPoint], list] = lambda point: [],
    cancel=None,
    **run_options,
) -> Iterator[PointResult]:
    """Run the points in order, yielding each PointResult as it finishes.

    Stops after a point that was cancelled or interrupted (what finished is
    written); a point that raises a FrictionlabError is recorded as ``error``
    and the sweep goes on.
    """
    from .errors import FrictionlabError
    from .runner import run_to_folder

    out_dir = Path(out_dir)
    cancel = threading.Event() if cancel is None else cancel
    options = _run_options(run_options)
    for point in sweep.points:
        folder = out_dir / "points" / point.folder_name
        if cancel.is_set():
            return
        try:
            outcome, _ = run_to_folder(
                point.scene, folder, workers=workers, listeners=point_listeners(point), cancel=cancel, **options
            )
        except FrictionlabError as exc:
            yield PointResult(point, "error", folder, error=str(exc))
            continue
        yield PointResult(point, outcome.status, folder, outcome=outcome, error=outcome.error)
        if outcome.status in ("cancelled", "interrupted"):
            return


def run_sweep(
    sweep: Sweep,
    out_dir: str | Path,
    *,
    workers: int | None = None,
    listeners: Iterable[object] = (),
    point_listeners: Callable[[SweepPoint], list] = lambda point: [],
    cancel=None,
    plot: bool = True,
    force: bool = False,
    **run_options,
) -> SweepOutcome:
    """Run every point and keep ``sweep.csv``/``sweep.json`` current; draw ``sweep.png`` at the end.
    ``out_dir`` must be new, empty or a folder of this same sweep unless ``force``."""
    out_dir = Path(out_dir)
    check_sweep_folder(sweep, out_dir, force)
    run_options["force"] = force
    listeners = list(listeners)
    started = time.perf_counter()
    results = {p.number: PointResult(p, "pending", out_dir / "points" / p.folder_name) for p in sweep.points}
    outcome = SweepOutcome(status="completed", results=list(results.values()), elapsed=0.0)
    _notify(listeners, "sweep_started", sweep=sweep)
    write_tables(sweep, outcome, out_dir)
    interrupted = False
    iterator = iter_sweep(
        sweep, out_dir, workers=workers, cancel=cancel, point_listeners=_announcing(sweep, listeners, point_listeners),
        **run_options,
    )
    try:
        for result in iterator:
            results[result.point.number] = result
            outcome.results = list(results.values())
            outcome.elapsed = time.perf_counter() - started
            write_tables(sweep, outcome, out_dir)
            _notify(listeners, "point_finished", sweep=sweep, point=result.point, result=result)
    except KeyboardInterrupt:  # Ctrl-C between two points
        interrupted = True
    statuses = {r.status for r in outcome.results}
    if interrupted or statuses & {"interrupted", "cancelled"} or "pending" in statuses:
        outcome.status = "interrupted"
    elif statuses & {"failed", "error"} or any(r.outcome is not None and r.outcome.failures for r in outcome.results):
        outcome.status = "failed"
    outcome.elapsed = time.perf_counter() - started
    outcome.files = write_tables(sweep, outcome, out_dir)
    if plot and any(r.outcome is not None and r.outcome.fit is not None for r in outcome.results):
        outcome.files["plot"] = out_dir / "sweep.png"
        atomic_write(outcome.files["plot"], lambda fh: plot_sweep(sweep, outcome.rows, fh), binary=True)
        write_tables(sweep, outcome, out_dir)
    _notify(listeners, "sweep_finished", sweep=sweep, outcome=outcome)
    return outcome


def check_sweep_folder(sweep: Sweep, out_dir: Path, force: bool = False) -> None:
    """OutputRefused unless ``out_dir`` is new, empty, or holds this same sweep
    (its sweep.json names the same sweep and base preset), or ``force``."""
    from .errors import OutputRefused
    from .rundir import _output_path_problem

    problem = _output_path_problem(out_dir)
    if problem:
        raise OutputRefused(f"{problem}; give --out a folder")
    if force or not out_dir.is_dir() or not any(out_dir.iterdir()):
        return
    hint = "give another --out folder, or --force to write into it anyway"
    try:
        old = json.loads((out_dir / "sweep.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        raise OutputRefused(
            f"{out_dir} is not empty and is not the folder of a frictionlab sweep (no readable sweep.json): {hint}"
        ) from None
    mine = {"name": sweep.name, "sweep": sweep.spec.model_dump(mode="json", exclude_none=True), "base_preset": sweep.base}
    mine = json.loads(json.dumps(mine, default=str))
    if not isinstance(old, dict) or any(old.get(key) != value for key, value in mine.items()):
        raise OutputRefused(f"{out_dir} holds another sweep: {hint} (its tables are then replaced)")


def _announcing(sweep, listeners, point_listeners):
    def make(point):
        _notify(listeners, "point_started", sweep=sweep, point=point)
        return point_listeners(point)

    return make


def write_tables(sweep: Sweep, outcome: SweepOutcome, out_dir: Path) -> dict[str, Path]:
    """Write sweep.csv and sweep.json atomically (called after every point)."""
    rows = outcome.rows
    columns = ["point", "label", *sweep.paths, *RESULT_COLUMNS]
    files = {"table": out_dir / "sweep.csv", "summary": out_dir / "sweep.json"}

    def write_csv(fh):
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(columns)
        for row in rows:
            writer.writerow(["" if row[c] is None else repr(row[c]) if isinstance(row[c], float) else row[c] for c in columns])

    atomic_write(files["table"], write_csv)
    summary = {
        "schema_version": SWEEP_SCHEMA_VERSION,
        "frictionlab_version": __version__,
        "name": sweep.name,
        "source": sweep.source,
        "status": outcome.status,
        "elapsed_seconds": round(outcome.elapsed, 3),
        "sweep": sweep.spec.model_dump(mode="json", exclude_none=True),
        "base_preset": sweep.base,
        "points": [
            {**row, "set": r.point.assignments, "error": r.error} for row, r in zip(rows, outcome.results, strict=True)
        ],
        "files": {"table": "sweep.csv", **({"plot": "sweep.png"} if "plot" in outcome.files else {})},
    }
    atomic_write(files["summary"], lambda fh: json.dump(summary, fh, indent=2, allow_nan=False, default=str))
    return {**outcome.files, **files}


def read_table(path: str | Path) -> list[dict[str, str]]:
    """sweep.csv as a list of rows (strings), for scripts and tests."""
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


# ------------------------------------------------------------------ plot


def _numeric(values) -> bool:
    return all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)


def plot_sweep(sweep: Sweep, rows: list[dict[str, Any]], fh, dpi: int = 90) -> None:
    """sweep.png: a and b (rows of panels) against each swept parameter (columns),
    with their bootstrap intervals; in a grid the other parameters' values make the series."""
    from .plot import plt  # matplotlib (Agg) is slow to import: only when drawing

    paths = sweep.paths
    fig, axes = plt.subplots(2, len(paths), figsize=(4.2 * len(paths), 5.6), squeeze=False, layout="constrained")
    done = [r for r in rows if r["a"] is not None]
    for col, path in enumerate(paths):
        xs_all = [r[path] for r in done]
        numeric = _numeric(xs_all)
        order = sorted({repr(x) for x in xs_all})  # categorical positions when not numeric
        others = [p for p in paths if p != path]
        series: dict[str, list] = {}
        for r in done:
            key = ", ".join(f"{p.rsplit('.', 1)[-1]}={r[p]}" for p in others)
            series.setdefault(key, []).append(r)
        for row, coef in enumerate(("a", "b")):
            ax = axes[row][col]
            for i, (key, members) in enumerate(series.items()):
                members = sorted(members, key=lambda r: r[path] if numeric else repr(r[path]))
                x = [m[path] if numeric else order.index(repr(m[path])) for m in members]
                y = [m[coef] for m in members]
                lo = [m[coef] - m[f"{coef}_lo"] if m[f"{coef}_lo"] is not None else 0 for m in members]
                hi = [m[f"{coef}_hi"] - m[coef] if m[f"{coef}_hi"] is not None else 0 for m in members]
                ax.errorbar(x, y, yerr=[lo, hi], fmt="o-", ms=4, capsize=3, color=f"C{i}", label=key or None)
            if not numeric:
                ax.set_xticks(range(len(order)), [o.strip("'") for o in order], rotation=20, fontsize=8)
            elif sweep.spec.parameters[path].spacing == "log" and min(xs_all, default=1) > 0:
                ax.set_xscale("log")
            ax.set_ylabel(coef)
            ax.grid(True, alpha=0.3)
            if row == 1:
                ax.set_xlabel(path)
            if any(series) and row == 0 and col == 0 and len(series) > 1:
                ax.legend(fontsize=7)
    fig.suptitle(f"{sweep.name}: xi = a + b ln f per point (95% bootstrap intervals)", fontsize=10)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


# ------------------------------------------------------------------ command line


class SweepProgress:
    """The CLI's sweep listener: one counter line per point on stderr (each point's
    own realization progress comes from a ProgressReporter)."""

    def __init__(self, stream=None):
        import sys

        self.stream = stream or sys.stderr

    def sweep_started(self, sweep):
        mode = sweep.spec.mode
        self.stream.write(f"{sweep.name}: sweep of {len(sweep.points)} points ({mode} over {', '.join(sweep.paths)})\n")
        self.stream.flush()

    def point_started(self, sweep, point):
        self.stream.write(f"point {point.number}/{len(sweep.points)}: {point.describe()}\n")
        self.stream.flush()

    def point_finished(self, sweep, point, result):
        if result.status == "error":
            self.stream.write(f"point {point.number} failed: {result.error}\n")
            self.stream.flush()


def _interval(low, high) -> str:
    return "n/a" if low is None or high is None else f"[{low:.4f}, {high:.4f}]"


def sweep_table(sweep: Sweep, outcome: SweepOutcome, out_dir: Path) -> str:
    """The short table ``frictionlab run`` prints on stdout after a sweep."""
    lines = [f"{sweep.name}: {len(sweep.points)} points in {outcome.elapsed:.1f} s, status {outcome.status}"]
    for row, result in zip(outcome.rows, outcome.results, strict=True):
        values = ", ".join(f"{p.rsplit('.', 1)[-1]}={yaml_scalar(result.point.values[p])}" for p in sweep.paths)
        if row["a"] is None:
            lines.append(f"  {row['point']:>3}  {values}: {row['status']}")
            continue
        lines.append(
            f"  {row['point']:>3}  {values}: a = {row['a']:.4f} {_interval(row['a_lo'], row['a_hi'])}, "
            f"b = {row['b']:.4f} {_interval(row['b_lo'], row['b_hi'])}, R^2 = {row['r2']:.3f}, "
            f"contacts {row['contact_first']:.2f} .. {row['contact_last']:.2f}"
            + ("" if row["status"] == "completed" else f" ({row['status']})")
        )
    lines.append(f"  results in {out_dir}/ (sweep.csv, sweep.png, points/)")
    return "\n".join(lines)


def run_sweep_command(args, overrides: list[str], out_dir: Path, run_options: dict) -> int:
    """``frictionlab run`` on a preset with a sweep section; returns an ExitCode."""
    import sys

    from .errors import ExitCode
    from .reporter import ProgressReporter

    sweep = load_sweep(args.preset, overrides)
    listeners = [] if args.quiet else [SweepProgress()]
    point_listeners = (lambda point: []) if args.quiet else (lambda point: [ProgressReporter()])
    try:
        outcome = run_sweep(
            sweep, out_dir, workers=args.workers, listeners=listeners, point_listeners=point_listeners, **run_options
        )
    except OSError as exc:
        print(f"error: cannot write results to {out_dir}: {exc.strerror or exc}", file=sys.stderr)
        return ExitCode.RUNTIME_FAILURE
    if args.json:
        print((out_dir / "sweep.json").read_text(encoding="utf-8"))
    else:
        print(sweep_table(sweep, outcome, out_dir))
    if outcome.status == "interrupted":
        from .signals import interrupted_exit_code

        return interrupted_exit_code()
    return ExitCode.RUNTIME_FAILURE if outcome.status == "failed" else ExitCode.OK
