"""``frictionlab exact3d``: run the study's ensembles and write the page
exact-3d-law.md with its figures (exact-3d-law/*.png) beside it."""

from __future__ import annotations

import os
import platform
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..compute.dask_session import one_dask_cluster
from ..errors import FrictionlabError, OutputRefused, RunError, command_word, shown_name
from ..io.files import atomic_write, output_path_problem, refuse_unreplaceable
from ..plugin.listeners import format_duration
from ..options import RunOptions
from ..runs.rundir import new_run_folder
from ..runs.runfolder import output_subfolder
from ..preset.seeds import realization_rng
from ..compute.signals import WorkInterrupted
from .evidence import MANY_SPOTS
from .evidence_text import (
    convergence_table,
    convergence_text,
    definitions,
    few_spots_text,
    gradient_table,
    gradient_text,
    limitations,
    model_table,
    nayak_text,
)
from .figures import plot_convergence, plot_few_spots, plot_gradient, plot_kappa, plot_nayak, plot_xi_against_f
from .markdown import (
    FEW_TEXT,
    WINDOW_TEXT,
    YASTREBOV,
    answer,
    ensemble_text,
    law_table,
    missing_text,
    paired_table,
    plan_status,
    self_averaging_text,
    surfaces_table,
)
from .markdown import convergence_table as ensembles_table
from .markdown import gradient_text as spectral_text
from .numbers import Numbers, study_numbers
from .plan import (
    FULL,
    MAIN,
    MIN_PIXELS_QUOTED,
    QUICK,
    Plan,
    StudyRuns,
    check_runs_folder,
    find_presets,
    preset_name,
    run_plan,
)

PAGE = "exact-3d-law.md"
FIGURES_DIR = "exact-3d-law"
FIGURES = ("xi-vs-f.png", "kappa.png", "convergence.png", "gradient.png", "nayak.png", "few-spots.png")
PLOTS = (plot_xi_against_f, plot_kappa, plot_convergence, plot_gradient, plot_nayak, plot_few_spots)


def page_paths(out_dir: Path, *, force: bool) -> tuple[Path, Path]:
    """The page and its figures folder in ``out_dir``; existing ones are refused unless ``force``,
    and so is an ``out_dir`` that cannot be a folder."""
    problem = output_path_problem(out_dir)
    if problem:
        raise OutputRefused(f"--out: {problem}; give a folder for the page")
    page, figures = out_dir / PAGE, output_subfolder(out_dir, FIGURES_DIR, "write the page again", make=False)
    taken = [p for p in (page, *(figures / name for name in FIGURES)) if os.path.lexists(p)]
    refuse_unreplaceable(taken, "exact 3D study", "give another --out")
    if taken and not force:
        raise OutputRefused(f"the page would overwrite {', '.join(map(str, taken[:3]))}: give another --out, or --force")
    return page, figures


def _refuse_out_inside_runs(out_dir: Path, runs_dir: Path) -> None:
    """Refuse an --out below --runs: --out RUNS/h0.3-n64-mdr wrote the page and its figures into
    an ensemble's run folder (--force or not), and any other would be a stranger there, for which
    the next --runs RUNS is refused."""
    out, runs = os.path.realpath(out_dir), os.path.realpath(runs_dir)
    if out.startswith(runs + os.sep):
        raise OutputRefused(f"--out {shown_name(out_dir)} is inside the runs folder {shown_name(runs_dir)}, which holds "
                            "only the ensembles' runs: give the runs folder itself (the default) or one outside it")  # fmt: skip


def same_surfaces(runs: StudyRuns) -> bool:
    """Whether the coarsest and the finest finished grid of the first H hold the same surface
    (realization 0) at the coarse grid's points."""
    grids = runs.exact_grids(runs.hursts()[0])
    coarse, fine = grids[0], grids[-1]
    heights = [e.scene.spectrum.generate(realization_rng(e.scene.preset.seed, 0)).heights for e in (coarse, fine)]
    stride = fine.points // coarse.points
    sampled = heights[1][::stride, ::stride]
    return sampled.shape == heights[0].shape and bool(np.allclose(sampled, heights[0], rtol=0, atol=1e-9 * heights[0].std()))


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return f"{cores} cores of an {cpu}, {platform.system()} {platform.release()}, Python {platform.python_version()}"


