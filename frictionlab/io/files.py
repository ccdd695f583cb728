"""Writing files safely: every file frictionlab writes goes through ``atomic_write``,
so a reader never sees half a file and an interrupted write leaves the previous
version intact, and it never writes through a symbolic link (the link is replaced);
a character device or FIFO the user named as an output is written into, a folder,
socket or block device is refused; ``output_path_problem`` says why a path cannot be an output folder;
``check_output_file`` refuses an existing output file unless ``--force``;
``write_npz`` writes arrays compressed where compressing them pays."""

from __future__ import annotations

import contextlib
import errno
import io
import math
import os
import re
import stat
import tempfile
import time
import zipfile
import zlib
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from ..errors import OutputRefused, shown, shown_name

_SAMPLE_BYTES = 65536  # of an array, deflated to decide whether the whole of it is worth deflating
_WORTH_IT = 0.75  # deflate an array whose sample shrinks below this fraction of its size


def _read_umask() -> int:
    mask = os.umask(0)  # the only portable way to read it; done once, at import
    os.umask(mask)
    return mask


_UMASK = _read_umask()
FIFO_READER_WAIT_S = 2.0  # how long a FIFO named as an output may go without a reader before it is refused


def atomic_write(
    path: Path, write: Callable[[io.IOBase], None], binary: bool = False, *, devices: bool = False, mode: int | None = None
) -> None:
    """Write via ``write(file)`` to a temporary sibling, fsync, then rename over ``path``.
    The file gets the usual permissions (0666 less the umask), not mkstemp's 0600, or ``mode``
    (a file rewritten keeps its own: one kept private stays so).

    Nothing is ever written through a symbolic link: a link at ``path`` is replaced by
    the new file, and the file it pointed at is left as it was (a run folder, or a
    tampered copy of one, cannot make frictionlab write outside it). ``devices``: for an
    output path the user named (``--markdown``), a character device (/dev/null) or a
    FIFO, or a link to one, and an open stream of this process (/dev/stdout, even
    redirected to a file) are written into, as any program writing there would
    (renaming over it would destroy the node: as root, /dev/null itself); without
    it (the files of a run folder) such a node is replaced like any file. A folder,
    socket or block device is refused (an OSError naming the path: "is a folder, not a
    file")."""
    path = Path(path)
    if devices and (_kind(path) in ("character device", "FIFO") or _is_open_stream(path)):
        with _naming(path), _open_node(path, binary) as fh:
            write(fh)
        return
    problem = replace_problem(path)
    if problem:  # an OSError, as renaming over it was: callers say "cannot write"
        error = IsADirectoryError if "folder" in problem else OSError
        raise error(errno.EISDIR if "folder" in problem else errno.EINVAL, problem, str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    with _naming(path):
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        try:
            os.fchmod(fd, 0o666 & ~_UMASK if mode is None else mode)
            with os.fdopen(fd, "wb" if binary else "w", **({} if binary else {"encoding": "utf-8", "newline": ""})) as fh:
                write(fh)
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, path)  # renames over a link itself, never its target
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise


@contextlib.contextmanager
def _naming(path: Path):
    """A write or fsync that fails (a full disk: ENOSPC) raises an OSError naming no file:
    it is given ``path``, so that its message says which file, in which folder, was not written;
    as is one naming the temporary sibling (a rename over an immutable file), a name never heard of."""
    try:
        yield
    except OSError as exc:
        temporary = exc.filename is not None and Path(exc.filename).name.startswith(f".{path.name}.")
        if exc.filename is None or temporary:
            exc.filename, exc.filename2 = str(path), None
        raise


def _open_node(path: Path, binary: bool):
    """A character device, FIFO or open stream the user named, opened for writing into. A FIFO
    is opened without blocking: with nothing reading it for FIFO_READER_WAIT_S, the open is
    refused, rather than waiting for a reader for ever."""
    mode, text = ("wb", {}) if binary else ("w", {"encoding": "utf-8", "newline": ""})
    if _kind(path) != "FIFO" or _is_open_stream(path):
        return open(path, mode, **text)
    deadline = time.monotonic() + FIFO_READER_WAIT_S
    while True:
        try:
            fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK | os.O_CLOEXEC)
            break
        except OSError as exc:
            if exc.errno != errno.ENXIO:
                raise
            if time.monotonic() > deadline:
                raise OutputRefused(
                    f"{shown(path)} is a FIFO (named pipe) that nothing reads: start its reader first, or give a file"
                ) from None
            time.sleep(0.05)  # a reader started beside this command may open it a moment later
    os.set_blocking(fd, True)
    return os.fdopen(fd, mode, **text)


_OPEN_STREAM = re.compile(r"/(proc/self|dev)/fd/\d+")


def _is_open_stream(path: Path) -> bool:
    """Whether ``path`` names one of this process's open files (/dev/stdout, /dev/fd/1,
    /proc/self/fd/1, or a link to one): written into, whatever it is redirected to;
    renaming over /dev/stdout would replace the system's link (as root)."""
    try:
        target = os.readlink(path) if path.is_symlink() else str(path)
    except OSError:
        return False
    return bool(_OPEN_STREAM.fullmatch(target)) or str(path) in ("/dev/stdout", "/dev/stderr")


