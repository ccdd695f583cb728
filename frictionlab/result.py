"""What ``frictionlab.run`` returns and ``frictionlab.load`` reads back: a run's ``Result``
(its fit, its table per load step, a notebook view and a plot) and a sweep's ``SweepResult``;
``load`` reads either from its folder, as untrusted input."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .arguments import path_argument
from .errors import FrictionlabError, RunFolderError, raised_here, refuse_unusable_matplotlib, require, shown
from .compute.fit import LogFit, format_number
from .runs.results import read_curve_table, read_summary, column_units
from .runs.runfolder import check_searchable, subfolder

if TYPE_CHECKING:
    from .compute.ensemble import RunOutcome

__all__ = ["Result", "SweepResult", "load"]

@dataclass(frozen=True, eq=False)  # compared by identity: its arrays have no single truth value
class Result:
    """One finished run: what ``frictionlab.run`` returns and ``frictionlab.load`` reads.

    ``fit``: the ``LogFit`` of xi = a + b ln f (``a``, ``b``, ``a_ci``, ``b_ci``,
    ``a_se``, ``b_se`` (least squares over the forces), ``a_se_bootstrap``, ``b_se_bootstrap``
    (over the realizations: ``standard_errors`` gives those shown), ``r2``, ``residual_rms``),
    None if nothing finished.
    ``table``: per load step, arrays named as curve.csv's columns: ``F`` (the
    load, see ``normalisation``), ``f``, ``xi``, ``xi_sem``, ``lines_used`` (the
    realizations whose xi is defined there; absent from a folder written before it), ``contact_count``,
    ``contact_fraction``, ``indentation``, ``half_load_points`` (the fewest points
    carrying half the load, NaN where the solver does not say), and ``real_area_corrected`` (the real area
    corrected for its perimeter's pixels, a fraction) for a solver that gives it
    (``bem-halfspace``), and ``real_gradient_rms`` (g_r, the rms slope over the corrected
    real contact), ``kappa`` and ``kappa_r`` ((A / A0) E* g / p with g the surface's rms
    gradient, and with g_r) for a solver that gives g_r (``bem-halfspace``,
    ``bem-halfspace-free``), and ``contact_spots`` (the mean number of contact spots) for a
    solver that counts them (the same two). ``caveats``: what a reader of the fit
    must know (fewer than 3 points in contact at the first load). ``folder``: the
    run folder, None for a run kept in memory. ``input``: for a measured profile or
    surface, what was read from its file (shape, pixel size, unit, rms height and
    where each came from), else None. ``error``: why a failed run has no fit (xi the same at
    every load, ...), else None. ``realizations``: (done, requested);
    ``elapsed``: wall seconds of computing, a resumed run's sessions summed (summary.json's
    ``elapsed_seconds``). f and xi are dimensionless; ``F`` and ``indentation`` are
    in the preset's units (lengths as its spacing, F in modulus x length², per unit
    depth on a half-plane): ``units`` says each column's, as curve.csv's header does
    (``to_pandas()`` keeps it in ``attrs["units"]``)."""

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
    input: dict | None = None
    units: dict[str, str] = field(default_factory=dict, repr=False, compare=False)  # by column, curve.csv's brackets
    error: str | None = None  # why the run failed

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
        """The table as a pandas DataFrame, one row per load step (pandas: the ``pandas``
        extra; without it, a ``MissingDependency`` naming it; ``table`` is the same as numpy arrays)."""
        frame = require("pandas", "Result.to_pandas()").DataFrame(self.table)
        frame.attrs["units"] = dict(self.units)
        return frame

    def plot(self, ax=None):
        """xi against f with the fit and its caveats, on ``ax`` (a new figure's when
        None, through pyplot, so a notebook shows it); returns the Axes."""
        refuse_unusable_matplotlib()  # a bad MPLBACKEND: named, not matplotlib's ValueError from its import
        from .plot import AXES_NEEDS, draw_curve
        from .runs.figures import SHOWN_LABEL_CHARS, cut, shown_caveats

        missing = [name for name in AXES_NEEDS if not callable(getattr(ax, name, None))] if ax is not None else []
        if missing or (ax is not None and not hasattr(ax, "transAxes")):
            needs = ", ".join(missing or ["transAxes"])
            raise FrictionlabError(f"ax must be a matplotlib Axes or None, got {type(ax).__name__}, which has no {needs}")
        if getattr(ax, "name", "rectilinear") != "rectilinear":  # a log x axis and error bars need flat x, y axes
            raise FrictionlabError(f"ax must be a flat (rectilinear) matplotlib Axes or None, got a {ax.name!r} projection")
        if ax is None:
            import matplotlib.pyplot as plt

            _, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
        t = self.table
        draw_curve(ax, t["f"], t["xi"], t["xi_sem"], self.fit, done=self.realizations[0],
                   caveats=shown_caveats(self.caveats))  # fmt: skip
        ax.set_xlabel(cut(self.normalisation, SHOWN_LABEL_CHARS), fontsize=8)  # a damaged folder's may be any length
        ax.set_title(cut(self.name, SHOWN_LABEL_CHARS), fontsize=10)
        return ax

    def _repr_html_(self) -> str:  # a notebook's view: the fit's table with its intervals, and the curve
        from .reprs import result_html

        return result_html(self)

    def __repr__(self) -> str:
        fit = "no fit" if self.fit is None else f"a = {format_number(self.fit.a)}, b = {format_number(self.fit.b)}, R² = {format_number(self.fit.r2, 3)}"
        where = f", folder {str(self.folder)!r}" if self.folder else ""
        done, requested = self.realizations
        return f"<Result {self.name!r}: {self.status}, {done}/{requested} realizations, {fit}{where}>"


SWEEP_UNITS = {  # a sweep's columns (sweep.csv's), by name
    "done": "count: realizations finished",
    **dict.fromkeys(("a", "a_lo", "a_hi"), "dimensionless: a of xi = a + b ln f (_lo, _hi: its interval)"),
    **dict.fromkeys(("b", "b_lo", "b_hi"), "dimensionless: b of xi = a + b ln f (_lo, _hi: its interval)"),
    "r2": "dimensionless: R² of the fit",
    "contact_first": "count: points in contact at the first load; ensemble mean",
    "contact_last": "count: points in contact at the last load; ensemble mean",
    "elapsed_s": "seconds: the point's wall time",
}


@dataclass(frozen=True, eq=False)
class SweepResult:
    """A finished sweep: one row per point (``rows``: the swept values by dotted path, ``a``,
    ``a_lo``, ``a_hi``, ``b``, ``b_lo``, ``b_hi``, ``r2``, ``contact_first``, ``contact_last``,
    ``status``, ``error`` (why a failed point failed), ``folder``), each point's run in ``folder``/points/."""

    name: str
    status: str  # completed | interrupted | failed
    parameters: list[str]  # the swept dotted paths
    rows: list[dict]
    folder: Path
    elapsed: float

    @property
    def points(self) -> list[Result]:
        """The ``Result`` of each point with a fit, read from its folder: an interrupted
        point's too (its ``status`` says so); a pending or failed one has none."""
        from .runs.sweeprecord import own_point  # a sweep's record: only where a sweep is read
        return [own_point(load(subfolder(self.folder, row["folder"])), self.name, row, self.parameters)
                for row in self.rows if row.get("a") is not None]  # never another run moved into its folder

    @property
    def units(self) -> dict[str, str]:
        """What each numeric column of ``rows`` is, in its unit (as ``Result.units``); the swept
        values are in the preset's units of their field."""
        columns = self.rows[0] if self.rows else {}
        return {name: unit for name, unit in SWEEP_UNITS.items() if name in columns}

    def to_pandas(self):
        """The rows as a pandas DataFrame (the ``pandas`` extra; ``rows`` holds them as dicts),
        ``units`` in its ``attrs["units"]``."""
        columns = {key: [row.get(key) for row in self.rows] for key in self.rows[0]} if self.rows else {}
        frame = require("pandas", "SweepResult.to_pandas()").DataFrame(columns)
        frame.attrs["units"] = self.units
        return frame

    def plot(self):
        """a and b against each swept parameter with their 95 % intervals, as sweep.png
        draws them, in a new figure through pyplot (so a notebook shows it); returns the Figure."""
        refuse_unusable_matplotlib()
        import matplotlib.pyplot as plt

        from .plot import sweep_figure
        from .runs.sweep import Sweep

        return sweep_figure(Sweep.recorded(self.folder), self.rows, make=plt.figure)  # its spec: the axes' scales and names

    def _repr_html_(self) -> str:  # a notebook's view: a row per point with its fit
        from .reprs import sweep_html

        return sweep_html(self)

    def __repr__(self) -> str:
        return f"<SweepResult {self.name!r}: {self.status}, {len(self.rows)} points over {', '.join(self.parameters)}>"