def write_page(
    out_dir: str | Path | None = None,
    *,
    runs_dir: str | Path | None = None,
    quick: bool = False,
    finished_only: bool = False,
    presets_dir: str | Path | None = None,
    options: RunOptions = RunOptions(),
    plan: Plan | None = None,
    command: str | None = None,
    dpi: int = 90,
    log: Callable[[str], None] = lambda text: None,
) -> Path:
    """Run the study (``QUICK`` or ``FULL``, or ``plan``) and write the page and its figures
    into ``out_dir`` (default: the runs folder). Runs go to ``runs_dir`` (default: a new
    ``runs/exact3d-<timestamp>``); giving an earlier one resumes it. ``finished_only``: run
    nothing, write the page from the ensembles of ``runs_dir`` that finished (the page lists
    the others). Returns the page's path."""
    plan = plan or (QUICK if quick else FULL)
    if finished_only and not runs_dir:
        raise FrictionlabError("--finished-only writes the page from the runs of an earlier study: give its --runs DIR")
    if finished_only and not Path(runs_dir).is_dir():  # not "holds no finished ensemble": it holds nothing
        what = "is not a folder" if os.path.lexists(runs_dir) else "does not exist"
        raise FrictionlabError(f"--runs {shown_name(runs_dir)} {what}: --finished-only writes the page from the runs folder of an "
                               "earlier study: give that folder")  # fmt: skip
    if out_dir:  # refused before a default runs folder is made
        page_paths(Path(out_dir), force=options.force)
    if runs_dir and not finished_only:  # --finished-only writes nothing into it: any folder is read
        check_runs_folder(Path(runs_dir), force=options.force, own=(PAGE, FIGURES_DIR))
    presets = find_presets(presets_dir, plan)  # refused before a default runs folder is made
    made = not runs_dir
    runs_dir = Path(runs_dir) if runs_dir else new_run_folder(f"exact3d-{plan.name}")
    command = command or _command(quick, out_dir, runs_dir, finished_only)  # names a default runs folder too
    out_dir = Path(out_dir) if out_dir else runs_dir
    _refuse_out_inside_runs(out_dir, runs_dir)
    page, figures = page_paths(out_dir, force=options.force)
    try:
        with one_dask_cluster(options):  # on Dask, every ensemble's run uses one client and cluster
            runs = run_plan(presets, runs_dir, plan, options, compute=not finished_only, log=log)
    except WorkInterrupted as exc:
        raise WorkInterrupted(f"{exc}; no page written") from None
    except RunError:  # refused before it began (the memory check): the runs folder made for it goes
        if made and not any(runs_dir.iterdir()):
            runs_dir.rmdir()
        raise
    if not runs.hursts():
        raise FrictionlabError(
            f"{shown_name(runs_dir)} holds no finished exact ensemble with MDR beside it: nothing to write a page from; "
            f"run the study (without --finished-only) with --runs {command_word(runs_dir)}"
        )
    numbers = study_numbers(runs)
    log(f"exact3d: {len(runs.ensembles)} ensembles in {format_duration(runs.seconds)}; drawing")
    for name, plot in zip(FIGURES, PLOTS, strict=True):
        atomic_write(figures / name, lambda fh, plot=plot: plot(runs, numbers, fh, dpi=dpi), binary=True)
    text = page_text(runs, numbers, command, machine(), _command(quick, out_dir, runs_dir, False))
    atomic_write(page, lambda fh: fh.write(text))
    return page


