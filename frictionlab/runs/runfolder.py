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
import re
import stat
from collections.abc import Callable
from pathlib import Path, PurePosixPath
from typing import Annotated

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError

from ..errors import OutputRefused, RunFolderError, command_word, short_repr, shown, shown_name
from ..io.inputs import InputFileProblem, open_regular_file, read_regular_file

MAX_JSON_BYTES = 64 * 1024 * 1024  # summary.json is a few kB, run.json ~100 bytes a chunk (4096 at most)
MAX_CSV_BYTES = 16 * 1024 * 1024  # curve.csv: a row of 9 to 14 numbers per load step


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
MAX_WALL_SECONDS = 1e9  # some 30 years: a wall time past it is no run's (1e300 s was shown in 300 digits)
Seconds = Annotated[float, Field(ge=0, le=MAX_WALL_SECONDS, allow_inf_nan=False, strict=True)]
"""A wall time a run folder's file records."""


class Record(BaseModel):
    """The base of a run folder file's schema: values strictly typed (a string is not a
    number), a field a later frictionlab adds kept unchecked."""

    model_config = ConfigDict(extra="allow", strict=True, defer_build=True)  # built when a folder is read


def check_searchable(folder: str | Path) -> None:
    """RunFolderError when the files in ``folder`` cannot be looked at (no permission to search
    it): said so, not taken for a folder that holds no run, nor an OSError of the first look."""
    try:
        os.lstat(Path(folder) / "run.json")
    except PermissionError:
        raise RunFolderError(f"{shown_name(folder)} cannot be read (permission denied): its files cannot be looked at") from None
    except OSError:
        pass  # absent, or not a folder: said where it is read


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


