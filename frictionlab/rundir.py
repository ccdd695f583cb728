"""The run directory: a lock, the preset the run was started with, and every
finished chunk of realizations, so that no finished work is lost.

Layout inside the output folder::

    run.lock            held (fcntl.flock) while a run writes here; the kernel
                        releases it when the process ends, even by kill -9
    run.json            fingerprint of the resolved preset, status of the run
    preset.yaml         the resolved preset, written before the first realization
    chunks/00000012-00000023.npz   one file per finished chunk, written atomically

A resume reads the chunks, checks the preset is the one the directory was
started with, and computes only the missing realizations. Since every
realization has its own seed and the statistics are formed by index, the
result is bitwise the one of an uninterrupted run.
"""

from __future__ import annotations

import fcntl
import hashlib
import io
import json
import os
import time
import warnings
from pathlib import Path

import numpy as np
import yaml

from . import __version__
from .errors import FrictionlabError, RunError
from .preset import Scene
from .realization import RealizationResult
from .results import atomic_write

CHUNK_DIR = "chunks"
LOCK_FILE = "run.lock"
STATE_FILE = "run.json"
PRESET_FILE = "preset.yaml"

# Lock descriptors of this process: a forked pool worker closes its copies, so
# the lock goes with the main process (flock is shared by every copy of the fd).
_held_locks: set[int] = set()


def _close_locks_in_child() -> None:
    for fd in _held_locks:
        try:
            os.close(fd)
        except OSError:
            pass
    _held_locks.clear()


os.register_at_fork(after_in_child=_close_locks_in_child)


