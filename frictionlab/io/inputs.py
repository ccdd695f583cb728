"""Input files: presets and the data files plugins read (measured profiles,
surfaces).

Only regular files are read, so a FIFO or a device never blocks a run; a file
is opened without blocking and checked on its open descriptor, so it cannot be
swapped between the check and the read. Messages name the file and a line,
never its content.

A plugin parameter that names a file is declared ``InputFile``: the framework
then resolves a relative path in a preset against the preset's folder, checks
the file exists when the preset is validated, and records its SHA-256 in the
run folder so that a resume refuses a file that changed.
"""

from __future__ import annotations

import errno
import hashlib
import math
import os
import stat
import sys
from pathlib import Path
from typing import Annotated

from pydantic import AfterValidator

from ..errors import short_repr, shown


class InputFileProblem(ValueError):
    """A file that cannot be read as input; the message names the file, not its content."""


_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def file_kind(mode: int) -> str:
    """What a non-regular file is, in words."""
    return next((name for test, name in _KINDS if test(mode)), "not a regular file")


def regular_file_problem(path: str | Path) -> str | None:
    """Why ``path`` is not an existing regular file (from ``stat``, which never
    blocks), or None."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "no such file"
    except NotADirectoryError:
        return "no such file (a parent of it is a file)"
    except PermissionError:
        return "permission denied"
    except UnicodeEncodeError:  # 'ü.npy' under LC_ALL=C: was 'cannot be read (UnicodeEncodeError)'
        return (f"cannot be named in this system's encoding of file names ({sys.getfilesystemencoding()}, from the "
                "locale): run under a UTF-8 locale (LC_ALL=C.UTF-8) or with PYTHONUTF8=1")
    except (OSError, ValueError) as exc:  # ValueError: an embedded NUL byte
        return f"cannot be read ({getattr(exc, 'strerror', None) or type(exc).__name__})"
    return None if stat.S_ISREG(mode) else f"is {file_kind(mode)}, not a regular file"


def input_file_problem(path: str | Path) -> str | None:
    """Why ``path`` cannot be a plugin's input file (``regular_file_problem``, or empty: a
    reader of each format would otherwise name it damaged or of no shape), or None."""
    problem = regular_file_problem(path)
    if problem is None and os.stat(path).st_size == 0 and not os.path.realpath(path).startswith(("/proc/", "/sys/")):
        return "is empty (0 bytes), it holds no heights"  # the kernel's files say 0 bytes and are refused when opened
    return problem


def open_regular_file(path: str | Path, what: str = "file", *, dir_fd: int | None = None, follow_links: bool = True):
    """``path`` opened for binary reading, once it is known to be a regular file
    (opened without blocking, checked on the open descriptor); InputFileProblem
    otherwise. The message says what is wrong (``no such <what>``, ``is a FIFO
    ...``); the caller says where. ``follow_links=False``: a symbolic link is refused
    (O_NOFOLLOW), not followed; ``dir_fd``: ``path`` is taken from that open folder."""
    flags = os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY | os.O_CLOEXEC | (0 if follow_links else os.O_NOFOLLOW)
    try:
        fd = os.open(path, flags, dir_fd=dir_fd)
    except (FileNotFoundError, NotADirectoryError):
        raise InputFileProblem(f"no such {what}") from None
    except (OSError, ValueError) as exc:  # ValueError: an embedded NUL byte
        if getattr(exc, "errno", None) == errno.ELOOP and not follow_links:
            raise InputFileProblem(f"{what} is a symbolic link, which is never followed here") from None
        if kind := _not_regular(path, dir_fd, follow_links):  # a socket cannot be opened: ENXIO said "no such device"
            raise InputFileProblem(f"{what} is {kind}, not a regular file") from None
        reason = getattr(exc, "strerror", None) or "cannot be opened"
        raise InputFileProblem(f"{what} cannot be read: {reason[:1].lower() + reason[1:]}") from None
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        raise InputFileProblem(f"{what} is {file_kind(mode)}, not a regular file")
    if _of_the_kernel(fd):
        os.close(fd)
        raise InputFileProblem(f"{what} is in the kernel's /proc or /sys (a read may block), not a data file")
    os.set_blocking(fd, True)
    return os.fdopen(fd, "rb")


def _not_regular(path, dir_fd: int | None, follow_links: bool) -> str | None:
    """What ``path`` is when it is there and no regular file, in words (``file_kind``); else None."""
    try:
        mode = os.stat(path, dir_fd=dir_fd, follow_symlinks=follow_links).st_mode
    except (OSError, ValueError):
        return None
    return None if stat.S_ISREG(mode) else file_kind(mode)


def _of_the_kernel(fd: int) -> bool:
    """Whether ``fd`` is a file of /proc or /sys (Linux): "regular" files whose reads may
    block for ever (/proc/kmsg) or never end."""
    try:
        where = os.readlink(f"/proc/self/fd/{fd}")
    except OSError:  # no /proc (not Linux): nothing to tell
        return False
    return where.startswith(("/proc/", "/sys/"))


def read_regular_file(
    path: str | Path, limit: int | None = None, what: str = "file", *, dir_fd: int | None = None, follow_links: bool = True
) -> bytes:
    """The bytes of the regular file ``path`` (see ``open_regular_file``), refused
    by its size before anything is read when it is over ``limit`` bytes."""
    with open_regular_file(path, what, dir_fd=dir_fd, follow_links=follow_links) as fh:
        size = os.fstat(fh.fileno()).st_size
        if limit is not None and size > limit:
            raise InputFileProblem(f"{what} of {size:,} bytes, more than the limit of {limit:,} bytes")
        data = read_bounded(fh, size, limit)
    if limit is not None and len(data) > limit:  # it grew while read
        raise InputFileProblem(f"{what} of more than the limit of {limit:,} bytes")
    return data


def holds_exactly(path: str | Path, data: bytes) -> bool:
    """Whether ``path`` is a regular file (never read through a link) of exactly ``data``."""
    try:
        with open_regular_file(path, follow_links=False) as fh:
            size = os.fstat(fh.fileno()).st_size
            return size == len(data) and read_bounded(fh, size, size) == data
    except InputFileProblem:
        return False


GROWTH_BLOCK = 1 << 20  # what is read at a time of a file that grew past its size


def read_bounded(fh, size: int, limit: int | None) -> bytes:
    """What the open binary file ``fh`` of ``size`` bytes (its fstat) holds, and at
    most one byte past ``limit``: the buffers are sized by what the file holds, never
    by the cap (a cap as a buffer is allocated whole: 16 GiB for a chunk of a few kB,
    which a process under a virtual-memory limit cannot have)."""
    cap = math.inf if limit is None else limit + 1
    parts = [fh.read(min(size + 1, cap))]
    got = len(parts[0])
    while got > size and got < cap:  # it grew while read: the rest in blocks
        block = fh.read(min(GROWTH_BLOCK, cap - got))
        if not block:
            break
        parts.append(block)
        got += len(block)
    return b"".join(parts) if len(parts) > 1 else parts[0]


def sha256_of(path: str | Path) -> str:
    """SHA-256 (hex) of the regular file ``path``, read in blocks."""
    digest = hashlib.sha256()
    with open_regular_file(path) as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


# ------------------------------------------------------------------ plugin parameters


class _InputFileMarker:
    """Metadata of a plugin parameter that names an input file."""

    def __repr__(self) -> str:
        return "InputFile"


INPUT_FILE_MARKER = _InputFileMarker()


def expand_user(value: str) -> str:
    """``value`` with a leading ``~`` or ``~user`` expanded; ValueError naming it for a user
    this system does not know (pathlib raises RuntimeError there, os.path leaves it as a folder name)."""
    expanded = os.path.expanduser(value)
    if expanded.startswith("~"):
        user = value.split("/", 1)[0]
        raise ValueError(f"{user} names no user of this system with a home folder; give the path in full")
    return expanded


def _absolute_path(value: str) -> str:
    if any(ord(c) < 32 or ord(c) == 127 for c in value):
        raise ValueError("must not contain control characters (NUL, newline, tab, ...)")
    return os.path.abspath(expand_user(value))


def as_typed(word: str) -> str:
    """A command-line word as it was typed: under LC_ALL=C Python decodes the UTF-8 bytes of
    an 'ü' as two bytes it cannot read (lone surrogates); they are UTF-8 once taken back."""
    try:
        return os.fsencode(word).decode("utf-8")
    except UnicodeError:  # bytes of another encoding, or a character the file system cannot name
        return word


InputFile = Annotated[str, INPUT_FILE_MARKER, AfterValidator(_absolute_path)]
"""A parameter that names an input file: stored as an absolute path (a
relative one is taken from the current folder, or from the preset's folder
when it was written in a preset file)."""


def input_fields(params_model) -> list[str]:
    """Names of the ``InputFile`` parameters of a plugin's ``Params`` model."""
    return [name for name, field in params_model.model_fields.items() if INPUT_FILE_MARKER in field.metadata]


