"""The Python API, for notebooks and scripts: ``frictionlab.run`` and ``frictionlab.load``.

``run`` takes a preset in any form (a file, a built-in's name, YAML text, a dict, a
``Preset``), overrides by dotted path, and returns a ``Result``: the fit of
xi = a + b ln f with its intervals and R², the table per load step, a plot. With
``out=FOLDER`` it writes the same run folder as ``frictionlab run --out FOLDER``;
``load(FOLDER)`` reads any finished run back, with the same numbers.

    >>> import frictionlab
    >>> r = frictionlab.run("quickstart", realizations=8, workers=1, progress=False)
    >>> r.status, r.realizations
    ('completed', (8, 8))
    >>> import numpy as np
    >>> ln_f, xi = np.log(r.table["f"]), r.table["xi"]  # a least-squares line passes through the means:
    >>> bool(abs(r.fit.a + r.fit.b * ln_f.mean() - xi.mean()) < 1e-9)
    True
    >>> sorted(r.table)[:3]
    ['F', 'contact_count', 'contact_fraction']

Overrides are dotted paths into the preset. Python keywords cannot hold dots: give
them as a dict, or spell each dot as a double underscore:

    >>> a = frictionlab.run("quickstart", {"spectrum.params.hurst": 0.6}, realizations=8, workers=1, progress=False)
    >>> b = frictionlab.run("quickstart", spectrum__params__hurst=0.6, realizations=8, workers=1, progress=False)
    >>> a.fit.a == b.fit.a and a.preset["spectrum"]["params"]["hurst"] == 0.6
    True

A run folder, read back:

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp()) / "run"
    >>> r = frictionlab.run("quickstart", realizations=8, workers=1, progress=False, plot=False, out=folder)
    >>> frictionlab.load(folder).fit == r.fit
    True

The CLI's ``frictionlab run`` goes through ``run_scene`` here, so both write the
same files; ``--no-plot`` is ``plot=False``.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import FrictionlabError, PresetError, RunFolderError
from .fit import LogFit
from .options import RunOptions
from .results import CORRECTED_AREA, CURVE_COLUMNS, read_curve

if TYPE_CHECKING:
    from .ensemble import RunOutcome
    from .preset import Preset, Scene

__all__ = ["Result", "SweepResult", "load", "read_preset_input", "run", "run_scene"]


@dataclass(frozen=True, eq=False)  # compared by identity: its arrays have no single truth value
class Result:
    """One finished run: what ``frictionlab.run`` returns and ``frictionlab.load`` reads.

    ``fit``: the ``LogFit`` of xi = a + b ln f (``a``, ``b``, ``a_ci``, ``b_ci``,
    ``a_se``, ``b_se``, ``r2``, ``residual_rms``), None if nothing finished.
    ``table``: per load step, arrays named as curve.csv's columns: ``F`` (the
    load, see ``normalisation``), ``f``, ``xi``, ``xi_sem``, ``contact_count``,
    ``contact_fraction``, ``indentation``, and ``real_area_corrected`` (the real area
    corrected for its perimeter's pixels, a fraction) for a solver that gives it
    (``bem-halfspace``). ``caveats``: what a reader of the fit
    must know (fewer than 3 points in contact at the first load). ``folder``: the
    run folder, None for a run kept in memory."""

    name: str
    status: str  # completed | cancelled | interrupted | failed
    fit: LogFit | None
    table: dict[str, np.ndarray]
    realizations: tuple[int, int]  # (done, requested)
    normalisation: str  # how f is formed, e.g. "f = F / (E* h L), ..."
    preset: dict  # the resolved preset: every default filled in
    elapsed: float  # seconds
    caveats: list[str] = field(default_factory=list)
    folder: Path | None = None
    outcome: RunOutcome | None = field(default=None, repr=False, compare=False)  # in-process runs only
    files: dict[str, Path] = field(default_factory=dict, repr=False, compare=False)

    @property
    def a(self) -> float:
        return self.fit.a if self.fit else math.nan

    @property
    def b(self) -> float:
        return self.fit.b if self.fit else math.nan

    @property
    def r2(self) -> float:
        return self.fit.r2 if self.fit else math.nan

    def to_pandas(self):
        """The table as a pandas DataFrame (one row per load step), or, without
        pandas installed, the dict of numpy arrays itself."""
        try:
            import pandas as pd
        except ImportError:
            return dict(self.table)
        return pd.DataFrame(self.table)

    def plot(self, ax=None):
        """xi against f with the fit and its caveats, on ``ax`` (a new figure's when
        None, through pyplot, so a notebook shows it); returns the Axes."""
        from .plot import draw_curve

        if ax is None:
            import matplotlib.pyplot as plt

            _, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
        t = self.table
        draw_curve(ax, t["f"], t["xi"], t["xi_sem"], self.fit, done=self.realizations[0], caveats=self.caveats)
        ax.set_xlabel(self.normalisation, fontsize=8)
        ax.set_title(self.name, fontsize=10)
        return ax

    def __repr__(self) -> str:
        fit = "no fit" if self.fit is None else f"a = {self.fit.a:.4f}, b = {self.fit.b:.4f}, R² = {self.fit.r2:.3f}"
        where = f", folder {str(self.folder)!r}" if self.folder else ""
        done, requested = self.realizations
        return f"<Result {self.name!r}: {self.status}, {done}/{requested} realizations, {fit}{where}>"


@dataclass(frozen=True, eq=False)
class SweepResult:
    """A finished sweep: one row per point (``rows``: the swept values by dotted path,
    ``a``, ``a_lo``, ``a_hi``, ``b``, ``b_lo``, ``b_hi``, ``r2``, ``contact_first``,
    ``contact_last``, ``status``, ``folder``), each point's run in ``folder``/points/."""

    name: str
    status: str  # completed | interrupted | failed
    parameters: list[str]  # the swept dotted paths
    rows: list[dict]
    folder: Path
    elapsed: float

    @property
    def points(self) -> list[Result]:
        """Each finished point's ``Result``, read from its folder."""
        return [load(self.folder / row["folder"]) for row in self.rows if row.get("a") is not None]

    def to_pandas(self):
        """The rows as a pandas DataFrame, or without pandas a dict of numpy arrays by column."""
        columns = {key: [row.get(key) for row in self.rows] for key in self.rows[0]} if self.rows else {}
        try:
            import pandas as pd
        except ImportError:
            return {key: np.array(values) for key, values in columns.items()}
        return pd.DataFrame(columns)

    def __repr__(self) -> str:
        return f"<SweepResult {self.name!r}: {self.status}, {len(self.rows)} points over {', '.join(self.parameters)}>"


def read_preset_input(
    preset: str | Path | Mapping[str, Any] | Preset, overrides: Mapping[str, Any] | None = None, **keys: Any
) -> tuple[dict, str, Path | None]:
    """Preset data from any input form, overrides applied; with a name for messages
    and the folder relative input files are taken from (a file's own; else None: the
    current folder). Forms: a ``Preset``; a dict; a string holding YAML (a newline,
    or a ``{...}`` flow mapping); else a path to a file, or a built-in's name."""
    from .preset import Preset, load_preset_file, set_path
    from .preset.builtin import resolve_preset_path
    from .preset.reading import resolve_input_paths
    from .safe_yaml import YamlProblem, load_yaml

    base_dir = None
    if isinstance(preset, Preset):
        data, source = preset.model_dump(mode="json", exclude_none=True), f"<Preset {preset.name}>"
    elif isinstance(preset, Mapping):
        data, source = copy.deepcopy(dict(preset)), "<dict>"  # never change the caller's dict
    elif isinstance(preset, str) and ("\n" in preset or preset.lstrip().startswith("{")):
        try:
            data = load_yaml(preset)
        except YamlProblem as exc:
            raise PresetError([f"(text): {exc}"], source="<YAML text>") from None
        if not isinstance(data, dict):
            raise PresetError([f"(text): a preset must be a mapping. Got {type(data).__name__} instead."], "<YAML text>")
        source = "<YAML text>"
    elif isinstance(preset, str | Path):
        path = resolve_preset_path(preset)
        data, source, base_dir = load_preset_file(path), str(path), path.parent
    else:
        raise FrictionlabError(
            f"preset must be a path, a built-in's name, YAML text, a dict or a Preset. Got {type(preset).__name__}."
        )
    if base_dir is not None:
        data = resolve_input_paths(data, base_dir)
    assignments = {**(overrides or {}), **{key.replace("__", "."): value for key, value in keys.items()}}
    problems = []
    for path, value in assignments.items():
        try:
            set_path(data, str(path), value)
        except ValueError as exc:
            problems.append(f"{path}: {exc}")
    if problems:
        raise PresetError(problems, source="overrides")
    return data, source, base_dir


def run(
    preset: str | Path | Mapping[str, Any] | Preset,
    overrides: Mapping[str, Any] | None = None,
    /,
    *,
    out: str | Path | None = None,
    workers: int | None = None,
    executor: str | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    force: bool = False,
    plot: bool = True,
    progress: bool = True,
    memory_check: bool = True,
    **keys: Any,
) -> Result:
    """Run a preset and return its ``Result``.

    ``preset``: a path, a built-in's name (``"quickstart"``), YAML text, a dict or a
    ``frictionlab.preset.Preset``. ``overrides``: ``{"spectrum.params.hurst": 0.8}``;
    keywords too, a double underscore for each dot (``spectrum__params__hurst=0.8``,
    ``seed=3``, ``realizations=20``), given values taking precedence in that order.

    ``out``: a folder to write the run into (as ``frictionlab run --out``: resumable,
    locked while running; ``resume``, ``force`` as there); None keeps the run in
    memory. ``plot``: draw plot.png into ``out``. ``workers``, ``executor``,
    ``scheduler``: where realizations run (every core by default; the numbers are the
    same whatever they are). ``progress``: a bar on stderr (on a terminal, or in
    Jupyter), plain lines elsewhere.

    A preset with a ``sweep`` runs every point into ``out`` (required: a folder per
    point) and returns a ``SweepResult``. Bad input raises a
    ``frictionlab.errors.FrictionlabError`` naming the field.
    """
    from .preset import build_scene
    from .progress import ProgressReporter, SweepProgress

    data, source, _ = read_preset_input(preset, overrides, **keys)
    scene = build_scene(data, source=source)
    options = RunOptions(
        workers=workers, executor=executor, scheduler=scheduler, resume=resume, force=force, memory_check=memory_check
    )
    if scene.preset.sweep is not None:
        from .sweep import plan_sweep, run_sweep

        if out is None:
            raise FrictionlabError(f"{source}: a sweep writes a run folder per point: give out=FOLDER")
        sweep = plan_sweep(data, source=source)
        run_sweep(sweep, out, options, listeners=[SweepProgress()] if progress else [], plot=plot)
        return load(out)
    return run_scene(scene, out, options, listeners=[ProgressReporter()] if progress else [], plot=plot)


def run_scene(
    scene: Scene,
    out: str | Path | None,
    options: RunOptions = RunOptions(),
    *,
    listeners: Sequence[object] = (),
    plot: bool = True,
    on_results=None,
    cancel=None,
) -> Result:
    """Run a validated ``Scene`` into the folder ``out`` (``runner.run_to_folder``) or,
    when None, in memory (``engine.run``); the one path of ``frictionlab.run`` and of
    ``frictionlab run``. ``on_results(result)`` is called before the figure is drawn."""
    if out is None:
        from . import engine
        from .runner import check_memory

        if options.resume:
            raise FrictionlabError("resume needs the run folder: give out=FOLDER")
        if options.memory_check:
            check_memory(scene, options)
        outcome = engine.run(scene, options, listeners=listeners, cancel=cancel)
        result = _result(scene, outcome, None, {})
        if on_results is not None:
            on_results(result)
        return result
    from .runner import run_to_folder

    def tell(outcome, files):
        if on_results is not None:
            on_results(_result(scene, outcome, Path(out), files))

    outcome, files = run_to_folder(
        scene, out, options, listeners=listeners, cancel=cancel, plot=plot, on_results=tell
    )
    return _result(scene, outcome, Path(out), files)


def _result(scene: Scene, outcome: RunOutcome, folder: Path | None, files: dict[str, Path]) -> Result:
    table = {
        "F": outcome.force, "f": outcome.f, "xi": outcome.xi, "xi_sem": outcome.xi_sem,
        "contact_count": outcome.contact_count, "contact_fraction": outcome.contact_fraction,
        "indentation": outcome.indentation,
    }  # fmt: skip
    if outcome.real_area_corrected is not None:  # the solvers that correct their area only
        table[CORRECTED_AREA] = outcome.real_area_corrected
    return Result(
        name=scene.preset.name, status=outcome.status, fit=outcome.fit, table=table,
        realizations=(outcome.done, outcome.requested), normalisation=outcome.normalisation.definition,
        preset=scene.resolved(), elapsed=outcome.elapsed, caveats=outcome.caveats, folder=folder,
        outcome=outcome, files=dict(files),
    )  # fmt: skip


def load(folder: str | Path) -> Result | SweepResult:
    """A finished run read back from its folder (written by ``frictionlab run`` or
    ``frictionlab.run(..., out=...)``): summary.json and curve.csv, the same numbers
    to the last bit; a sweep's folder (sweep.json) as a ``SweepResult``. A folder
    with neither is a ``RunFolderError``."""
    folder = Path(folder)
    if not (folder / "summary.json").exists() and (folder / "sweep.json").exists():
        return _load_sweep(folder)
    try:
        summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise RunFolderError(f"{folder}: no summary.json (nor sweep.json): not a finished run") from None
    except (OSError, ValueError) as exc:
        raise RunFolderError(f"{folder}/summary.json cannot be read: {exc}") from None
    curve = read_curve(folder / summary.get("files", {}).get("curve", "curve.csv"))
    names = [name.rstrip("'") for name in curve]  # F' on the half-plane
    if names not in (list(CURVE_COLUMNS), [*CURVE_COLUMNS, CORRECTED_AREA]):
        raise RunFolderError(f"{folder}/curve.csv: columns {list(curve)} are not those frictionlab writes")
    table = dict(zip(names, curve.values()))
    realizations = summary.get("realizations") or {}
    return Result(
        name=summary["preset"]["name"],
        status=summary.get("status", "completed"),
        fit=LogFit.from_dict(summary["fit"]) if summary.get("fit") else None,
        table=table,
        realizations=(int(realizations.get("done", 0)), int(realizations.get("requested", 0))),
        normalisation=(summary.get("normalisation") or {}).get("f", ""),
        preset=summary["preset"],
        elapsed=float(summary.get("elapsed_seconds") or 0.0),
        caveats=list(summary.get("caveats") or []),
        folder=folder,
        files={k: folder / v for k, v in (summary.get("files") or {}).items()},
    )


def _load_sweep(folder: Path) -> SweepResult:
    try:
        summary = json.loads((folder / "sweep.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise RunFolderError(f"{folder}/sweep.json cannot be read: {exc}") from None
    rows = [{k: v for k, v in point.items() if k not in ("set", "error")} for point in summary["points"]]
    return SweepResult(
        name=summary["name"], status=summary["status"], parameters=list(summary["sweep"]["parameters"]), rows=rows,
        folder=folder, elapsed=float(summary.get("elapsed_seconds") or 0.0),
    )  # fmt: skip
