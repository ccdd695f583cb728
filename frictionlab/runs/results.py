"""Result files of a run. Every file is written to a temporary name in the same
folder and renamed into place, so a reader never sees half a file and an
interrupted write leaves the previous version intact.

Files in the output folder::

    summary.json       what ran, the fit, where the arrays are
    curve.csv          one row per load step
    realizations.npz   per-realization curves (output.realizations)
    preset.yaml        the resolved preset (every default filled in)
    plot.png           xi against f with the fit (output.plot); drawn last, after
                       summary.json, which is then rewritten to list it

The run directory's own files (run.lock, run.json, chunks/) are ``rundir``'s.
"""

from __future__ import annotations

import csv
import io
import json
import math
import platform
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import yaml
from pydantic import AfterValidator, Field, field_validator

from .. import __version__
from ..compute.ensemble import RunOutcome
from ..errors import RunFolderError, shown
from ..io.files import atomic_write, write_npz
from ..io.inputs import InputFileProblem, holds_exactly, open_regular_file
from ..compute.fit import json_safe
from ..preset import Scene
from ..plugin import MAX_MAGNITUDE
from ..preset.schema import MAX_BOOTSTRAP, MAX_REALIZATIONS, MAX_STEPS
from .figures import CurveFigure, DrawingProcess, plot_wanted, write_figure
from .import_ahead import PLOT_MODULE, imported
from .runfolder import Count, Finite, MemberName, Record, Seconds, check_schema_version, checked, read_json, read_number_table

SUMMARY_SCHEMA_VERSION = 2  # 2: "normalisation" says what the load means and defines f per solver
CURVE_COLUMNS = (
    "F", "f", "xi", "xi_sem", "lines_used", "contact_count", "contact_fraction", "indentation", "half_load_points",
)  # fmt: skip
# columns a later frictionlab added: a folder written before them is read without them
ADDED_CURVE_COLUMNS = frozenset({"lines_used", "half_load_points"})
HALF_LOAD_HEADER = "half_load_points [the fewest points carrying half the load; ensemble mean; empty: not given]"
CONTACT_MEASURES = {
    "real contact": "real contact fraction",
    "mdr springs": "fraction of MDR springs in contact; not the real area",
}
# beside the pixel count, for the solvers that declare corrected_area (others have no such column)
CORRECTED_AREA = "real_area_corrected"
CORRECTED_AREA_HEADER = f"{CORRECTED_AREA} [real contact fraction, corrected for the pixels its perimeter crosses]"
# beside it, for the solvers that declare real_gradient: g_r and the area law's kappa with g and with g_r
GRADIENT_COLUMNS = {
    "real_gradient_rms": "real_gradient_rms [g_r: rms |grad z| over the real contact, each pixel weighted by its share "
    "of the corrected area; dimensionless; mean over realizations]",
    "kappa": "kappa [(A / A0) E* g / p: A the real area (corrected where given), g the surface's rms |grad z|, "
    "p = F / A0; dimensionless; mean over realizations]",
    "kappa_r": "kappa_r [(A / A0) E* g_r / p; dimensionless; mean over realizations]",
}
SPOTS = "contact_spots"  # last, for the solvers that count spots
SPOTS_HEADER = f"{SPOTS} [number of contact spots: clusters of contact pixels joined along rows and columns; mean over realizations]"
INDENTATION_REFERENCES = {
    "undeformed body": "length; from the first touch; against the undeformed body",
    "mean surface": "length; from the first touch; against the mean plane of the elastic surface",
}


