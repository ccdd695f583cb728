"""Runs that do not depend on the terminal that started them, and the state of a run folder.

``start_detached`` starts a run (or a sweep: one run per point) as its own process in
its own session (a closed terminal's SIGHUP does not reach it; its stdin, stdout and
stderr are not the terminal): it holds the folder's lock (``run.lock`` names its pid)
and writes its events to ``progress.jsonl`` (``progresslog``; a sweep's, ``sweeplog``),
which any front end can follow. Cancelling it is SIGTERM to that pid: what finished is
kept, the run ends "interrupted" and can be resumed.

``run_state`` tells what a folder holds: a run or a sweep going on, or one that ended
and how. A manifest (a sweep's sweep.json) that still says "running" while no live
process holds the lock was left by one that died: it reads as interrupted, never as running.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass
from pathlib import Path

from . import runfolder
from ..errors import ExitCode, FrictionlabError, RunFolderError, command_word, short_repr, shown, shown_name, warn_user
from ..options import RunOptions
from ..io.files import refuse_unusable_folder
from .figures import cut
from .progressevents import MAX_COUNT
from .progresslog import ProgressLog, ProgressReader, StartOf, progress_file_problem, told_by
from .results import read_summary
from .rundir import LOCK_FILE, STATE_FILE, RunDirectory

LISTED_NAME_CHARS = 100
"""A listed run's name is cut there: a preset's name is at most that long, a damaged folder's any length."""

SWEEP_FILE = "sweep.json"  # what marks a sweep's folder (it has no run.json)
RUN_MARKERS = (STATE_FILE, "summary.json", SWEEP_FILE)  # a folder holding one is a run's (or was meant to be)
TAIL_BYTES = 256 * 1024  # of progress.jsonl, read for the count of a listed run
STARTED_WAIT = 120.0  # seconds ``wait_started`` waits for the run's first event
STARTED = ("started", "sweep_started")  # the first event of a run, of a sweep


# ------------------------------------------------------------------ starting


def check_startable(scene, out_dir: str | Path, options: RunOptions) -> None:
    """Refuse, before a process is started, what the run would refuse as it begins: a
    folder in use or not its own (a fresh run), a run that does not fit in memory."""
    from .runner import check_memory

    _check_not_in_use(out_dir)
    _check_followable_folder(out_dir)
    if not options.resume:
        RunDirectory(out_dir, force=options.force).check_fresh(scene)
    if options.memory_check:
        check_memory(scene, options)


def _check_not_in_use(out_dir: str | Path) -> None:
    if lock_held(out_dir):
        raise in_use(out_dir)


def _check_followable_folder(out_dir: str | Path) -> None:
    """A folder that cannot be one (a file, a path under a file) is refused as the run would
    refuse it, before its progress file is looked for (that was 'Not a directory: afile/progress.jsonl',
    exit 1); a detached run is followed through its progress file: one it would not write is refused."""
    refuse_unusable_folder(out_dir)
    if (problem := progress_file_problem(out_dir)) is not None:  # its run would go on unseen, said to end at once
        raise RunFolderError(f"{problem}; remove it, then run again (a detached run is followed through it)")


def in_use(out_dir: str | Path, holder: int | None = None) -> RunFolderError:
    """The refusal of a folder another run holds, naming its verified process."""
    holder = holder or lock_holder(out_dir)
    who = f"pid {holder}" if holder is not None else "a process that cannot be verified"
    return RunFolderError(f"{shown(out_dir)} is in use by another run ({who}): "
                          "wait for it to end (frictionlab follow shows it), or give another output folder")  # fmt: skip


def check_sweep_startable(sweep, out_dir: str | Path, options: RunOptions) -> None:
    """``check_startable`` for a sweep (``sweep.Sweep``): its folder, and each point's memory."""
    from .sweep import check_sweep_memory
    from .sweepfiles import check_sweep_folder

    _check_not_in_use(out_dir)
    _check_followable_folder(out_dir)
    check_sweep_folder(sweep, Path(out_dir), options.force, options.resume)
    check_sweep_memory(sweep, options)


