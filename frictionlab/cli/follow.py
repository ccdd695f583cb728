"""``frictionlab follow DIR``: the progress of the run (or sweep) in DIR (started by
``run --detach``, the TUI, or anyone) until it ends; Ctrl-C stops following, never the run."""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

from ..errors import ExitCode, command_word, shown, shown_name
from ..compute.signals import ENDINGS, SignalsNoted

POLL_SECONDS = 0.2
EXAMPLES = """examples:
  frictionlab run quickstart --detach         start a run that outlives the terminal
  frictionlab follow runs/quickstart-20250101-120000
  frictionlab follow runs/quickstart-20250101-120000 --json   its final state as JSON
"""


def add_parser(sub) -> None:
    p = sub.add_parser(
        "follow",
        help="show the progress of a run going on in DIR until it ends",
        description="Follow the run in DIR by reading what it writes there (progress.jsonl): progress on stderr "
        "until it ends, then its state on stdout. A run started without --detach outside the TUI writes no "
        "progress.jsonl: the count of realizations its chunks hold is shown instead. For a sweep's folder: each point as it starts, its "
        "realizations, and its fit once it ends. Ctrl-C stops following; the run goes on. The exit code is 0 "
        "if the run completed, 1 if it ended any other way (frictionlab resume DIR continues it) or its folder was "
        "deleted while it ran, 5 if DIR is no run folder or cannot be read (a damaged or unreadable run.json, a link "
        "in its place), 130 if following was stopped with Ctrl-C (143: SIGTERM, 129: SIGHUP).",
        epilog=EXAMPLES,
    )
    p.add_argument("run_dir", metavar="DIR", help="a run folder, or a sweep's folder")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr: only wait for the end")
    p.add_argument("--json", action="store_true", help="print the final state as one JSON object on stdout")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..runs.detached import logged_error, logged_warnings, process_alive, run_state
    from ..runs.runfolder import check_searchable
    from .resume import refuse_a_part_of_a_run

    folder = Path(args.run_dir)
    check_searchable(folder)  # before the first look at it: a folder whose parent cannot be searched too
    if folder.is_symlink() and folder.is_dir():  # the folder named may be a link, as for resume: it is the user's
        from ..io.files import real_path

        folder = real_path(folder)
    refuse_a_part_of_a_run(folder, "follow")
    if folder.is_dir():  # else run_state says what it is
        from ..runs.sweepfiles import refuse_a_sweep_without_record

        refuse_a_sweep_without_record(folder, "follow")
    state = run_state(folder)  # RunFolderError: not a run folder
    sweep = _stored_sweep(folder) if state.kind == "sweep" else None
    error, gone, identity, holder = None, False, _identity(folder), state.pid
    if state.status == "running":
        follower = _follower(folder, sweep, args.quiet)
        counter = None if args.quiet else _ChunkCount(follower.reader, folder, sweep)
        stopped = SignalsNoted()  # acted on between polls: raised mid-draw, it left the bar's lock held for ever
        try:
            try:
                with stopped:
                    while state.status == "running" and stopped.signal is None:  # until its process ends
                        polled = follower.poll()
                        _say_warnings(follower.warnings.take())
                        if not polled:
                            stopped.wait(POLL_SECONDS)
                            now = _state_unless_gone(folder, identity)
                            if now is None:  # deleted (or replaced) under the run
                                gone = True
                                break
                            state = now
                            if counter is not None:
                                counter.tell(state)
                    if stopped.signal is None:
                        follower.poll()  # the last events, written as it ended
                        _say_warnings(follower.warnings.take())
            finally:  # a bar still showing ends on its own line, before anything else is printed
                for listener in follower.listeners:
                    listener.close()
                if counter is not None:
                    counter.close()
            if stopped.signal is not None:
                raise KeyboardInterrupt
        except KeyboardInterrupt:
            print(f"stopped following; the run goes on{f' (pid {state.pid})' if state.pid else ''}", file=sys.stderr)
            return ENDINGS[stopped.signal][0]
        if follower.finished is not None:
            error = follower.finished.error
    else:  # ended before: why, as a run's summary.json says (it was said only to a follower), or its log (a full disk)
        _say_warnings(logged_warnings(folder))  # said only to a follower too: its stderr was no one's
        error = _ended_error(folder) if sweep is None else None
        if error is None and state.status != "completed":
            error = logged_error(folder)
    if gone:  # what is true: the folder it followed is no more; nothing there to resume
        message = f"{shown(folder)} was deleted or replaced while its run was going: nothing of that run is left to resume"
        if holder and process_alive(holder):  # it goes on, and its next write makes the folder anew
            message += (f"; its process (pid {holder}) still runs and may write a new {shown_name(folder)}/ as it goes "
                        f"on (kill -TERM {holder} stops it)")  # fmt: skip
        if args.json:
            from .jsonout import emit

            emit("follow", {**state.to_dict(), "status": "deleted", "pid": holder, "error": message})
        print(f"error: {message}", file=sys.stderr)
        return ExitCode.RUNTIME_FAILURE
    rows = _rows(folder) if sweep is not None else []
    if args.json:
        from .jsonout import emit

        extra = {"points": rows} if sweep is not None else {}
        emit("follow", {**state.to_dict(), "error": error, **extra})
    else:
        if state.reason is not None:  # damaged: what is known, not a count with a question mark
            print(shown(f"{state.name}: damaged, in {shown_name(folder)}/: {state.reason}"))
            return ExitCode.RUNTIME_FAILURE
        done = state.done
        from ..runs.settled import why_no_resume_helps

        mendable = state.resumable and not why_no_resume_helps(folder)[0]  # not a fit failed with every realization done
        hint = f"; frictionlab resume {command_word(folder)} continues it" if mendable else ""
        if any(row.get("status") == "error" for row in rows):  # a resume fails there again until it is fixed
            hint = f"; do what the points in error say, then frictionlab resume {command_word(folder)} continues it"
        what = "points" if sweep is not None else "realizations"
        print(shown(f"{state.name}: {state.status}, {done}/{state.total} {what}, in {shown_name(folder)}/{hint}"))
        if sweep is not None:
            from ..progress import point_result_line

            for point, row in zip(sweep.points, rows):
                print(point_result_line(sweep, point, row))
        if error:
            print(f"error: {shown(error)}", file=sys.stderr)
    return ExitCode.OK if state.status == "completed" else ExitCode.RUNTIME_FAILURE