def summary_dict(scene: Scene, outcome: RunOutcome, files: dict[str, str]) -> dict:
    fit = outcome.fit.to_dict() if outcome.fit else None
    counts = outcome.contact_count
    return {
        "schema_version": SUMMARY_SCHEMA_VERSION,
        "frictionlab_version": __version__,
        "python": platform.python_version(),
        "preset": scene.resolved(),
        "input": scene.spectrum.input_summary(),  # a file's shape, pixel size, unit as read (JSON-ready: the kit checks)
        "seed": scene.preset.seed,
        "status": outcome.status,
        "error": outcome.error,
        "realizations": {
            "requested": outcome.requested,
            "done": outcome.done,
            "failed": len(outcome.failures),
            "failures": [{"index": i, "error": e} for i, e in outcome.failures[:20]],
        },
        "fit": fit,
        "normalisation": {
            key: json_safe(value) if isinstance(value, float) else value
            for key, value in outcome.normalisation.describe(outcome.stiffness, outcome.rms_height, outcome.extent).items()
        },
        "heights": heights_summary(outcome),
        "lines_used": {
            "min": int(outcome.lines_used.min()) if outcome.lines_used.size else None,
            "max": int(outcome.lines_used.max()) if outcome.lines_used.size else None,
            "meaning": "realizations whose xi is defined at a load step (some point in contact has a slope)",
        },
        "contact_count_at_first_load": json_safe(float(counts[0])) if counts.size else None,
        "contact_count_at_last_load": json_safe(float(counts[-1])) if counts.size else None,
        **_corrected_area_ends(outcome),
        **_half_load_ends(outcome),
        "peak_height_rms": json_safe(float(outcome.peak_rms)),
        "caveats": outcome.caveats,
        # the run's sessions summed (run_to_folder): a resume's own time added to what the folder recorded
        "elapsed_seconds": round(outcome.sessions_elapsed, 6),
        "workers": outcome.workers,
        "executor": outcome.extra.get("executor"),
        "resumed_realizations": outcome.extra.get("resumed", 0),
        "retried_realizations": outcome.extra.get("retried", 0),  # had failed before the resume, ran again
        "files": files,
    }


def heights_summary(outcome: RunOutcome) -> dict:
    """Which h forms f, and the rms heights the lines measured about their own means."""
    measured = outcome.per_realization.get("measured_rms_height", np.empty(0))
    measured = measured[np.isfinite(measured)]

    def stat(op):
        return json_safe(float(op(measured))) if measured.size else None

    return {
        "h_in_f": "each line's own rms height about its mean" if outcome.own_rms_height
        else "the spectrum's nominal rms height",
        "h": json_safe(outcome.rms_height),
        "measured_rms_height": {
            "mean": stat(np.mean),
            "std": stat(lambda m: np.std(m, ddof=1)) if measured.size >= 2 else None,
            "min": stat(np.min),
            "max": stat(np.max),
            "lines": int(measured.size),
        },
    }


def _corrected_area_ends(outcome: RunOutcome) -> dict:
    """The corrected real area at the first and last load; None where the solver gives none."""
    corrected = outcome.real_area_corrected
    ends = {"first": None, "last": None}
    if corrected is not None and corrected.size:
        ends = {"first": json_safe(float(corrected[0])), "last": json_safe(float(corrected[-1]))}
    return {f"{CORRECTED_AREA}_at_{end}_load": value for end, value in ends.items()}


def _half_load_ends(outcome: RunOutcome) -> dict:
    """The mean points carrying half the load at the first and last load; None where not said."""
    half = outcome.half_load_points
    ends = {"first": None, "last": None}
    if half is not None and half.size:
        ends = {"first": json_safe(float(half[0])), "last": json_safe(float(half[-1]))}
    return {f"half_load_points_at_{end}_load": value for end, value in ends.items()}


def curve_header(scene: Scene) -> list[str]:
    """The columns of curve.csv, each a short name (``CURVE_COLUMNS``) with what it
    means in brackets: the load with its unit, f with its definition."""
    n = scene.normalisation
    f = n.definition.removeprefix("f = ").replace(", ", "; ")
    labels = {
        "F": f"{n.load_symbol} [{n.load}: {n.load_unit}]",
        "f": f"f [{f}]",
        "contact_fraction": f"contact_fraction [{CONTACT_MEASURES[scene.solver.contact_measure]}]",
        "indentation": f"indentation [{INDENTATION_REFERENCES[scene.solver.indentation_reference]}]",
        "half_load_points": HALF_LOAD_HEADER,
    }
    return [labels.get(column, column) for column in CURVE_COLUMNS]