def start_detached(resolved: dict, out_dir: str | Path, options: RunOptions = RunOptions(), *,
                   plot: bool = True, source: str | None = None) -> subprocess.Popen:  # fmt: skip
    """Start the run of the preset ``resolved`` (``Scene.resolved()``; for a sweep, the
    preset data with its ``sweep`` section, as ``sweep.plan_sweep`` takes it) into ``out_dir``
    as its own process in a new session, and return at once. The preset and the options
    go through a pipe, read before the run begins: the terminal is none of its files."""
    _check_followable_folder(out_dir)  # checked again: a caller may start it unchecked
    request = {"preset": resolved, "out": str(Path(out_dir).absolute()), "options": asdict(options), "plot": plot,
               "source": source}  # fmt: skip
    process = subprocess.Popen(
        [sys.executable, "-m", "frictionlab.runs.detached"],
        stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        start_new_session=True, close_fds=True,
    )  # fmt: skip
    process.stdin.write(json.dumps(request, default=str).encode())  # a sweep's data as sweep.json stores it
    process.stdin.close()
    return process


def wait_started(process: subprocess.Popen, out_dir: str | Path, timeout: float = STARTED_WAIT) -> None:
    """Return once the detached run has begun (its ``started`` event is written); raise
    FrictionlabError with the run's own message (and exit code) if it could not begin."""
    reader = ProgressReader(out_dir)
    ours = StartOf(process.pid, *STARTED)  # a resume's folder holds the file of the run it continues
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for event in ours.after(reader.new_events(), reader.restarted):
            if event["event"] in STARTED:
                return
            if event["event"] == "error":
                _raise_run_error(event)
        if process.poll() is not None:
            for event in ours.after(reader.new_events(), reader.restarted):
                if event["event"] == "error":
                    _raise_run_error(event)
            if any(event["event"] in STARTED and event.get("pid") == process.pid
                   for event in ProgressReader(out_dir).new_events()):  # fmt: skip
                return  # a run so short it ended already
            holder = lock_holder(out_dir)
            if holder is not None and holder != process.pid:  # it lost the folder to another (its word may be lost)
                raise in_use(out_dir, holder)
            raise FrictionlabError(f"the run into {shown_name(out_dir)} ended at once (exit code {process.returncode}) without a word")
        time.sleep(0.05)
    raise FrictionlabError(f"the run into {shown_name(out_dir)} has not started after {timeout:g} s (pid {process.pid}); "
                           f"`frictionlab follow {command_word(out_dir)}` shows it if it does")  # fmt: skip


def _raise_run_error(event: dict) -> None:
    error = FrictionlabError(str(event.get("message")))
    code = event.get("exit_code")
    error.exit_code = ExitCode(code) if code in ExitCode._value2member_map_ else ExitCode.RUNTIME_FAILURE
    raise error


def cancel(folder: str | Path) -> int:
    """Ask the run (or sweep) going on in ``folder`` to stop (SIGTERM): what finished is kept,
    the run ends interrupted. Only the process that holds the folder's lock is signalled, as
    the kernel says (``runfolder.signal_holder``); return its pid. RunFolderError if none can be."""
    return runfolder.signal_holder(Path(folder) / LOCK_FILE, signal.SIGTERM, folder)


def _child() -> int:
    """The detached process: read the request from stdin, run it, tell the folder how it went."""
    from ..compute.heap import keep_freed_memory
    from ..compute.signals import RaiseOnSignals
    from .sweeplog import SweepProgressLog

    keep_freed_memory()  # a process of frictionlab's own, as the command's is
    if hasattr(signal, "SIGHUP"):
        signal.signal(signal.SIGHUP, signal.SIG_IGN)  # no terminal of its own; a stray hangup is not a cancel
    request = json.loads(sys.stdin.read())
    out = Path(request["out"])
    is_sweep = bool(request["preset"].get("sweep"))
    log = SweepProgressLog(out) if is_sweep else ProgressLog(out)
    try:
        with RaiseOnSignals(), _warnings_to(log):
            options = RunOptions(**request["options"])
            run = _run_sweep if is_sweep else _run_one
            status = run(request, out, options, log)
    except FrictionlabError as exc:
        log.error(str(exc), exc.exit_code)
        return exc.exit_code
    except KeyboardInterrupt:  # SIGTERM before the run began, or a second one during it
        log.error("the run was stopped (SIGTERM) before it could write its results", ExitCode.TERMINATED)
        return ExitCode.TERMINATED
    except OSError as exc:
        log.error(f"cannot write results to {shown_name(exc.filename or out)}: {exc.strerror or exc}", ExitCode.RUNTIME_FAILURE)
        return ExitCode.RUNTIME_FAILURE
    except Exception as exc:  # a bug: said where a follower looks, since stderr is nobody's
        log.error(f"internal error ({type(exc).__name__}: {exc}); please report it", ExitCode.INTERNAL)
        return ExitCode.INTERNAL
    finally:
        log.close()
    if status in ("interrupted", "cancelled"):
        return ExitCode.TERMINATED
    return ExitCode.OK if status == "completed" else ExitCode.RUNTIME_FAILURE


