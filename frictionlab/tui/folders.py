"""Where the TUI finds presets and past runs (no Textual here: plain files).

Presets come from ``./presets`` (when it exists; new ones are saved there) and the user folder
(``$FRICTIONLAB_PRESETS_DIR``, else ``$XDG_CONFIG_HOME/frictionlab/presets``,
else the platform's config folder: ``~/.config/frictionlab/presets`` on Linux). Runs are the output folders the
headless ``frictionlab run`` writes, found by their ``summary.json``, and sweep
folders, found by their ``sweep.json``.
"""

from __future__ import annotations

import errno
import itertools
import os
import re
import stat
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import yaml

from ..errors import FrictionlabError, RunFolderError
from ..io.files import real_path
from ..io.inputs import expand_user, read_regular_file
from ..preset import load_preset_file, resolve_input_paths
from ..preset.builtin import BUILTIN, PROJECT_PRESETS_DIR, builtin_folder, builtin_presets, user_presets_dir
from ..preset.reading import MAX_PRESET_BYTES, NOT_A_MAPPING
from ..preset.schema import NAME_PATTERN
from ..io.safe_yaml import load_yaml
from ..io.values import number_or_nan, whole_or

# The runs' modules (``detached``, ``runfolder``) and the comment-keeping YAML writer are
# imported where runs are read or a preset written: the first screen lists presets only.

def writable_folder(folders: list[tuple[str, Path]]) -> Path:
    """Where copies go by default: the user folder (or the only one given)."""
    return next(folder for label, folder in reversed(folders) if label != BUILTIN)


def is_builtin(path: Path) -> bool:
    """Whether ``path`` is one of the presets shipped in the installed package (not to be written)."""
    shipped = builtin_folder()
    return shipped is not None and real_path(shipped) != real_path(PROJECT_PRESETS_DIR) and \
        real_path(path).parent == real_path(shipped)  # fmt: skip


def save_folder(presets_dir: Path | None = None) -> Path:
    """Where a new preset (or a built-in one's copy) is saved unless the user says
    otherwise: the folder given with ``--presets``, else ``./presets`` (made when
    first saved into). Both are listed, so a saved preset is in the list at once."""
    return Path(presets_dir) if presets_dir is not None else PROJECT_PRESETS_DIR


def made_when_saved(folder: Path, save_to: Path) -> bool:
    """Whether ``folder`` is a presets folder made when first saved into: ``save_to`` (where new
    presets go) or the user folder (offered for a preset that cannot be written where it is)."""
    try:
        return any(real_path(expand_user(str(folder))) == real_path(expand_user(str(made)))
                   for made in (save_to, user_presets_dir()))  # fmt: skip
    except ValueError:  # ~user of no user: no folder of ours
        return False


def new_preset_path(name: str, folder: Path) -> Path:
    return Path(folder) / f"{name}.yaml"


@dataclass(frozen=True)
class PresetEntry:
    label: str  # which folder
    path: Path
    name: str  # the preset's own name, or the file stem if unreadable
    description: str
    error: str = ""


def list_presets(folders: list[tuple[str, Path]]) -> list[PresetEntry]:
    entries = []
    for label, folder in folders:
        if not folder.is_dir():
            continue
        for path in sorted(folder.glob("*.y*ml")):
            try:  # read as a preset is: bounded, a regular file, so that a hostile file (a FIFO) cannot stop the listing
                data = load_yaml(read_regular_file(path, MAX_PRESET_BYTES, "preset file").decode("utf-8"))
            except (OSError, ValueError) as exc:  # unreadable, not UTF-8, not YAML, beyond the limits
                entries.append(PresetEntry(label, path, path.stem, "", f"cannot be read: {_unreadable(exc)}"))
                continue
            if not isinstance(data, dict):  # a list, a bare value, an empty file: opening it is refused, so it says why
                entries.append(PresetEntry(label, path, path.stem, "", f"cannot be read: {NOT_A_MAPPING}"))
                continue
            description = " ".join(str(data.get("description") or "").split())
            entries.append(PresetEntry(label, path, str(data.get("name") or path.stem), description))
    return entries


def presets_signature(folders: list[tuple[str, Path]]) -> tuple:
    """What changes when a preset file is added to ``folders``, removed, renamed or written (by
    an editor, a shell, another TUI): each folder's preset files' names, times and sizes (nothing read)."""
    return tuple((str(folder), _files_stamp(folder)) for _, folder in folders)


def _files_stamp(folder: Path) -> tuple | None:
    try:
        return tuple((p.name, _stamp(p)) for p in sorted(folder.glob("*.y*ml"))) if folder.is_dir() else None
    except OSError:  # not to be looked into: looked at again next time
        return None