def fingerprint(resolved: dict) -> str:
    text = json.dumps(resolved, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def preset_differences(old, new, path: str = "") -> list[str]:
    """Dotted paths where two resolved presets differ, with both values."""
    if isinstance(old, dict) and isinstance(new, dict):
        out = []
        for key in list(old) + [k for k in new if k not in old]:
            where = f"{path}.{key}" if path else str(key)
            if key not in old or key not in new:
                out.append(f"{where}: {old.get(key, '(absent)')!r} in the run directory, {new.get(key, '(absent)')!r} given")
            else:
                out.extend(preset_differences(old[key], new[key], where))
        return out
    if old != new:
        return [f"{path}: {old!r} in the run directory, {new!r} given"]
    return []


class RunDirectory:
    def __init__(self, path: str | Path):
        self.path = Path(path)
        self._lock_fd: int | None = None

    @property
    def chunks(self) -> Path:
        return self.path / CHUNK_DIR

    # ------------------------------------------------------------ lock

    def __enter__(self) -> RunDirectory:
        self.path.mkdir(parents=True, exist_ok=True)
        lock = self.path / LOCK_FILE
        fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 200, 0).decode(errors="replace").strip() or "unknown"
            os.close(fd)
            raise RunError(
                f"{self.path} is in use by another run ({holder}): wait for it to end, "
                "or give another output folder"
            ) from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()}, started {time.strftime('%Y-%m-%d %H:%M:%S')}\n".encode(), 0)
        self._lock_fd = fd
        _held_locks.add(fd)
        return self

    def __exit__(self, *exc) -> bool:
        if self._lock_fd is not None:
            _held_locks.discard(self._lock_fd)
            os.close(self._lock_fd)  # releases the flock
            self._lock_fd = None
        return False

    # ------------------------------------------------------------ state

    def state(self) -> dict | None:
        try:
            return json.loads((self.path / STATE_FILE).read_text(encoding="utf-8"))
        except FileNotFoundError:
            return None
        except (OSError, ValueError) as exc:
            raise RunError(f"{self.path / STATE_FILE} is unreadable: {exc}") from None

    def _write_state(self, resolved: dict, status: str) -> None:
        state = {
            "fingerprint": fingerprint(resolved),
            "status": status,
            "realizations": resolved.get("realizations"),
            "frictionlab_version": __version__,
        }
        atomic_write(self.path / STATE_FILE, lambda fh: json.dump(state, fh, indent=2))

    def stored_preset(self) -> dict:
        try:
            return yaml.safe_load((self.path / PRESET_FILE).read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise FrictionlabError(f"{self.path} holds no run to resume (no {PRESET_FILE})") from None

    def start(self, scene: Scene, *, resume: bool) -> list[RealizationResult]:
        """Prepare the directory for ``scene``; return the results already stored
        (resume) or none (a fresh run). Refuses to resume another preset, and to
        start afresh over an unfinished run."""
        resolved = json.loads(json.dumps(scene.resolved()))
        state = self.state()
        if state is not None and resume:
            if state.get("fingerprint") != fingerprint(resolved):
                differences = preset_differences(self.stored_preset(), resolved)
                raise FrictionlabError(
                    f"cannot resume {self.path}: its preset differs from the one given\n  "
                    + "\n  ".join(differences or ["(the fingerprints differ)"])
                )
            self._write_state(resolved, "running")
            return self.load()
        if state is not None and state.get("status") != "completed":
            stored = sum(1 for _ in self.chunks.glob("[0-9]*.npz")) if self.chunks.exists() else 0
            if stored:
                raise FrictionlabError(
                    f"{self.path} holds an unfinished run ({stored} chunk file(s) in {CHUNK_DIR}/, status "
                    f"{state.get('status')}): continue it with --resume (or `frictionlab resume {self.path}`), "
                    "or give another output folder"
                )
        for old in self.chunks.glob("*"):  # a fresh run: an earlier completed run's chunks go
            old.unlink()
        self.chunks.mkdir(parents=True, exist_ok=True)
        atomic_write(self.path / PRESET_FILE, lambda fh: yaml.safe_dump(resolved, fh, sort_keys=False))
        self._write_state(resolved, "running")
        return []

    def finish(self, scene: Scene, status: str) -> None:
        self._write_state(json.loads(json.dumps(scene.resolved())), status)

    # ------------------------------------------------------------ chunks

    def save_chunk(self, results: list[RealizationResult]) -> Path:
        """Write one finished chunk atomically; its name is its index range."""
        ok = [r for r in results if r.ok]
        failed = [r for r in results if not r.ok]
        indices = sorted(r.index for r in results)
        arrays: dict[str, np.ndarray] = {
            "index": np.array([r.index for r in ok], dtype=np.int64),
            "seconds": np.array([r.seconds for r in ok]),
            "slope_rms_line": np.array([r.slope_rms_line for r in ok]),
            "points": np.array([r.points for r in ok], dtype=np.int64),
            "force_unit": np.array([r.force_unit for r in ok]),
            "failed_index": np.array([r.index for r in failed], dtype=np.int64),
            "failed_seconds": np.array([r.seconds for r in failed]),
            "failed_error": np.array([r.error for r in failed], dtype=str),
        }
        for name in ("xi", "contact_count", "indentation", "force"):
            rows = [getattr(r, name) for r in ok]
            if ok and rows[0] is not None:
                arrays[name] = np.vstack(rows)
        path = self.chunks / f"{indices[0]:08d}-{indices[-1]:08d}.npz"
        buffer = io.BytesIO()
        np.savez(buffer, **arrays)
        atomic_write(path, lambda fh: fh.write(buffer.getbuffer()), binary=True)
        return path

    def load(self) -> list[RealizationResult]:
        """Every result stored in ``chunks/``; an unreadable file is skipped (its
        realizations are recomputed) with a warning."""
        results: dict[int, RealizationResult] = {}
        if not self.chunks.exists():
            return []
        for path in sorted(self.chunks.glob("[0-9]*.npz")):
            try:
                with np.load(path, allow_pickle=False) as data:
                    arrays = {name: data[name] for name in data.files}
            except (OSError, ValueError, KeyError) as exc:
                warnings.warn(f"skipping unreadable chunk {path.name} ({exc}); its realizations are recomputed")
                continue
            if "force_unit" not in arrays:  # written before f had its solver's normalisation
                warnings.warn(f"skipping chunk {path.name} of an older format; its realizations are recomputed")
                continue
            for row, index in enumerate(arrays["index"].tolist()):
                results[index] = RealizationResult(
                    index=index,
                    seconds=float(arrays["seconds"][row]),
                    xi=arrays["xi"][row],
                    contact_count=arrays["contact_count"][row],
                    indentation=arrays["indentation"][row],
                    force=arrays["force"][row] if "force" in arrays else None,
                    slope_rms_line=float(arrays["slope_rms_line"][row]),
                    points=int(arrays["points"][row]),
                    force_unit=float(arrays["force_unit"][row]),
                )
            for row, index in enumerate(arrays["failed_index"].tolist()):
                results[index] = RealizationResult(
                    index=index, seconds=float(arrays["failed_seconds"][row]), error=str(arrays["failed_error"][row])
                )
        return [results[i] for i in sorted(results)]
