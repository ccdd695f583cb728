"""A sweep folder's sweep.json read back as untrusted input: every value checked
(``runfolder``), and a row for every point its sweep section plans, that point's own
(``combinations`` and ``folder_name``, which the planner ``sweep.plan_sweep`` uses too)."""

from __future__ import annotations

import itertools
import json
import math
import re
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, ValidationError, model_validator

from ..errors import RunFolderError, short_repr, shown, shown_name
from ..preset.paths import MISSING, as_now, get_path
from ..preset.schema import SweepSettings
from .runfolder import Count, Finite, MemberName, Record, Seconds, check_schema_version, checked, read_json

SWEEP_SCHEMA_VERSION = 1
MAX_SWEEP_RECORD_BYTES = 64 * 1024 * 1024  # a sweep.json holds a row per point: at most 1000 of them


class PointRecord(Record):
    """A point's row of sweep.json (or of a followed sweep's progress log): each value checked."""

    folder: MemberName
    status: Literal["completed", "cancelled", "interrupted", "failed", "error", "pending"]  # PointResult's
    point: Annotated[int, Field(ge=1, strict=True)] | None = None
    label: str | None = None
    set: list[str] | None = None  # the point's --set options
    done: Count | None = None
    elapsed_s: Seconds | None = None
    contact_first: Finite | None = None
    contact_last: Finite | None = None
    a: Finite | None = None
    a_lo: Finite | None = None
    a_hi: Finite | None = None
    b: Finite | None = None
    b_lo: Finite | None = None
    b_hi: Finite | None = None
    r2: Finite | None = None
    error: str | None = None  # why a failed point failed

    @model_validator(mode="after")
    def _finite_values(self):
        """A swept value of NaN or infinity (its row's own keys): follow --json failed on it, an internal error."""
        for key, value in (self.model_extra or {}).items():
            if isinstance(value, float) and not math.isfinite(value):
                raise ValueError(f"{key} must be a finite number, or text, got {value!r}")
        return self


class _SweepSpecRecord(Record):
    parameters: dict[str, Any]


class SweepRecord(Record):
    """What load(), resume and the TUI trust of a sweep.json: each value checked."""

    sweep: _SweepSpecRecord  # first: what a resume needs, named first when missing
    base_preset: dict[str, Any]
    schema_version: Annotated[int, Field(ge=1, strict=True)] = 1
    name: Annotated[str, Field(min_length=1)]
    status: Literal["running", "completed", "interrupted", "failed"]  # SweepOutcome's
    elapsed_seconds: Seconds = 0.0
    points: list[PointRecord]


def read_sweep_record(out_dir: Path) -> tuple[dict[str, Any], SweepRecord]:
    """A sweep folder's sweep.json (read as any run folder's file is: ``runfolder``): the
    JSON object and its checked record; RunFolderError naming the file and the field."""
    path = Path(out_dir) / "sweep.json"
    data = as_it_ran(read_json(out_dir, "sweep.json", MAX_SWEEP_RECORD_BYTES))
    check_schema_version(data, path, SWEEP_SCHEMA_VERSION)
    record = checked(SweepRecord, data, path)
    try:  # a row per point: a list cut short would be read as a smaller sweep
        spec = SweepSettings.model_validate(data["sweep"])
    except ValidationError:
        raise RunFolderError(f"{shown_name(path)} is damaged (sweep: not a sweep section a preset can hold)") from None
    if len(record.points) != (points := spec.count()):
        raise RunFolderError(f"{shown_name(path)} is damaged (points: {len(record.points)} rows for a sweep of {points} points)")
    _check_swept_values(data["points"], list(record.sweep.parameters), path)
    _check_rows_are_the_plans(data["points"], combinations(spec), path)
    return data, record


def combinations(spec: SweepSettings) -> list[dict[str, Any]]:
    """Each point's swept values, in the points' order: the product of the values (grid), or their pairs (zip)."""
    paths = list(spec.parameters)
    columns = [spec.parameters[p].points() for p in paths]
    rows = itertools.product(*columns) if spec.mode == "grid" else zip(*columns, strict=True)
    return [dict(zip(paths, row, strict=True)) for row in rows]