@raised_here
def load(folder: str | Path) -> Result | SweepResult:
    """A finished run read back from its folder (written by ``frictionlab run`` or
    ``frictionlab.run(..., out=...)``): summary.json and curve.csv, the same numbers
    to the last bit; a sweep's folder (sweep.json) as a ``SweepResult``. The folder is
    read as untrusted input (``frictionlab.runs.runfolder``: only regular files inside it,
    never through a link, every value checked): any problem, a folder with neither
    file too, is a ``RunFolderError`` naming the file and what is wrong."""
    check_searchable(folder := path_argument(folder, "folder", "a run folder"))
    if not os.path.lexists(folder / "summary.json") and os.path.lexists(folder / "sweep.json"):
        return _load_sweep(folder)
    if not os.path.lexists(folder / "summary.json"):
        where = "" if folder.is_dir() else " (not a folder)" if os.path.lexists(folder) else " (no such folder)"
        raise RunFolderError(f"{shown(folder)}: no summary.json (nor sweep.json){where}: not a finished run")
    summary, record = read_summary(folder)
    curve_name = record.files.get("curve", "curve.csv")
    header, curve = read_curve_table(folder, curve_name)
    loading = summary["preset"].get("loading")
    steps = loading.get("steps") if isinstance(loading, dict) else None
    rows = len(next(iter(curve.values())))
    if isinstance(steps, int) and not isinstance(steps, bool) and rows != steps:
        raise RunFolderError(
            f"{shown(folder / curve_name)} is damaged: {rows} rows, but the run's preset has {steps} load steps"
        )
    if record.fit is not None and not np.all(np.isfinite(curve["f"]) & (curve["f"] > 0)):
        raise RunFolderError(  # a run's fit is a law in ln f: it has one only where every f is
            f"{shown(folder / curve_name)} is damaged: f must be a finite number > 0 at every load step, "
            "as the fit in summary.json, a law in ln f, needs"
        )
    if "lines_used" in curve and np.any(curve["lines_used"] > record.realizations.done):
        raise RunFolderError(
            f"{shown(folder / curve_name)} is damaged: lines_used exceeds the {record.realizations.done} "
            "realizations done"
        )
    return Result(
        name=record.preset.name, status=record.status, fit=None if record.fit is None else LogFit.from_dict(summary["fit"]),
        table={name.rstrip("'"): values for name, values in curve.items()},  # F' on the half-plane
        realizations=(record.realizations.done, record.realizations.requested), normalisation=record.normalisation.f,
        preset=summary["preset"], elapsed=record.elapsed_seconds, caveats=list(record.caveats), folder=folder,
        files={key: folder / name for key, name in record.files.items()}, input=record.input,
        units=column_units(header), error=record.error,
    )  # fmt: skip


def _load_sweep(folder: Path) -> SweepResult:
    from .runs.sweeprecord import read_sweep_record
    summary, record = read_sweep_record(folder)
    rows = [{k: v for k, v in point.items() if k != "set"} for point in summary["points"]]
    return SweepResult(
        name=record.name, status=record.status, parameters=list(record.sweep.parameters), rows=rows,
        folder=folder, elapsed=record.elapsed_seconds,
    )  # fmt: skip