def column_name(header: str) -> str:
    """The short name of a curve.csv column (``F'`` of ``F' [force per unit depth: ...]``)."""
    return header.split(" [", 1)[0]


def read_curve(folder: Path, name: str = "curve.csv") -> dict[str, np.ndarray]:
    """A run folder's curve.csv read back (``runfolder``: inside the folder, never
    through a link): each column by its short name (``column_name``), empty cells as
    NaN. RunFolderError naming the file for anything but the table frictionlab writes."""
    return read_curve_table(folder, name)[1]


def read_curve_table(folder: Path, name: str = "curve.csv") -> tuple[list[str], dict[str, np.ndarray]]:
    """``read_curve``, with the header row as written."""

    def check_header(header: list[str]) -> None:
        stripped = [column_name(h).rstrip("'") for h in header]  # F' on the half-plane
        expected = [c for c in CURVE_COLUMNS if c in stripped or c not in ADDED_CURVE_COLUMNS]
        optional = [CORRECTED_AREA, *GRADIENT_COLUMNS, SPOTS]  # in this order, for the solvers that give them
        extra = stripped[len(expected) :]
        if stripped[: len(expected)] != expected or extra != [c for c in optional if c in extra] or len(set(extra)) != len(extra):
            raise RunFolderError(
                f"{shown(Path(folder) / name)} is damaged (its header does not name the {len(CURVE_COLUMNS)} columns "
                f"frictionlab writes: {', '.join(CURVE_COLUMNS)})"
            )

    header, rows = read_number_table(folder, name, check_header=check_header)
    names = [column_name(h) for h in header]
    table = np.array(rows, dtype=float).reshape(len(rows), len(names))
    curve = {n: table[:, i].copy() for i, n in enumerate(names)}
    _check_counts(curve, Path(folder) / name)
    return header, curve


def _check_counts(curve: dict[str, np.ndarray], path: Path) -> None:
    """Counts are counts: ``lines_used`` a whole number >= 0 at every step, the mean
    ``contact_count`` >= 0 and ``contact_fraction`` in [0, 1] where given; the force, xi
    and its standard error are >= 0 where given, as every run writes them."""
    problems = []
    if "lines_used" in curve:
        used = curve["lines_used"]
        if not np.all(np.isfinite(used) & (used >= 0) & (used == np.round(used))):
            problems.append("lines_used must be a whole number >= 0 at every load step")
    bounds = [("contact_count", 0.0, np.inf), ("contact_fraction", 0.0, 1.0), (CORRECTED_AREA, 0.0, 1.0)]
    extra = ("F", "F'", "f", "xi", "xi_sem", *GRADIENT_COLUMNS, SPOTS, "half_load_points")
    for column, low, high in bounds + [(name, 0.0, np.inf) for name in extra]:
        if column not in curve:
            continue
        values = curve[column][~np.isnan(curve[column])]
        if np.any((values < low) | (values > high)):
            problems.append(f"{column} must be {'in [0, 1]' if high == 1.0 else '>= 0'}")
    if problems:
        raise RunFolderError(f"{shown(path)} is damaged ({'; '.join(problems)})")


# ------------------------------------------------------------------ summary.json, read back

WRITTEN_FILES = {"curve": "curve.csv", "preset": "preset.yaml", "realizations": "realizations.npz",
                 "summary": "summary.json", "plot": "plot.png"}  # summary.json's files, by key: the names written
Coefficient = Annotated[float, Field(ge=-MAX_MAGNITUDE, le=MAX_MAGNITUDE, allow_inf_nan=False, strict=True)]