def _stamp(path: Path) -> tuple[int, int] | None:
    try:
        found = path.stat()
    except OSError:  # a link to nothing, a file gone meanwhile: listed as it is
        return None
    return found.st_mtime_ns, found.st_size


def _unreadable(exc: Exception) -> str:
    """Why a preset file cannot be read, in words (never a line of it)."""
    if isinstance(exc, UnicodeDecodeError):
        return f"not UTF-8 text (byte {exc.start + 1}); save the preset as UTF-8"
    if isinstance(exc, OSError):
        return exc.strerror or "an error of the system"
    return str(exc)  # YamlProblem, InputFileProblem: they name a line, never quote the text


FIRST_TEMPLATE = "quickstart"  # runs in about a second: the template a new preset starts from


def templates(entries: list[PresetEntry]) -> list[tuple[str, Path]]:
    """(label, file) of the presets a new one may start from: the built-in ones
    (quickstart first), then the listed ones that can be read."""
    shipped = sorted(builtin_presets(), key=lambda p: p.name != FIRST_TEMPLATE)
    choices = [(f"{p.name} ({BUILTIN})", p.path) for p in shipped]
    seen = {real_path(p.path) for p in shipped}
    for entry in entries:
        if not entry.error and real_path(entry.path) not in seen:
            choices.append((f"{entry.name} ({entry.label})", entry.path))
    return choices


def preset_from_template(template: Path, name: str, new_path: Path, registry=None) -> dict:
    """A template preset's data renamed ``name``, its relative input files
    made to work from ``new_path``'s folder (raises ``PresetError``)."""
    data = load_preset_file(template)
    if real_path(template).parent != real_path(new_path).parent:
        data = resolve_input_paths(data, Path(template).parent, registry)
    data["name"] = name
    return data


def copy_target(name: str, stem: str, folder: Path, taken: set[str]) -> tuple[str, Path]:
    """A copy's name and the file offered for it: ``<name>-copy`` in ``<stem>-copy.yaml``, numbered
    (``-copy-2``) until the name is no listed preset's and the file is not there (never replaced)."""
    for number in itertools.count(1):
        suffix = "-copy" if number == 1 else f"-copy-{number}"
        path = Path(folder) / f"{stem}{suffix}.yaml"
        copied = name[: 100 - len(suffix)] + suffix  # a name is at most 100 characters
        if copied not in taken and not os.path.lexists(path):
            return copied, path
    raise AssertionError("unreachable")


def copy_name(name: str, path: Path, default: Path, taken: set[str]) -> str:
    """A copy's name: ``name`` (``copy_target``'s) saved where offered (``default``), else the
    file's own name when it can name a preset and no listed preset has it, as New names the
    file after the preset."""
    own = path != default and re.fullmatch(NAME_PATTERN, path.stem) and path.stem not in taken
    return path.stem if own else name


def names_taken(entries: list[PresetEntry], replaced: Path | None = None) -> set[str]:
    """The names of the listed presets ``entries``, but that of the file a copy replaces."""
    gone = _resolved(replaced) if replaced is not None else None
    return {entry.name for entry in entries if gone is None or _resolved(entry.path) != gone}


def _resolved(path: Path) -> Path:
    try:
        return real_path(path)
    except (OSError, RuntimeError):  # a link loop
        return Path(path)


def save_preset(path: Path, data: dict, template: Path | None = None) -> None:
    """Write preset data as YAML, atomically. With ``template`` (the file the draft
    was read from) the text keeps that file's comments, key order and formatting,
    only the edited values change; without one, or if it cannot be read, plain YAML."""
    from ..io.files import atomic_write
    from .roundtrip import dump_preserving

    if _read_only(path):  # renaming over it would replace it, made writable, as no editor does unasked
        raise PermissionError(errno.EACCES, "the file is read-only", str(path))
    text = None
    if template is not None:
        try:
            text = dump_preserving(Path(template).read_text(encoding="utf-8"), data)
        except (OSError, UnicodeDecodeError):
            text = None
    if text is None:
        text = yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
    atomic_write(Path(path), lambda fh: fh.write(text), mode=_own_mode(path))


def _own_mode(path: Path) -> int | None:
    """The permissions of the regular file at ``path`` (kept when it is rewritten), None if there is none."""
    try:
        mode = os.lstat(path).st_mode
    except OSError:
        return None
    return stat.S_IMODE(mode) if stat.S_ISREG(mode) else None


def file_stamp(path: Path) -> tuple[int, int, int] | None:
    """What changes when a file is written or replaced (its inode, size and time of change), None
    where it is not there: another program's (an editor's, another TUI's) write is seen by it."""
    try:
        stat = os.stat(path)
    except OSError:
        return None
    return stat.st_ino, stat.st_size, stat.st_mtime_ns


