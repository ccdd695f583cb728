"""``frictionlab study PRESET``: the trade-off study (``frictionlab.tradeoff``) from the
command line: its options, checked, and the run. Heavy modules are imported inside
``run`` so building the parser stays cheap."""

from __future__ import annotations

import math
import sys

from ..errors import (ExitCode, FrictionlabError, RunError, not_an_option, refuse_unusable_matplotlib, shell_word, short_repr,
                      shown_name)
from ..tradeoff.options import AXES, StudyOptions
from .options import preset_overrides


def _listed(values) -> str:
    return ",".join(f"{v:g}" for v in values)


_D = StudyOptions()
MAX_GRID_FACTOR = 1e6  # times the preset's N: past any memory (a factor of 1e300 was skipped as a note, exit 0)
MAX_REPEATS = 100  # timings of one setting: as many as the report's replicates
DEFAULTS = {  # the flags' defaults, as typed: StudyOptions' own
    "reference": _D.reference,
    "axes": ",".join(_D.axes),
    "target": _D.target,
    "points": None,  # the preset's N up to compare_points (compare_points_surface per side)
    "compare_realizations": _D.compare_realizations,
    "compare_steps": _D.compare_steps,
    "grid_realizations": _D.grid_realizations,
    "grid_factors": _listed(_D.grid_factors),
    "tolerances": _listed(_D.tolerances),
    "reference_grid": _listed(_D.reference_grid),
    "repeats": _D.repeats,
}


def add_parser(sub) -> None:
    parser = sub.add_parser(
        "study",
        help="error against cost of grid, realizations, steps, solver and tolerance",
        description="The speed/accuracy study of a preset: the error of b against the cost along each axis "
        "(grid, realizations, steps, solver, tolerance), and the cheapest settings that reach --target.",
        epilog="examples:\n  frictionlab study quickstart --axes grid,realizations\n"
        "  frictionlab study mdr-vs-halfspace --tolerances 1e-4,1e-6 --json",
    )
    d = DEFAULTS
    parser.add_argument("preset", help="preset YAML file, or a built-in preset's name")
    parser.add_argument("--out", metavar="DIR", help="output folder (default: a new runs/<name>-study-<timestamp>); "
                        "one holding anything but a study of the same preset is refused unless --force")
    parser.add_argument("--force", action="store_true",
                        help="write into --out even if it holds other files (study.csv, study.md, study.png are replaced)")
    parser.add_argument("--set", action="append", metavar="PATH=VALUE", help="override a preset value first")
    parser.add_argument("--seed", type=int, metavar="S", help="root seed (overrides the preset's)")
    parser.add_argument(
        "--reference", default=d["reference"], metavar="SOLVER",
        help="contact solver the preset's solver is compared with; it must solve the same physical problem "
        "(default: the installed exact solver of that problem, e.g. bem-halfspace for mdr on a surface)",
    )
    parser.add_argument("--axes", default=d["axes"], metavar="LIST", help=f"axes to run (default {d['axes']})")
    parser.add_argument("--target", type=float, default=d["target"], help=f"relative error in b to recommend for (default {d['target']:g})")
    parser.add_argument(
        "--points", type=int, default=d["points"], metavar="N",
        help="grid of the solver and tolerance axes, where the reference runs, at most the preset's N (default: the preset's N up to "
        f"{_D.compare_points} points on a line, {_D.compare_points_surface} per side on a surface)",
    )
    parser.add_argument("--compare-realizations", type=int, default=d["compare_realizations"], metavar="M",
                        help=f"realizations on the solver and tolerance axes, at most the preset's (default {d['compare_realizations']})")
    parser.add_argument("--compare-steps", type=int, default=d["compare_steps"], metavar="K",
                        help=f"load steps on the solver and tolerance axes, at most the preset's (default {d['compare_steps']})")
    parser.add_argument("--grid-realizations", type=int, default=d["grid_realizations"], metavar="M",
                        help=f"realizations on the grid and steps axes, at most the preset's (default {d['grid_realizations']})")
    parser.add_argument("--grid-factors", default=d["grid_factors"], metavar="LIST",
                        help=f"grid sizes as multiples of the preset's N; the largest is the reference (default {d['grid_factors']})")
    parser.add_argument("--tolerances", default=d["tolerances"], metavar="LIST",
                        help=f"tolerances of the reference solver; the tightest is the reference (default {d['tolerances']})")
    parser.add_argument("--reference-grid", default=d["reference_grid"], metavar="LIST",
                        help="also refine the reference solver's grid by these factors of --points (e.g. 0.5,1,2)")
    parser.add_argument("--repeats", type=int, default=d["repeats"], metavar="R", help="time each setting R times, keep the best")
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr")
    parser.add_argument("--json", action="store_true", help="the recommendation, the rows and the files as JSON on stdout")
    parser.set_defaults(handler=run)