_KINDS = {stat.S_IFREG: "file", stat.S_IFDIR: "folder", stat.S_IFCHR: "character device", stat.S_IFIFO: "FIFO",
          stat.S_IFSOCK: "socket", stat.S_IFBLK: "block device", stat.S_IFLNK: "symbolic link"}  # fmt: skip


def replace_problem(path: Path) -> str | None:
    """Why ``atomic_write`` cannot replace what is at ``path`` ("is a folder, not a file"; a
    socket or block device too), or None: a file, a link, a FIFO or nothing there."""
    kind = _kind(path, follow_links=False)
    return f"is a {kind}, not a file" if kind in ("folder", "socket", "block device") else None


def named_files(preset: dict) -> set[Path]:
    """The files a resolved preset's plugins name (absolute paths once resolved), resolved: a
    run's results must not be written over one of them (--force into the folder of its scan)."""
    params = [slot.get("params") for slot in preset.values() if isinstance(slot, dict)]
    values = [value for p in params if isinstance(p, dict) for value in p.values()]
    return {real_path(value) for value in values if isinstance(value, str) and os.path.isabs(value)}


def refuse_unreplaceable(paths, what: str, instead: str) -> None:
    """OutputRefused naming the first of ``paths`` that ``atomic_write`` cannot replace (a
    folder, ...): said before the ``what`` (a study, a report) does its work, --force or not,
    never when it writes after the work; ``instead`` says what else to do."""
    for path in paths:
        if problem := replace_problem(Path(path)):
            raise OutputRefused(f"{shown(str(path))} {problem}: the {what} writes its {shown(Path(path).name)} there; "
                                f"move it aside, or {instead}")


def real_path(path: str | Path) -> Path:
    """``path`` with every link resolved as far as it goes: ``Path.resolve`` raises
    RuntimeError on a link that points back at itself, and a folder is untrusted."""
    return Path(os.path.realpath(path))


def _kind(path: Path, follow_links: bool = True) -> str | None:
    """What is at ``path`` (links followed unless ``follow_links`` is False: then a
    link is "symbolic link"): "file", "folder", "FIFO"..., None if nothing (or a
    link that leads to itself)."""
    try:
        mode = os.stat(path, follow_symlinks=follow_links).st_mode
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            return None
        raise
    return _KINDS.get(stat.S_IFMT(mode), "special file")


def check_output_file(path: str | Path, option: str, *, force: bool) -> Path:
    """``path`` as a file a command may write (``option`` names it in messages):
    OutputRefused for a folder (or a name ending in /), a path under a file, a
    socket or block device, and an existing file or a symbolic link unless ``force``
    (which replaces the link, never the file it points at). A character device or
    FIFO, or a link to one (/dev/stdout), is accepted (written into, see ``atomic_write``)."""
    text = os.fsdecode(path)
    path = Path(path)
    kind = _kind(path)
    if kind == "folder" or text.endswith(os.sep):
        raise OutputRefused(f"{option} {shown_name(text)} is a folder: give a file name (e.g. {shown(path / 'name')})")
    if _is_open_stream(path):  # /dev/stdout: written into, wherever it is redirected
        return path
    problem = output_path_problem(path.parent)
    if problem:
        raise OutputRefused(f"{option} {shown(path)}: {problem}")
    if kind in ("socket", "block device", "special file"):
        raise OutputRefused(f"{option} {shown(path)} is a {kind}, not a file: give a file to write to")
    if path.is_symlink() and kind not in ("character device", "FIFO") and not force:
        raise OutputRefused(
            f"{option} {shown(path)} is a symbolic link: give another file, or --force to replace the link "
            "(the file it points at is never written)"
        )
    if kind == "file" and not force:
        raise OutputRefused(f"{option} {shown(path)} exists: give another file, or --force to replace it")
    return path


def output_path_problem(path: Path) -> str | None:
    """Why ``path`` cannot be (or become) a folder to write in: it, or the nearest
    existing folder above it, is a file, or files cannot be created in it (read-only,
    no permission: tried, so that long work does not start only to fail at its end)."""
    path = Path(path)
    for candidate in (path, *path.parents):
        if candidate.exists() or candidate.is_symlink():
            if candidate.is_dir():
                return _unwritable(candidate, path)
            if candidate == path:
                return f"{shown(path)} is {_not_a_folder(path)}, not a folder"
            return f"{shown(path)} cannot be made a folder: {shown(candidate)} is {_not_a_folder(candidate)}"
    return None


def refuse_unusable_folder(path: str | Path) -> None:
    """OutputRefused where ``path`` cannot be (or become) a run's folder (``output_path_problem``)."""
    if (problem := output_path_problem(Path(path))) is not None:
        raise OutputRefused(f"{problem}; give a folder for the output")


