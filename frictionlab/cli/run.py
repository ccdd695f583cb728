"""``frictionlab run PRESET``: one ensemble (or one per point of a sweep) into a
run folder; a short table (or the summary as JSON) on stdout, progress on stderr."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

from ..errors import (MEMORY_ADVICE, ExitCode, FrictionlabError, OutputRefused, RunFolderError, command_word, counted,
                      ran_out_of_memory, refuse_unusable_matplotlib, resume_hint, shown, shown_name, too_long_path,
                      write_failed)  # fmt: skip
from .options import (
    add_executor_options,
    add_workers_option,
    executor_run_options,
    preset_overrides,
    refuse_swept_overrides,
)


def add_parser(sub) -> None:
    p = sub.add_parser(
        "run",
        help="run a preset headless and write its results",
        description="Run a preset (a file, or a built-in's name) and write its run folder: summary.json, "
        "curve.csv, realizations.npz, preset.yaml, then plot.png after the fit is printed.",
        epilog="examples:\n  frictionlab run quickstart\n  frictionlab run quickstart --set spectrum.params.hurst=0.6 --out runs/h06\n"
        "  frictionlab run presets/benad2012-fig2.yaml --no-plot --json\n"
        "  frictionlab run quickstart --detach      runs on after the terminal closes (frictionlab follow DIR);\n"
        "                                           a preset with a sweep too",
    )
    p.add_argument("preset", help="preset YAML file, or a built-in preset's name (frictionlab presets)")
    p.add_argument("--out", metavar="DIR", help="output folder (default: runs/<name>-<timestamp>)")
    p.add_argument(
        "--set", action="append", metavar="PATH=VALUE", help="override a preset value, e.g. spectrum.params.hurst=0.8"
    )
    add_workers_option(p)
    p.add_argument("--seed", type=int, metavar="S", help="root seed (overrides the preset's)")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    p.add_argument(
        "--no-plot", action="store_true", help="draw no plot.png (sweep.png): the fastest run; the numbers are the same"
    )
    add_executor_options(p)
    p.add_argument("--resume", action="store_true", help="continue the run left in --out DIR: compute only what is missing")
    add_detach_option(p)
    p.add_argument(
        "--force",
        action="store_true",
        help="write into --out DIR even if it is not empty and not a run of this preset (never deletes your files)",
    )
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..runs.figures import DrawingProcess

    if args.resume and args.out and not getattr(args, "stored", False):  # `resume DIR` said it already
        refuse_what_no_resume_helps(Path(args.out))

    # forked before anything heavy is imported: it imports matplotlib on the core this start leaves idle
    drawer = None if args.no_plot or args.detach else DrawingProcess.start()
    try:
        return _run(args, drawer)
    finally:
        if drawer is not None:
            drawer.close()


SHOWN_POINTS = 10  # of a sweep's points whose fit failed, said one a line


def refuse_what_no_resume_helps(run_dir: Path) -> None:
    """RunFolderError, before anything is read or written, for a run whose fit failed with every
    realization finished (no law), or a sweep whose points all ended so, or completed: a resume
    would restore them, compute nothing and fail the same way (``runs.settled``)."""
    from ..runs.rundir import PRESET_FILE
    from ..runs.settled import why_no_resume_helps

    kind, reasons = why_no_resume_helps(run_dir)
    if not kind:
        return
    if kind == "run":
        head = f"cannot resume {shown_name(run_dir)}: all its realizations finished, and its fit failed: {reasons[0]}"
        again = f"the preset it ran is {command_word(run_dir / PRESET_FILE)}"
    else:
        lines = [f"  {reason}" for reason in reasons[:SHOWN_POINTS]]
        lines += [f"  (and {len(reasons) - SHOWN_POINTS} more)"] if len(reasons) > SHOWN_POINTS else []
        head = (f"cannot resume {shown_name(run_dir)}: every point of the sweep ended, and at "
                f"{counted(len(reasons), 'point')} all the realizations finished but the fit failed:\n" + "\n".join(lines))  # fmt: skip
        again = f"each point's preset is its {PRESET_FILE} in {command_word(run_dir / 'points')}/"
    raise RunFolderError(
        f"{head}\nA resume restores every realization, computes nothing new and fails the same way (nothing in "
        f"{shown_name(run_dir)} was changed). Change the preset as that says (other loads, a wider range, more "
        f"realizations) and run it into a new folder ({again})"
    )


def _run(args, drawer) -> ExitCode:
    from ..preset import build_scene, read_preset
    from ..preset.builtin import preset_source, resolve_preset_path, same_name_note
    from ..runs.rundir import PRESET_FILE, new_run_folder
    from ..runs.runfolder import refuse_nothing_to_resume
    from ..runs.runner import memory_check_before_reading

    overrides = preset_overrides(args)
    source = args.source = preset_source(args.preset, args.set or [])  # what messages name, a sweep's too
    resolved = resolve_preset_path(args.preset)  # a path, or a built-in's name
    if note := same_name_note(args.preset, resolved):
        print(shown(note), file=sys.stderr)
    args.preset = str(resolved)
    data = read_preset(args.preset, overrides)  # read once: a sweep plans its points from the same data
    if getattr(args, "stored", False):  # a run folder's own preset.yaml (resume DIR): read as this version reads it
        from ..preset.paths import as_now

        data = as_now(data)[0]  # the resume says what it changed
    refuse_swept_overrides(args, data)
    options = executor_run_options(args, resume=args.resume, force=args.force)
    reading = None if data.get("sweep") else memory_check_before_reading(options)  # a sweep checks each point
    scene = build_scene(data, source=source, before_reading=reading)
    if scene.preset.sweep is not None:  # its points are planned anew: of the base, what pressing needs is kept
        scene = scene.for_pressing()
    if drawer is not None and (scene.preset.sweep is not None or not scene.preset.output.plot):
        drawer.close()  # no plot.png to draw: its import takes a core no longer
    if not args.no_plot and scene.preset.output.plot and os.environ.get("MPLBACKEND", "").strip().lower() not in ("", "agg"):
        refuse_unusable_matplotlib()  # named before the work, not as each plot.png failed after it; agg costs no import
    if args.out is not None and (too_long := too_long_path(args.out)):
        raise FrictionlabError(f"--out {too_long}")
    if args.resume and not args.out:
        raise FrictionlabError("--resume needs the run directory: give --out DIR (or use `frictionlab resume DIR`).")
    if args.resume:
        refuse_nothing_to_resume(args.out)
    out_dir = args.out_dir = Path(args.out) if args.out else new_run_folder(scene.preset.name)  # named if memory runs out
    from ..io.files import real_path

    if not getattr(args, "stored", False) and real_path(args.preset) == real_path(out_dir / PRESET_FILE):
        raise OutputRefused(f"{shown_name(args.preset)} is the preset being run: the run writes its own {PRESET_FILE} "
                            "there; give another --out, or rename the preset")  # --force would replace it
    try:
        if args.detach:
            return detach(args, data, scene, out_dir, options)
        if scene.preset.sweep is not None:  # one ensemble per point
            return run_sweep_into(args, data, out_dir, options)
        return _run_scene(args, scene, out_dir, options, drawer)
    except FrictionlabError:  # refused before it began (the memory check): the folder made for it goes
        if not args.out and not any(out_dir.iterdir()):
            out_dir.rmdir()
        raise


def add_detach_option(p) -> None:
    p.add_argument(
        "--detach", action="store_true",
        help="run as a process of its own that outlives the terminal; print its folder and pid once it has "
        "started (frictionlab follow DIR shows its progress, kill -TERM PID cancels it); with --quiet only its folder",
    )  # fmt: skip


def detach(args, data: dict, scene, out_dir: Path, options) -> ExitCode:
    """Start the run of ``scene`` (a sweep, when ``data`` has one) as a process of its own; say where."""
    from ..runs.detached import check_startable, check_sweep_startable, start_detached, wait_started

    if data.get("sweep"):
        from ..runs.sweep import plan_sweep

        sweep = plan_sweep(data, source=args.source)
        check_sweep_startable(sweep, out_dir, options)
        process = start_detached(data, out_dir, options, plot=not args.no_plot, source=args.source)
        kind, what = "sweep", f"sweep of {counted(len(sweep.points), 'point')}"
    else:
        check_startable(scene, out_dir, options)
        process = start_detached(scene.resolved(), out_dir, options, plot=not args.no_plot)
        kind, what = "run", "running"
    wait_started(process, out_dir)
    if args.json:
        from .jsonout import emit

        emit("detached", {"folder": str(out_dir), "kind": kind, "pid": process.pid, "status": "running"})
    elif args.quiet:  # only the folder: a script captures it
        print(out_dir)
    else:
        print(shown(f"{scene.preset.name}: {what} detached in {out_dir}/ (pid {process.pid})\n"
                    f"  frictionlab follow {command_word(out_dir)}    shows its progress\n"
                    f"  kill -TERM {process.pid}    cancels it (what finished is kept; frictionlab resume continues it)"))  # fmt: skip
    return ExitCode.OK


def _run_scene(args, scene, out_dir: Path, options, drawer=None) -> ExitCode:
    from ..api import run_scene
    from ..progress import ProgressReporter
    from ..runs.results import summary_dict
    from ..compute.signals import interrupted_exit_code

    closed = []  # stdout closed or full: raised again once the run folder is finished

    def print_table(result) -> None:  # before the figure is drawn: nobody waits for matplotlib
        if not args.json:
            try:
                print(shown(result_table(scene, result.outcome, out_dir)), flush=True)
            except OSError as exc:
                closed.append(exc)

    listeners = [] if args.quiet else [ProgressReporter()]
    try:
        result = run_scene(
            scene, out_dir, options, listeners=listeners, plot=not args.no_plot, on_results=print_table, drawer=drawer
        )
    except OSError as exc:  # a full disk: said as every refusal is, as the error object under --json too
        raise write_failed(exc, resumable(out_dir)) from None
    if closed:
        raise closed[0]
    outcome = result.outcome
    if args.resume:  # a sweep's point resumed alone: its sweep's tables (the sweep module only then)
        from ..runs.sweep import refresh_point_tables

        if (refreshed := refresh_point_tables(out_dir, plot=not args.no_plot)) is not None:
            print(shown(f"  {refreshed[1]}"), file=sys.stderr)
    if args.json:
        from .jsonout import emit

        emit("run", summary_dict(scene, outcome, {k: str(p) for k, p in result.files.items()}))
    if outcome.status in ("interrupted", "cancelled"):
        print(shown(f"  {resumable(out_dir)}"), file=sys.stderr)
        return interrupted_exit_code()
    if outcome.failures or outcome.status == "failed":
        if outcome.error:
            print(f"error: {shown(outcome.error)}", file=sys.stderr)
        short = sum(ran_out_of_memory(error) for _, error in outcome.failures)
        if short:  # the machine's limit, not the preset's: the same run goes on where more fits
            print(shown(f"{short} realization(s) ran out of memory; {resumable(out_dir)} (with {MEMORY_ADVICE})"),
                  file=sys.stderr)  # fmt: skip
        return ExitCode.RUNTIME_FAILURE
    return ExitCode.OK


def resumable(out_dir: Path) -> str:
    """``resume_hint`` for a folder a run (run.json) or a sweep (sweep.json) has recorded itself in,
    else that nothing was kept."""
    from ..runs.rundir import STATE_FILE

    recorded = any((out_dir / name).is_file() for name in (STATE_FILE, "sweep.json"))
    return resume_hint(out_dir) if recorded else "nothing was kept"


def run_sweep_into(args, data: dict, out_dir: Path, options) -> ExitCode:
    from ..compute.signals import interrupted_exit_code
    from ..runs.runner import memory_check_before_reading
    from ..runs.settled import why_no_resume_helps
    from ..runs.sweep import plan_sweep, run_sweep
    from ..progress import SweepProgress

    sweep = plan_sweep(data, source=args.source, before_reading=memory_check_before_reading(options))
    try:
        outcome = run_sweep(
            sweep, out_dir, options, listeners=[] if args.quiet else [SweepProgress()], plot=not args.no_plot
        )
    except OSError as exc:  # a full disk: said as every refusal is, as the error object under --json too
        raise write_failed(exc, resumable(out_dir)) from None
    if args.json:
        from .jsonout import emit

        emit("sweep", json.loads((out_dir / "sweep.json").read_text(encoding="utf-8")))
    else:
        rows = [{**result.row(), "error": result.error} for result in outcome.results]  # why a point failed
        print(shown(sweep_table(sweep, outcome.status, outcome.elapsed, rows, out_dir, "plot" in outcome.files)))
    if outcome.status == "interrupted":
        print(shown(f"  {resumable(out_dir)}"), file=sys.stderr)
        return interrupted_exit_code()
    if outcome.status == "failed":  # said on stderr as a run's failure is, under --quiet and --json too
        failed = [result for result in outcome.results if result.failure]
        first = f"; first: point {failed[0].point.number}: {failed[0].failure}" if failed else ""
        settled = why_no_resume_helps(out_dir)[0] == "sweep"  # each failed its fit with every realization done
        then = ("a resume would compute nothing new and fail the same way: change the preset as that says (other "
                "loads, more realizations) and run it into a new folder" if settled else resumable(out_dir))
        print(shown(f"error: {len(failed)} of {counted(len(sweep.points), 'point')} failed{first}; {then}"),
              file=sys.stderr)  # fmt: skip
        return ExitCode.RUNTIME_FAILURE
    return ExitCode.OK


def result_table(scene, outcome, out_dir: Path) -> str:
    """What ``frictionlab run`` prints on stdout after a run: the fit and the contact counts."""
    from ..compute.fit import format_interval

    preset = scene.preset
    lines = [
        f"{preset.name}: {outcome.done}/{outcome.requested} realizations in {outcome.elapsed:.2f} s "
        f"({outcome.workers} worker{'s' if outcome.workers != 1 else ''}), status {outcome.status}"
    ]
    fit = outcome.fit
    if fit is not None:
        level = f"{100 * fit.confidence:g}% CI"
        a_se, b_se = fit.standard_errors
        lines += [
            f"  xi = a + b ln f      estimate    std.err    {level} (bootstrap {fit.bootstrap})",
            f"  a                  {fit.a:10.4f} {a_se:10.4f}    {format_interval(fit.a_ci)}",
            f"  b                  {fit.b:10.4f} {b_se:10.4f}    {format_interval(fit.b_ci)}",
            f"  R^2 = {fit.r2:.4f}, residual rms = {fit.residual_rms:.3g}, {fit.points} load steps",
            f"  {outcome.normalisation.definition}",
        ]
        count = outcome.contact_count
        unit = outcome.normalisation.load_symbol if scene.control == "force" else "d"
        ends = (outcome.force[0], outcome.force[-1]) if scene.control == "force" else (outcome.loads[0], outcome.loads[-1])
        lines.append(
            f"  mean points in contact: {count[0]:.2f} at {unit} = {ends[0]:g}, {count[-1]:.2f} at {unit} = {ends[1]:g}"
        )
    for caveat in outcome.caveats:
        lines.append(f"  caveat: {caveat}")
    if outcome.failures:
        index, error = outcome.failures[0]
        lines.append(f"  {len(outcome.failures)} realization(s) failed; first: #{index}: {error}")
    lines.append(f"  results in {shown_name(out_dir)}/")
    return "\n".join(lines)


def sweep_table(sweep, status: str, elapsed: float, rows: list[dict], out_dir: Path, drawn: bool = True) -> str:
    """What ``frictionlab run`` prints on stdout after a sweep: one line per point (``rows``:
    each point's row of sweep.json, in the order of the points); ``drawn``: sweep.png was drawn."""
    lines = [f"{sweep.name}: {counted(len(sweep.points), 'point')} in {elapsed:.1f} s, status {status}"]
    from ..progress import point_result_line

    lines += [point_result_line(sweep, point, row) for point, row in zip(sweep.points, rows)]
    lines.append(f"  results in {shown_name(out_dir)}/ (sweep.csv, {'sweep.png, ' if drawn else ''}points/)")
    return "\n".join(lines)