def _ended_error(folder: Path) -> str | None:
    """The error of the run that ended in ``folder`` (a fit refused, every realization failed), as
    its summary.json says; None where it says none or has none (an interrupted run)."""
    from ..errors import RunFolderError
    from ..runs.results import read_summary

    try:
        data, _ = read_summary(folder)
    except (RunFolderError, OSError):  # none, or one the state already names damaged
        return None
    error = data.get("error")
    return error if isinstance(error, str) and error else None


def _state_unless_gone(folder: Path, identity):
    """The state of the run in ``folder`` now; None if ``folder`` is no longer the folder of ``identity``."""
    from ..runs.detached import run_state
    from ..errors import RunFolderError

    try:
        state = run_state(folder)
    except RunFolderError:
        if _identity(folder) != identity:
            return None
        raise
    return state if _identity(folder) == identity else None


def _identity(folder: Path) -> tuple[int, int] | None:
    """Which folder ``folder`` is (its device and inode), None once it is gone."""
    try:
        info = os.stat(folder)
    except OSError:
        return None
    return info.st_dev, info.st_ino


def _say_warnings(messages: list[str]) -> None:
    """The warnings the run's process wrote to its log (its stderr is no one's), as a run in
    the foreground shows them."""
    for message in messages:
        print(f"warning: {shown(message)}", file=sys.stderr, flush=True)


