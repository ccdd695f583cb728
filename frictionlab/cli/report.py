"""``frictionlab report``: reproduce the source paper's Figs. 2 to 5 (``frictionlab.paper``)."""

from __future__ import annotations

import os
import re

from ..errors import ExitCode, FrictionlabError, refuse_unusable_matplotlib, shown
from .console import stderr_log
from .options import add_workers_option, run_options

MAX_REPLICATES = 100  # each is a full run of every reading


def add_parser(sub) -> None:
    p = sub.add_parser(
        "report",
        help="run the source paper's Figs. 2 to 5 and write REPRODUCTION.md with figures",
        description="Reproduce the source paper's Figs. 2 to 5 from the built-in presets and write a report "
        "(markdown and figures); --readings adds the readings of the paper's method (minutes).",
        epilog="examples:\n  frictionlab report --out runs/report\n  frictionlab report --readings --json",
    )
    p.add_argument("--presets", metavar="DIR", help="folder with benad2012-fig2..5.yaml (default: ./presets if it holds them, else the built-in presets)")
    p.add_argument("--out", metavar="DIR", help="output folder (default: a new runs/report-<timestamp>)")
    p.add_argument("--markdown", metavar="FILE", help="the report (default: REPRODUCTION.md in --out)")
    p.add_argument("--figures", metavar="DIR", help="PNG folder (default: figures/ in --out); a file is refused")
    p.add_argument("--force", action="store_true", help="overwrite an earlier report, its figures and runs (run "
                   "afresh), and a --markdown you name; never files it did not write: an --out that is not a "
                   "report's, or a figure in --figures that no report drew, is refused")
    add_workers_option(p, "all cores")
    p.add_argument("--readings", action="store_true", help="also run the readings of the paper's method (slower)")
    p.add_argument("--replicates", type=int, default=1, metavar="K",
                   help="with --readings: run each reading on K independent ensembles (the preset's seed, then seeds "
                   "from one SeedSequence) and report the spread of a and b between them (default 1)")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.add_argument("--json", action="store_true", help="print where the report and its figures are, as JSON")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    if not 1 <= args.replicates <= MAX_REPLICATES:
        raise FrictionlabError(f"--replicates must be a whole number from 1 to {MAX_REPLICATES}. Got {args.replicates} instead.")
    if args.replicates != 1 and not args.readings:
        raise FrictionlabError(f"--replicates {args.replicates} needs --readings: only the readings run on several ensembles")
    refuse_unusable_matplotlib()  # before paper.reproduce's import of its figures' module
    from ..paper.reproduce import write_report

    path = write_report(  # interrupted: signals.WorkInterrupted, said by cli.main with its exit code
        presets_dir=args.presets, out_dir=args.out, markdown_path=args.markdown, figures_dir=args.figures,
        options=run_options(workers=args.workers, force=args.force), readings=args.readings, replicates=args.replicates,
        log=stderr_log(args.quiet),
        quiet=args.quiet,
    )  # fmt: skip
    if args.json:  # the figures the report shows, as its image links name them
        images = re.findall(r"!\[[^\]]*\]\(([^)\s]+)\)", path.read_text(encoding="utf-8"))
        figures = list(dict.fromkeys(os.path.normpath(path.parent / image) for image in images))
        from .jsonout import emit

        emit("report", {"report": str(path), "figures": figures})
    else:
        print(shown(path))
    return ExitCode.OK
