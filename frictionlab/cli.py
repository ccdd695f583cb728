"""The headless front end: ``frictionlab run | validate | schema | plugins``.

Results go to stdout (a short table, or JSON with ``--json``), progress and
errors to stderr. Exit codes are ``ExitCode``. A user error never prints a
traceback (set ``FRICTIONLAB_DEBUG=1`` to see one for an internal error).
SIGTERM ends a run as Ctrl-C does; a closed stdout ends the command quietly.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings
from pathlib import Path

from . import __version__
from .errors import ExitCode, FrictionlabError, short_repr
from .signals import RaiseOnSigterm, interrupted_exit_code

DEFAULT_RUNS_DIR = Path("runs")


def _interval(ci) -> str:
    low, high = ci
    return "n/a" if low != low else f"[{low:.4f}, {high:.4f}]"  # NaN check without math


def result_table(scene, outcome, out_dir: Path) -> str:
    preset = scene.preset
    lines = [
        f"{preset.name}: {outcome.done}/{outcome.requested} realizations in {outcome.elapsed:.2f} s "
        f"({outcome.workers} worker{'s' if outcome.workers != 1 else ''}), status {outcome.status}"
    ]
    fit = outcome.fit
    if fit is not None:
        level = f"{100 * fit.confidence:g}% CI"
        lines += [
            f"  xi = a + b ln f      estimate    std.err    {level} (bootstrap {fit.bootstrap})",
            f"  a                  {fit.a:10.4f} {fit.a_se:10.4f}    {_interval(fit.a_ci)}",
            f"  b                  {fit.b:10.4f} {fit.b_se:10.4f}    {_interval(fit.b_ci)}",
            f"  R^2 = {fit.r2:.4f}, residual rms = {fit.residual_rms:.3g}, {fit.points} load steps",
            f"  {outcome.normalisation.definition}",
        ]
        count = outcome.contact_count
        unit = outcome.normalisation.load_symbol if scene.control == "force" else "d"
        lines.append(
            f"  mean points in contact: {count[0]:.2f} at {unit} = {outcome.loads[0]:g}, "
            f"{count[-1]:.2f} at {unit} = {outcome.loads[-1]:g}"
        )
    if outcome.failures:
        index, error = outcome.failures[0]
        lines.append(f"  {len(outcome.failures)} realization(s) failed; first: #{index}: {error}")
    lines.append(f"  results in {out_dir}/")
    return "\n".join(lines)


def _default_out(name: str) -> Path:
    return DEFAULT_RUNS_DIR / f"{name}-{time.strftime('%Y%m%d-%H%M%S')}"


# ------------------------------------------------------------------ commands


def cmd_run(args) -> ExitCode:
    from .preset import load_scene
    from .reporter import ProgressReporter
    from .results import summary_dict
    from .runner import run_to_folder

    overrides = list(args.set or [])
    if args.seed is not None:
        overrides.append(f"seed={args.seed}")
    scene = load_scene(args.preset, overrides)
    if args.workers is not None and args.workers < 1:
        raise FrictionlabError(f"--workers must be >= 1. Got {args.workers} instead.")
    if args.resume and not args.out:
        raise FrictionlabError("--resume needs the run directory: give --out DIR (or use `frictionlab resume DIR`).")
    _use_executor_options(args)
    out_dir = Path(args.out) if args.out else _default_out(scene.preset.name)
    run_options = {
        "executor": args.executor,
        "scheduler": args.scheduler,
        "resume": args.resume,
        "memory_check": not args.no_memory_check,
        "force": args.force,
        "dashboard": args.dashboard,
    }
    if scene.preset.sweep is not None:  # one ensemble per point (issue 6)
        from .sweep import run_sweep_command

        return run_sweep_command(args, overrides, out_dir, run_options)
    listeners = [] if args.quiet else [ProgressReporter()]
    try:
        outcome, files = run_to_folder(scene, out_dir, workers=args.workers, listeners=listeners, **run_options)
    except OSError as exc:
        print(f"error: cannot write results to {out_dir}: {exc.strerror or exc}", file=sys.stderr)
        return ExitCode.RUNTIME_FAILURE
    if args.json:
        summary = summary_dict(scene, outcome, {k: str(p) for k, p in files.items()})
        print(json.dumps(summary, indent=2, allow_nan=False))
    else:
        print(result_table(scene, outcome, out_dir))
    if outcome.status == "interrupted" or outcome.status == "cancelled":
        return interrupted_exit_code()
    if outcome.failures or outcome.status == "failed":
        if outcome.error:
            print(f"error: {outcome.error}", file=sys.stderr)
        return ExitCode.RUNTIME_FAILURE
    return ExitCode.OK


def cmd_validate(args) -> ExitCode:
    from .preset import load_scene

    worst = ExitCode.OK
    for path in args.presets:
        try:
            scene = load_scene(path, args.set or [])
            if scene.preset.sweep is not None:  # every point too (issue 6)
                from .sweep import load_sweep

                points = len(load_sweep(path, args.set or []).points)
        except FrictionlabError as exc:
            print(str(exc), file=sys.stderr)
            worst = ExitCode(max(worst, exc.exit_code))
            continue
        preset = scene.preset
        print(
            f"{path}: ok ({preset.realizations} realizations, {scene.spectrum.name} / {scene.solver.name} / "
            f"{scene.slope.name}, {preset.loading.steps} {preset.loading.control} steps"
            + (f", sweep of {points} points)" if scene.preset.sweep is not None else ")")
        )
    return worst


def cmd_schema(args) -> ExitCode:
    from .preset import preset_json_schema

    text = json.dumps(preset_json_schema(), indent=2)
    if args.out:
        from .results import atomic_write

        atomic_write(Path(args.out), lambda fh: fh.write(text + "\n"))
    else:
        print(text)
    return ExitCode.OK


def cmd_plugins(args) -> ExitCode:
    from .registry import default_registry

    registry = default_registry()
    infos = registry.infos()
    if args.json:
        rows = [
            {"kind": i.kind, "name": i.name, "summary": i.summary, "provider": i.provider, "version": i.version}
            for i in infos
        ]
        failures = [f.__dict__ for f in registry.failures]
        print(json.dumps({"plugins": rows, "failed": failures}, indent=2))
        return ExitCode.OK
    header = ("KIND", "NAME", "PROVIDER", "VERSION", "SUMMARY")
    rows = [(i.kind, i.name, i.provider, i.version, i.summary) for i in infos]
    widths = [max(len(r[c]) for r in [header, *rows]) for c in range(4)]
    for row in [header, *rows]:
        print("  ".join(cell.ljust(w) for cell, w in zip(row[:4], widths)) + "  " + row[4])
    for failure in registry.failures:
        print(f"failed to load: {failure.entry_point} ({failure.distribution}): {failure.error}", file=sys.stderr)
    return ExitCode.OK


def cmd_tui(args) -> ExitCode:
    if args.preset is not None:
        from .preset import load_preset_file

        load_preset_file(args.preset)  # a missing or unreadable file is a usage error, before the UI starts
    if args.workers is not None and args.workers < 1:
        raise FrictionlabError(f"--workers must be >= 1. Got {args.workers} instead.")
    from .tui import run_app  # Textual is imported here only: headless commands never load it

    return run_app(args.preset, presets_dir=args.presets, runs_dir=args.runs, workers=args.workers)


def cmd_resume(args) -> ExitCode:
    from .rundir import PRESET_FILE, RunDirectory

    run_dir = Path(args.run_dir)
    RunDirectory(run_dir).stored_preset()  # a clear error when there is nothing to resume, or it is damaged
    args.preset, args.out, args.resume, args.set, args.seed = str(run_dir / PRESET_FILE), str(run_dir), True, None, None
    args.force = False
    return cmd_run(args)


def cmd_study(args) -> ExitCode:
    from .study.command import run_command

    return run_command(args)


# ------------------------------------------------------------------ parser


def _add_executor_options(parser) -> None:
    parser.add_argument(
        "--executor",
        choices=("serial", "processes", "dask"),
        help="where realizations run (default: processes, or serial for --workers 1)",
    )
    parser.add_argument(
        "--scheduler", metavar="ADDRESS", help="an existing Dask scheduler, tls://HOST:PORT or tcp://HOST:PORT"
    )
    parser.add_argument("--tls-ca-file", metavar="FILE", help="CA certificate of a tls:// Dask scheduler")
    parser.add_argument("--tls-cert", metavar="FILE", help="client certificate for a tls:// Dask scheduler")
    parser.add_argument("--tls-key", metavar="FILE", help="client key for a tls:// Dask scheduler")
    parser.add_argument(
        "--dashboard", action="store_true", help="serve the Dask dashboard of the local cluster (on 127.0.0.1)"
    )
    parser.add_argument(
        "--no-memory-check", action="store_true", help="skip the peak-memory estimate made before the run starts"
    )


def _use_executor_options(args) -> None:
    """Check the Dask options before anything starts."""
    tls = {"ca_file": args.tls_ca_file, "cert": args.tls_cert, "key": args.tls_key}
    if any(tls.values()) or (args.scheduler and args.scheduler.startswith("tls://")):
        for name, value in tls.items():
            if value:
                from .inputs import regular_file_problem

                problem = regular_file_problem(value)
                if problem:
                    flag = "--tls-" + ("ca-file" if name == "ca_file" else name)
                    raise FrictionlabError(f"{flag} {value}: {problem}")
        from .dask_security import use_tls_files

        use_tls_files(**tls)
    if args.scheduler:
        from .dask_security import check_address

        check_address(args.scheduler)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="frictionlab",
        description="rms slope in contact against normal force, over ensembles of random rough lines.",
    )
    parser.add_argument("--version", action="version", version=f"frictionlab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    run = sub.add_parser("run", help="run a preset headless and write its results")
    run.add_argument("preset", help="preset YAML file")
    run.add_argument("--out", metavar="DIR", help="output folder (default: runs/<name>-<timestamp>)")
    run.add_argument(
        "--set", action="append", metavar="PATH=VALUE", help="override a preset value, e.g. spectrum.params.hurst=0.8"
    )
    run.add_argument("--workers", type=int, metavar="N", help="worker processes (default: all cores; 1: in-process)")
    run.add_argument("--seed", type=int, metavar="S", help="root seed (overrides the preset's)")
    run.add_argument("--quiet", action="store_true", help="no progress on stderr")
    run.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    _add_executor_options(run)
    run.add_argument("--resume", action="store_true", help="continue the run left in --out DIR: compute only what is missing")
    run.add_argument(
        "--force",
        action="store_true",
        help="write into --out DIR even if it is not empty and not a run of this preset (never deletes your files)",
    )
    run.set_defaults(handler=cmd_run)

    resume = sub.add_parser("resume", help="continue an interrupted run in DIR with the preset stored there")
    resume.add_argument("run_dir", metavar="DIR", help="the output folder of the interrupted run")
    resume.add_argument("--workers", type=int, metavar="N", help="worker processes (default: all cores; 1: in-process)")
    resume.add_argument("--quiet", action="store_true", help="no progress on stderr")
    resume.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    _add_executor_options(resume)
    resume.set_defaults(handler=cmd_resume)

    validate = sub.add_parser("validate", help="check presets and report every problem")
    validate.add_argument("presets", nargs="+", metavar="PRESET")
    validate.add_argument("--set", action="append", metavar="PATH=VALUE", help="override before validating")
    validate.set_defaults(handler=cmd_validate)

    schema = sub.add_parser("schema", help="JSON Schema of presets with the installed plugins")
    schema.add_argument("--out", metavar="FILE", help="write to FILE instead of stdout")
    schema.set_defaults(handler=cmd_schema)

    plugins = sub.add_parser("plugins", help="list installed plugins")
    plugins.add_argument("--json", action="store_true", help="as JSON")
    plugins.set_defaults(handler=cmd_plugins)

    from . import predict, report  # their subcommands (issue 6)

    report.add_parser(sub)
    predict.add_parser(sub)

    tui = sub.add_parser("tui", help="terminal UI: edit presets, run with live progress, compare results")
    tui.add_argument("preset", nargs="?", help="preset YAML file to open (optional)")
    tui.add_argument("--presets", metavar="DIR", help="presets folder to browse (default: ./presets and the user folder)")
    tui.add_argument("--runs", metavar="DIR", help="where runs are written and listed (default: runs)")
    tui.add_argument("--workers", type=int, metavar="N", help="worker processes (default: all cores; 1: in-process)")
    tui.set_defaults(handler=cmd_tui)

    from .study.command import add_arguments as add_study_arguments  # argparse only: cheap

    study = sub.add_parser("study", help="error against cost of grid, realizations, steps, solver and tolerance")
    add_study_arguments(study)
    study.set_defaults(handler=cmd_study)
    return parser


def _plain_warning(message, category, filename, lineno, file=None, line=None):
    return f"warning: {message}\n"


def _quiet_stdout() -> None:
    """After a BrokenPipeError: point stdout at /dev/null so the interpreter's
    final flush does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):  # stdout without a descriptor (a test's capture)
        pass


