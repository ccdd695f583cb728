"""Writing files safely: every file frictionlab writes goes through ``atomic_write``,
so a reader never sees half a file and an interrupted write leaves the previous
version intact; ``output_path_problem`` says why a path cannot be an output folder."""

from __future__ import annotations

import io
import os
import tempfile
from collections.abc import Callable
from pathlib import Path


def _read_umask() -> int:
    mask = os.umask(0)  # the only portable way to read it; done once, at import
    os.umask(mask)
    return mask


_UMASK = _read_umask()


def atomic_write(path: Path, write: Callable[[io.IOBase], None], binary: bool = False) -> None:
    """Write via ``write(file)`` to a temporary sibling, fsync, then rename over ``path``.
    The file gets the usual permissions (0666 less the umask), not mkstemp's 0600."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        os.fchmod(fd, 0o666 & ~_UMASK)
        with os.fdopen(fd, "wb" if binary else "w", **({} if binary else {"encoding": "utf-8", "newline": ""})) as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def output_path_problem(path: Path) -> str | None:
    """Why ``path`` cannot be (or become) a folder: it, or the nearest existing
    folder above it, is a file."""
    path = Path(path)
    for candidate in (path, *path.parents):
        if candidate.exists() or candidate.is_symlink():
            if candidate.is_dir():
                return None
            if candidate == path:
                return f"{path} is a file, not a folder"
            return f"{path} cannot be made a folder: {candidate} is a file"
    return None