def _numbers(option: str, text: str, kind=float, low: float = 0.0, required: bool = False,
             high: float = math.inf) -> tuple:
    written = [v.strip() for v in text.split(",") if v.strip()]
    try:
        values = tuple(kind(v) for v in written)
    except ValueError:
        raise FrictionlabError(f"{option} must be a comma-separated list of numbers. Got {short_repr(text)} instead.") from None
    bad = [w for w, v in zip(written, values) if not (v > low and math.isfinite(v))]  # inf made a grid of int(inf) points
    if bad:  # as written: 1e-400 is read as 0.0
        raise FrictionlabError(f"{option} values must be finite numbers > {low:g}. Got {short_repr(bad[0])} instead.")
    beyond = [w for w, v in zip(written, values) if v > high]
    if beyond:
        raise FrictionlabError(f"{option} values must be at most {high:g}. Got {short_repr(beyond[0])} instead.")
    if required and not values:  # an empty list left its axis out without a word
        raise FrictionlabError(f"{option} names no value: give a comma-separated list of numbers. Got {short_repr(text)} instead.")
    return values


def _compared(option: str, text: str, axis_runs: bool, reference: str, high: float = math.inf) -> tuple:
    """The values of an axis measured against its largest (or tightest) one: where that axis
    runs, two at least; one alone was the reference, compared with nothing, and the grid
    axis then said 'N > 4096 (not reached)' of a grid it never measured."""
    values = _numbers(option, text, required=axis_runs, high=high)
    if axis_runs and len(set(values)) < 2:
        raise FrictionlabError(f"{option} must give two different values at least (the axis measures the others "
                               f"against the {reference}). "
                               f"Got {short_repr(text)} instead.")  # fmt: skip
    return values


def _between(option: str, value: int, low: int, high: int) -> int:
    if not low <= value <= high:
        raise FrictionlabError(f"{option} must be a whole number from {low} to {high}. Got {value} instead.")
    return value


def _at_least(option: str, value: int, low: int) -> int:
    if value < low:
        raise FrictionlabError(f"{option} must be >= {low}. Got {value} instead.")
    return value


def options_from_args(args) -> StudyOptions:
    axes = tuple(a.strip() for a in args.axes.split(",") if a.strip())
    unknown = [a for a in axes if a not in AXES]
    if unknown or not axes:
        raise FrictionlabError(
            f"--axes must name some of {', '.join(AXES)}. Got {short_repr(args.axes)} instead."
        )
    if twice := sorted({a for a in axes if axes.count(a) > 1}):  # each ran again: the same rows, the time twice
        raise FrictionlabError(f"--axes names {', '.join(twice)} more than once; each axis runs once: name it once. "
                               f"Got {short_repr(args.axes)} instead.")  # fmt: skip
    if not 0 < args.target < 1:
        raise FrictionlabError(f"--target must be > 0 and < 1 (a relative error). Got {args.target} instead.")
    _refuse_unused_options(args, axes)
    return StudyOptions(
        reference=args.reference,
        axes=axes,
        target=args.target,
        **({} if args.points is None else {
            "compare_points": _at_least("--points", args.points, 8),
            "compare_points_surface": _at_least("--points", args.points, 8),
        }),
        compare_realizations=_at_least("--compare-realizations", args.compare_realizations, 2),
        compare_steps=_at_least("--compare-steps", args.compare_steps, 2),
        grid_realizations=_at_least("--grid-realizations", args.grid_realizations, 2),
        grid_factors=_compared("--grid-factors", args.grid_factors, "grid" in axes, "largest", MAX_GRID_FACTOR),
        tolerances=_compared("--tolerances", args.tolerances, "tolerance" in axes, "tightest") or (min(_D.tolerances),),
        reference_grid=_numbers("--reference-grid", args.reference_grid, high=MAX_GRID_FACTOR),
        repeats=_between("--repeats", args.repeats, 1, MAX_REPEATS),
    )


COMPARED = ("solver", "tolerance")  # the axes (and --reference-grid) that run the reference solver
AXIS_OPTIONS = {  # an option given, and the axes it changes: none of them run, it did nothing, unsaid
    "grid_factors": ("grid",),
    "grid_realizations": ("grid", "steps"),
    **dict.fromkeys(("points", "compare_realizations", "compare_steps", "tolerances", "reference"), COMPARED),
}


