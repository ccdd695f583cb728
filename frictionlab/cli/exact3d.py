"""``frictionlab exact3d``: the exact 3D law (``frictionlab.exact3d``): run the study and
write the page exact-3d-law.md with its figures."""

from __future__ import annotations

from ..errors import ExitCode, refuse_unusable_matplotlib, shown
from .console import stderr_log
from .options import add_workers_option, run_options


def add_parser(sub) -> None:
    p = sub.add_parser(
        "exact3d",
        help="xi against f in exact half-space contact for H = 0.3..1, beside MDR: write exact-3d-law.md",
        description="The exact 3D law: run the presets exact3d-h03..h10 on four grids of the same surfaces "
        "(exact half-space contact, 256² to 2048²) and MDR on their equivalent lines, with a broad-band family, a "
        "comparison family (long cut-off = side) and spectral gradients; fit xi = a + b ln f with bootstrap "
        "intervals, show its convergence on paired grids with a Richardson limit, test it against a power law and "
        "a log law with curvature, measure kappa and kappa_r (the rms gradient over the real contact) of the "
        "corrected contact area and the contact spots, and write the page exact-3d-law.md with its figures. The "
        "full plan takes many hours of 2 cores (run it resumably with --runs); --quick about half a minute of one core "
        "(not converged).",
        epilog="examples:\n  frictionlab exact3d --quick --out runs/exact3d-quick\n"
        "  frictionlab exact3d --out docs --runs runs/exact3d-full --force\n"
        "  frictionlab exact3d --out docs --runs runs/exact3d-full --finished-only --force",
    )
    p.add_argument("--quick", action="store_true", help="smaller grids and ensembles: about half a minute of one core, not converged")
    p.add_argument("--finished-only", action="store_true", help="run nothing: write the page from the ensembles of "
                   "--runs that finished; the page lists the plan's others as not run")
    p.add_argument("--out", metavar="DIR", help="folder of the page and its figures (default: the runs folder)")
    p.add_argument("--runs", metavar="DIR", help="folder of the ensembles' runs; an earlier one is resumed, one holding "
                   "other files is refused unless --force (default: a new runs/exact3d-<plan>-<timestamp>)")
    p.add_argument("--presets", metavar="DIR", help="folder with exact3d-h03..h10.yaml (default: ./presets if it holds them, else the built-in presets)")
    p.add_argument("--force", action="store_true", help="overwrite an existing page and its figures; write runs into a --runs folder holding other files")
    add_workers_option(p, "all cores")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    refuse_unusable_matplotlib()  # before exact3d.report's import of its figures' module
    from ..exact3d.report import write_page

    page = write_page(  # interrupted: signals.WorkInterrupted, said by cli.main with its exit code
        args.out, runs_dir=args.runs, quick=args.quick, finished_only=args.finished_only, presets_dir=args.presets,
        options=run_options(workers=args.workers, force=args.force),
        log=stderr_log(args.quiet),
    )  # fmt: skip
    print(shown(page))
    return ExitCode.OK
