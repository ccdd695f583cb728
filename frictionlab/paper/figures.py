"""What the source paper (Benad 2012) reports for its Figs. 2 to 5, and running
frictionlab's presets of those figures (``presets/benad2012-fig*.yaml``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..errors import FrictionlabError
from ..options import RunOptions
from ..preset import build_scene, read_preset
from ..runs.runner import run_to_folder
from ..compute.signals import WorkInterrupted, interrupted_since, mark
from ..runs.sweep import plan_sweep, run_sweep


@dataclass(frozen=True)
class PaperFigure:
    """What the paper reports for one figure."""

    key: str
    preset: str  # file name in the presets folder
    title: str
    a: float | None
    b: float | None
    counts: dict[float, float] = field(default_factory=dict)  # force -> mean points in contact
    note: str = ""


FIGURES = (
    PaperFigure("fig2", "benad2012-fig2.yaml", "Fig. 2: H = 1, F = 1..20", 1.8847, 0.0805, {1.0: 4.0, 20.0: 12.0}),
    PaperFigure("fig3", "benad2012-fig3.yaml", "Fig. 3: H = 1, F = 1..500", 1.5289, 0.0614, {500.0: 40.0}),
    PaperFigure("fig4", "benad2012-fig4.yaml", "Fig. 4: H = 0.5, F = 1..20", 2.6252, 0.1341, {},
                "the paper: the log fit is visibly poorer than at H = 1; contact counts not stated"),
    PaperFigure("fig5", "benad2012-fig5.yaml", "Fig. 5: a and b against H, each point as Fig. 2", 2.9, 0.14, {},
                "the paper: a about 2.9 and b about 0.14 near H = 0.7"),
)  # fmt: skip
PAPER_H07 = (0.7, 2.9, 0.14)  # H, a, b "about", as the paper states them
PAPER_POINTS_VS_H = ((1.0, 1.8847, 0.0805, "Fig. 2"), (0.5, 2.6252, 0.1341, "Fig. 4"))
COUNT_TARGETS = {1.0: 4.0, 20.0: 12.0}  # the paper's Fig. 2 contact counts, used to calibrate h


@dataclass
class FigureRun:
    figure: PaperFigure
    preset_path: Path
    folder: Path
    scene: object = None  # Scene (single run)
    outcome: object = None  # RunOutcome (single run)
    sweep: object = None  # sweep.Sweep (Fig. 5)
    sweep_outcome: object = None

    def preset_rms_height(self) -> str:
        """The rms height h of a sweep's preset, as the text shows it."""
        return f"{self.sweep.base['spectrum']['params'].get('rms_height'):g}"


def find_presets(presets_dir: str | Path | None) -> Path:
    from ..io.inputs import regular_file_problem
    from ..preset.builtin import builtin_folder

    candidates = [Path(presets_dir)] if presets_dir else [Path("presets"), *filter(None, [builtin_folder()])]
    for folder in candidates:
        if all((folder / fig.preset).is_file() for fig in FIGURES):
            return folder
    wanted = ", ".join(fig.preset for fig in FIGURES)
    given = Path(presets_dir) if presets_dir and Path(presets_dir).is_dir() else None
    problems = {fig.preset: regular_file_problem(given / fig.preset) for fig in FIGURES} if given else {}
    which = "; ".join(f"{name}: {problem}" for name, problem in problems.items() if problem)  # a FIFO, say
    which = f" (in {given}, {which})" if which else ""
    raise FrictionlabError(
        f"--presets: no folder with the paper's presets ({wanted}); looked in {', '.join(map(str, candidates))}{which}"
    )


def plan_figures(presets: Path, out_dir: Path) -> list[FigureRun]:
    """Each figure's preset read and checked (its scene built, or its sweep planned), none
    run: a bad preset is refused before minutes of the others' runs."""
    runs = []
    for fig in FIGURES:
        path = presets / fig.preset
        run = FigureRun(fig, path, out_dir / fig.key)
        data = read_preset(path)
        if data.get("sweep") is not None:
            run.sweep = plan_sweep(data, source=str(path))
        else:
            run.scene = build_scene(data, source=str(path))
        runs.append(run)
    return runs


def run_figures(presets: Path, out_dir: Path, options: RunOptions = RunOptions(), *, progress: bool = False) -> list[FigureRun]:
    """Run each figure's preset into ``out_dir``, every preset checked first; with
    ``progress``, each run's progress on stderr."""
    from ..progress import ProgressReporter, SweepProgress

    runs = plan_figures(presets, out_dir)
    for run in runs:
        fig, path = run.figure, run.preset_path
        seen = mark()
        if run.sweep is not None:
            listeners = [SweepProgress()] if progress else []
            run.sweep_outcome = run_sweep(run.sweep, run.folder, options, plot=False, listeners=listeners)
        else:
            listeners = [ProgressReporter()] if progress else []
            run.outcome, _ = run_to_folder(run.scene, run.folder, options, listeners=listeners)
        status = (run.sweep_outcome or run.outcome).status
        if status in ("interrupted", "cancelled"):
            how = (f"frictionlab run {path} --out {run.folder} --resume" if run.sweep is not None
                   else f"frictionlab resume {run.folder}")  # fmt: skip
            raise WorkInterrupted(f"{fig.key} ended interrupted in {run.folder} (continue it with `{how}`)")
        if interrupted_since(seen):  # the signal came as its last realizations ran: it completed
            raise WorkInterrupted(f"{fig.key} completed in {run.folder}")
    return runs
