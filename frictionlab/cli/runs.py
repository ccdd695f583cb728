"""``frictionlab runs [DIR]``: the run folders (and sweep folders) under DIR with their
status: running (with the pid of its process), completed, ended early and resumable, or
damaged (a file of it cannot be read as frictionlab writes it: the reason is said)."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import ExitCode, FrictionlabError, command_word, shown, shown_name

EXAMPLES = """examples:
  frictionlab runs                            the runs under runs/
  frictionlab runs /scratch/me/runs --json    as one JSON object
  frictionlab follow runs/quickstart-20250101-120000   follow a running one
"""


def add_parser(sub) -> None:
    p = sub.add_parser(
        "runs",
        help="list run folders with their status (running, completed, interrupted...)",
        description="The run folders under DIR, running ones first: a run whose process is gone reads as "
        "interrupted (frictionlab resume continues it), never as running. A sweep's folder is one entry, "
        "its points counted in DONE. A folder whose files cannot be read is listed as damaged, with the reason.",
        epilog=EXAMPLES,
    )
    p.add_argument("runs_dir", nargs="?", default=None, metavar="DIR", help="the folder of run folders (default: runs)")
    p.add_argument("--json", action="store_true", help='as one JSON object: {"runs_dir": ..., "runs": [...]}')
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..runs.detached import list_run_states
    from ..runs.rundir import DEFAULT_RUNS_DIR
    from ..runs.runfolder import check_searchable

    runs_dir = Path(args.runs_dir) if args.runs_dir is not None else DEFAULT_RUNS_DIR
    check_searchable(runs_dir)  # a folder that cannot be looked into: said so (exit 5), never "Permission denied"
    if args.runs_dir is not None and not runs_dir.is_dir():
        what = "is not a folder" if runs_dir.exists() else "does not exist"
        # a bad argument (exit 2, as exact3d's --runs), not a run folder that cannot be used (5)
        raise FrictionlabError(f"DIR: {shown_name(runs_dir)} {what}: give the folder that holds run folders")
    states = list_run_states(runs_dir)
    if args.json:
        from .jsonout import emit

        emit("runs", {"runs_dir": str(runs_dir), "runs": [s.to_dict() for s in states]})
        return ExitCode.OK
    if not states:
        print(f"no run folders in {shown(runs_dir).rstrip('/')}/{_what_it_is(runs_dir)}")  # "/", not "//"
        return ExitCode.OK
    from .console import print_table

    rows = []
    for state in states:
        done = "not yet known" if state.done is None else str(state.done)  # a running run before its first count
        total = "unknown" if state.total is None else str(state.total)
        status = f"running (pid {state.pid})" if state.pid else state.status
        unit = " points" if state.kind == "sweep" else ""
        count = "-" if state.status == "damaged" else f"{done}/{total}{unit}"  # the reason follows the table
        rows.append((str(state.folder), state.name, status, count))
    print_table(["FOLDER", "NAME", "STATUS", "DONE"], rows)
    for state in states:
        if state.reason:
            print(f"{shown(state.folder)} is damaged: {shown(state.reason)}")
    return ExitCode.OK


def _what_it_is(folder: Path) -> str:
    """A hint when DIR is itself a run's or a sweep's folder, not the folder that holds them."""
    from ..runs.detached import RUN_MARKERS, is_sweep_folder

    if not any(os.path.lexists(folder / name) for name in RUN_MARKERS):
        return ""
    if is_sweep_folder(folder):
        return (f": it is a sweep's folder (frictionlab follow {command_word(folder)} shows it); "
                f"its points' run folders: frictionlab runs {command_word(folder / 'points')}")
    return (f": it is a run folder itself (frictionlab follow {command_word(folder)} shows it); "
            f"the runs beside it: frictionlab runs {command_word(folder.parent)}")