def _not_a_folder(path: Path) -> str:
    """What ``path``, which is there and no folder, is: a file, or the node or dangling link it is."""
    if path.is_symlink() and not path.exists():
        return "a symbolic link to nothing"
    kind = _kind(path)
    return "a file" if kind == "file" else f"a {kind}" + (" (named pipe)" if kind == "FIFO" else "")


def _unwritable(folder: Path, asked: Path) -> str | None:
    """Why no file can be created in ``folder`` (where ``asked`` is, or would be made), or None."""
    try:
        fd, probe = tempfile.mkstemp(prefix=".frictionlab-write-check-", dir=folder)
    except OSError as exc:
        where = "" if folder == asked else f" (it would be made in {shown(folder)})"
        return f"{shown(asked)} cannot be written in{where}: {exc.strerror or type(exc).__name__}"
    os.close(fd)
    os.unlink(probe)
    return None


def write_npz(fh, arrays: Mapping[str, np.ndarray]) -> None:
    """Write ``arrays`` to the open binary file ``fh`` as an ``.npz`` (what ``np.load``
    reads), each array deflated as by ``np.savez_compressed`` unless a sample of it
    shrinks by less than a quarter: rough floating-point data (the indentations of a
    run) costs 25 ms a megabyte to deflate and keeps 87 % of its size, while the
    contact counts and xi shrink 35-100 fold. Same arrays, same bytes: members carry
    no time stamp."""
    with zipfile.ZipFile(fh, "w", allowZip64=True) as archive:
        for name, value in arrays.items():
            array = np.asanyarray(value)
            member = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            member.compress_type = zipfile.ZIP_DEFLATED if _deflates(array) else zipfile.ZIP_STORED
            with archive.open(member, "w", force_zip64=True) as out:
                np.lib.format.write_array(out, array, allow_pickle=False)


def npz_unpacked_problem(archive: zipfile.ZipFile, most: int) -> str | None:
    """Why the opened .npz ``archive`` is no run's, or None: an array that its central directory
    says unpacks to more than ``most`` bytes (zeros deflated: 1 MB on disk, 1 GB unpacked, all of
    it in memory before its shape could be checked; zipfile unpacks no more of a member than that
    declared size), or whose .npy header claims more data than its entry holds (numpy allocates
    what the header claims before reading any: 7 TiB for a 3 kB file). Only headers are read."""
    for member in archive.infolist():
        name = member.filename.removesuffix(".npy")
        if member.file_size > most:
            return (f"array {name!r} unpacks to {member.file_size:,} bytes, "
                    f"more than the {most:,} its run can write")  # fmt: skip
        with archive.open(member) as fh:
            try:
                shape, dtype = npy_header(fh)
            except ValueError as exc:  # no .npy magic: np.load hands back the entry's bytes, not an array
                return f"array {name!r} has no readable .npy header ({exc})"
            held = _entry_bytes(member) - fh.tell()
        claimed = math.prod(shape) * dtype.itemsize
        if claimed > held and not dtype.hasobject:  # an object array np.load refuses before it allocates
            return (f"array {name!r}: its header claims shape {shape} of {dtype} ({claimed:,} bytes), "
                    f"but its entry holds {max(held, 0):,} bytes of data")  # fmt: skip
    return None


DEFLATE_MOST_RATIO = 1032  # deflate writes at least 2 bits for 258 bytes: no entry unpacks to more than this times its size


def _entry_bytes(member: zipfile.ZipInfo) -> int:
    """The most bytes the zip entry ``member`` can unpack to: its declared size, and for a stored or
    deflated entry no more than its packed bytes allow (zipfile ends the read there: EOFError)."""
    if member.compress_type == zipfile.ZIP_STORED:
        return min(member.file_size, member.compress_size)
    if member.compress_type == zipfile.ZIP_DEFLATED:
        return min(member.file_size, DEFLATE_MOST_RATIO * member.compress_size)
    return member.file_size


def npy_header(fh) -> tuple[tuple[int, ...], np.dtype]:
    """The shape and type that the .npy header at ``fh`` declares, read without its data (a
    forged shape must size no buffer); ValueError for a damaged header."""
    version = np.lib.format.read_magic(fh)
    read_header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
    shape, _, dtype = read_header(fh)
    return shape, dtype


def _deflates(array: np.ndarray) -> bool:
    items = max(1, _SAMPLE_BYTES // max(array.itemsize, 1))
    sample = np.ascontiguousarray(array.reshape(-1)[:items]).tobytes()
    return bool(sample) and len(zlib.compress(sample, 1)) < _WORTH_IT * len(sample)


def written_through(status: os.stat_result) -> str | None:
    """Why a run folder's file opened in place (its lock, its progress file) must not be written:
    not a regular file, or a file with another name (a hard link: writing it would change a file
    outside the folder); None if it is the folder's own."""
    if not stat.S_ISREG(status.st_mode):
        return "not a regular file"
    return "a hard link (the file has another name)" if status.st_nlink > 1 else None
