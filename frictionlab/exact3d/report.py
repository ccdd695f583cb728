"""``frictionlab exact3d``: run the study's ensembles and write the page
exact-3d-law.md with its figures (exact-3d-law/*.png) beside it."""

from __future__ import annotations

import math
import os
import platform
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..dask_session import one_dask_cluster
from ..errors import OutputRefused
from ..files import atomic_write, output_path_problem
from ..listeners import format_duration
from ..options import RunOptions
from ..rundir import new_run_folder
from ..seeds import bootstrap_rng, realization_rng
from ..signals import WorkInterrupted
from .analysis import SMALL_LOAD_FRACTION, Kappa, contact_area_law
from .figures import plot_convergence, plot_xi_against_f
from .markdown import YASTREBOV, answer, convergence_table, ensemble_text, law_table, paired_extra_grids
from .plan import FULL, QUICK, Plan, StudyRuns, check_runs_folder, find_presets, preset_name, run_plan

PAGE = "exact-3d-law.md"
FIGURES_DIR = "exact-3d-law"
FIGURES = ("xi-vs-f.png", "convergence.png")


def page_paths(out_dir: Path, *, force: bool) -> tuple[Path, Path]:
    """The page and its figures folder in ``out_dir``; existing ones are refused unless ``force``,
    and so is an ``out_dir`` that cannot be a folder."""
    problem = output_path_problem(out_dir)
    if problem:
        raise OutputRefused(f"--out: {problem}; give a folder for the page")
    page, figures = out_dir / PAGE, out_dir / FIGURES_DIR
    taken = [p for p in (page, *(figures / name for name in FIGURES)) if os.path.lexists(p)]
    if taken and not force:
        raise OutputRefused(f"the page would overwrite {', '.join(map(str, taken[:3]))}: give another --out, or --force")
    return page, figures


def kappas_of(runs: StudyRuns) -> dict[tuple[float, int], Kappa]:
    """kappa of every exact ensemble, from its per-realization contact counts."""
    found = {}
    for e in runs.ensembles:
        if not e.exact:
            continue
        o = e.outcome
        length = o.force_unit / (o.stiffness * o.rms_height)  # L of f = F / (E* h L)
        area = math.pi * (length / 2) ** 2  # L = 2 sqrt(A / pi)
        pixels = e.points**2  # the study's grids are square
        found[(e.hurst, e.points)] = contact_area_law(
            o.per_realization["contact_count"] / pixels, o.force, area, o.stiffness,
            o.per_realization["slope_rms_line"], rng=bootstrap_rng(e.scene.preset.seed),
            bootstrap=runs.plan.bootstrap,
        )  # fmt: skip
    return found


def same_surfaces(runs: StudyRuns) -> bool:
    """Whether the coarsest and the finest grid of the first H hold the same surface
    (realization 0) at the coarse grid's points."""
    hurst = runs.plan.hursts[0]
    coarse, fine = runs.find(hurst, runs.plan.resolutions[0]), runs.find(hurst)
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
    presets_dir: str | Path | None = None,
    options: RunOptions = RunOptions(),
    plan: Plan | None = None,
    command: str | None = None,
    dpi: int = 90,
    log: Callable[[str], None] = lambda text: None,
) -> Path:
    """Run the study (``QUICK`` or ``FULL``, or ``plan``) and write the page and its figures
    into ``out_dir`` (default: the runs folder). Runs go to ``runs_dir`` (default: a new
    ``runs/exact3d-<timestamp>``); giving an earlier one resumes it. Returns the page's path."""
    plan = plan or (QUICK if quick else FULL)
    command = command or _command(quick, out_dir, runs_dir)
    if out_dir:  # refused before a default runs folder is made
        page_paths(Path(out_dir), force=options.force)
    if runs_dir:
        check_runs_folder(Path(runs_dir), force=options.force, own=(PAGE, FIGURES_DIR))
    runs_dir = Path(runs_dir) if runs_dir else new_run_folder(f"exact3d-{plan.name}")
    out_dir = Path(out_dir) if out_dir else runs_dir
    page, figures = page_paths(out_dir, force=options.force)
    try:
        with one_dask_cluster(options):  # on Dask, every ensemble's run uses one client and cluster
            runs = run_plan(find_presets(presets_dir, plan), runs_dir, plan, options, log=log)
    except WorkInterrupted as exc:
        raise WorkInterrupted(f"{exc}; no page written") from None
    kappas = kappas_of(runs)
    log(f"exact3d: {len(runs.ensembles)} ensembles in {format_duration(runs.seconds)}; drawing")
    atomic_write(figures / FIGURES[0], lambda fh: plot_xi_against_f(runs, fh, kappas, dpi=dpi), binary=True)
    atomic_write(figures / FIGURES[1], lambda fh: plot_convergence(runs, fh, dpi=dpi), binary=True)
    text = page_text(runs, kappas, command, machine())
    atomic_write(page, lambda fh: fh.write(text))
    return page