def _command(quick: bool, out_dir: str | Path | None, runs_dir: str | Path | None, finished_only: bool) -> str:
    """The command that regenerates the page: with the runs folder it was given, so
    that rerunning it reads those runs back instead of computing them again."""
    return (f"frictionlab exact3d{' --quick' if quick else ''}" + (f" --out {command_word(out_dir)}" if out_dir else "")
            + (f" --runs {command_word(runs_dir)}" if runs_dir else "") + (" --finished-only" if finished_only else "")
            + " --force")  # fmt: skip


def wall_time_text(recorded: float, compute: float, cores: int) -> str:
    """The study's wall time as its time file records it (``recorded`` seconds), or, where
    that is less than its ``compute`` seconds shared among the machine's ``cores``
    (invocations stopped before they recorded theirs), that bound."""
    bound = compute / max(cores, 1)
    if recorded >= bound:
        return f"**{format_duration(recorded)}** of wall time (summed over the invocations that computed it, each up to its last finished ensemble)"
    return (
        f"at least **{format_duration(bound)}** of wall time (its compute shared among {cores} cores; the "
        f"invocations' own record, {format_duration(recorded)}, misses those that were stopped before they "
        "recorded theirs)"
    )


def page_text(runs: StudyRuns, numbers: Numbers, command: str, machine_text: str, finish_command: str) -> str:
    plan = runs.plan
    compute = sum(e.outcome.compute_seconds for e in runs.ensembles)  # seconds: the surfaces' solve times summed
    first = runs.find(runs.hursts()[0])
    o = first.outcome
    figures = FIGURES_DIR
    presets = ", ".join(f"`presets/{preset_name(h)}`" for h in plan.hursts)
    tolerance = first.scene.solver.tolerance()
    side = first.spacing * first.points
    grids = sorted({e.points for e in runs.ensembles if e.exact and e.family == MAIN})
    finish = ([f"The plan's other ensembles are computed (and this page written again) by `{finish_command}`, "
               "which resumes the finished ones without computing them again.", ""] if runs.missing else [])  # fmt: skip
    quick = plan.name == "quick"
    lines = [
        "# The exact 3D law",
        "",
        "How the rms slope over the real contact area of a self-affine surface grows with load when the contact "
        "is solved exactly (an elastic half-space, boundary elements), and how far the method of reduction of "
        "dimensionality (MDR) is from it.",
        "",
        *(["**This page comes from the quick plan: small grids and ensembles, none resolving the short cut-off. "
           "Its numbers are not converged and answer nothing; they show the pipeline.**", ""] if quick else []),
        "Regenerate this page, its figures and tables with",
        "",
        "```",
        command,
        "```",
        "",
        *finish,
        f"The {'ensembles that finished' if runs.missing else f'study ({plan.name} plan)'} took "
        f"{wall_time_text(runs.seconds, compute, os.cpu_count() or 1)} on {machine_text}, a machine shared with "
        f"other jobs, and **{format_duration(compute)}** of compute (the surfaces' "
        "solve times summed, so waiting for a busy CPU counts in it; each ensemble's is in the ensembles' table). "
        "`--quick` runs the same pipeline on small grids and ensembles in half a minute of one core (not converged).",
        "",
        *definitions(runs, numbers),
        "## What ran",
        "",
        *plan_status(runs),
        "",
        missing_text(runs),
        "",
        "## The answer",
        "",
        *answer(runs, numbers),
        "",
        f"![xi against f for each H: exact on every grid, MDR and the comparison family; per-surface skewness]"
        f"({figures}/{FIGURES[0]})",
        "",
        "These surfaces are not the source study's lines: there the MDR line had 10^5 points and f was of order "
        f"1e-9, a few points in contact; here f runs over {o.f.min():.3g} to {o.f.max():.3g}, from "
        f"{o.real_area_corrected.min():.2%} to {o.real_area_corrected.max():.1%} of real contact on the main family. "
        "The source study's 3D law (a about 2.9, b about 0.14 near H = 0.7) belongs to its regime; the numbers here "
        "belong to this one, exact and MDR alike.",
        "",
        "## The law on the finest grid",
        "",
        "a and b are the least-squares fit of ξ = a + b ln f to the mean curve, with 95 % percentile-bootstrap "
        f"intervals over the surfaces; the fit is a description, tested against other models below. A grid with "
        f"fewer than {MIN_PIXELS_QUOTED} pixels on the short cut-off is marked and not quoted. The Nayak parameter "
        "is the mean over the surfaces. The MDR interval is from the two ensembles' standard errors.",
        "",
        *law_table(runs, numbers),
        "",
        "## Convergence in the grid",
        "",
        f"The grids sample the same surfaces ({'the same modes and random phases: a grid' + chr(39) + 's heights are those of a finer one at its points' if same_surfaces(runs) else 'the same spectrum'}) "
        f"with {', '.join(f'{n}²' for n in grids)} pixels, that is "
        + ", ".join(f"{n * first.short_cutoff / side:g}" for n in grids)
        + f" pixels on the short cut-off λs = {first.short_cutoff:g}. The loads, F = {o.force.min():g} to "
        f"{o.force.max():g} in {o.force.size} log steps, are the same f on every grid. The Richardson limit "
        "Q + (Q - Q') / (2^p - 1) (grids doubled each time) from the three finest grids uses the observed order p; its interval comes from "
        "re-estimating p on every bootstrap draw (clipped to 0.5 to 4), so it holds the order's uncertainty.",
        "",
        *convergence_table(numbers),
        "",
        f"![a, b and kappa on the same surfaces against the pixels on the short cut-off]({figures}/{FIGURES[2]})",
        "",
        convergence_text(numbers),
        "",
        "## Which law? The model test",
        "",
        "Three models of ξ(f), each fitted by least squares: the log law a + b ln f, a power law c f^β, and a log "
        "law with curvature a + b ln f + c (ln f)². ΔBIC is each model's BIC above the best (0: the best; 2 or "
        "more: positive evidence against it); the runs test counts runs of like sign in the residuals (z below "
        "-2: a curve left in them). On the mean curve over all loads, and over the loads with at least "
        f"{MANY_SPOTS} contact spots per surface; per surface, how many prefer each model.",
        "",
        *model_table(runs, numbers),
        "",
        "## The real contact area and κ",
        "",
        "A contact pixel counts whole although the contact's edge crosses it, so the pixel count overestimates the "
        "real area by a strip along the perimeter, an error that shrinks only as one over the resolution. The area "
        f"here is corrected as {YASTREBOV} do (the column `real_area_corrected` of every `bem-halfspace` run). On a "
        "Hertz contact with 20 pixels on its radius it brings the area within 0.6 % of π a² where the count is 1 % "
        "to 1.5 % over (`tests/test_contact_area.py`).",
        "",
        f"κ is averaged over the loads whose mean contact fraction is {WINDOW_TEXT} for the number quoted, and "
        f"below {FEW_TEXT} apart (a handful of spots per surface: the few-spot regime below). The figure shows κ at "
        "every load against p / (E* g), with its 95 % bootstrap band, on every grid on the surfaces all grids ran, the pixel count's κ on the "
        "finest grid, and the literature: √(2π) = 2.51 at vanishing load on an infinite surface (Bush, Gibson and "
        "Thomas 1975), √(8/π) = 1.60 in Persson's theory, and about 2 to 2.3 in simulations of broad spectra at "
        "0.5 % to 5 % contact (Hyun et al. 2004; Campañá and Müser 2007; Prodanov, Dapp and Müser 2014; Yastrebov, "
        "Anciaux and Molinari 2017; van Dokkum et al. 2018).",
        "",
        f"![kappa against p / (E* rms gradient) for each H, with the literature]({figures}/{FIGURES[1]})",
        "",
        "### κ against the breadth of the spectrum",
        "",
        nayak_text(runs, numbers),
        "",
        f"![kappa against the Nayak parameter, main, broad-band and comparison families]({figures}/{FIGURES[4]})",
        "",
        "## g_r and κ_r: the rms gradient over the real contact",
        "",
        "g_r / g is ξ with the edge pixels weighted as the corrected area weighs them; κ_r replaces the surface's "
        "rms gradient by g_r. The drift is the slope of the mean κ (or κ_r) against ln p over the loads named, "
        "relative to its mean, with paired bootstrap intervals; κ_r is called closer to constant only where the "
        "paired difference of the two drifts' sizes excludes 0.",
        "",
        gradient_text(runs, numbers),
        "",
        *gradient_table(runs, numbers),
        "",
        f"![g_r / g, kappa and kappa_r against p / (E* g)]({figures}/{FIGURES[3]})",
        "",
        "## The few-spot regime",
        "",
        few_spots_text(runs, numbers),
        "",
        f"![contact spots per surface, the area against f, and its local exponent]({figures}/{FIGURES[5]})",
        "",
        "## Surfaces that self-average",
        "",
        f"The main family's long cut-off is {first.long_cutoff:g}, a quarter of the side {side:g}: each surface "
        "holds 16 cells of its longest wave and its heights are close to Gaussian one by one. The comparison "
        "family, the same spectrum with the long cut-off at the side, is dominated by its few longest waves. "
        "Skewness and kurtosis are those of each surface's heights (0 and 3 for a Gaussian); the Nayak parameter "
        "α = m0 m4 / m2² of its rows, each taken about its own mean as a profile trace is (m_n the spectral "
        "moments; 1 for a single wave, growing with the band). Counted about the surface's mean, the rows' own "
        "means add to m0 the variance of the waves along y alone, and α is larger: most where a few long waves "
        "carry much of the height, as in the comparison family.",
        "",
        *surfaces_table(runs, numbers),
        "",
        self_averaging_text(runs, numbers),
        "",
        "## MDR on the same surfaces",
        "",
        "MDR presses a line of springs, the MDR-equivalent line of the surface (length L = 2 √(A/π), spectrum "
        "C1D(q) = π q C2D(q), the same mean square height and gradient), at the same loads, so at the same f. That "
        "line depends on a surface only through its spectrum, which all surfaces of a family share: one random "
        f"line per surface is noisy, so each surface's prediction is averaged over {plan.mdr_lines} lines. MDR is "
        "built to keep the force against the approach; it does not keep the real area, and its fraction of "
        "springs in contact is not one. " + ensemble_text(runs),
        "",
        "## Every ensemble",
        "",
        *ensembles_table(runs, numbers),
        "",
        *paired_table(numbers.extra, "grid"),
        "",
        spectral_text(numbers),
        "",
        *paired_table(numbers.spectral, "grid, gradient"),
        "",
        *limitations(runs),
        "## The solver under it",
        "",
        f"`bem-halfspace`: FFT boundary elements (surface stiffness E*|q|/2) and a constrained conjugate gradient, "
        f"at its default tolerance ({tolerance:g} of the rms height). Its closed-form tests "
        "(`tests/test_bem_closed_forms.py`): a Hertz sphere on the periodic half-space (contact radius and "
        "approach against Hertz's, under force and indentation control), the Westergaard wave (full-contact "
        "pressure p* and the force under indentation control), a doubly sinusoidal surface (full-contact pressure "
        "exact; each peak Hertzian at small loads), and the Hertz cylinder on the half-plane; the corrected area "
        "against Hertz's π a² (`tests/test_contact_area.py`).",
        "",
        f"The presets are {presets}; each runs alone as `frictionlab run presets/exact3d-h08.yaml` (its 1024² grid "
        "and its own loads; the study presses every family at the plan's loads). The exact runs are ordinary runs: "
        "processes or Dask, the memory estimate before the start, resumable (`--runs` of an interrupted study "
        "resumes every ensemble, and `--finished-only` writes the page from those that finished); their folders hold "
        "the files of `frictionlab run` but plot.png, the figures here drawing the ensembles together.",
        "",
    ]
    return "\n".join(lines)