def _ordered(interval: list | None) -> list | None:
    if interval is not None and None not in interval and interval[0] > interval[1]:
        raise ValueError(f"must be an interval LO <= HI, got {interval[0]!r} > {interval[1]!r}")
    return interval


_Interval = Annotated[list[Coefficient | None], Field(min_length=2, max_length=2), AfterValidator(_ordered)]


Spread = Annotated[float, Field(ge=0, allow_inf_nan=False, strict=True)]  # a standard error, an rms: never < 0


class FitRecord(Record):
    a: Coefficient  # xi is at most a few: 1e308 drew an overflow
    b: Coefficient
    a_se: Spread | None = None
    b_se: Spread | None = None
    a_se_bootstrap: Spread | None = None
    b_se_bootstrap: Spread | None = None
    a_ci: _Interval | None = None
    b_ci: _Interval | None = None
    confidence: Annotated[float, Field(gt=0, lt=1, strict=True)] = 0.95
    bootstrap: Annotated[int, Field(ge=0, le=MAX_BOOTSTRAP, strict=True)] = 0  # predict --from redraws them
    r2: Finite | None = None
    residual_rms: Spread | None = None
    points: Annotated[int, Field(ge=0, le=MAX_STEPS, strict=True)] = 0  # load steps fitted


class _Failure(Record):
    index: Count
    error: str


class _Counts(Record):
    requested: Annotated[int, Field(ge=0, le=MAX_REALIZATIONS, strict=True)]
    done: Count
    failed: Count = 0
    failures: list[_Failure] = []


class _PresetName(Record):
    name: Annotated[str, Field(min_length=1)]
    realizations: Annotated[int, Field(ge=1, le=MAX_REALIZATIONS, strict=True)] | None = None


class _Normalisation(Record):
    f: str = ""


_InputScalar = str | int | Finite | bool | None
_InputPart = _InputScalar | list[_InputScalar] | dict[str, _InputScalar | list[_InputScalar]]
# A value of an input summary (``SpectrumGenerator.input_summary``): a number, text, a flag, or a list or mapping
# of them one level deep (the file's channels, each a mapping; the crop's spans; despike's k and count; caveats).
InputValue = _InputScalar | list[_InputPart] | dict[str, _InputPart]


class SummaryRecord(Record):
    """What load() and predict --from trust of a summary.json: each value checked."""

    schema_version: Annotated[int, Field(ge=1, strict=True)] = 1
    preset: _PresetName
    status: Literal["completed", "cancelled", "interrupted", "failed"]
    error: str | None = None  # why a failed run failed
    seed: Count | None = None
    fit: FitRecord | None = None
    realizations: _Counts
    normalisation: _Normalisation = _Normalisation()
    caveats: list[str] = []
    elapsed_seconds: Seconds = 0.0
    contact_count_at_first_load: Finite | None = None
    contact_count_at_last_load: Finite | None = None
    workers: Annotated[int, Field(ge=1, strict=True)] | None = None
    executor: str | None = None
    files: dict[str, MemberName] = {}
    # what a measured file gave (shape, pixel size, unit, rms height, where each came from)
    input: dict[str, InputValue] | None = None

    @field_validator("files")
    @classmethod
    def _files_named_as_written(cls, files: dict[str, str]) -> dict[str, str]:
        """Each file a run writes under its own name: another (curve: run.json) was read as it, and
        its faults blamed on a file that has none."""
        for key, name in files.items():
            if key in WRITTEN_FILES and name != WRITTEN_FILES[key]:
                raise ValueError(f"files.{key} must be {WRITTEN_FILES[key]!r}, the name a run writes it under; got {name!r}")
        return files


