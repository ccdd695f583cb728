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
import json
import math
import platform
from pathlib import Path

import numpy as np
import yaml

from . import __version__
from .ensemble import RunOutcome
from .errors import RunError
from .files import atomic_write, write_npz
from .fit import json_safe
from .preset import Scene

SUMMARY_SCHEMA_VERSION = 2  # 2: "normalisation" says what the load means and defines f per solver
CURVE_COLUMNS = ("F", "f", "xi", "xi_sem", "contact_count", "contact_fraction", "indentation")
CONTACT_MEASURES = {
    "real contact": "real contact fraction",
    "mdr springs": "fraction of MDR springs in contact; not the real area",
}
# beside the pixel count, for the solvers that declare corrected_area (others have no such column)
CORRECTED_AREA = "real_area_corrected"
CORRECTED_AREA_HEADER = f"{CORRECTED_AREA} [real contact fraction, corrected for the pixels its perimeter crosses]"
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
        "contact_count_at_first_load": json_safe(float(counts[0])) if counts.size else None,
        "contact_count_at_last_load": json_safe(float(counts[-1])) if counts.size else None,
        **_corrected_area_ends(outcome),
        "caveats": outcome.caveats,
        "elapsed_seconds": round(outcome.elapsed, 6),
        "workers": outcome.workers,
        "executor": outcome.extra.get("executor"),
        "resumed_realizations": outcome.extra.get("resumed", 0),
        "retried_realizations": outcome.extra.get("retried", 0),  # had failed before the resume, ran again
        "files": files,
    }


def _corrected_area_ends(outcome: RunOutcome) -> dict:
    """The corrected real area at the first and last load; None where the solver gives none."""
    corrected = outcome.real_area_corrected
    ends = {"first": None, "last": None}
    if corrected is not None and corrected.size:
        ends = {"first": json_safe(float(corrected[0])), "last": json_safe(float(corrected[-1]))}
    return {f"{CORRECTED_AREA}_at_{end}_load": value for end, value in ends.items()}


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
    }
    return [labels.get(column, column) for column in CURVE_COLUMNS]


def column_name(header: str) -> str:
    """The short name of a curve.csv column (``F'`` of ``F' [force per unit depth: ...]``)."""
    return header.split(" [", 1)[0]


def read_curve(path: Path) -> dict[str, np.ndarray]:
    """curve.csv read back: each column by its short name (``column_name``), empty
    cells as NaN; an empty file has no columns."""
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        return {}
    return {
        column_name(header): np.array([float(row[i]) if row[i] else math.nan for row in rows[1:]])
        for i, header in enumerate(rows[0])
    }


def _write_curve(scene: Scene, outcome: RunOutcome, fh) -> None:
    writer = csv.writer(fh, lineterminator="\n")
    corrected = [CORRECTED_AREA_HEADER] if scene.solver.corrected_area else []
    writer.writerow(curve_header(scene) + corrected)
    columns = (
        outcome.force,
        outcome.f,
        outcome.xi,
        outcome.xi_sem,
        outcome.contact_count,
        outcome.contact_fraction,
        outcome.indentation,
    )
    if corrected:
        columns = (*columns, outcome.real_area_corrected)

    for row in zip(*columns, strict=True):
        writer.writerow(["" if not np.isfinite(v) else repr(float(v)) for v in row])


def write_results(out_dir: str | Path, scene: Scene, outcome: RunOutcome) -> dict[str, Path]:
    """Write the numbers of ``outcome`` into ``out_dir`` (every file but the figure,
    which is ``add_plot``'s); return their paths."""
    out = Path(out_dir)
    files: dict[str, Path] = {}

    files["curve"] = out / "curve.csv"
    atomic_write(files["curve"], lambda fh: _write_curve(scene, outcome, fh))

    files["preset"] = out / "preset.yaml"
    atomic_write(files["preset"], lambda fh: yaml.safe_dump(scene.resolved(), fh, sort_keys=False))

    if scene.preset.output.realizations:
        files["realizations"] = out / "realizations.npz"
        arrays = {**outcome.per_realization, "loads": outcome.loads, "f": outcome.f}
        atomic_write(files["realizations"], lambda fh: write_npz(fh, arrays), binary=True)

    files["summary"] = out / "summary.json"  # last: its presence means the numbers are complete
    _write_summary(out, scene, outcome, files)
    return files


def add_plot(out_dir: str | Path, scene: Scene, outcome: RunOutcome, files: dict[str, Path]) -> dict[str, Path]:
    """Draw plot.png (if the preset asks for it and anything finished) after the other
    files, and list it in summary.json (rewritten); ``files`` with the plot's path."""
    if not (scene.preset.output.plot and outcome.done):
        return files
    out = Path(out_dir)
    files = {**files, "plot": out / "plot.png"}

    def draw(fh) -> None:
        from .plot import plot_curve  # matplotlib is slow to import: only when drawing

        plot_curve(scene, outcome, fh)

    write_figure(files["plot"], draw)
    _write_summary(out, scene, outcome, files)
    return files


def write_figure(path: Path, draw) -> None:
    """Write a figure file with ``draw(file)``, which imports matplotlib itself. A
    failure is a RunError naming the file: a folder that said no, or matplotlib
    refusing (a bad MPLBACKEND, a broken font cache); the numbers are written by then."""
    try:
        atomic_write(path, draw, binary=True)
    except OSError as exc:
        raise RunError(f"cannot write {path}: {exc.strerror or exc}; the numbers are written") from None
    except Exception as exc:
        raise RunError(f"cannot draw {path}: {type(exc).__name__}: {exc}; the numbers are written") from None


def _write_summary(out: Path, scene: Scene, outcome: RunOutcome, files: dict[str, Path]) -> None:
    summary = summary_dict(scene, outcome, {k: p.name for k, p in files.items() if k != "summary"})
    atomic_write(out / "summary.json", lambda fh: json.dump(summary, fh, indent=2, allow_nan=False))