@contextmanager
def _warnings_to(log) -> Iterator[None]:
    """Warnings go to the run's progress log, where a follower (the TUI, ``follow``) shows
    them: this process's stderr is no one's."""
    with warnings.catch_warnings():
        warnings.showwarning = lambda message, category, *where, **keys: log.warning(str(message))
        yield


def _run_one(request: dict, out: Path, options: RunOptions, log: ProgressLog) -> str:
    """One ensemble; its status ("failed" when some realization failed)."""
    from ..preset import build_scene
    from .runner import run_to_folder
    from .sweep import refresh_point_tables

    scene = build_scene(request["preset"])
    outcome, _ = run_to_folder(scene, out, options, listeners=[log], plot=bool(request.get("plot", True)))
    if options.resume and (refreshed := refresh_point_tables(out, bool(request.get("plot", True)))) and not refreshed[0]:
        warn_user(refreshed[1])  # a sweep's point resumed alone: its sweep's tables not updated, and why
    return "failed" if outcome.status == "completed" and outcome.failures else outcome.status


def _run_sweep(request: dict, out: Path, options: RunOptions, log) -> str:
    """One ensemble per point (a point with failures makes the sweep "failed"); its status."""
    from .sweep import plan_sweep, run_sweep

    sweep = plan_sweep(request["preset"], source=request.get("source"))
    return run_sweep(sweep, out, options, listeners=[log], plot=bool(request.get("plot", True))).status


# ------------------------------------------------------------------ the state of a folder


def lock_holder(folder: str | Path) -> int | None:
    """The process that holds the folder's lock now, verified with the kernel
    (``runfolder.lock_holder``), never read from a file; None if none can be."""
    return runfolder.lock_holder(Path(folder) / LOCK_FILE)