def _refuse_unused_options(args, axes: tuple[str, ...]) -> None:
    """Refuse an option set away from its default whose axes ``axes`` leave out: the study ran
    without it and said nothing (``--axes grid --tolerances 1e-4``)."""
    for name, used_by in AXIS_OPTIONS.items():
        if getattr(args, name) == DEFAULTS[name] or set(used_by) & set(axes):
            continue
        if used_by == COMPARED and args.reference_grid:  # the reference's own grid runs with them
            continue
        option = "--" + name.replace("_", "-")
        which = f"the {' and '.join(used_by)} {'axes' if len(used_by) > 1 else 'axis'}"
        raise FrictionlabError(f"{option} changes {which}, which --axes {','.join(axes)} leaves out: add "
                               f"{' or '.join(used_by)} to --axes, or drop {option}")  # fmt: skip


def command_line(args) -> str:
    """The command as a user would type it: the preset and every option that differs from its default."""
    words = ["frictionlab", "study", not_an_option(args.preset)]
    for assignment in args.set or []:
        words += ["--set", assignment]
    if args.seed is not None:
        words += ["--seed", str(args.seed)]
    for dest, default in DEFAULTS.items():
        value = getattr(args, dest)
        if value != default:
            words += [f"--{dest.replace('_', '-')}", str(value)]
    if args.out:
        words += ["--out", not_an_option(args.out)]
    if args.force:
        words.append("--force")
    # a folder name that is not UTF-8 in bash's $'...', its bytes escaped (the page is UTF-8 text), on one line
    return " ".join(map(shell_word, words))


def _again(out_dir, name: str, force: bool) -> str:
    """How to write the study once there is room: the same command, with --force where the files
    written before the disk filled (study.csv without its study.md) would make its folder refused."""
    from ..tradeoff.outputs import is_study_of

    if force or not out_dir.is_dir() or not any(out_dir.iterdir()) or is_study_of(out_dir / "study.md", name):
        return "free some space and run the study again"
    return "free some space and run the study again with --force (it replaces only study.csv, study.md and study.png)"


def _kept_elsewhere(study, out_dir, text: str, args, exc: OSError) -> None:
    """The study's files could not be written to ``out_dir``: write them to a new temporary
    folder (``TMPDIR``, often another disk) and say how to move them there; where that fails
    too, print its rows (study.csv) and recommendation on stderr. Raises the RunError that says so."""
    import io
    import shutil
    import tempfile
    from pathlib import Path

    from ..errors import command_word
    from ..tradeoff.outputs import write_csv, write_outputs

    refused = f"cannot write the study to {shown_name(out_dir)}: {exc.strerror or exc}"
    spare = None
    try:
        spare = Path(tempfile.mkdtemp(prefix=f"{study.factory.base.preset.name}-study-"))
        files = write_outputs(study, spare, text, command_line(args))
    except OSError as again:
        if spare is not None:
            shutil.rmtree(spare, ignore_errors=True)  # the folder made here, for nothing
        table = io.StringIO()
        write_csv(table, study.rows)
        print(f"{text}\n\nstudy.csv:\n{table.getvalue()}", file=sys.stderr, end="")
        raise RunError(f"{refused}, nor to a temporary folder ({again.strerror or again}): its rows (study.csv) and "
                       f"recommendation are printed above; {_again(out_dir, study.factory.base.preset.name, args.force)}") from None
    names = ", ".join(path.name for path in files.values())
    out = command_word(out_dir)
    raise RunError(f"{refused}; it was written to {shown_name(spare)}/ instead ({names}): once {shown_name(out_dir)} "
                   f"can be written, mkdir -p {out} && mv {command_word(spare)}/study.* {out}/") from None


def _refuse_nothing_to_run(study, axes: tuple[str, ...]) -> None:
    """Refuse axes that all need a reference solver where there is none: the study ran nothing,
    wrote a study.md of notes, and said 'no axis measured enough' with exit code 0."""
    if study.reference_choice is not None or not set(axes) <= set(COMPARED):
        return
    why = next((n.split(": skipped: ", 1)[1] for n in study.notes if ": skipped: " in n), "there is no reference solver")
    raise FrictionlabError(f"--axes {','.join(axes)}: nothing would run: {'it needs' if len(axes) == 1 else 'they need'} "
                           f"a reference solver, and {why}; give other --axes (grid, realizations, steps)")  # fmt: skip


