"""The run directory: a small database of one run, so that no finished work is
lost, no damaged data is used, and no file frictionlab did not write is touched.

Layout inside the output folder::

    run.lock      held (an flock on POSIX: ``runlock``) while a run writes here, removed when it
                  ends; the kernel releases the lock even on kill -9
    run.json      the manifest: status, the resolved preset and its fingerprint, every
                  input file with its SHA-256 and what was read from it (``inputrecord``),
                  every chunk file with its SHA-256
    preset.yaml   the resolved preset, written before the first realization
    chunks/00000012-00000023.npz   one file per finished chunk, written to a temporary name and
                  renamed; the manifest is updated after. A completed run's chunks are compacted into one.

A resume trusts nothing it has not verified: every chunk listed in the
manifest is read and its SHA-256 and arrays checked; a missing or damaged one
is recomputed (with a warning that says how many), a file in ``chunks/`` the
manifest does not list is ignored. Realizations are keyed by index, so none is
counted twice, and since each has its own seed the resumed result is bitwise
the one of an uninterrupted run. A resume refuses another preset, an input
file whose content changed, and one now read otherwise (another version's reading).

A fresh run refuses a folder that holds anything but a run of its own preset (whose completed
run it runs again, saying so) unless ``force``; even then it deletes only chunk files its manifest lists.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import re
import time
from pathlib import Path

import yaml

from .. import __version__
from ..errors import OutputRefused, PresetError, RunFolderError, command_word, shown, shown_name, warn_user
from ..io.files import atomic_write, named_files, real_path, refuse_unusable_folder, replace_problem
from ..io.inputs import InputFileProblem, holds_exactly
from ..preset import Scene, differences, load_preset_file
from ..preset.paths import as_now, with_new_defaults
from ..compute.realization import RealizationResult
from .inputrecord import file_hashes, input_changes, refuse_changed_inputs, what_was_read
from .chunks import CHUNK_DIR, CHUNK_NAME, ChunkDamage, check_chunk_folder, chunk_bytes, damage_report, read_chunk
from .runfolder import check_schema_version, json_kind, lock_holder, read_json_object, read_member, refuse_other_kind
from .runlock import LockHeld, RunLock

DEFAULT_RUNS_DIR = Path("runs")  # where front ends put a run that names no folder
LOCK_FILE = "run.lock"
STATE_FILE = "run.json"
PRESET_FILE = "preset.yaml"
MANIFEST_FORMAT = 2
MANIFEST_STATUSES = ("running", "completed", "interrupted", "cancelled", "failed")  # what start and finish write
MAX_MANIFEST_BYTES = 64 * 1024 * 1024  # ~4096 chunks of ~100 bytes each, with ample room
# what a run killed while it started leaves (atomic_write's temporary files of its own names)
START_LEFTOVER = re.compile(rf"\.(?:{re.escape(PRESET_FILE)}|{re.escape(STATE_FILE)})\.\w+\.tmp")
# kept when the control or the solver gives them

def _write_holder(fd: int) -> None:
    """Who holds run.lock, for the message of a run refused because of it."""
    os.ftruncate(fd, 0)
    with contextlib.suppress(OSError):  # a courtesy a full disk goes without: raised, it left run.lock behind
        os.pwrite(fd, f"pid {os.getpid()}, started {time.strftime('%Y-%m-%d %H:%M:%S')}\n".encode(), 0)


def new_run_folder(name: str, runs_dir: str | Path = DEFAULT_RUNS_DIR) -> Path:
    """``runs_dir/<name>-<timestamp>``, made now and empty (``-2``, ``-3``, ... appended when
    the name is taken, also by a run started in the same second by another process: making
    the folder is what claims it): where a run goes when the user names no folder."""
    base = Path(runs_dir) / f"{name}-{time.strftime('%Y%m%d-%H%M%S')}"
    refuse_unusable_folder(base.parent)
    base.parent.mkdir(parents=True, exist_ok=True)
    candidate, n = base, 2
    while True:
        try:
            candidate.mkdir()
            return candidate
        except FileExistsError:
            candidate, n = base.with_name(f"{base.name}-{n}"), n + 1


def fingerprint(resolved: dict) -> str:
    text = json.dumps(resolved, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def same_preset(state: dict, resolved: dict, scene: Scene) -> bool:
    """Whether a manifest's run is of ``scene``'s preset (``resolved``, its JSON form): the same
    fingerprint, or the same once each field added to frictionlab since the run started is
    taken at its default, and each value since retired as what it now reads as (``as_now``)."""
    if state.get("fingerprint") == fingerprint(resolved):
        return True
    stored = state.get("preset")
    if not isinstance(stored, dict) or fingerprint(stored) != state.get("fingerprint"):
        return False
    return with_new_defaults(as_now(stored)[0], resolved, json_copy(scene.defaults())) == resolved


def json_copy(data: dict) -> dict:
    return json.loads(json.dumps(data))


_MANIFEST_FIELDS = (  # what a manifest's fields must be, when present (a format of "2" lost the run its chunks)
    ("format", int, "a whole number"), ("status", str, "a word"),
    ("fingerprint", str, "a string"),
    ("preset", dict, "a mapping"),
    ("inputs", dict, "a mapping of input files"),
    ("read", dict, "a mapping of what was read from the input file"),
    ("chunks", dict, "a mapping of chunk file names to SHA-256 digests"),
    ("retired", list, "a list of chunk file names"),
)


def _well_formed(key: str, value) -> bool:
    if key == "chunks":
        return all(isinstance(name, str) and isinstance(digest, str) for name, digest in value.items())
    if key == "retired":
        return all(isinstance(name, str) for name in value)
    return True


class RunDirectory:
    """One run's folder. ``force``: a fresh run may write into a folder that is
    not a run of its preset (deleting only chunk files its manifest lists)."""

    def __init__(self, path: str | Path, *, force: bool = False):
        self.path = Path(path)
        self.force = force
        self._lock: RunLock | None = None  # while held
        self._manifest: dict | None = None
        self._kept: dict[int, RealizationResult] = {}  # every result stored or verified here, by index

    @property
    def chunks(self) -> Path:
        return self.path / CHUNK_DIR

    # ------------------------------------------------------------ lock

    def __enter__(self) -> RunDirectory:
        refuse_unusable_folder(self.path)
        self.path.mkdir(parents=True, exist_ok=True)
        lock = self.path / LOCK_FILE
        if lock.is_symlink() or (os.path.lexists(lock) and not lock.is_file()):  # a link would be truncated through
            raise RunFolderError(
                f"{shown(lock)} is not a regular file (a link, a folder, ...): it cannot hold the run's lock "
                "(remove it, or give another folder)"
            )
        # a forked worker does not keep the lock, a holder that died (kill -9) holds it no
        # more, and a waiter that opened a file the holder then removed takes the lock on the new file.
        held = RunLock(lock, on_acquired=_write_holder)
        try:
            held.acquire()
        except LockHeld:
            pid = lock_holder(lock)  # as the kernel says: the lock file's text is anyone's
            try:  # what _write_holder wrote, believed only where it names that process
                text = read_member(self.path, LOCK_FILE, 4096).decode("utf-8", "replace").strip()[:200]
            except (OSError, InputFileProblem):
                text = ""
            holder = (shown(text) if text.startswith(f"pid {pid},") else f"pid {pid}") if pid else "a process that cannot be verified"
            raise RunFolderError(
                f"{shown(self.path)} is in use by another run ({holder}): wait for it to end, "
                "or give another output folder"
            ) from None
        except OSError as exc:
            if exc.errno not in (errno.ENOLCK, errno.ENOSYS, errno.EOPNOTSUPP):
                raise
            raise RunFolderError(  # two runs into one folder would mix their chunks: none without the lock
                f"{shown(lock)} cannot be locked ({exc.strerror}): the file system of {shown(self.path)} does not "
                "keep locks (some network file systems do not); give an output folder on a local disk"
            ) from None
        self._lock = held
        return self

    def __exit__(self, *exc) -> bool:
        if self._lock is not None:
            with contextlib.suppress(OSError):  # while still held: a waiter that opened it retries on the new one
                (self.path / LOCK_FILE).unlink()
            self._lock.release()
            self._lock = None
        return False

    # ------------------------------------------------------------ manifest

    def state(self) -> dict | None:
        """The manifest (run.json), None if there is none; RunFolderError if it is damaged."""
        path = self.path / STATE_FILE
        if not os.path.lexists(path):
            return None
        try:
            state = read_json_object(path, MAX_MANIFEST_BYTES, "manifest")
        except InputFileProblem as exc:
            raise RunFolderError(f"{shown_name(path)}: {exc}") from None
        check_schema_version(state, path, MANIFEST_FORMAT, key="format")
        for key, kind, what in _MANIFEST_FIELDS:
            value = state.get(key)
            if value is not None and (not isinstance(value, kind) or isinstance(value, bool)):
                raise RunFolderError(f"{shown_name(path)} is damaged ({key} is not {what}, but {json_kind(value)})")
            if value is not None and not _well_formed(key, value):
                raise RunFolderError(f"{shown_name(path)} is damaged ({key} is not {what}: an entry is not a string)")
        if state.get("status") is not None and state["status"] not in MANIFEST_STATUSES:  # listed as it was, unexplained
            raise RunFolderError(f"{shown_name(path)} is damaged (status is {shown(repr(state['status'][:80]))}, not one "
                                 f"of {', '.join(MANIFEST_STATUSES)})")  # fmt: skip
        return state

    def _write_manifest(self) -> None:
        manifest = self._manifest
        atomic_write(self.path / STATE_FILE, lambda fh: json.dump(manifest, fh, indent=1))

    def stored_preset(self) -> dict:
        """The preset the run was started with (preset.yaml), read as any preset is."""
        path = self.path / PRESET_FILE
        if not self.path.is_dir():
            what = "is not a folder" if os.path.lexists(self.path) else "does not exist"
            raise RunFolderError(f"{shown(self.path)} {what}: there is no run to resume there")
        if not os.path.lexists(path):
            raise RunFolderError(f"{shown_name(self.path)} holds no run to resume (no {PRESET_FILE})")
        try:
            return load_preset_file(path, follow_links=False)
        except PresetError as exc:
            raise RunFolderError(
                f"{shown_name(path)} is damaged ({exc.problems[0].removeprefix('(file): ')}): this run cannot be resumed"
            ) from None

    # ------------------------------------------------------------ start, finish

    def start(self, scene: Scene, *, resume: bool) -> list[RealizationResult]:
        """Prepare the directory for ``scene``; return the results already stored
        and verified (resume) or none (a fresh run)."""
        check_chunk_folder(self.chunks)
        self._check_replaceable(scene, resume)
        resolved = json_copy(scene.resolved())
        inputs, read = file_hashes(scene), what_was_read(scene)
        if resume:
            return self._resume(scene, resolved, inputs, read)
        try:
            state = self.state()
        except RunFolderError:
            if not self.force:
                raise
            state = None  # a damaged manifest lists nothing: nothing is deleted
        self._refuse_unless_ours(state, scene, resolved)
        if state is not None and state.get("status") == "completed" and same_preset(state, resolved, scene):
            warn_user(f"{shown_name(self.path)} holds a completed run of this preset: it runs again, to the same numbers")
        listed = [*self._listed(state), *((state or {}).get("retired") or [])]
        self._remove_chunks(listed)  # chunks of the run that was here: frictionlab wrote them
        self.chunks.mkdir(parents=True, exist_ok=True)
        atomic_write(self.path / PRESET_FILE, lambda fh: yaml.safe_dump(resolved, fh, sort_keys=False))
        self._manifest = {
            "format": MANIFEST_FORMAT,
            "frictionlab_version": __version__,
            "status": "running",
            "fingerprint": fingerprint(resolved),
            "realizations": resolved.get("realizations"),
            "preset": resolved,
            "inputs": inputs,
            **({"read": read} if read is not None else {}),
            "chunks": {},
        }
        self._write_manifest()
        return []

    def _check_replaceable(self, scene: Scene, resume: bool) -> None:
        """Refuse before any work a file of the run that is a folder (a socket...) here: its
        results, written at the end, could never replace it (plot.png only where one is drawn)."""
        written = [STATE_FILE, PRESET_FILE, "summary.json", "curve.csv"]
        written += ["realizations.npz"] if scene.preset.output.realizations else []
        inputs = named_files(scene.resolved())  # a result written over the run's own scan: --force into its folder
        for name in written:
            problem = replace_problem(self.path / name) or ("is this run's input" if real_path(self.path / name) in inputs else None)
            if problem:
                refused, then = (RunFolderError, "resume") if resume else (OutputRefused, "run again")
                raise refused(f"{shown(self.path / name)} {problem}: the run writes its {name} there; move it aside, then {then}")

    def finish(self, scene: Scene, status: str, seconds: float | None = None) -> None:
        """Record the final status (and the ``seconds`` the run's sessions took); a completed
        run's chunks are compacted into one file."""
        if self._manifest is None:
            return
        self._manifest.update(status=status, **({} if seconds is None else {"elapsed_seconds": round(seconds, 6)}))
        self._manifest["frictionlab_version"] = __version__
        if status == "completed":
            self.compact()
        self._write_manifest()  # the status, and no more the chunks a compaction retired

    def check_fresh(self, scene: Scene) -> None:
        """Refuse now, writing nothing, what a fresh ``start(scene)`` would refuse here
        (a front end that starts the run in another process says it at once)."""
        refuse_unusable_folder(self.path)
        if not self.path.is_dir():
            return
        try:
            state = self.state()
        except RunFolderError:
            if not self.force:
                raise
            state = None
        self._refuse_unless_ours(state, scene, json_copy(scene.resolved()))

    @staticmethod
    def _listed(state: dict | None) -> list[str]:
        chunks = (state or {}).get("chunks")
        return list(chunks) if isinstance(chunks, dict) else []

    def _refuse_unless_ours(self, state: dict | None, scene: Scene, resolved: dict) -> None:
        """OutputRefused when a fresh run here would replace what is not a
        finished run of the same preset (unless ``force``), or is a sweep's (``force`` too)."""
        refuse_other_kind(self.path, "run")
        if self.force:
            return
        hint = "give another output folder, or force it (--force; force=True in Python) to write into it anyway"
        if state is None:
            others = sorted(p.name for p in self.path.iterdir() if not _left_by_a_start(p, resolved))
            if others:
                listed = ", ".join(repr(name) for name in others[:3]) + (", ..." if len(others) > 3 else "")
                raise OutputRefused(
                    f"{shown_name(self.path)} is not empty and is not a frictionlab run folder (it holds {listed}): "
                    f"{hint} (frictionlab then replaces only the files it writes and deletes none)"
                )
            return
        status = state.get("status")
        if status == "completed" and not same_preset(state, resolved, scene):
            old = state.get("preset")
            changed = differences(old, resolved) if isinstance(old, dict) else []
            fields = ", ".join(d.split(":", 1)[0] for d in changed[:5]) or "its fingerprint"
            raise OutputRefused(
                f"{shown_name(self.path)} holds a finished run of another preset (it differs in {fields}): "
                f"{hint} (its results are then replaced)"
            )
        if status != "completed" and self._listed(state):
            raise OutputRefused(
                f"{shown_name(self.path)} holds an unfinished run ({len(self._listed(state))} chunk file(s) in {CHUNK_DIR}/, "
                f"status {status}): continue it with --resume (resume=True in Python, or `frictionlab resume {command_word(self.path)}`), "
                "or give another output folder, or force it (--force; force=True) to start it again"
            )

    def _resume(self, scene: Scene, resolved: dict, inputs: dict, read: dict | None) -> list[RealizationResult]:
        state = self.state()
        if state is None:
            sweep = os.path.lexists(self.path / "sweep.json")  # its points are runs of their own
            raise RunFolderError(f"{shown_name(self.path)} holds no run to resume (no {STATE_FILE})" + (
                f": it is a sweep's folder, which `frictionlab resume {command_word(self.path)}` continues" if sweep else ""))
        if changed := self.preset_changes(state, resolved, scene):
            given = f" ({scene.source})" if scene.source else ""  # `resume DIR`: DIR/preset.yaml, edited
            raise RunFolderError(f"cannot resume {shown_name(self.path)}: the preset its {STATE_FILE} started with differs from the one "
                                 f"given{given}\n  " + "\n  ".join(changed))
        refuse_changed_inputs(self.path, state, inputs, read)
        recorded = state.get("inputs") if isinstance(state.get("inputs"), dict) else {}
        if state.get("fingerprint") != fingerprint(resolved):  # started before fields now at their defaults, or retired values
            atomic_write(self.path / PRESET_FILE, lambda fh: yaml.safe_dump(resolved, fh, sort_keys=False))
            for note in as_now(state.get("preset"))[1]:
                warn_user(f"resume of {shown_name(self.path)}: {note}")
        self._manifest = {**state, "format": MANIFEST_FORMAT, "status": "running", "preset": resolved,
                          "fingerprint": fingerprint(resolved), "realizations": resolved.get("realizations"),
                          "inputs": {**inputs, **{k: v for k, v in recorded.items() if k not in inputs}},
                          **({"read": read} if read is not None else {})}  # fmt: skip
        self._manifest["chunks"] = dict(state.get("chunks") or {}) if state.get("format") == MANIFEST_FORMAT else {}
        self._remove_chunks(self._manifest.pop("retired", None) or [], keep=self._manifest["chunks"])  # an unfinished compaction's
        results = self._verified(scene, warn=True)
        self._kept = {r.index: r for r in results}
        self._write_manifest()
        return results

    def preset_changes(self, state: dict, resolved: dict, scene: Scene) -> list[str]:
        """Where the preset the manifest ``state`` started with differs from ``scene``'s (``resolved``), a
        line per field; [] where it is the same, RunFolderError where the manifest's fingerprint is not its own."""
        if same_preset(state, resolved, scene):
            return []
        stored = state.get("preset") if isinstance(state.get("preset"), dict) else self.stored_preset()
        if not (changed := differences(stored, resolved)):  # the same preset, and a fingerprint that is not its own
            raise RunFolderError(f"cannot resume {shown_name(self.path)}: the fingerprint in its {STATE_FILE} is not that of "
                                 "the preset it holds (the file damaged or edited); run the preset again into a new folder")
        return changed

    # ------------------------------------------------------------ chunks

    def _remove_chunks(self, names: list, keep=()) -> None:
        """Delete the chunks ``names`` a manifest lists (those with a chunk's name, not in ``keep``);
        a folder so named is the user's (no chunk is one): unlinking it ended the run, exit code 1."""
        for name in names:
            path = self.chunks / name if isinstance(name, str) and CHUNK_NAME.fullmatch(name) else None
            if path is not None and name not in keep and (path.is_symlink() or not path.is_dir()):
                path.unlink(missing_ok=True)

    def _free_name(self, first: int, last: int) -> str:
        """The chunk's file name, or a variant of it when a file the manifest does
        not list already has it (never overwritten)."""
        listed = self._manifest["chunks"]
        name, copy = f"{first:08d}-{last:08d}.npz", 0
        while os.path.lexists(self.chunks / name) and name not in listed:
            copy += 1
            name = f"{first:08d}-{last:08d}.{copy}.npz"
        return name

    def save_chunk(self, results: list[RealizationResult]) -> Path:
        """Write one finished chunk atomically, then list it with its SHA-256 in
        the manifest; its name is its index range."""
        indices = sorted(r.index for r in results)
        data = chunk_bytes(results)
        name = self._free_name(indices[0], indices[-1])
        path = self.chunks / name
        atomic_write(path, lambda fh: fh.write(data), binary=True)
        chunks = self._manifest["chunks"]
        chunks.pop(name, None)  # listed again last: later chunks win where they overlap (a retried failure)
        chunks[name] = hashlib.sha256(data).hexdigest()
        self._write_manifest()
        self._kept.update((r.index, r) for r in results)
        return path

    def completed_results(self, scene: Scene) -> list[RealizationResult] | None:
        """Every result of a completed run of ``scene`` in this folder, read without its lock
        and without writing anything (a reader beside another that holds the lock); None
        unless the manifest says completed, for this preset and these input files, and every
        realization's chunk checks out (then resuming the run says what is wrong, or repairs it)."""
        try:
            state = self.state()
        except RunFolderError:
            return None
        if not state or state.get("status") != "completed" or state.get("format") != MANIFEST_FORMAT:
            return None
        if not same_preset(state, json_copy(scene.resolved()), scene) or as_now(state.get("preset"))[1]:  # its retired
            return None  # values are rewritten, and said, by a resume
        hashes = file_hashes(scene)
        recorded = state.get("inputs") if isinstance(state.get("inputs"), dict) else {}
        if any(not isinstance(recorded.get(field), dict) for field in hashes) or input_changes(state, hashes, what_was_read(scene)):
            return None
        results = self._verified(scene, dict(state.get("chunks") or {}), warn=False)
        return results if len(results) == scene.preset.realizations else None

    def _verified(self, scene: Scene, chunks: dict | None = None, *, warn: bool) -> list[RealizationResult]:
        """The results of every chunk listed in ``chunks`` (by default the manifest's) whose
        SHA-256 and arrays check out, a later chunk winning where two hold the same index;
        the others are dropped from ``chunks`` (and, with ``warn``, counted in a warning)."""
        chunks = self._manifest["chunks"] if chunks is None else chunks
        results: dict[int, RealizationResult] = {}
        damaged: dict[str, str] = {}
        for name, digest in list(chunks.items()):
            try:
                rows = read_chunk(self.path, name, digest, scene)
            except ChunkDamage as exc:
                damaged[name] = str(exc)
                del chunks[name]
                continue
            results.update((r.index, r) for r in rows)
        if warn:
            self._warn_damage(damaged, results, scene.preset.realizations)
        return [results[i] for i in sorted(results)]

    def _warn_damage(self, damaged: dict[str, str], results: dict, total: int) -> None:
        report = damage_report(self.chunks, set(self._manifest["chunks"]), damaged, set(results), total)
        if report:
            warn_user(f"resume of {shown_name(self.path)}: {report}")

    def compact(self, pending: list[RealizationResult] | tuple = ()) -> bool:
        """Merge the chunks of a completed run, with ``pending`` (its last results, not yet
        written: they are not written apart first), into one file: written and listed
        first, the old ones deleted after (a crash in between leaves them listed as retired,
        deleted by the next start). The results are those this object stored or verified
        (the chunks' content, not read back), a pending one winning over a stored one of
        its index. Whether it merged. The manifest on disk lists the old ones as retired
        until its next write (``finish``, which follows), which drops them."""
        old = list(self._manifest["chunks"])
        if len(old) + bool(pending) <= 1 or not self._kept:
            return False
        merged, listed = {**self._kept, **{r.index: r for r in pending}}, self._manifest["chunks"]
        self._manifest["chunks"] = {}
        self._manifest["retired"] = old
        try:
            self.save_chunk([merged[i] for i in sorted(merged)])
        except BaseException:  # not written (a full disk): the old chunks stay listed, never retired
            self._manifest["chunks"] = listed
            self._manifest.pop("retired")
            raise
        kept = set(self._manifest["chunks"])
        for name in old:
            if name not in kept:
                (self.chunks / name).unlink(missing_ok=True)
        self._manifest.pop("retired")
        return True


def _left_by_a_start(path: Path, resolved: dict) -> bool:
    """Whether ``path`` in a folder with no manifest is what a run of ``resolved`` killed while
    it started left there (its lock, its empty chunks folder, its preset.yaml to the byte, a
    temporary file of its preset or manifest): a folder of nothing else is started afresh, as
    an empty one is (a sweep's point killed as it began was refused as "not empty" on resume)."""
    if path.name == LOCK_FILE or START_LEFTOVER.fullmatch(path.name):
        return True
    if path.is_symlink():
        return False
    if path.name == CHUNK_DIR:
        return path.is_dir() and not any(path.iterdir())
    if path.name == PRESET_FILE:  # replaced by the same bytes: nothing is lost
        return holds_exactly(path, yaml.safe_dump(resolved, sort_keys=False).encode())
    return False