def _stored_sweep(folder: Path):
    from ..runs.sweep import plan_sweep
    from ..runs.sweepfiles import stored_sweep
    from .resume import stored_run

    return stored_run(folder, lambda: plan_sweep(stored_sweep(folder), source=str(folder / "sweep.json")), "followed")


def _rows(folder: Path) -> list[dict]:
    """Each point's row of the sweep's sweep.json, its values checked."""
    from ..runs.sweeprecord import read_sweep_record

    _, record = read_sweep_record(folder)
    return [point.model_dump() for point in record.points]


class _ChunkCount:
    """The count of a run (a sweep) that writes no progress file (``frictionlab run`` in a
    terminal), read from its chunks (its points done, and the chunks of the one going on): why,
    said once, then the count as it moves, on one line of a terminal (a line at most every
    LOG_SECONDS elsewhere)."""

    LOG_SECONDS = 30.0

    def __init__(self, reader, folder: Path, sweep=None):
        from ..runs.progresslog import NoProgressFile

        self.missing = NoProgressFile(reader)
        self.folder, self.sweep = folder, sweep
        self.said = False
        self.shown: tuple | None = None
        self.at = -math.inf
        self.terminal = sys.stderr.isatty()

    def tell(self, state) -> None:
        if (why := self.missing.reason()) is None:
            return
        if not self.said:
            self.said = True
            print(f"{why}: its count comes from its chunks", file=sys.stderr)
        count = (state.done, state.total, *self._point_count(state))
        now = time.monotonic()
        if count == self.shown or state.done is None or (not self.terminal and now - self.at < self.LOG_SECONDS):
            return
        self.shown, self.at = count, now
        if self.sweep is None:
            line = shown(f"{state.name}: {state.done}/{state.total} realizations stored")
        else:
            point = f"; point {count[2]}: {count[3]}/{count[4]} realizations stored" if count[2] else ""
            line = shown(f"{state.name}: {state.done}/{state.total} points done{point}")
        print(f"\r{line}\x1b[K" if self.terminal else line, end="" if self.terminal else "\n", file=sys.stderr, flush=True)

    def _point_count(self, state) -> tuple:
        """A sweep's point going on (the first not done): (its number, its stored realizations, its
        total); () of a run, or of a sweep with none going on."""
        from ..errors import FrictionlabError
        from ..runs.detached import stored_count
        from ..runs.sweep import UNFINISHED, point_folder
        from ..runs.sweeprecord import read_sweep_record

        if self.sweep is None:
            return ()
        try:
            done = {row.point for row in read_sweep_record(self.folder)[1].points if row.status not in UNFINISHED}
            point = next((point for point in self.sweep.points if point.number not in done), None)
            stored, total = (None, None) if point is None else stored_count(point_folder(self.folder, point))
        except (OSError, FrictionlabError):  # a point not begun: nothing stored
            return ()
        return () if point is None else (point.number, stored or 0, total or point.scene.preset.realizations)

    def close(self) -> None:
        if self.terminal and self.shown is not None:
            print(file=sys.stderr)  # what follows on a line of its own


def _follower(folder: Path, sweep, quiet: bool):
    """What replays the run's (the sweep's) progress file, printing its progress unless ``quiet``."""
    from ..preset import build_scene
    from ..progress import ProgressReporter, SweepProgress
    from ..runs.progresslog import Follower
    from ..runs.rundir import RunDirectory
    from ..runs.sweeplog import SweepFollower

    if sweep is None:
        follower = Follower(folder, build_scene(RunDirectory(folder).stored_preset()))
        if not quiet:
            follower.listeners.append(ProgressReporter(after=0.0, clock=follower.now))
        return follower
    follower = SweepFollower(folder, sweep)
    if not quiet:
        follower.listeners.append(SweepProgress(after=0.0, clock=follower.now, fits=True))
    return follower
