"""Run and sweep folders a resume cannot help: every realization finished and none failed, but
the fit failed (no law: each load pressed the same points). A resume restores them all, computes
nothing and fails the same way; only another preset (other loads, more realizations) can fit.
A failed realization (out of memory, say) is computed again by a resume: that run can go on."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import FrictionlabError
from ..io.values import whole_or
from .runfolder import read_json, subfolder

MAX_SAID = 500  # characters of a recorded error said (frictionlab's own are shorter)


def fit_failed(summary: dict) -> str:
    """The error of a run whose summary.json says it failed with every realization finished and
    none failed (its fit failed), "" for any other run (a resume can go on with it)."""
    counts = summary.get("realizations") if isinstance(summary.get("realizations"), dict) else {}
    error, done = summary.get("error"), whole_or(counts.get("done"))
    if summary.get("status") != "failed" or not isinstance(error, str) or not error:
        return ""
    if not (0 < done == whole_or(counts.get("requested"), -1) and _none_failed(counts)):
        return ""
    return error if len(error) <= MAX_SAID else error[: MAX_SAID - 3] + "..."  # a file's, said whole: bounded


def _none_failed(counts: dict) -> bool:
    return whole_or(counts.get("failed"), -1) == 0  # a summary that does not say is not one a resume cannot help


def points_fit_failed(folder: Path, points: list[dict]) -> list[str]:
    """"point N: error" for each point of the sweep in ``folder`` (``points``: sweep.json's rows)
    whose fit failed with every realization finished, where each other point completed with none
    failed: what a resume of the sweep cannot help. [] where some point can go on (one pending,
    interrupted, in error, with a failed realization) or its files do not say."""
    said = []
    for number, row in enumerate(points, 1):
        try:
            summary = read_json(subfolder(folder, row["folder"]), "summary.json")
        except (OSError, FrictionlabError):
            return []
        counts = summary.get("realizations") if isinstance(summary.get("realizations"), dict) else {}
        if row.get("status") != summary.get("status"):  # a point in error: its summary is an earlier run's
            return []
        if row["status"] == "completed" and _none_failed(counts):
            continue
        if not (error := fit_failed(summary)):
            return []
        said.append(f"point {row.get('point') or number}: {error}")
    return said


def why_no_resume_helps(folder: str | Path) -> tuple[str, list[str]]:
    """("run", [its error]) for a run in ``folder`` whose fit failed with every realization
    finished, ("sweep", ["point N: error", ...]) for an ended sweep of such points (each other one
    completed), ("", []) where a resume can go on, or the folder does not say (the resume then
    says what is wrong with it). Nothing is written."""
    from .rundir import STATE_FILE
    from .sweeprecord import read_sweep_record

    folder = Path(folder)
    try:
        if os.path.lexists(folder / "sweep.json") and not os.path.lexists(folder / STATE_FILE):
            data, record = read_sweep_record(folder)
            points = points_fit_failed(folder, data["points"]) if record.status == "failed" else []
            return ("sweep", points) if points else ("", [])
        if (error := fit_failed(read_json(folder, "summary.json"))) and _ended(folder):
            return "run", [error]
    except (OSError, FrictionlabError):
        pass
    return "", []


def _ended(folder: Path) -> bool:
    """Whether run.json (where there is one) says the run ended as failed: one that says running
    is a resume going on, its summary.json an earlier run's."""
    from .rundir import STATE_FILE

    if not os.path.lexists(folder / STATE_FILE):
        return True
    return read_json(folder, STATE_FILE).get("status") == "failed"
