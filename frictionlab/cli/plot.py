"""``frictionlab plot DIR``: a run's plot.png (a sweep's sweep.png) drawn from its folder, as the
run draws it: for a run made with --no-plot or ``output.plot: false``. Nothing is computed."""

from __future__ import annotations

from pathlib import Path

from ..errors import (ExitCode, FrictionlabError, OutputRefused, RunFolderError, command_word,
                      refuse_unusable_matplotlib, resume_hint, shown_name)  # fmt: skip

REDRAWN = "the run folder is as it was"  # what a figure that could not be drawn leaves: nothing is computed here


def add_parser(sub) -> None:
    p = sub.add_parser(
        "plot",
        help="draw a run folder's plot.png (a sweep's sweep.png) from its numbers",
        description="Draw the figure of a finished or interrupted run from its folder, as `frictionlab run` draws "
        "it: plot.png of a run, sweep.png of a sweep. For a run made with --no-plot (or output.plot: false); the "
        "folder is only read, nothing is computed.",
        epilog="examples:\n  frictionlab plot runs/quickstart              runs/quickstart/plot.png\n"
        "  frictionlab plot runs/h06 --out h06.png --force",
    )
    p.add_argument("folder", metavar="DIR", help="a run folder (summary.json) or a sweep's folder (sweep.json)")
    p.add_argument("--out", metavar="FILE",
                   help="the PNG file to write (default: plot.png in DIR, a sweep's sweep.png)")  # fmt: skip
    p.add_argument("--force", action="store_true", help="replace the file if it exists (a link is replaced, never the "
                   "file it points at)")  # fmt: skip
    p.add_argument("--quiet", action="store_true", help="print nothing once the figure is written")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    if args.out is not None and not args.out.lower().endswith(".png"):
        raise FrictionlabError(f"--out {shown_name(args.out)}: the figure is a PNG image; give a file name that ends "
                               "in .png")  # fmt: skip
    refuse_unusable_matplotlib()  # a bad MPLBACKEND named before the folder is read
    from ..result import SweepResult, load

    result = load(args.folder)  # as untrusted input: a RunFolderError naming the file and what is wrong
    folder, named = Path(args.folder), args.out is not None  # a FIFO the user named is written into
    if isinstance(result, SweepResult):
        if not any(row.get("a") is not None for row in result.rows):  # the sweep itself draws none then
            then = f"; {resume_hint(folder)}" if result.status in ("interrupted", "running") else ""
            raise RunFolderError(f"{shown_name(folder)}: no point of the sweep has a fit (sweep {result.status}): "
                                 f"nothing to draw{then}")  # fmt: skip
        from ..runs.sweep import Sweep, write_sweep_figure

        out = _output(args, folder / "sweep.png")
        write_sweep_figure(out, Sweep.recorded(folder), result.rows, devices=named, kept=REDRAWN)
    else:
        done, requested = result.realizations
        if not done:  # the run itself draws none then (``plot_wanted``)
            raise RunFolderError(f"{shown_name(folder)}: no realization finished (0 of {requested}, run "
                                 f"{result.status}): nothing to draw; `frictionlab resume {command_word(folder)}` "
                                 "computes them")  # fmt: skip
        from ..runs.figures import CurveFigure
        from ..runs.results import write_curve_figure

        figure = CurveFigure.read_back(result)
        out = _output(args, folder / "plot.png")
        write_curve_figure(out, figure, devices=named, kept=REDRAWN)
    if not args.quiet:
        print(f"wrote {shown_name(out)}")
    return ExitCode.OK


def _output(args, default: Path) -> Path:
    """The file to write, checked before drawing: --out, else ``default`` in the folder, where
    whatever is there (a file, a link, a FIFO) is kept unless --force."""
    import os

    from ..io.files import check_output_file

    if args.out is None and os.path.lexists(default):
        if os.path.isdir(default):  # never replaced, --force or not
            raise OutputRefused(f"{shown_name(default)} is a folder: move it aside, or give --out FILE.png to write "
                                "another file")  # fmt: skip
        if not args.force:
            raise OutputRefused(f"{shown_name(default)} exists: give --force to replace it, or --out FILE.png to "
                                "write another")  # fmt: skip
    return check_output_file(args.out or default, "--out", force=args.force)
