"""Reading a run folder, which is untrusted input: it may come from anyone (an archive,
a colleague's copy, a tampered folder). The one reader of ``load()``, resume,
``predict --from``, sweeps and the TUI's list of runs:

- a file is named relative to the folder by a plain path (no absolute path, no
  ``..``) and opened one component at a time without following a symbolic link
  (O_NOFOLLOW), so nothing read lies outside the folder;
- only a regular file is read (opened without blocking, checked on the open
  descriptor: a FIFO or a device never blocks), within a size cap;
- JSON must be an object, and its values are checked against a schema (pydantic); a
  schema version newer than this frictionlab reads is refused by its number;
- every problem is a RunFolderError naming the file and what is wrong, never quoting
  the file's content (a link out of the folder must not leak a line of its target).

Writing is ``files.atomic_write``'s: a file in a run folder is replaced, never written
through a link.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from pathlib import Path, PurePosixPath
from typing import Annotated

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError

from .errors import RunFolderError, shown
from .inputs import InputFileProblem, read_regular_file

MAX_JSON_BYTES = 64 * 1024 * 1024  # summary.json is a few kB, run.json ~100 bytes a chunk (4096 at most)
MAX_CSV_BYTES = 16 * 1024 * 1024  # curve.csv: a row of 7 numbers per load step


def _member(name: str) -> str:
    """A file name inside a run folder: a plain relative path (what pydantic calls a value error)."""
    parts = PurePosixPath(name).parts
    if not parts or name.startswith("/") or "\\" in name or any(p in ("..", ".") for p in parts) or "\0" in name:
        raise ValueError("must name a file inside the run folder (a relative path without '..')")
    return name


MemberName = Annotated[str, AfterValidator(_member)]
"""A schema field that names a file (or folder) of the run folder."""
Finite = Annotated[float, Field(allow_inf_nan=False, strict=True)]
Count = Annotated[int, Field(ge=0, strict=True)]


class Record(BaseModel):
    """The base of a run folder file's schema: values strictly typed (a string is not a
    number), a field a later frictionlab adds kept unchecked."""

    model_config = ConfigDict(extra="allow", strict=True, defer_build=True)  # built when a folder is read


def subfolder(root: Path, name: str) -> Path:
    """``root / name`` once every component of ``name`` (a relative path) is known to be
    a folder and not a symbolic link: a sweep's point folders stay inside the sweep's.
    RunFolderError naming the path otherwise."""
    path = Path(root) / name
    try:
        parts = PurePosixPath(_member(name)).parts
    except ValueError as exc:
        raise RunFolderError(f"{shown(path)}: {exc}") from None
    here = Path(root)
    for part in parts:
        here = here / part
        try:
            fd = os.open(here, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC)
        except FileNotFoundError:
            raise RunFolderError(f"{shown(path)} does not exist") from None
        except OSError:
            raise RunFolderError(f"{shown(here)} is a symbolic link or not a folder, which is never followed") from None
        os.close(fd)
    return path


def read_member(folder: str | Path, name: str, limit: int, what: str | None = None) -> bytes:
    """The bytes of the file ``name`` (a relative path) inside ``folder``, opened one
    component at a time with O_NOFOLLOW: a symbolic link anywhere below ``folder``, a
    FIFO, a device or a file over ``limit`` bytes is refused. InputFileProblem (saying
    what is wrong, not where) when it cannot be read; the caller names the file."""
    what = what or name
    try:
        parts = PurePosixPath(_member(name)).parts
    except ValueError as exc:
        raise InputFileProblem(f"{what} {exc}") from None
    try:
        fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)  # the folder the user named: as given
    except (FileNotFoundError, NotADirectoryError):
        raise InputFileProblem("the run folder does not exist or is not a folder") from None
    except (OSError, ValueError) as exc:
        raise InputFileProblem(f"the run folder cannot be read ({getattr(exc, 'strerror', None) or 'bad name'})") from None
    try:
        for part in parts[:-1]:
            try:
                inner = os.open(part, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=fd)
            except FileNotFoundError:
                raise InputFileProblem(f"no such {what}") from None
            except OSError:  # ELOOP: a link; ENOTDIR: a file
                raise InputFileProblem(f"{part}/ is a symbolic link or not a folder, which is never followed") from None
            os.close(fd)
            fd = inner
        return read_regular_file(parts[-1], limit, what, dir_fd=fd, follow_links=False)
    finally:
        os.close(fd)


def parse_json_object(raw: bytes, path: Path) -> dict:
    """``raw`` (the bytes of the run folder's file ``path``) as a JSON object;
    RunFolderError naming the file otherwise."""
    try:
        data = json.loads(raw)
    except ValueError as exc:  # not JSON, not UTF-8, an int of too many digits
        where = f" at line {exc.lineno}" if hasattr(exc, "lineno") else ""
        raise RunFolderError(f"{shown(path)} is damaged (not valid JSON{where})") from None
    except RecursionError:
        raise RunFolderError(f"{shown(path)} is damaged (JSON nested too deeply)") from None
    if not isinstance(data, dict):
        raise RunFolderError(f"{shown(path)} is damaged (a JSON {type(data).__name__}, not an object)")
    return data


_JSON_KINDS = {dict: "an object", list: "an array", str: "a string", int: "a number", float: "a number", bool: "true or false"}


def json_kind(value) -> str:
    """What a JSON value is, in JSON's words (a message names the kind, never the value)."""
    return "null" if value is None else _JSON_KINDS.get(type(value), type(value).__name__)


def read_json_object(path: Path, limit: int, what: str) -> dict:
    """A run folder's JSON file (``what`` it is, at most ``limit`` bytes, never through a
    link) as a mapping: RunFolderError naming the file if it is not JSON, or not a JSON
    object; InputFileProblem if it cannot be read at all (each caller says what that means)."""
    path = Path(path)
    return parse_json_object(read_member(path.parent, path.name, limit, what), path)


def read_json(folder: Path, name: str, limit: int = MAX_JSON_BYTES) -> dict:
    """The JSON object ``name`` of the run folder ``folder``; RunFolderError for any problem."""
    path = Path(folder) / name
    try:
        raw = read_member(folder, name, limit)
    except InputFileProblem as exc:
        raise RunFolderError(f"{shown(path)}: {exc}") from None
    return parse_json_object(raw, path)


def check_schema_version(data: dict, path: Path, newest: int, key: str = "schema_version") -> None:
    """RunFolderError, naming the version, when ``data`` was written by a newer frictionlab."""
    version = data.get(key, 1)
    if isinstance(version, int) and not isinstance(version, bool) and version > newest:
        number = version if version < 10**9 else "of more than 9 digits"
        raise RunFolderError(
            f"{shown(path)} was written by a newer frictionlab ({key} {number}; this one reads up to {newest}): "
            "upgrade frictionlab to read it"
        )


def checked(model: type[BaseModel], data: dict, path: Path):
    """``data`` validated as ``model``; RunFolderError naming the file and each field at
    fault (what it must be, never the value found)."""
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors(include_input=False, include_url=False, include_context=False)
        problems = [f"field '{_dotted(e['loc'])}': {_lower(e['msg'])}" for e in errors[:3]]
        more = f" (and {len(errors) - 3} more)" if len(errors) > 3 else ""
        raise RunFolderError(f"{shown(path)} is damaged: " + "; ".join(problems) + more) from None


def _dotted(loc) -> str:
    return ".".join(shown(str(part))[:40] for part in loc) or "(top)"


def _lower(message: str) -> str:
    return message[:1].lower() + message[1:]


def read_number_table(folder: Path, name: str, limit: int = MAX_CSV_BYTES) -> tuple[list[str], list[list[float]]]:
    """A CSV file of the run folder as written by frictionlab: a header, then rows of as
    many cells, each a finite number or empty (read as NaN). RunFolderError naming the
    file, the line and the column for binary content, a ragged row or a cell that is not
    a number."""
    path = Path(folder) / name
    try:
        raw = read_member(folder, name, limit)
    except InputFileProblem as exc:
        raise RunFolderError(f"{shown(path)}: {exc}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise RunFolderError(f"{shown(path)} is damaged (not UTF-8 text, at line {line})") from None
    if "\0" in text:
        raise RunFolderError(f"{shown(path)} is damaged (binary content: a NUL byte)")
    try:
        rows = list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as exc:  # a field over csv's limit, a stray quote
        raise RunFolderError(f"{shown(path)} is damaged (not CSV: {_lower(str(exc).split(':')[0])})") from None
    if not rows:
        raise RunFolderError(f"{shown(path)} is damaged (empty: no header)")
    header, table = rows[0], []
    for line, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise RunFolderError(
                f"{shown(path)} is damaged (line {line} has {len(row)} cells, the header {len(header)})"
            )
        table.append([_cell(cell, path, line, column) for column, cell in enumerate(row, start=1)])
    return header, table


def _cell(cell: str, path: Path, line: int, column: int) -> float:
    if not cell:
        return math.nan
    try:
        value = float(cell)
    except ValueError:
        value = math.nan
    else:
        if math.isfinite(value):
            return value
    raise RunFolderError(f"{shown(path)} is damaged (line {line}, column {column}: not a finite number)")