def _read_only(path: Path) -> bool:
    """Whether ``path`` is a file no one may write (mode 444: kept from changes on purpose)."""
    mode = _own_mode(path)
    return mode is not None and not mode & 0o222


# ------------------------------------------------------------------ past runs


def _mapping(value) -> dict:
    return value if isinstance(value, dict) else {}


@dataclass
class RunEntry:
    path: Path
    name: str
    status: str
    done: int
    requested: int
    fit: dict | None
    summary: dict
    mtime: float
    curve: dict[str, list[float]] = field(default_factory=dict)
    reason: str = ""  # why a damaged folder (status "damaged") cannot be read

    @property
    def a(self) -> float:
        return number_or_nan((self.fit or {}).get("a"))

    @property
    def b(self) -> float:
        return number_or_nan((self.fit or {}).get("b"))

    @property
    def r2(self) -> float:
        return number_or_nan((self.fit or {}).get("r2"))

    @property
    def confidence(self) -> float | None:
        """The level of the fit's intervals, None where the summary gives none (or not a level)."""
        return recorded_level((self.fit or {}).get("confidence"))

    def interval(self, key: str) -> tuple[float, float] | None:
        """The fit's ``a_ci`` or ``b_ci`` as two numbers, None if it has none (or a damaged one)."""
        pair = (self.fit or {}).get(key)
        return (number_or_nan(pair[0]), number_or_nan(pair[1])) if isinstance(pair, list) and len(pair) == 2 else None

    @property
    def contact_counts(self) -> tuple[float, float]:
        """The mean points in contact at the first and the last load (NaN where unknown)."""
        return number_or_nan(self.summary.get("contact_count_at_first_load")), number_or_nan(self.summary.get("contact_count_at_last_load"))

    @property
    def formula(self) -> str:
        """f's formula as summary.json gives it ("" if it does not)."""
        formula = _mapping(self.summary.get("normalisation")).get("formula")
        return formula if isinstance(formula, str) else ""

    @property
    def definition(self) -> str:
        """f with its symbols said (``f = F / (E* h L), F the force, ...``), as summary.json gives it ("" if not)."""
        definition = _mapping(self.summary.get("normalisation")).get("f")
        return definition if isinstance(definition, str) else ""

    @property
    def failed_for_good(self) -> str:
        """Why the run failed with every realization finished and none failed (no law: each load
        pressed the same points), "" otherwise: a resume computes nothing and fails the same way
        (``runs.settled``; a failed realization is computed again by a resume)."""
        from ..runs.settled import fit_failed

        return fit_failed(self.summary) if self.status == "failed" else ""  # not a resume going on


def read_run(folder: Path) -> RunEntry:
    """A run folder's summary (read as untrusted input: ``runfolder``); RunFolderError
    if it has none readable."""
    from ..runs.runfolder import read_json

    folder = Path(folder)
    summary_path = folder / "summary.json"
    summary = read_json(folder, "summary.json")
    realizations, preset = _mapping(summary.get("realizations")), _mapping(summary.get("preset"))
    return RunEntry(  # a field of the wrong kind is shown as missing, never trusted
        path=folder,
        name=str(preset.get("name") or folder.name),
        status=str(summary.get("status", "?")),
        done=whole_or(realizations.get("done")),
        requested=whole_or(realizations.get("requested")),
        fit=summary.get("fit") if isinstance(summary.get("fit"), dict) else None,
        summary=summary,
        mtime=os.lstat(summary_path).st_mtime,
    )


@dataclass
class SweepEntry:
    """A sweep folder (``frictionlab.runs.sweep``): its sweep.json, one row per point."""

    path: Path
    name: str
    status: str
    paths: list[str]  # the swept dotted paths
    points: list[dict]  # sweep.json's rows: the swept values and the columns of sweep.csv
    confidence: float | None  # the level of the points' intervals; None where the sweep sets it
    mtime: float
    elapsed: float = 0.0  # seconds, as sweep.json says

    @cached_property
    def failed_for_good(self) -> str:
        """Each point's error, one a line, where every point ended and those failed with every
        realization finished (the others completed), "" otherwise: a resume cannot help them."""
        from ..runs.settled import points_fit_failed

        return "\n".join(points_fit_failed(self.path, self.points)) if self.status == "failed" else ""

    def point_folder(self, row: dict) -> Path:
        """The folder of a point (RunFolderError if sweep.json names one outside the sweep's, or a link)."""
        from ..runs.runfolder import subfolder

        return subfolder(self.path, row["folder"])


