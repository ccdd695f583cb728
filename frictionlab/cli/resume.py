"""``frictionlab resume DIR``: continue an interrupted run with the preset stored in its folder."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import ExitCode, OutputRefused, PresetError, RunFolderError, command_word, shown_name
from . import run as run_command
from .options import add_executor_options, add_workers_option
from .run import add_detach_option


def add_parser(sub) -> None:
    p = sub.add_parser(
        "resume",
        help="continue an interrupted run in DIR with the preset stored there",
        description="Continue a run that was interrupted, killed or crashed: only the missing realizations are computed.",
        epilog="examples:\n  frictionlab resume runs/quickstart-20250101-120000\n"
        "  frictionlab resume runs/quickstart-20250101-120000 --detach",
    )
    p.add_argument("run_dir", metavar="DIR", help="the output folder of the interrupted run")
    add_workers_option(p)
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    p.add_argument("--no-plot", action="store_true", help="draw no plot.png")
    add_executor_options(p)
    add_detach_option(p)
    p.set_defaults(handler=run)


def refuse_a_part_of_a_run(path: Path, verb: str) -> None:
    """RunFolderError naming the folder to give where ``path`` is a file or folder inside a run's
    or a sweep's folder (its summary.json, chunks/ or points/), not one itself: it was refused
    as 'not a folder' or 'holds no run', without the folder the user meant."""
    from ..runs.detached import SWEEP_FILE
    from ..runs.rundir import PRESET_FILE, STATE_FILE

    holds = lambda folder, *names: any(os.path.lexists(folder / name) for name in names)  # noqa: E731
    if path.name in ("", ".", "..") or (path.is_dir() and holds(path, PRESET_FILE, STATE_FILE, SWEEP_FILE)):
        return
    parent = path.parent
    kind = "run" if holds(parent, PRESET_FILE, STATE_FILE) else "sweep" if holds(parent, SWEEP_FILE) else None
    if kind is not None:
        raise RunFolderError(f"{shown_name(path)} is inside the {kind} folder {shown_name(parent)}, not one itself: give "
                             f"that folder (frictionlab {verb} {command_word(parent)})")  # fmt: skip


def run(args) -> ExitCode:
    from ..io.files import output_path_problem
    from ..runs.rundir import PRESET_FILE, RunDirectory
    from ..runs.runfolder import check_searchable
    from ..runs.sweepfiles import refuse_a_sweep_without_record

    run_dir = Path(args.run_dir)
    check_searchable(run_dir)
    refuse_a_part_of_a_run(run_dir, "resume")
    run_command.refuse_what_no_resume_helps(run_dir)
    if run_dir.is_dir() and (problem := output_path_problem(run_dir)) is not None:  # said as a resume can act on it
        raise OutputRefused(f"{problem}; a resume writes into the folder it continues: copy it where you can write "
                            f"(cp -r {command_word(run_dir)} NEW_FOLDER) and resume the copy")
    args.out, args.resume, args.set, args.seed, args.force = str(run_dir), True, None, None, False
    # a sweep's folder, its sweep.json a folder or a link too: read as one, it says what is wrong with it
    if os.path.lexists(run_dir / "sweep.json") and not os.path.lexists(run_dir / PRESET_FILE):
        from ..preset import build_scene
        from ..runs.sweepfiles import OtherSweep, stored_sweep
        from .options import executor_run_options

        args.preset = args.source = str(run_dir / "sweep.json")
        data, options = stored_sweep(run_dir), executor_run_options(args, resume=True)
        try:
            if args.detach:
                return stored_run(run_dir, lambda: run_command.detach(args, data, build_scene(data), run_dir, options))
            return stored_run(run_dir, lambda: run_command.run_sweep_into(args, data, run_dir, options))
        except OtherSweep:  # the folder checked against the sweep its own sweep.json gives: they differ
            raise RunFolderError(
                f"{shown_name(args.preset)} is damaged: its name, sweep and base preset are not those of one sweep "
                "(a field edited): it cannot be resumed"
            ) from None
    refuse_a_sweep_without_record(run_dir, "resume")
    # a clear error when there is nothing to resume, or it is damaged; a sweep added to a run's preset.yaml
    # was refused as no sweep's folder, to be forced with --force, which resume lacks
    if RunDirectory(run_dir).stored_preset().get("sweep") is not None:
        raise RunFolderError(
            f"cannot resume {shown_name(run_dir)}: its {PRESET_FILE} has a sweep section, but the run there is one "
            "ensemble, not a sweep (the file was edited): remove that section to resume it, or run the sweep into another folder"
        )
    args.preset, args.stored = str(run_dir / PRESET_FILE), True
    return stored_run(run_dir, lambda: run_command.run(args))


def stored_run(run_dir: Path, start, doing: str = "resumed"):
    """``start()``, on the run or sweep stored in ``run_dir``: a preset stored there that is not
    valid (a value edited, a plugin not installed here) refuses the folder (exit code 5), as a
    damaged manifest does, not the command line (2); the problems are named as any preset's."""
    try:
        return start()
    except PresetError as exc:
        refused = RunFolderError(f"{exc}\n{shown_name(run_dir)} cannot be {doing}: the preset stored there is not valid here")
        refused.problems = exc.problems
        raise refused from None
