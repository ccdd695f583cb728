"""What the source paper (Benad 2012) reports for its Figs. 2 to 5, and running
frictionlab's presets of those figures (``presets/benad2012-fig*.yaml``)."""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import FrictionlabError, OutputRefused, RunError, command_word, first_names, short_repr, shown_name
from ..options import RunOptions
from ..preset import build_scene, first_unlike, read_preset
from ..runs.rundir import STATE_FILE, RunDirectory, json_copy, same_preset
from ..runs.runfolder import output_subfolder
from ..runs.runner import check_memory, read_back, run_to_folder
from ..compute.signals import WorkInterrupted, interrupted_since, mark
from ..runs.sweep import check_sweep_folder, plan_sweep, run_sweep


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
    setup: dict[str, float] = field(default_factory=dict)  # what the title states: dotted path -> value
    swept: tuple[str, ...] = ()  # the paths its preset sweeps (none: a single run)


def _as_paper(hurst: float | None, stop: float) -> dict[str, float]:
    """A figure's setup as its title states it: H (None: swept) and the forces 1..stop."""
    return {**({"spectrum.params.hurst": hurst} if hurst is not None else {}), "loading.start": 1.0, "loading.stop": stop}


FIGURES = (
    PaperFigure("fig2", "benad2012-fig2.yaml", "Fig. 2: H = 1, F = 1..20", 1.8847, 0.0805, {1.0: 4.0, 20.0: 12.0},
                setup=_as_paper(1.0, 20.0)),
    PaperFigure("fig3", "benad2012-fig3.yaml", "Fig. 3: H = 1, F = 1..500", 1.5289, 0.0614, {500.0: 40.0},
                setup=_as_paper(1.0, 500.0)),
    PaperFigure("fig4", "benad2012-fig4.yaml", "Fig. 4: H = 0.5, F = 1..20", 2.6252, 0.1341, {},
                "the paper: the log fit is visibly poorer than at H = 1; contact counts not stated", _as_paper(0.5, 20.0)),
    PaperFigure("fig5", "benad2012-fig5.yaml", "Fig. 5: a and b against H, each point as Fig. 2", 2.9, 0.14, {},
                "the paper: a about 2.9 and b about 0.14 near H = 0.7", _as_paper(None, 20.0), ("spectrum.params.hurst",)),
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

    @property
    def scenes(self) -> list:
        """What it runs: the sweep's points' scenes, or its one scene."""
        return [point.scene for point in self.sweep.points] if self.sweep else [self.scene]

    def preset_rms_height(self) -> str:
        """The rms height h of a sweep's preset, as the text shows it."""
        return f"{self.sweep.base['spectrum']['params'].get('rms_height'):g}"


def find_presets(presets_dir: str | Path | None) -> Path:
    from ..preset.builtin import preset_folder

    names = [fig.preset for fig in FIGURES]
    return preset_folder(presets_dir, names, f"the paper's presets ({', '.join(names)})")


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
        _check_swept(fig, path, tuple(run.sweep.paths) if run.sweep else ())
        _check_setup(fig, path, run.scenes)
        runs.append(run)
    return runs


def _check_swept(fig: PaperFigure, path: Path, swept: tuple[str, ...]) -> None:
    """FrictionlabError unless the preset sweeps what the figure does: Fig. 2 swept over seeds was
    reported as 'Fig. 5 at H = 1', its seeds as H; Fig. 5 without its sweep as 'a and b against H'."""
    if swept != fig.swept:
        said = f"sweeps {', '.join(swept)}" if swept else "has no sweep (a single run)"
        wanted = f"a sweep of {', '.join(fig.swept)} alone" if fig.swept else "a single run (no sweep)"
        raise FrictionlabError(
            f"{shown_name(path)}: sweep: the preset {said}, but the report shows it as '{fig.title}', {wanted}; give "
            f"the paper's preset (frictionlab presets copy {fig.preset.removesuffix('.yaml')}), or run yours with "
            "frictionlab run"
        )


def _check_setup(fig: PaperFigure, path: Path, scenes: list) -> None:
    """FrictionlabError unless every scene is what the figure's title states (``setup``): a
    preset of H = 0.5 in benad2012-fig2.yaml was reported as 'Fig. 2: H = 1' beside the paper's numbers."""
    for scene in scenes:
        if (unlike := first_unlike(scene.resolved(), fig.setup)) is not None:
            dotted, value, stated = unlike
            raise FrictionlabError(
                f"{shown_name(path)}: {dotted} is {short_repr(value)}, but the report shows this preset as '{fig.title}' beside "
                f"the paper's numbers ({dotted} = {stated:g}); give the paper's preset (frictionlab presets copy "
                f"{fig.preset.removesuffix('.yaml')}), or run yours with frictionlab run"
            )


def continuing(options: RunOptions, folder: Path, scene=None) -> RunOptions:
    """``options`` resuming what a report run before into this --out left in ``folder`` (a run of
    ``scene``'s preset, stopped or finished; a sweep's folder when ``scene`` is None), unless
    --force: it was run again from its start, the work of a report stopped by Ctrl-C (or of a
    `frictionlab resume` of its figure, as the message said) thrown away."""
    if options.force:
        return options
    if scene is None:
        return replace(options, resume=os.path.lexists(folder / "sweep.json"))  # it reads back its own points only
    try:
        state = RunDirectory(folder).state()
    except FrictionlabError:
        return options  # damaged: the fresh run says how
    ours = state is not None and same_preset(state, json_copy(scene.resolved()), scene)
    return replace(options, resume=ours)


def own_force(options: RunOptions, folder: Path) -> RunOptions:
    """``options`` for a run of the report into ``folder``: --force replaces what frictionlab
    wrote there (a run's or a sweep's, run afresh), never a folder of other files, which is
    refused as without it (--force wrote a figure's run over the user's summary.json)."""
    return options if not options.force or _holds_a_run(folder) else replace(options, force=False)


def _holds_a_run(folder: Path) -> bool:
    return any(os.path.lexists(folder / name) for name in (STATE_FILE, "sweep.json"))


def _check_folder(run: FigureRun, options: RunOptions) -> None:
    """Refuse what a figure's run refuses in its folder (a folder of the user's files, another
    preset's run): Figs. 2 and 3 ran for minutes before Fig. 4's folder was refused."""
    own = own_force(options, run.folder)
    try:
        if run.sweep is not None:
            check_sweep_folder(run.sweep, run.folder, own.force)
        elif not continuing(own, run.folder, run.scene).resume:
            RunDirectory(run.folder, force=own.force).check_fresh(run.scene)
    except OutputRefused:
        refuse_foreign_files(run.folder)
        raise  # another preset's run: its message says what --force does


def refuse_foreign_files(folder: Path) -> None:
    """OutputRefused for a folder the report runs into (a figure's, a reading's) that holds files
    no frictionlab run wrote: --force never writes there (``own_force``), so the run's own advice,
    --force, would not help; nothing when it holds a run, or nothing at all."""
    if _holds_a_run(folder) or not folder.is_dir() or not (names := sorted(p.name for p in folder.iterdir())):
        return
    raise OutputRefused(f"{shown_name(folder)} holds files that no frictionlab run wrote ({first_names(names)}): the report "
                        "writes its runs only into new or empty folders or its own, --force or not; move them aside, "
                        "or give another --out") from None  # fmt: skip


def _check_memory_ahead(runs: list[FigureRun], options: RunOptions) -> None:
    """Refuse (RunError), before any figure runs, a report one of whose runs does not fit in
    memory (each run's own check, ``runner.check_memory``): not once the figures before it ran."""
    if not options.memory_check:
        return
    for run in runs:
        for scene in run.scenes:
            try:
                check_memory(scene, replace(options, resume=False))
            except RunError as exc:
                raise RunError(f"the report starts nothing: {run.figure.key} does not fit: {exc} Of that advice, a "
                               "preset's setting applies to a copy of the presets (--presets DIR); --workers and a "
                               "higher limit do, or more memory free.") from None  # fmt: skip


def kept_in(out_dir: Path) -> str:
    """What a report that stopped keeps, and how to go on."""
    return f"the runs that finished are kept in {shown_name(out_dir)}: the report run again with the same --out continues them"


def _run(run: FigureRun, options: RunOptions, progress: bool) -> None:
    """Run (or continue) one figure's run; with ``progress``, its progress on stderr."""
    from ..progress import ProgressReporter, SweepProgress

    if run.sweep is not None:
        listeners = [SweepProgress()] if progress else []
        own = continuing(own_force(options, run.folder), run.folder)
        run.sweep_outcome = run_sweep(run.sweep, run.folder, own, plot=False, listeners=listeners)
    else:
        run.outcome = run_or_read_back(run.scene, run.folder, options, [ProgressReporter()] if progress else [])


def run_or_read_back(scene, folder: Path, options: RunOptions, listeners: list):
    """The outcome of ``scene`` run into ``folder``, continuing what an earlier report left there
    (``continuing``); a run it completed is read back as it is, its files (its recorded wall time) kept."""
    options = continuing(own_force(options, folder), folder, scene)
    if options.resume:
        with RunDirectory(folder):  # not while another process runs it
            outcome = read_back(scene, folder, listeners)
        if outcome is not None:
            return outcome
    return run_to_folder(scene, folder, options, listeners=listeners)[0]


def run_figures(presets: Path, out_dir: Path, options: RunOptions = RunOptions(), *, progress: bool = False) -> list[FigureRun]:
    """Run each figure's preset into ``out_dir``, every preset checked first; with
    ``progress``, each run's progress on stderr."""
    runs = plan_figures(presets, out_dir)
    for run in runs:  # a link at a figure's folder, or one its run refuses, refused before any figure runs
        output_subfolder(out_dir, run.figure.key, "run the report again", make=False)
        _check_folder(run, options)
    _check_memory_ahead(runs, options)
    for run in runs:
        fig, path = run.figure, run.preset_path
        output_subfolder(out_dir, fig.key, "run the report again")
        seen = mark()
        try:
            _run(run, options, progress)
        except RunError as exc:  # its own memory check (this process grew), a figure not written: the others stay
            raise RunError(f"{str(exc).rstrip('.')}; {kept_in(out_dir)}") from None
        status = (run.sweep_outcome or run.outcome).status
        if status in ("interrupted", "cancelled"):
            how = (f"frictionlab run {command_word(path)} --out {command_word(run.folder)} --resume" if run.sweep is not None
                   else f"frictionlab resume {command_word(run.folder)}")  # fmt: skip
            raise WorkInterrupted(f"{fig.key} ended interrupted in {shown_name(run.folder)} (the report run again with the "
                                  f"same --out continues it, or `{how}` alone)")  # fmt: skip
        if interrupted_since(seen):  # the signal came as its last realizations ran: it completed
            raise WorkInterrupted(f"{fig.key} completed in {shown_name(run.folder)}")
        if (unfit := _without_fit(run)) is not None:  # nothing to draw or tell for it: said, never a traceback
            raise RunError(f"{fig.key} has no fit ({unfit}); {kept_in(out_dir)}")
    return runs


def _without_fit(run: FigureRun) -> str | None:
    """Why a figure's run (one of its sweep's points) has no fit, None if it has every one."""
    if run.sweep_outcome is None:
        return None if run.outcome.fit is not None else str(run.outcome.error or run.outcome.status)
    for point in run.sweep_outcome.results:
        if point.fit is None:
            return f"sweep point {point.point.number} ({point.point.describe()}): {point.error or point.status}"
    return None