def folder_name(number: int, count: int, values: dict[str, Any]) -> str:
    """The name of the folder in points/ of point ``number`` (of ``count``) whose swept values are ``values``."""
    parts = [f"{path.rsplit('.', 1)[-1]}-{f'{v:.6g}' if isinstance(v, float) else v}" for path, v in values.items()]
    label = re.sub(r"[^A-Za-z0-9._+=-]+", "-", "_".join(parts))[:80].strip("-") or "point"
    return f"{number:0{max(2, len(str(count)))}d}-{label}"


def _check_rows_are_the_plans(rows: list[dict], planned: list[dict[str, Any]], path: Path) -> None:
    """Each row is its point's of the plan (sweep.parameters): its number, its swept values, its folder. A row
    edited, repeated or reordered was shown, drawn and counted as the point's, and a resume left its folder behind."""
    same = lambda a, b: a == b and isinstance(a, bool) == isinstance(b, bool)  # noqa: E731  (True is 1 to Python)
    for index, (row, values) in enumerate(zip(rows, planned, strict=True)):
        number, name = index + 1, folder_name(index + 1, len(planned), values)
        wanted = {"point": number, **json.loads(json.dumps(values, default=str)), "label": name, "folder": f"points/{name}"}
        for field, value in wanted.items():
            if (field in values or row.get(field) is not None) and not same(row.get(field), value):
                raise RunFolderError(
                    f"{shown_name(path)} is damaged: field 'points.{index}.{field}' is {short_repr(row.get(field))}, but "
                    f"point {number} of its sweep.parameters has {short_repr(value)}: its rows are not those of its sweep")


def as_it_ran(data):
    """A sweep.json's object with each parameter's ``spacing: log`` beside ``values`` read as
    ``linear``, and its base preset's retired values as they now read (``as_now``): a sweep
    started before that pair was refused ran its values as listed, and stays one that resume,
    follow and load read (and a run into its folder takes as the same sweep)."""
    if isinstance(data, dict) and isinstance(data.get("base_preset"), dict):
        data = {**data, "base_preset": as_now(data["base_preset"])[0]}
    sweep = data.get("sweep") if isinstance(data, dict) else None
    if not isinstance(sweep, dict) or not isinstance(sweep.get("parameters"), dict):
        return data
    listed = lambda p: isinstance(p, dict) and p.get("values") is not None and p.get("spacing") == "log"  # noqa: E731
    parameters = {path: {**p, "spacing": "linear"} if listed(p) else p for path, p in sweep["parameters"].items()}
    return {**data, "sweep": {**sweep, "parameters": parameters}}


def _check_swept_values(rows: list[dict], parameters: list[str], path: Path) -> None:
    """Each row holds the value its point gave each swept parameter, a scalar as a sweep's values
    are: a row without it, or with a mapping there, was shown and compared as the point's value."""
    for number, row in enumerate(rows):
        for parameter in parameters:
            value = row.get(parameter, MISSING)
            if value is MISSING or not (value is None or isinstance(value, (str, int, float, bool))):
                said = "missing" if value is MISSING else f"a {type(value).__name__}, not text, a number, true, false or null"
                raise RunFolderError(f"{shown_name(path)} is damaged: field 'points.{number}.{parameter}' (the swept value "
                                     f"of point {number + 1}) is {said}")  # fmt: skip


def own_point(point, name: str, row: dict, parameters: list[str]):
    """``point`` (a run read back from a point's folder: its ``folder``, its resolved ``preset``) if it
    is that ``row``'s point of sweep ``name``, else RunFolderError: another run moved into its place
    would be read as it."""
    preset = point.preset
    wrong = [] if preset.get("name") == name else [("name", preset.get("name"), name)]
    for path in parameters:  # a swept value as the row holds it; a mapping or list is filled in by the reader
        value, held = row.get(path), get_path(preset, path)
        if held is not MISSING and isinstance(value, (str, int, float, bool)) and value != held:
            wrong.append((path, held, value))
    if wrong:
        field, held, wanted = wrong[0]
        raise RunFolderError(
            f"{shown(point.folder)} holds another run than point {row.get('point')} of sweep {name!r} (its {field} is "
            f"{held!r}, the point's {wanted!r}): move it aside, then resume the sweep to compute the point afresh"
        )
    return point