def read_summary(folder: Path) -> tuple[dict[str, Any], SummaryRecord]:
    """A run folder's summary.json: the JSON object and its checked record
    (RunFolderError naming the file and the field, a newer schema by its version)."""
    path = Path(folder) / "summary.json"
    data = read_json(folder, "summary.json")
    check_schema_version(data, path, SUMMARY_SCHEMA_VERSION)
    record = checked(SummaryRecord, data, path)
    counts = record.realizations
    problem = None
    ran = counts.done + counts.failed  # done: finished with a curve; failed: raised (a run goes on past them)
    if ran > counts.requested:
        problem = "fields 'realizations.done' and 'realizations.failed' add up to more than 'realizations.requested'"
    elif record.status == "completed" and ran < counts.requested:  # else cancelled or interrupted
        problem = ("its status is 'completed', but fields 'realizations.done' and 'realizations.failed' add up "
                   "to less than 'realizations.requested'")  # fmt: skip
    elif record.fit is not None and not counts.done:
        problem = "field 'fit' holds a fit, but no realization was done"
    elif record.fit is None and counts.done and record.status != "failed":
        problem = "field 'fit' is null, but realizations were done and the run did not fail"
    if problem:
        raise RunFolderError(f"{shown(path)} is damaged: {problem}")
    return data, record


def curve_headers(scene: Scene) -> list[str]:
    """curve.csv's whole header row: ``curve_header``, then the columns the solver adds."""
    corrected = [CORRECTED_AREA_HEADER] if scene.solver.corrected_area else []
    gradient = list(GRADIENT_COLUMNS.values()) if scene.solver.real_gradient else []
    spots = [SPOTS_HEADER] if scene.solver.counts_spots else []
    return curve_header(scene) + corrected + gradient + spots


PLAIN_COLUMNS = {  # the columns whose header has no brackets: numbers without a unit, said as such
    "xi": "dimensionless: rms slope in contact / rms slope of the line; ensemble mean",
    "xi_sem": "dimensionless: standard error of the mean of xi",
    "lines_used": "count: realizations whose xi is defined at this load",
    "contact_count": "count: points in contact; ensemble mean",
}


def column_units(headers: list[str]) -> dict[str, str]:
    """What each column is, in its unit, by short name (``F`` of ``F' [...]`` too): the
    brackets of curve.csv's header, or for a column without them what kind of number it is."""
    units = {column_name(h).rstrip("'"): h.split(" [", 1)[1].removesuffix("]") for h in headers if " [" in h}
    return {**{name: PLAIN_COLUMNS[name] for name in headers if name in PLAIN_COLUMNS}, **units}


def _write_curve(scene: Scene, outcome: RunOutcome, fh) -> None:
    writer = csv.writer(fh, lineterminator="\n")
    writer.writerow(curve_headers(scene))
    columns = (
        outcome.force,
        outcome.f,
        outcome.xi,
        outcome.xi_sem,
        outcome.lines_used,
        outcome.contact_count,
        outcome.contact_fraction,
        outcome.indentation,
        outcome.half_load_points if outcome.half_load_points is not None else np.full(outcome.f.size, np.nan),
    )
    if scene.solver.corrected_area:
        columns = (*columns, outcome.real_area_corrected)
    if scene.solver.real_gradient:
        columns = (*columns, outcome.real_gradient_rms, outcome.kappa, outcome.kappa_r)
    if scene.solver.counts_spots:
        columns = (*columns, outcome.contact_spots)

    plain = [np.asarray(column, dtype=float).tolist() for column in columns]  # Python floats: no numpy scalar per cell
    for row in zip(*plain, strict=True):
        writer.writerow([repr(v) if math.isfinite(v) else "" for v in row])


def results_on_disk(folder: Path, scene: Scene, plot: bool) -> bool:
    """Whether ``folder`` holds what ``write_results`` (and ``add_plot`` with ``plot``) wrote for
    a completed run of ``scene``: each file regular (no link), summary.json an object saying so."""
    out = scene.preset.output
    wanted = ["curve.csv"] + (["realizations.npz"] if out.realizations else []) + (["plot.png"] if plot and out.plot else [])
    try:
        for name in wanted:
            open_regular_file(folder / name, follow_links=False).close()
        return read_json(folder, "summary.json").get("status") == "completed"
    except (InputFileProblem, RunFolderError):
        return False