def is_relative(value) -> bool:
    """Whether a path is taken from the preset's folder: not absolute, nor from a home folder (``~``)."""
    return isinstance(value, str) and bool(value) and not value.startswith("~") and not os.path.isabs(value)


# ------------------------------------------------------------------ what a plugin read


def describe_input(summary: dict) -> str:
    """One line on a spectrum's ``input_summary()``: shape (x by y, as instruments and
    Gwyddion give it), pixel size, unit and rms height, where the pixel size and the unit
    came from, and what was done to the scan (levelling, crop, resampling, spikes). Every
    string from the file is escaped (``errors.shown``)."""
    unit = shown(summary.get("unit") or "")
    length = f" {unit}" if unit else ""
    shape = " x ".join(str(n) for n in summary["shape"][::-1])  # (Ny, Nx) stored: x first
    kind = "points" if len(summary["shape"]) == 1 else "pixels"
    spacing_from = summary.get("spacing_from")
    converted = summary.get("file_unit")
    unit_note = f", converted from the file's {shown(converted)}" if converted and unit and converted != unit else ""
    if "file_unit" in summary and converted is None and unit:  # an instrument file that states no unit
        unit_note = f", the file states no unit: its numbers taken as {unit}"
    if summary.get("unit_from") == "header":  # a table's bare numbers, in the unit its header names
        unit_note = f", unit {unit} from the file's header"
    channel = summary.get("channel")
    notes = [f"channel {summary.get('channel_index', '?')} {short_repr(shown(channel))}"] if channel is not None else []
    if summary.get("x_decreasing"):
        notes.append("x decreasing (a scan written right to left): the line read as written, mirrored, which changes "
                     "no statistic and no contact")
    if summary.get("region_pixels"):
        spans = ", ".join(f"{axis} {start}:{stop}" for axis, (start, stop) in zip("xy", summary["region_pixels"]))
        notes.append(f"cropped to {spans} ({kind} of the file)")
    if summary.get("pixels"):
        notes.append(f"pixels {summary['pixels']}")
    stated, given = summary.get("file_spacing"), summary.get("downsampled", {}).get("from_pixel", summary["spacing"])
    sides = stated if isinstance(stated, list) else [] if stated is None else [stated]
    rectangle = summary.get("spacing_given")  # spacing and spacing_y: the preset's pixel, not square
    if spacing_from == "preset" and any(not math.isclose(side, given, rel_tol=1e-9) for side in sides) and \
            not (rectangle and len(sides) == 2 and all(map(math.isclose, sides, rectangle))):  # fmt: skip
        by = f"pixels of {' x '.join(f'{side:.6g}' for side in rectangle)}" if rectangle else "spacing, square"
        notes.append(f"the file's pixels of {' x '.join(f'{side:.6g}' for side in sides)}{length} replaced by the "
                     f"preset's {by}")  # fmt: skip
    if summary.get("downsampled"):
        down = summary["downsampled"]
        notes.append(f"downsampled from pixels of {down['from_pixel']:.6g} to {down['to_pixel']:.6g}{length}")
    if summary.get("extent"):
        notes.append(_extent_note(summary["extent"], length))
    if summary.get("despiked"):
        replaced = summary["despiked"]["points"]
        notes.append(f"despike {summary['despiked']['k']:g} rms: {replaced} point{'' if replaced == 1 else 's'} replaced")
    if "detrend" in summary:
        notes.append(f"detrend {summary['detrend']} ({summary.get('detrend_from', 'preset')}) removed "
                     f"{100 * summary['rms_removed_fraction']:.1f} % of the rms height "
                     f"({summary['rms_before_detrend']:.4g}{length} before)")
    return (
        f"{shown(Path(summary['file']).name)} ({shown(summary.get('format', '?'))}): {shape} {kind}"
        + (" (x by y)" if kind == "pixels" else "") + f" of {summary['spacing']:.6g}"
        f"{length}{f' (from the {spacing_from})' if spacing_from else ''}, rms height {summary['rms_height']:.6g}"
        f"{length}{unit_note}" + ("" if unit else ", no unit (bare numbers)")
        + (", periodic" if summary.get("periodic") else ", not periodic")
        + (f", {summary['undefined_points']} undefined points filled ({summary['filled_by']})"
           if summary.get("filled_by") else "")
        + (f", {summary['undefined_outside_region']} undefined points outside the region"
           if summary.get("undefined_outside_region") else "")
        + "".join(f"; {note}" for note in notes)
    )  # fmt: skip