def make_subfolder(root: str | Path, name: str) -> Path:
    """``root / name`` (a relative path), each component made if missing and checked to be
    a folder, not a symbolic link (``subfolder``'s rule), one at a time from the folder
    above's descriptor: a sweep writes its points inside its own folder, never through a
    link someone put there. RunFolderError naming the path."""
    here, fd = Path(root), os.open(root, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        for part in PurePosixPath(_member(name)).parts:
            here = here / part
            try:
                os.mkdir(part, dir_fd=fd)
            except FileExistsError:
                pass
            except OSError as exc:
                raise RunFolderError(f"{shown(here)}: cannot make the folder ({exc.strerror or exc})") from None
            try:
                inner = os.open(part, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=fd)
            except OSError:
                raise RunFolderError(f"{shown(here)} is a symbolic link or not a folder, which is never followed") from None
            os.close(fd)
            fd = inner
    finally:
        os.close(fd)
    return Path(root) / name


def output_subfolder(root: str | Path, name: str, then: str, *, make: bool = True) -> Path:
    """``root / name``, a folder frictionlab writes into below one the user named (a report's
    ``fig2``, a study's ensemble): made one level at a time (``make_subfolder``), or, with
    ``make`` False, only checked where it exists. A link or a file there is refused as output
    (exit code 4), never written or read through: it could point anywhere."""
    try:
        if make:
            Path(root).mkdir(parents=True, exist_ok=True)  # the folder named: it may be a link, it is the user's
            return make_subfolder(root, name)
        return subfolder(root, name) if os.path.lexists(Path(root) / name) else Path(root) / name
    except RunFolderError as exc:
        raise OutputRefused(f"{exc}: move it aside, then {then}") from None


# the files that make a folder a run's, or a sweep's (a run killed as it started leaves its preset.yaml alone)
KIND_FILES = {"run": ("run.json", "preset.yaml"), "sweep": ("sweep.json",)}


def refuse_other_kind(folder: Path, kind: str) -> None:
    """OutputRefused, --force or not, where a ``kind`` ("run" or "sweep") is to be written into
    ``folder`` and it holds the other kind: written beside it, both manifests stayed there, and
    the folder read as either (``runs``, ``load`` and ``resume`` took the run, the sweep unseen)."""
    other = "sweep" if kind == "run" else "run"
    held = [name for name in KIND_FILES[other] if os.path.lexists(folder / name)]
    if held:
        raise OutputRefused(
            f"{shown_name(folder)} holds a frictionlab {other} ({held[0]}), not a {kind}: a {kind} is not written into "
            f"a {other}'s folder, even forced (--force; force=True in Python): both would stay there, the folder read as either; give "
            f"another output folder, or move the {other} aside (mv {command_word(folder)} NEW_NAME) and run again"
        )


def read_member(folder: str | Path, name: str, limit: int, what: str | None = None) -> bytes:
    """The bytes of the file ``name`` (a relative path) inside ``folder``, opened one
    component at a time with O_NOFOLLOW: a symbolic link anywhere below ``folder``, a
    FIFO, a device or a file over ``limit`` bytes is refused. InputFileProblem (saying
    what is wrong, not where) when it cannot be read; the caller names the file."""
    what = what or name
    return _in_folder(folder, name, what, lambda leaf, fd: read_regular_file(leaf, limit, what, dir_fd=fd,
                                                                              follow_links=False))


def open_member(folder: str | Path, name: str, what: str | None = None):
    """The file ``name`` inside ``folder`` opened for binary reading, as ``read_member``
    reaches it (no link followed, only a regular file), for a reader that needs a part of it."""
    what = what or name
    return _in_folder(folder, name, what, lambda leaf, fd: open_regular_file(leaf, what, dir_fd=fd, follow_links=False))


def _in_folder(folder: str | Path, name: str, what: str, leaf):
    """``leaf(last component, descriptor of its folder)`` once every folder on the way to
    ``name`` inside ``folder`` is opened without following a link."""
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
        return leaf(parts[-1], fd)
    finally:
        os.close(fd)


def parse_json_object(raw: bytes, path: Path) -> dict:
    """``raw`` (the bytes of the run folder's file ``path``) as a JSON object;
    RunFolderError naming the file otherwise."""
    try:
        data = json.loads(raw, object_pairs_hook=_unique_keys)
    except _RepeatedKey as exc:  # frictionlab writes each key once: the file was edited, or pieced together
        raise RunFolderError(f"{shown(path)} is damaged (key {short_repr(exc.args[0])} given twice in one object)") from None
    except ValueError as exc:  # not JSON, not UTF-8, an int of too many digits
        where = f" at line {exc.lineno}" if hasattr(exc, "lineno") else ""
        what = "a number of more digits than are read" if "digits" in str(exc) else "not valid JSON"
        raise RunFolderError(f"{shown(path)} is damaged ({what}{where})") from None
    except RecursionError:
        raise RunFolderError(f"{shown(path)} is damaged (JSON nested too deeply)") from None
    if not isinstance(data, dict):
        raise RunFolderError(f"{shown(path)} is damaged ({json_kind(data)}, not a JSON object)")
    return data


class _RepeatedKey(Exception):
    pass


def _unique_keys(pairs: list) -> dict:
    """A JSON object whose keys are all different: JSON itself keeps the last of two silently."""
    seen = set()
    for key, _ in pairs:
        if key in seen:
            raise _RepeatedKey(key)
        seen.add(key)
    return dict(pairs)


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
    """RunFolderError, naming the version, when ``data`` was written by a newer frictionlab, or
    holds a version below the first (1), which no frictionlab wrote: read as an older one, a
    manifest of format 0 had its chunk list ignored and every finished chunk computed again."""
    version = data.get(key, 1)
    if not isinstance(version, int) or isinstance(version, bool):
        return
    number = version if abs(version) < 10**9 else "of more than 9 digits"
    if version < 1:
        raise RunFolderError(f"{shown(path)} is damaged ({key} {number}: the first is 1)")
    if version > newest:
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
        problems = [f"field '{_dotted(e['loc'])}': {_said(e)}" for e in errors[:3]]
        more = f" (and {len(errors) - 3} more)" if len(errors) > 3 else ""
        raise RunFolderError(f"{shown(path)} is damaged: " + "; ".join(problems) + more) from None


def _dotted(loc) -> str:
    return ".".join(shown(str(part))[:40] for part in loc) or "(top)"


def _said(error: dict) -> str:
    """Pydantic's message for one field, in the file's terms (a nested record is a JSON object)."""
    if error["type"] == "model_type":  # "a valid dictionary or instance of _Counts": a class name of ours
        return "input should be a JSON object"
    return _lower(error["msg"])


def _lower(message: str) -> str:
    return message[:1].lower() + message[1:]


def read_number_table(folder: Path, name: str, limit: int = MAX_CSV_BYTES,
                      check_header: Callable[[list[str]], None] | None = None) -> tuple[list[str], list[list[float]]]:  # fmt: skip
    """A CSV of the run folder as frictionlab writes it: a header (``check_header`` raises for others' columns),
    rows of as many cells, each a finite number or empty (NaN); else RunFolderError naming file, line, column."""
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
    if check_header is not None:  # another's column said as such, not by its first cell that is no number
        check_header(header)
    for line, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise RunFolderError(
                f"{shown(path)} is damaged (line {line} has {len(row)} cells, the header {len(header)})"
            )
        table.append([_cell(cell, path, line, column) for column, cell in enumerate(row, start=1)])
    return header, table


_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)  # as Python writes a float


def _cell(cell: str, path: Path, line: int, column: int) -> float:
    if not cell:
        return math.nan
    value = float(cell) if _NUMBER.fullmatch(cell) else math.nan  # float() also takes '1_0', ' 1', Arabic digits
    if math.isfinite(value):
        return value
    raise RunFolderError(f"{shown(path)} is damaged (line {line}, column {column}: not a finite number)")


# ------------------------------------------------------------------ who holds a folder's lock

MAX_LOCK_TABLE_LINES = 1_000_000  # of /proc/locks: a machine's locks, read line by line
MAX_OPEN_FILES = 1 << 20  # of a process, looked through for the lock file


def _open_lock(path: Path) -> int | None:
    """A descriptor of the lock file ``path`` (a regular file, never through a link), or None."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        return None
    return fd


def _held(fd: int) -> bool:
    """Whether another open file description holds an flock on ``fd``'s file now (True where it cannot be probed)."""
    try:
        import fcntl
    except ImportError:  # no flock to probe (Windows)
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError:  # BlockingIOError: held
        return True
    fcntl.flock(fd, fcntl.LOCK_UN)
    return False