def holds_results(folder: Path, scene: Scene, outcome: RunOutcome) -> bool:
    """Whether curve.csv in ``folder`` (and realizations.npz where the preset asks for it) is
    exactly what ``write_results`` writes for ``outcome``: both are the same bytes for the
    same numbers (the archive's members carry no time stamp)."""
    buffer = io.StringIO(newline="")
    _write_curve(scene, outcome, buffer)
    if not holds_exactly(folder / "curve.csv", buffer.getvalue().encode()):
        return False
    if not scene.preset.output.realizations:
        return True
    archive = io.BytesIO()
    write_npz(archive, _realization_arrays(outcome))
    return holds_exactly(folder / "realizations.npz", archive.getvalue())


def _realization_arrays(outcome: RunOutcome) -> dict:
    return {**outcome.per_realization, "loads": outcome.loads, "f": outcome.f, "lines_used": outcome.lines_used}


def write_results(out_dir: str | Path, scene: Scene, outcome: RunOutcome) -> dict[str, Path]:
    """Write the numbers of ``outcome`` into ``out_dir`` (every file but the figure,
    which is ``add_plot``'s); return their paths."""
    out = Path(out_dir)
    files: dict[str, Path] = {}

    files["curve"] = out / WRITTEN_FILES["curve"]
    atomic_write(files["curve"], lambda fh: _write_curve(scene, outcome, fh))

    files["preset"] = out / WRITTEN_FILES["preset"]
    preset = yaml.safe_dump(scene.resolved(), sort_keys=False)
    if not holds_exactly(files["preset"], preset.encode()):  # the run's start wrote it: one fsync less
        atomic_write(files["preset"], lambda fh: fh.write(preset))

    if scene.preset.output.realizations:
        files["realizations"] = out / WRITTEN_FILES["realizations"]
        arrays = _realization_arrays(outcome)
        atomic_write(files["realizations"], lambda fh: write_npz(fh, arrays), binary=True)

    files["summary"] = out / WRITTEN_FILES["summary"]  # last: its presence means the numbers are complete
    _write_summary(out, scene, outcome, files)
    return files


def plot_path(out_dir: str | Path) -> Path:
    return Path(out_dir) / WRITTEN_FILES["plot"]


def add_plot(out_dir: str | Path, scene: Scene, outcome: RunOutcome, files: dict[str, Path],
             drawing: DrawingProcess | None = None) -> dict[str, Path]:  # fmt: skip
    """Draw plot.png (if the preset asks for it and anything finished) after the other
    files, and list it in summary.json (rewritten); ``files`` with the plot's path.
    ``drawing``: a ``DrawingProcess`` sent it already, waited for (drawn here if it died)."""
    if not plot_wanted(scene, outcome):
        return files
    out = Path(out_dir)
    files = {**files, "plot": plot_path(out)}
    if drawing is None or not drawing.wait():
        write_curve_figure(files["plot"], CurveFigure.of(scene, outcome))
    _write_summary(out, scene, outcome, files)
    return files


def write_curve_figure(path: Path, figure: CurveFigure, **written) -> None:
    """plot.png of ``figure``, drawn in this process (``written``: ``write_figure``'s devices and kept)."""
    write_figure(path, lambda fh: imported(PLOT_MODULE).plot_curve(figure, fh), **written)


def _write_summary(out: Path, scene: Scene, outcome: RunOutcome, files: dict[str, Path]) -> None:
    summary = summary_dict(scene, outcome, {k: p.name for k, p in files.items() if k != "summary"})
    atomic_write(out / "summary.json", lambda fh: json.dump(summary, fh, indent=2, allow_nan=False))