def read_sweep(folder: Path) -> SweepEntry:
    """A sweep folder's sweep.json, checked (``sweeprecord.read_sweep_record``); RunFolderError if unreadable."""
    from ..runs.sweeprecord import read_sweep_record

    folder = Path(folder)
    summary, record = read_sweep_record(folder)
    return SweepEntry(
        path=folder,
        name=record.name,
        status=record.status,
        paths=[str(p) for p in record.sweep.parameters],
        points=summary["points"],
        mtime=os.lstat(folder / "sweep.json").st_mtime,
        elapsed=record.elapsed_seconds,
        confidence=_recorded_confidence(record.base_preset, list(record.sweep.parameters)),
    )


def recorded_level(value) -> float | None:
    """A level of intervals (``fit.confidence``) as a run folder's record gives it: a number in
    (0, 1), else None (the records are untrusted)."""
    level = number_or_nan(value)
    return level if 0 < level < 1 else None


def _recorded_confidence(base_preset: dict, paths: list[str]) -> float | None:
    """The level of the intervals of a sweep read from its folder: its base preset's
    ``fit.confidence`` (the default where unsaid), None where the sweep sets it point by point
    or the base preset's is not a level."""
    from ..preset.schema import FitSettings

    fit = base_preset.get("fit", {})
    if "fit.confidence" in paths or not isinstance(fit, dict):
        return None
    return recorded_level(fit.get("confidence", FitSettings().confidence))


def list_runs(runs_dir: Path) -> list[RunEntry | SweepEntry]:
    """Every run folder under ``runs_dir`` (one with a summary.json, a run.json, or a
    sweep's sweep.json), newest first; one whose files cannot be read is listed as
    damaged with the reason, never left out."""
    from ..runs.detached import RUN_MARKERS

    runs_dir = Path(runs_dir)
    if not runs_dir.is_dir():
        return []
    entries = []
    for folder in runs_dir.iterdir():
        if folder.is_symlink() or not any(os.path.lexists(folder / name) for name in RUN_MARKERS):
            continue
        try:
            entry = _entry(folder)
        except (OSError, FrictionlabError) as exc:
            entry = _damaged(folder, exc)
        if entry is not None:
            entries.append(entry)
    return sorted(entries, key=lambda e: (e.status != "running", -e.mtime, e.path.name))


def runs_signature(runs_dir: Path, running: list[Path] = ()) -> tuple:
    """What changes when a run starts, writes its manifest or summary, ends, or is removed
    under ``runs_dir``: the folder's and each run folder's modification time (names and
    times only, nothing read), and whether each of ``running`` is still held by its process
    (a run killed with kill -9 changes no file)."""
    from ..runs.detached import lock_held

    try:
        top = os.stat(runs_dir).st_mtime_ns
        folders = sorted((entry.name, entry.stat(follow_symlinks=False).st_mtime_ns) for entry in os.scandir(runs_dir))
    except OSError:
        return ()
    return top, tuple(folders), tuple(lock_held(folder) for folder in running)


def _entry(folder: Path) -> RunEntry | SweepEntry | None:
    """The folder's run or sweep as it is now (OSError, FrictionlabError if it cannot be read)."""
    from ..runs.detached import SWEEP_FILE, run_state
    from ..runs.rundir import STATE_FILE

    if not os.path.lexists(folder / STATE_FILE) and os.path.lexists(folder / SWEEP_FILE):
        entry = read_sweep(folder)
        return _sweep_with_state(entry) if entry.status == "running" else entry
    if not os.path.lexists(folder / STATE_FILE):  # a summary alone (copied without its run.json)
        return read_run(folder)
    state = run_state(folder)  # run.json: running, or ended (and how); damaged if its summary is
    if state.status == "damaged":
        return _damaged(folder, RunFolderError(state.reason or "damaged"), state.name)
    if state.status == "running" or not os.path.lexists(folder / "summary.json"):
        # a run going on (its summary, if any, is an earlier run's), or one that ended before its summary (killed)
        mtime = os.lstat(folder / STATE_FILE).st_mtime
        return RunEntry(folder, state.name, state.status, state.done or 0, state.total or 0, None, {}, mtime)
    entry = read_run(folder)
    entry.status = state.status
    return entry


def _damaged(folder: Path, error: Exception, name: str = "") -> RunEntry:
    from ..runs.detached import damage_reason

    reason = damage_reason(folder, error) if isinstance(error, FrictionlabError) else (error.strerror or str(error))
    try:
        mtime = folder.lstat().st_mtime
    except OSError:
        mtime = 0.0
    return RunEntry(folder, name or folder.name, "damaged", 0, 0, None, {}, mtime, reason=reason)


def _sweep_with_state(entry: SweepEntry) -> SweepEntry:
    """A sweep that says it is running: interrupted if no live process holds its folder."""
    from ..runs.detached import run_state

    try:
        entry.status = run_state(entry.path).status
    except (OSError, FrictionlabError):
        pass
    return entry
