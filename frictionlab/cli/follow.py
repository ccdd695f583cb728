"""``frictionlab follow DIR``: the progress of the run in DIR (started by ``run --detach``,
the TUI, or anyone) until it ends; Ctrl-C stops following, never the run."""

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
        "until it ends, then its state on stdout. Ctrl-C stops following; the run goes on. The exit code is 0 "
        "if the run completed, 1 if it ended any other way (frictionlab resume DIR continues it).",
        epilog=EXAMPLES,
    )
    p.add_argument("run_dir", metavar="DIR", help="a run folder")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr: only wait for the end")
    p.add_argument("--json", action="store_true", help="print the final state as one JSON object on stdout")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..detached import run_state
    from ..preset import build_scene
    from ..progress import ProgressReporter
    from ..progresslog import Follower
    from ..rundir import RunDirectory

    folder = Path(args.run_dir)
    state = run_state(folder)  # RunFolderError: not a run folder
    error = None
    if state.status == "running":
        scene = build_scene(RunDirectory(folder).stored_preset())
        follower = Follower(folder, scene)
        if not args.quiet:
            follower.listeners.append(ProgressReporter(after=0.0, clock=follower.now))
        try:
            while state.status == "running":  # until its process ends: its files are written then
                if not follower.poll():
                    time.sleep(POLL_SECONDS)
                    state = run_state(folder)
            follower.poll()  # the last events, written as it ended
        except KeyboardInterrupt:
            print(f"stopped following; the run goes on (pid {state.pid})", file=sys.stderr)
            return ExitCode.INTERRUPTED
        if follower.finished is not None:
            error = follower.finished.error
    if args.json:
        from .jsonout import emit

        emit("follow", {**state.to_dict(), "error": error})
    else:
        done = "?" if state.done is None else state.done
        hint = f"; frictionlab resume {folder} continues it" if state.resumable else ""
        print(f"{state.name}: {state.status}, {done}/{state.total} realizations, in {folder}/{hint}")
        if error:
            print(f"error: {error}", file=sys.stderr)
    return ExitCode.OK if state.status == "completed" else ExitCode.RUNTIME_FAILURE