def _extent_note(extent: dict, length: str) -> str:
    """The area the pressed map covers against the scan's, when resampling changed it: its points
    run from the first sample to the last, so up to a new pixel of each side is not covered."""
    scan, pressed = extent["scan"], extent["pressed"]
    change = pressed[0] * pressed[1] / (scan[0] * scan[1]) - 1
    return (f"the map pressed covers {pressed[0]:.6g} x {pressed[1]:.6g}{length} of the scan's {scan[0]:.6g} x "
            f"{scan[1]:.6g}{length} (x by y), {100 * abs(change):.3g} % {'less' if change < 0 else 'more'} area: "
            "resampled points run from the first sample to the last")


def input_lines(summary: dict) -> list[str]:
    """What was read, as ``validate`` and a run's progress say it: ``read`` and
    ``describe_input``'s line, then ``describe_channels``' lines, indented under it."""
    return [f"read {describe_input(summary)}", *(f"  {line}" for line in describe_channels(summary))]


def describe_channels(summary: dict) -> list[str]:
    """One line per channel of a file with several (index, name, points x by y, units), and
    which one was taken when several share its name; escaped (``errors.shown``)."""
    lines = []
    for channel in summary.get("channels") or ():
        points = " x ".join(map(str, channel["points"])) if channel.get("points") else "?"
        units = f"lengths in {shown(channel['unit'] or '?')}, values in {shown(channel['data_unit'] or '?')}"
        taken = " (taken)" if channel["index"] == summary.get("channel_index") else ""
        lines.append(f"channel {channel['index']}: {short_repr(shown(channel['name']))}, {points} points, {units}{taken}")
    if summary.get("channel_note"):
        lines.append(shown(summary["channel_note"]))
    return lines