def main(argv: list[str] | None = None) -> int:
    warnings.formatwarning = _plain_warning
    args = build_parser().parse_args(argv)
    with RaiseOnSigterm():
        return _run_command(args)


def _run_command(args) -> int:
    try:
        code = int(args.handler(args))
        sys.stdout.flush()  # a closed pipe shows here, not at exit
        return code
    except BrokenPipeError:  # `frictionlab plugins --json | head -c 10`: the reader has enough
        _quiet_stdout()
        return int(ExitCode.BROKEN_PIPE)
    except FrictionlabError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return int(exc.exit_code)
    except OSError as exc:  # the machine said no (disk full, permission denied): not a bug
        where = f": {exc.filename}" if exc.filename else ""
        print(f"error: {exc.strerror or exc}{where}", file=sys.stderr)
        return int(ExitCode.RUNTIME_FAILURE)
    except KeyboardInterrupt:  # Ctrl-C, or SIGTERM (signals.Terminated), outside a run's own handling
        code = interrupted_exit_code()
        print("terminated" if code == ExitCode.TERMINATED else "interrupted", file=sys.stderr)
        return int(code)
    except Exception as exc:  # an internal error (a bug): say so plainly, traceback on request
        if os.environ.get("FRICTIONLAB_DEBUG"):
            raise
        print(
            f"internal error: {type(exc).__name__}: {short_repr(str(exc), 300)[1:-1]}\n"
            "(this is a bug; set FRICTIONLAB_DEBUG=1 for the traceback)",
            file=sys.stderr,
        )
        return int(ExitCode.INTERNAL)


if __name__ == "__main__":
    sys.exit(main())