def _refuse_beyond_the_preset(args, base) -> None:
    """Refuse a size given above the preset's own: the study takes at most the preset's, so
    ``--compare-realizations 1000`` on a preset of 4 ran with 4 and said nothing."""
    from ..tradeoff.axes import preset_points

    preset = base.preset
    limits = {"points": (preset_points(base), "points per side" if base.spectrum.dimension == 2 else "points"),
              "compare_realizations": (preset.realizations, "realizations"),
              "grid_realizations": (preset.realizations, "realizations"),
              "compare_steps": (preset.loading.steps, "load steps")}  # fmt: skip
    for name, (limit, what) in limits.items():
        value = getattr(args, name)
        if value == DEFAULTS[name] or limit is None or value <= limit:  # a default above it is the preset's, as documented
            continue
        option = "--" + name.replace("_", "-")
        raise FrictionlabError(f"{option} {value} is more than the preset's {limit} {what}: the study takes at most the "
                               f"preset's; give {option} {limit} or less, or raise the preset's with --set")  # fmt: skip


def run(args) -> ExitCode:
    from ..preset import read_preset
    from ..preset.builtin import preset_source, resolve_preset_path
    from ..plugin.registry import default_registry
    from ..tradeoff.axes import PRESET_GRID, Study, refuse_beyond
    from ..tradeoff.outputs import claim_study_folder, recommendation, write_outputs
    from ..tradeoff.scenes import SceneFactory

    options = options_from_args(args)
    refuse_unusable_matplotlib()  # study.png is drawn once every axis has run
    overrides = preset_overrides(args)
    data = read_preset(resolve_preset_path(args.preset), overrides)  # relative input files taken from the preset's folder
    if data.get("sweep") is not None:
        print(
            "warning: the preset's sweep is not studied: the study varies its own axes around the preset's "
            "base values (--set sweep=null says so and silences this)",
            file=sys.stderr,
        )
        data = {**data, "sweep": None}
    factory = SceneFactory(data, default_registry(), source=preset_source(args.preset, args.set or []),
                           before_reading=refuse_beyond(*PRESET_GRID))  # before its map is read or its line made
    _refuse_beyond_the_preset(args, factory.base)

    def progress(message: str) -> None:
        if not args.quiet:
            print(f"study: {message}", file=sys.stderr, flush=True)

    from ..progress import ProgressReporter

    said: set[str] = set()  # its runs read one file alike: what was read is said once
    study = Study(factory, options, progress,
                  run_listeners=list if args.quiet else (lambda: [ProgressReporter(inputs_said=said)]))  # fmt: skip
    study.check_memory()  # before a folder is made
    _refuse_nothing_to_run(study, options.axes)
    out_dir = claim_study_folder(args.out, factory.base.preset.name, force=args.force)
    reference = study.reference_choice["name"] if study.reference_choice else "none (solver and tolerance axes skipped)"
    progress(f"{factory.base.preset.name}: axes {', '.join(options.axes)}; reference {reference}")
    interrupted = False
    try:
        study.run()
    except KeyboardInterrupt:
        interrupted = True
    from ..compute.signals import SignalsNoted

    with SignalsNoted() as held:  # a signal among the writes left study.csv without its study.md: the folder was refused
        text = recommendation(study)
        try:
            files = write_outputs(study, out_dir, text, command_line(args))
        except OSError as exc:  # a full disk: what was measured is kept elsewhere, never measured again
            _kept_elsewhere(study, out_dir, text, args, exc)
    interrupted = interrupted or held.signal is not None
    if args.json:
        from ..compute.fit import json_safe
        from ..tradeoff.axes import COLUMNS

        def cell(value):
            return json_safe(float(value)) if isinstance(value, float) else value

        rows = [{c: cell(getattr(row, c)) for c in COLUMNS} for row in study.rows]
        from .jsonout import emit

        emit("study", {"recommendation": text, "rows": rows, "files": {k: str(p) for k, p in files.items()},
                       "interrupted": interrupted})  # fmt: skip
    else:
        print(text)
        print(f"  {', '.join(p.name for p in files.values())} in {shown_name(out_dir)}/")
    if interrupted:
        from ..compute.signals import interrupted_exit_code, interrupted_word

        print(f"{interrupted_word()}: the files hold the axes finished before the interrupt", file=sys.stderr)
        return interrupted_exit_code()
    failed = [r for r in study.rows if r.outcome is not None and r.outcome.failures]
    if failed:
        print(f"error: realizations failed in {len(failed)} setting(s); see the notes in study.md", file=sys.stderr)
        return ExitCode.RUNTIME_FAILURE
    return ExitCode.OK