def _command(quick: bool, out_dir: str | Path | None, runs_dir: str | Path | None) -> str:
    """The command that regenerates the page: with the runs folder it was given, so
    that rerunning it reads those runs back instead of computing them again."""
    return (f"frictionlab exact3d{' --quick' if quick else ''}" + (f" --out {out_dir}" if out_dir else "")
            + (f" --runs {runs_dir}" if runs_dir else "") + " --force")  # fmt: skip


def page_text(runs: StudyRuns, kappas: dict, command: str, machine_text: str) -> str:
    plan = runs.plan
    finest = runs.find(plan.hursts[0])
    o = finest.outcome
    realizations = ", ".join(f"{m} on {n}²" for n, m in zip(plan.resolutions, plan.realizations))
    extra = "".join(f"; {m} on {n}² at H = {h:g}" for h, n, m in plan.extra)
    figures = FIGURES_DIR
    presets = ", ".join(f"`presets/{preset_name(h)}`" for h in plan.hursts)
    tolerance = finest.scene.solver.tolerance()
    lines = [
        "# The exact 3D law",
        "",
        "How the rms slope over the real contact area of a self-affine surface grows with load when the contact "
        "is solved exactly (an elastic half-space, boundary elements), and how far the method of reduction of "
        "dimensionality (MDR) is from it.",
        "",
        "Regenerate this page, its figures and tables with",
        "",
        "```",
        command,
        "```",
        "",
        f"This run ({plan.name} plan) took **{format_duration(runs.seconds)}** (wall time of the study, summed over "
        f"the invocations that ran it) on {machine_text}, with "
        f"{o.workers} worker process(es) per ensemble on a machine shared with other jobs. "
        + ("`--quick` runs the same pipeline on smaller grids and ensembles in a few minutes; its numbers are "
           "not converged." if plan.name == "quick" else
           "`--quick` runs the same pipeline on smaller grids and ensembles in a few minutes (its numbers are "
           "not converged); the full plan was sized to finish in tens of minutes on two shared cores."),
        "",
        "## The answer",
        "",
        *answer(runs, kappas),
        "",
        f"![xi against f for each H, exact on every grid and MDR on the same surfaces]({figures}/xi-vs-f.png)",
        "",
        "These surfaces are not the source study's lines: there the MDR line had 10^5 points and f was of order "
        "1e-9, a few points in contact; here f = F / (E* h L) runs over "
        f"{o.f.min():.3g} to {o.f.max():.3g} on surfaces whose band spans a factor "
        f"{finest.long_cutoff / finest.short_cutoff:g} in wavelength, from a few tenths of a percent to tens of "
        "percent of real contact. The study's 3D law (a about 2.9, b about 0.14 near H = 0.7) belongs to its regime; "
        "the numbers here belong to this one, exact and MDR alike.",
        "",
        f"## The law on the finest grid ({plan.resolutions[-1]}² pixels)",
        "",
        "ξ = rms |∇z| over the contact pixels / rms |∇z| over the whole surface (both components of the "
        "gradient, forward differences), averaged over the surfaces at each load; a and b are the least-squares "
        "fit of ξ = a + b ln f to that mean curve, with 95 % percentile-bootstrap intervals over the surfaces. "
        "MDR presses the MDR-equivalent line of each surface's spectrum (the same mean square height and "
        "gradient, length L) at the same loads, so at the same f. κ: below.",
        "",
        *law_table(runs, kappas),
        "",
        "## Convergence in the grid",
        "",
        f"Each surface has side {finest.spacing * finest.points:g} (length units), rms height 1, long cut-off "
        f"the side ({finest.long_cutoff:g}) and short cut-off λs = {finest.short_cutoff:g}; the grids sample the "
        + ("same surfaces (the same modes and random phases: a grid's heights are those of a finer one at its "
           "points) with " if same_surfaces(runs) else "same spectrum (not the same surfaces: the coarsest grid "
           "holds the short cut-off at its Nyquist mode, drawn otherwise) with ")
        + f"{', '.join(f'{n}²' for n in plan.resolutions)} pixels"
        + "".join(f" (and {n}² at H = {h:g})" for h, n, _ in plan.extra)
        + ", that is "
        + ", ".join(f"{n * finest.short_cutoff / (finest.spacing * finest.points):g}" for n in plan.resolutions)
        + " pixels on the short cut-off λs. The loads, "
        f"F = {o.force.min():g} to {o.force.max():g} in {o.force.size} log steps, are the same f = "
        f"{o.f.min():.3g} to {o.f.max():.3g} on every grid.",
        "",
        f"The real contact area on a grid carries a discretisation error that decays slowly as the pixels on the "
        f"short cut-off grow; {YASTREBOV} show how to measure and correct it, and that the growth of the area "
        "with load depends on the breadth of the spectrum, measured by the Nayak parameter α = m0 m4 / m2² "
        "(m_n the spectral moments of a profile; 1 for a single wave, large for a broad band). The α of these "
        "surfaces is in the first table (computed from the spectrum of one surface of each grid). Here the "
        "convergence is shown, not corrected: the same a, b and κ on each grid. The compute time is the "
        "surfaces' solve times summed (seconds of one core), kept in the run folders, so a regenerated page "
        "shows what the runs cost, not what reading them back took.",
        "",
        *convergence_table(runs, kappas),
        "",
        f"![a and b against the pixels on the short cut-off]({figures}/convergence.png)",
        "",
        *paired_extra_grids(runs),
        "",
        f"Ensemble sizes: {realizations}{extra}. " + ensemble_text(runs),
        "",
        "## Known-answer check: the contact area at small loads",
        "",
        f"At small loads the real contact area grows as A / A0 = κ p / (E* rms|∇z|), p = F / A0 the nominal "
        f"pressure; κ is about 1.6 in Persson's theory and about 2 in simulations. Here κ = (A/A0) E* rms|∇z| / p "
        f"per surface, averaged over the loads where the mean contact fraction is at most {SMALL_LOAD_FRACTION:.0%} "
        "(the two smallest loads if none is), then over the surfaces, with a bootstrap interval; rms|∇z| is the "
        "whole surface's, with the same forward differences as ξ.",
        "",
        "## The solver under it",
        "",
        f"`bem-halfspace`: FFT boundary elements (surface stiffness E*|q|/2) and the constrained conjugate "
        f"gradient of Polonsky and Keer, at its default tolerance ({tolerance:g} of the rms height). Its closed-form "
        "tests (`tests/test_bem_closed_forms.py`): a Hertz sphere on the periodic half-space (contact radius and "
        "approach against Hertz's, under force and indentation control), the Westergaard wave (full-contact "
        "pressure p* and the force under indentation control), a doubly sinusoidal surface (full-contact pressure "
        "exact; each peak Hertzian at small loads), and the Hertz cylinder on the half-plane.",
        "",
        f"The presets are {presets}; each runs alone as `frictionlab run presets/exact3d-h08.yaml`. "
        "The exact runs are ordinary runs: processes or Dask, the memory estimate before the start, resumable "
        "(`--runs` of an interrupted study resumes every ensemble).",
        "",
    ]
    return "\n".join(lines)