def lock_held(path: str | Path) -> bool:
    """Whether some process holds the lock file ``path`` now (an flock is released by the
    kernel when its holder dies, even on kill -9). Not a regular file, or none: False."""
    fd = _open_lock(Path(path))
    if fd is None:
        return False
    try:
        return _held(fd)
    finally:
        os.close(fd)


def _kernel_lockers(info: os.stat_result) -> list[int]:
    """The pids the kernel's lock table (/proc/locks, Linux) names as holding a lock on the
    file ``info`` describes; [] where there is no such table."""
    pids, inode, device = [], str(info.st_ino).encode(), f"{os.major(info.st_dev):02x}:{os.minor(info.st_dev):02x}:"
    try:
        with open("/proc/locks", "rb") as fh:
            for _, line in zip(range(MAX_LOCK_TABLE_LINES), fh):
                words = line.split()
                if len(words) < 6 or words[1] == b"->":  # a process waiting for a lock holds none
                    continue
                pid, where = words[4], words[5]
                if where.rpartition(b":")[2] == inode and pid.isdigit():
                    pids.append((not where.startswith(device.encode()), int(pid)))
    except OSError:
        return []
    return [pid for _, pid in sorted(pids)]  # the same device first (an inode number is per file system)


def _has_open(pid: int, info: os.stat_result) -> bool:
    """Whether the process ``pid`` has the file ``info`` describes open now (/proc/PID/fd)."""
    try:
        names = os.listdir(f"/proc/{pid}/fd")
    except OSError:
        return False
    for name in names[:MAX_OPEN_FILES]:
        try:
            seen = os.stat(f"/proc/{pid}/fd/{name}")
        except OSError:
            continue
        if (seen.st_dev, seen.st_ino) == (info.st_dev, info.st_ino):
            return True
    return False


def lock_holder(path: str | Path) -> int | None:
    """The process that holds the lock file ``path`` now, as the kernel says: the lock is
    held, the kernel's lock table names the pid, and that process has the file open. Never
    what a file says (run.lock's text, progress.jsonl's ``pid``: anyone may have written them).
    None when no lock is held, or its holder cannot be verified (another user's process, no /proc)."""
    fd = _open_lock(Path(path))
    if fd is None:
        return None
    try:
        info = os.fstat(fd)
        if not _held(fd):
            return None
        for pid in _kernel_lockers(info):
            if pid > 0 and _has_open(pid, info) and _held(fd):
                return pid
        return None
    finally:
        os.close(fd)


def signal_holder(path: str | Path, signum: int, folder: str | Path) -> int:
    """Send ``signum`` to the verified holder of the lock file ``path`` (``lock_holder``) of
    the run folder ``folder``, and return its pid. Never pid 1, this process, a process of
    this session or process group, or another user's: RunFolderError saying why not."""
    pid = lock_holder(path)
    if pid is None:
        raise RunFolderError(f"{shown(folder)}: no process that can be verified holds its lock "
                             "(the run ended, or it is not this user's): nothing was signalled")  # fmt: skip
    try:
        handle = os.pidfd_open(pid) if hasattr(os, "pidfd_open") else None  # the process, not a number reused
    except ProcessLookupError:
        raise RunFolderError(f"{shown(folder)}: its run (pid {pid}) has ended: nothing was signalled") from None
    except OSError:  # a kernel without pidfds: the pid, verified again just before the signal
        handle = None
    try:
        why = _not_to_signal(pid)
        if why is None and lock_holder(path) != pid:
            why = "it no longer holds the folder's lock"
        if why is not None:
            raise RunFolderError(f"{shown(folder)}: the process holding its lock (pid {pid}) is {why}: it was not signalled")
        if handle is not None:
            import signal

            signal.pidfd_send_signal(handle, signum)
        else:
            os.kill(pid, signum)
    except ProcessLookupError:
        raise RunFolderError(f"{shown(folder)}: its run (pid {pid}) has ended: nothing was signalled") from None
    finally:
        if handle is not None:
            os.close(handle)
    return pid


def _not_to_signal(pid: int) -> str | None:
    """Why the process ``pid`` is never signalled (None if it may be)."""
    if pid <= 1:
        return "the system's first process"
    if pid == os.getpid():
        return "this process"
    try:
        if os.getsid(pid) == os.getsid(0) or os.getpgid(pid) == os.getpgid(0):
            return "in this session"
        owner = os.stat(f"/proc/{pid}").st_uid if os.path.isdir("/proc/self") else os.getuid()
    except OSError:
        return "gone, or not this user's"
    return None if owner == os.getuid() else "another user's"


def refuse_nothing_to_resume(out_dir: str | Path) -> None:
    """A resume into a folder that is not there: refused before anything is made (the folder
    was made, then refused as holding no run, and left behind empty)."""
    if not os.path.isdir(out_dir):
        raise RunFolderError(f"{shown_name(out_dir)} is not a run folder to resume (it does not exist, or is not a folder)")
