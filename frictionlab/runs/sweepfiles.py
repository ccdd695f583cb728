"""A sweep's own files beside its points/ folder: sweep.csv and sweep.json written after every
point, a folder checked before a sweep writes into it, and the sweep read back from them."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path
from typing import TYPE_CHECKING

from .. import __version__
from ..errors import OutputRefused, RunFolderError, shown_name
from ..io.files import atomic_write, refuse_unreplaceable, refuse_unusable_folder
from .runfolder import read_json, refuse_other_kind
from .sweeprecord import MAX_SWEEP_RECORD_BYTES, SWEEP_SCHEMA_VERSION, as_it_ran, read_sweep_record

if TYPE_CHECKING:
    from .sweep import Sweep, SweepOutcome

RESULT_COLUMNS = (
    "status", "done", "a", "a_lo", "a_hi", "b", "b_lo", "b_hi", "r2",
    "contact_first", "contact_last", "elapsed_s", "folder",
)  # fmt: skip

class OtherSweep(OutputRefused):
    """The folder holds something else than this sweep (a resume reads it as its sweep.json edited)."""


SWEEP_FILES = ("sweep.csv", "sweep.json", "sweep.png")  # what a sweep writes in its folder, beside points/


def check_sweep_folder(sweep: Sweep, out_dir: Path, force: bool = False, resume: bool = False) -> None:
    """OutputRefused unless ``out_dir`` is new, empty, or holds this same sweep
    (its sweep.json names the same sweep and base preset), or ``force``; with ``resume``,
    RunFolderError where a point's folder started another preset (``refuse_changed_points``)."""
    refuse_unusable_folder(out_dir)
    refuse_unreplaceable([out_dir / name for name in SWEEP_FILES], "sweep", "give another output folder")  # --force too
    refuse_other_kind(out_dir, "sweep")  # --force too
    if not force and out_dir.is_dir() and any(out_dir.iterdir()):
        _refuse_other_sweep(sweep, out_dir)
    if resume:  # after: a preset given that is not the sweep's is said so, not as sweep.json edited
        refuse_changed_points(sweep, out_dir)


def _refuse_other_sweep(sweep: Sweep, out_dir: Path) -> None:
    hint = "give another output folder, or force it (--force; force=True in Python) to write into it anyway"
    try:
        old = as_it_ran(read_json(out_dir, "sweep.json", MAX_SWEEP_RECORD_BYTES))
    except RunFolderError:
        raise OtherSweep(
            f"{shown_name(out_dir)} is not empty and is not the folder of a frictionlab sweep (no readable sweep.json): {hint}"
        ) from None
    mine = {"name": sweep.name, "sweep": sweep.spec.model_dump(mode="json", exclude_none=True), "base_preset": sweep.base}
    mine = json.loads(json.dumps(mine, default=str))
    if not isinstance(old, dict) or any(old.get(key) != value for key, value in mine.items()):
        raise OtherSweep(f"{shown_name(out_dir)} holds another sweep: {hint} (its tables are then replaced)"
                         + _changes(old, mine))


def refuse_changed_points(sweep: Sweep, out_dir: Path, shown: int = 8) -> None:
    """RunFolderError, before a resumed sweep runs or writes anything, where every started point's run.json
    began with another preset than the sweep (its sweep.json, edited) plans for it: each point's own resume
    refused it, and the sweep then wrote its finished rows as errors, their fits gone. Where only some
    differ, their folders do (another run moved there): the sweep goes on, and says so of each."""
    from .rundir import STATE_FILE, RunDirectory, json_copy

    changed: dict[tuple[str, ...], list[int]] = {}  # the differences, and the points that have them
    started = 0
    for point in sweep.points:
        folder = RunDirectory(out_dir / "points" / point.folder_name)
        if folder.path.is_symlink() or not (folder.path / STATE_FILE).is_file():
            continue  # not started, or not a folder of the sweep's: the point's own run says so
        try:
            state = folder.state()
            lines = folder.preset_changes(state, json_copy(point.scene.resolved()), point.scene) if state else []
        except RunFolderError:  # a damaged run.json: the point's own resume says what is wrong
            continue
        started += 1
        if lines:
            changed.setdefault(tuple(lines), []).append(point.number)
    if changed and sum(map(len, changed.values())) == started:
        said = "".join(f"\n  point{'s' if len(n) > 1 else ''} {', '.join(map(str, n))}: " + "; ".join(lines[:shown])
                       + (f"; ... and {len(lines) - shown} more" if len(lines) > shown else "") for lines, n in changed.items())
        raise RunFolderError(
            f"cannot resume {shown_name(out_dir)}: {shown_name(out_dir / 'sweep.json')} (its base_preset and sweep) differs from "
            f"the preset its points' {STATE_FILE} started with ('in the run directory': a point's {STATE_FILE}; 'given': sweep.json)"
            f"{said}\nnothing was run or written: put sweep.json back as it was, or run the changed sweep into another "
            f"folder; a point folder that holds another run: move it aside, then resume the sweep to compute that point afresh"
        )


def _changes(old, mine: dict, shown: int = 8) -> str:
    """Where the sweep stored (``old``, its sweep.json) and the one given differ, a line each, the
    first ``shown`` of them: 'holds another sweep' alone named no field to look at."""
    from ..preset.paths import differences

    def flat(record: dict) -> dict:  # as the preset reads: its fields, and its sweep section
        base = record.get("base_preset")
        return {**(base if isinstance(base, dict) else {"base_preset": base}), "sweep": record.get("sweep")}

    changed = differences(flat(old), flat(mine)) if isinstance(old, dict) else []
    more = f"\n  ... and {len(changed) - shown} more" if len(changed) > shown else ""
    return "".join(f"\n  {line}" for line in changed[:shown]) + more


def refuse_a_sweep_without_record(folder: Path, command: str) -> None:
    """RunFolderError where ``folder`` is a sweep's (its sweep.csv or points/, no run of its own) whose
    sweep.json is gone: it was refused as 'no preset.yaml' (or 'no run.json'), files no sweep has."""
    from .rundir import PRESET_FILE, STATE_FILE

    # lexists: a folder that cannot be searched is said so by the reads that follow, not raised here
    if any(os.path.lexists(folder / name) for name in ("sweep.json", PRESET_FILE, STATE_FILE)):
        return
    left = [shown for name, shown in (("sweep.csv", "sweep.csv"), ("points", "points/")) if os.path.lexists(folder / name)]
    if left:
        raise RunFolderError(
            f"{shown_name(folder)} is a sweep's folder (it holds {' and '.join(left)}) but its sweep.json, which says "
            f"what the sweep is, is missing: frictionlab {command} cannot read the sweep without it. Each point in "
            f"{shown_name(folder / 'points')}/ is a run of its own (frictionlab {command} POINT_FOLDER); or run the "
            "sweep's preset into another folder"
        )


def stored_sweep(out_dir: Path) -> dict:
    """The preset data of the sweep stored in ``out_dir`` (its sweep.json: the base preset
    and the sweep), for ``frictionlab resume``; RunFolderError if it holds none, or a damaged one."""
    data, _ = read_sweep_record(out_dir)
    return {**data["base_preset"], "sweep": data["sweep"]}  # as Sweep.preset_data


def completed_rows(out_dir: Path) -> dict[int, dict]:
    """The rows of the sweep.json in ``out_dir`` whose point completed, by number ({} where none is read):
    a resumed point in error (its folder refused) kept its fit nowhere but in its row."""
    try:
        return {n: row for n, row in enumerate(read_sweep_record(out_dir)[0]["points"], 1) if row["status"] == "completed"}
    except RunFolderError:
        return {}


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
