"""``frictionlab follow DIR``: the progress of the run (or sweep) in DIR (started by
``run --detach``, the TUI, or anyone) until it ends; Ctrl-C stops following, never the run."""

from __future__ import annotations

import sys
import time
from pathlib import Path

from ..errors import ExitCode

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
        "until it ends, then its state on stdout. For a sweep's folder: each point as it starts, its "
        "realizations, and its fit once it ends. Ctrl-C stops following; the run goes on. The exit code is 0 "
        "if the run completed, 1 if it ended any other way (frictionlab resume DIR continues it).",
        epilog=EXAMPLES,
    )
    p.add_argument("run_dir", metavar="DIR", help="a run folder, or a sweep's folder")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr: only wait for the end")
    p.add_argument("--json", action="store_true", help="print the final state as one JSON object on stdout")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..detached import run_state

    folder = Path(args.run_dir)
    state = run_state(folder)  # RunFolderError: not a run folder
    sweep = _stored_sweep(folder) if state.kind == "sweep" else None
    error = None
    if state.status == "running":
        follower = _follower(folder, sweep, args.quiet)
        try:
            try:
                while state.status == "running":  # until its process ends: its files are written then
                    if not follower.poll():
                        time.sleep(POLL_SECONDS)
                        state = run_state(folder)
                follower.poll()  # the last events, written as it ended
            finally:  # a bar still showing ends on its own line, before anything else is printed
                for listener in follower.listeners:
                    listener.close()
        except KeyboardInterrupt:
            print(f"stopped following; the run goes on (pid {state.pid})", file=sys.stderr)
            return ExitCode.INTERRUPTED
        if follower.finished is not None:
            error = follower.finished.error
    if args.json:
        from .jsonout import emit

        extra = {"points": _rows(folder)} if sweep is not None else {}
        emit("follow", {**state.to_dict(), "error": error, **extra})
    else:
        done = "?" if state.done is None else state.done
        hint = f"; frictionlab resume {folder} continues it" if state.resumable else ""
        what = "points" if sweep is not None else "realizations"
        print(f"{state.name}: {state.status}, {done}/{state.total} {what}, in {folder}/{hint}")
        if sweep is not None:
            from ..progress import point_result_line

            for point, row in zip(sweep.points, _rows(folder)):
                print(point_result_line(sweep, point, row))
        if error:
            print(f"error: {error}", file=sys.stderr)
    return ExitCode.OK if state.status == "completed" else ExitCode.RUNTIME_FAILURE


def _stored_sweep(folder: Path):
    from ..sweep import plan_sweep, stored_sweep

    return plan_sweep(stored_sweep(folder), source=str(folder / "sweep.json"))


def _rows(folder: Path) -> list[dict]:
    """Each point's row of the sweep's sweep.json, its values checked."""
    from ..sweep import read_sweep_record

    _, record = read_sweep_record(folder)
    return [point.model_dump() for point in record.points]


def _follower(folder: Path, sweep, quiet: bool):
    """What replays the run's (the sweep's) progress file, printing its progress unless ``quiet``."""
    from ..preset import build_scene
    from ..progress import ProgressReporter, SweepProgress
    from ..progresslog import Follower
    from ..rundir import RunDirectory
    from ..sweeplog import SweepFollower

    if sweep is None:
        follower = Follower(folder, build_scene(RunDirectory(folder).stored_preset()))
        if not quiet:
            follower.listeners.append(ProgressReporter(after=0.0, clock=follower.now))
        return follower
    follower = SweepFollower(folder, sweep)
    if not quiet:
        follower.listeners.append(SweepProgress(after=0.0, clock=follower.now, fits=True))
    return follower