def process_alive(pid: int) -> bool:
    """Whether ``pid`` is a live process (a zombie, dead but not yet reaped, is not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # another user's process: alive
    except OverflowError:
        return False
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            return fh.read().rsplit(b")", 1)[-1].split()[0] != b"Z"
    except (OSError, IndexError):
        return True  # no /proc (macOS): kill said it is there


def lock_held(folder: str | Path) -> bool:
    """Whether some process holds the folder's run lock now (a flock is released by the
    kernel when its holder dies, even on kill -9). Where it cannot be probed, True."""
    return runfolder.lock_held(Path(folder) / LOCK_FILE)


RESUMABLE = ("cancelled", "interrupted", "failed")  # how a run ended that resume goes on from


@dataclass
class RunState:
    """What a run folder holds now. ``status``: running, completed, cancelled,
    interrupted, failed, or damaged (``reason`` says what is wrong: a file that cannot
    be read as frictionlab writes it); ``pid`` the live run's process (running only).
    ``kind``: "run", or "sweep" (a sweep's folder: ``done`` and ``total`` count its points)."""

    folder: Path
    name: str
    status: str
    done: int | None  # realizations (a sweep's points) finished, None where nothing says
    total: int | None
    pid: int | None = None
    kind: str = "run"
    reason: str | None = None  # why a damaged folder is (None otherwise)

    @property
    def resumable(self) -> bool:
        return self.status in RESUMABLE

    def to_dict(self) -> dict:
        return {"folder": str(self.folder), "kind": self.kind, "name": self.name, "status": self.status,
                "done": self.done, "total": self.total, "pid": self.pid, "reason": self.reason}  # fmt: skip


def _count(value) -> int | None:
    """A count read from a file: a whole number from 0 to ``MAX_COUNT``, else None (shown as ``?``)."""
    return value if isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= MAX_COUNT else None


def is_sweep_folder(folder: Path) -> bool:
    """Whether ``folder`` holds a sweep (its sweep.json, and no run.json of its own)."""
    return os.path.lexists(folder / SWEEP_FILE) and not os.path.lexists(folder / STATE_FILE)


def run_state(folder: str | Path) -> RunState:
    """The state of the run (or sweep) in ``folder``; RunFolderError if it holds none (or a damaged one)."""
    folder = Path(folder)
    if folder.is_symlink() or not folder.is_dir():
        raise RunFolderError(f"{shown_name(folder)} is not a run folder (not a folder, or a link to one)")
    runfolder.check_searchable(folder)
    if is_sweep_folder(folder):
        return sweep_state(folder)
    manifest = RunDirectory(folder).state()  # read as untrusted input
    if manifest is None:
        raise RunFolderError(f"{shown_name(folder)} holds no run (no {STATE_FILE})")
    preset = manifest.get("preset") if isinstance(manifest.get("preset"), dict) else {}
    name = cut(str(preset.get("name") or folder.name), LISTED_NAME_CHARS)
    status = str(manifest.get("status") or "?")
    total = _count(manifest.get("realizations"))
    if total is None:  # the count the run was started with is its preset's too
        total = _count(preset.get("realizations"))
    pid = None

    def stored() -> int | None:  # what a resume restores; it opens every chunk, so only where asked
        return _chunk_count(folder, manifest.get("chunks"), total)

    if status == "running":
        if lock_held(folder):
            pid = lock_holder(folder)  # None where it cannot be verified: never a pid a file names
        else:  # gone, or it ended between the two looks: its manifest, read again, says which
            manifest = RunDirectory(folder).state() or manifest
            status = str(manifest.get("status") or "?")
            status = "interrupted" if status == "running" else status  # the process that wrote "running" is gone
    if status == "running":  # its log's last count (none to read, a link never followed: what it stored)
        done = _last_count(folder)
        return RunState(folder, name, status, stored() if done is None else done, total, pid)

    def ended_count() -> int | None:  # what its chunks hold (its log also counted what was never stored)
        count = stored()
        return count if count is not None else _last_count(folder)

    try:
        summary = _summary(folder)
    except RunFolderError as exc:  # never listed as what run.json says: its results cannot be read
        return RunState(folder, name, "damaged", ended_count(), total, reason=damage_reason(folder, exc))
    counts = summary.get("realizations") if summary is not None and isinstance(summary.get("realizations"), dict) else {}
    done = _count(counts.get("done"))
    if done is None:  # no summary, or none that counts: the chunks say
        done = ended_count()
    if (reason := _uncounted(manifest, preset, done, total)) is not None:
        return RunState(folder, name, "damaged", None if reason.startswith("its chunks") else done, total, reason=reason)
    return RunState(folder, name, status, done, total, pid)


def _uncounted(manifest: dict, preset: dict, done: int | None, total: int | None) -> str | None:
    """Why an ended run's count of realizations cannot be told (None where it can): said, never shown as ``?``."""
    if total is None:
        told = (short_repr(manifest.get("realizations")), short_repr(preset.get("realizations")))
        return f"{STATE_FILE} does not say how many realizations the run has (its realizations is {told[0]}, its preset's {told[1]})"
    if done is None:
        return f"{STATE_FILE} does not list its chunks: what finished cannot be counted"
    if done > total:
        return f"its chunks hold {done} realizations, more than the {total} of its {STATE_FILE}: not this run's"
    return None


def damage_reason(folder: Path, error: Exception) -> str:
    """What is wrong with ``folder``, as ``error`` says it, without the folder's path in front."""
    text, prefix = str(error), shown(str(folder))
    for start in (prefix + os.sep, prefix + ": ", prefix + " "):
        if text.startswith(start):
            text = text[len(start):]
            break
    name, colon, rest = text.partition(": ")
    return rest if colon and rest.startswith(name + " ") else text  # "sweep.json: sweep.json is ..." said once


def stored_count(folder: str | Path) -> tuple[int | None, int | None]:
    """(stored, total): the realizations the run folder's chunks hold, as its manifest lists
    them (what a resume restores, before it reads them), and the run's total; None where
    the manifest does not say."""
    manifest = RunDirectory(Path(folder)).state()
    if not isinstance(manifest, dict):
        return None, None
    total = _count(manifest.get("realizations"))
    return _chunk_count(Path(folder), manifest.get("chunks"), total), total


def _chunk_count(folder: Path, chunks, total: int | None) -> int | None:
    """Realizations the manifest's chunks hold, each chunk's read from its index arrays
    (``chunks.chunk_indices``); an index past the run's total is none of this run's."""
    from .chunks import chunk_indices

    if not isinstance(chunks, dict):
        return None
    indices = set()
    for name in chunks:
        indices.update(i for i in chunk_indices(folder, name) if total is None or i < total)
    return len(indices)


def sweep_state(folder: str | Path) -> RunState:
    """The state of the sweep in ``folder`` (its sweep.json, checked); RunFolderError if it holds none."""
    from .sweep import UNFINISHED
    from .sweeprecord import read_sweep_record

    folder = Path(folder)
    _, record = read_sweep_record(folder)
    status, pid = record.status, None
    if status == "running":
        if lock_held(folder):
            pid = lock_holder(folder)  # None where it cannot be verified: never a pid a file names
        else:  # gone, or it ended between the two looks: its sweep.json, read again, says which
            _, record = read_sweep_record(folder)
            status = "interrupted" if record.status == "running" else record.status
    done = sum(point.status not in UNFINISHED for point in record.points)
    return RunState(folder, cut(record.name, LISTED_NAME_CHARS), status, done, len(record.points), pid, kind="sweep")


def _summary(folder: Path) -> dict | None:
    """summary.json, None if there is none; RunFolderError if it is damaged (a link, not JSON,
    a value its schema refuses: what ``frictionlab.load`` refuses is never listed as completed)."""
    if not os.path.lexists(folder / "summary.json"):
        return None
    try:
        return read_summary(folder)[0]
    except OSError as exc:
        raise RunFolderError(f"{shown(folder / 'summary.json')} cannot be read ({exc.strerror or exc})") from None


def _tail_events(folder: Path):
    """The events of the progress log's last ``TAIL_BYTES`` (a cut first line is skipped);
    none if the log cannot be read."""
    reader = ProgressReader(folder)
    try:
        reader.offset = max(0, os.lstat(reader.path).st_size - TAIL_BYTES)
    except OSError:
        return
    while events := reader.new_events():
        yield from events


def _last_count(folder: Path) -> int | None:
    """Realizations finished as the progress log's last counting event says (read from its tail)."""
    done = None
    for event in _tail_events(folder):
        if event["event"] == "started":  # none finished yet but those restored
            done = _count(event.get("resumed")) or 0
        elif event["event"] in ("realization", "realizations", "finished"):
            done = _count(event.get("done"))
    return done


def logged_error(folder: Path) -> str | None:
    """The error the run in ``folder`` logged as its last word (a full disk), read from the
    progress log's tail; None if its last event is another."""
    last = None
    for last in _tail_events(folder):  # noqa: B007 - the last one is what is said
        pass
    return str(last.get("message")) if last is not None and last["event"] == "error" else None


def logged_warnings(folder: Path) -> list[str]:
    """The warnings the last run in ``folder`` wrote to its progress log (read from its tail):
    those of the process whose ``started`` event is the last, not of a second run refused the folder."""
    warnings, pid = [], None
    for event in _tail_events(folder):
        if event["event"] == "started":
            warnings, pid = [], event.get("pid")
        elif event["event"] == "warning" and told_by(event, pid):
            warnings.append(str(event.get("message")))
    return warnings


def list_run_states(runs_dir: str | Path) -> list[RunState]:
    """The state of every run folder directly under ``runs_dir`` (one holding a
    ``run.json``, a ``summary.json``, or a sweep's ``sweep.json``), running ones first,
    then the newest; links are not followed. A folder whose files cannot be read is
    listed as damaged, with the reason, never left out."""
    runs_dir = Path(runs_dir)
    if not runs_dir.is_dir():
        return []
    states = []
    for folder in runs_dir.iterdir():
        try:
            mtime = folder.lstat().st_mtime
        except OSError:
            continue  # gone since it was listed
        if folder.is_symlink():
            continue
        try:
            runfolder.check_searchable(folder)  # one that cannot be looked into is listed, never left out
            if not any(os.path.lexists(folder / name) for name in RUN_MARKERS):
                continue
            states.append((mtime, run_state(folder)))
        except (OSError, FrictionlabError) as exc:
            kind = "sweep" if is_sweep_folder(folder) else "run"
            reason = damage_reason(folder, exc) if isinstance(exc, FrictionlabError) else (exc.strerror or str(exc))
            states.append((mtime, RunState(folder, folder.name, "damaged", None, None, kind=kind, reason=reason)))
    states.sort(key=lambda item: (item[1].status != "running", -item[0], item[1].folder.name))
    return [state for _, state in states]


if __name__ == "__main__":
    sys.exit(int(_child()))
