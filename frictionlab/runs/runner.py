"""Run one scene into one output folder: the single path every front end uses
(``frictionlab run``, the TUI, each point of a sweep), so they all write the
same files, hold the same lock and can all be resumed."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING

from ..compute import engine
from ..compute.ensemble import RunOutcome
from ..compute.executors import dask_memory_limits
from ..errors import RunError, RunFolderError, command_word, process_limit, short_repr, shown_name, warn_user
from ..preset.loads import check_loads
from ..compute.memory import check_fits, check_worker_limits
from ..options import RunOptions
from ..preset import Scene
from .import_ahead import PlotImportAhead
from .runfolder import MAX_WALL_SECONDS, refuse_nothing_to_resume
from .results import add_plot, holds_results, plot_path, read_summary, results_on_disk, write_results
from ..compute.realization import RealizationResult
from .rundir import RunDirectory

if TYPE_CHECKING:
    from .figures import DrawingProcess

UNSAVED_WORK_SECONDS = 0.5  # of the run's time: finished chunks are written once this much is not on disk yet


class BatchedStore:
    """A run directory's chunks, written in batches: once the finished work not yet on
    disk reaches ``unsaved`` seconds of the run's time (its computing shared among the
    run's ``workers``), and at the end (``flush``). A run of under half a second writes one
    chunk and no compaction, whatever its worker count; a long one a chunk about every half
    second, what a kill -9 may lose besides the realizations running. A cancel, Ctrl-C or
    SIGTERM loses nothing: the run ends through ``flush``. ``awaited``: how many results the
    run computes; given, the batch holding the last of them is written as it comes, before
    the fit (under a limit on memory, OpenBLAS may end the process at the fit's first call,
    past Python's reach: the run's work is on disk by then)."""

    def __init__(self, run_dir: RunDirectory, unsaved: float | None = None, workers: int = 1, awaited: int | None = None):
        self.run_dir = run_dir
        self.unsaved = (UNSAVED_WORK_SECONDS if unsaved is None else unsaved) * max(1, workers)
        self.pending: list[RealizationResult] = []
        self.work = 0.0
        self.awaited = awaited

    def save_chunk(self, results: list[RealizationResult]) -> None:
        self.pending.extend(results)
        self.work += sum(r.seconds for r in results)
        if self.awaited is not None:
            self.awaited -= len(results)
        if self.work >= self.unsaved or (self.awaited is not None and self.awaited <= 0):
            self.flush()

    def flush(self, merge: bool = False) -> None:
        """Write what is pending as one chunk (its name: the range of its indices); with
        ``merge`` (a completed run), as one chunk with those already written (its compaction)."""
        batch, self.pending, self.work = sorted(self.pending, key=lambda r: r.index), [], 0.0
        try:
            merged = merge and self.run_dir.compact(batch)
        except (OSError, MemoryError):  # the merged chunk did not fit: the last batch apart, as a run not completed
            if batch:
                self.run_dir.save_chunk(batch)
            raise
        if not merged and batch:
            self.run_dir.save_chunk(batch)


def check_memory(scene: Scene, options: RunOptions) -> None:
    """Refuse, before anything starts, a run whose estimated peak memory exceeds what
    is available (on Dask, one whose realization exceeds a worker's memory limit)."""
    total = scene.preset.realizations
    workers = options.workers_for(total)
    kind = options.executor_for(workers)
    try:
        check_fits(scene, workers=workers, executor=kind, remote_workers=bool(options.scheduler))
        if kind == "dask" and total > 1:  # each Dask worker (the first realization runs here)
            limits, usable = dask_memory_limits(options.scheduler, workers)
            check_worker_limits(scene, limits, usable=usable)
    except RunError as exc:
        if not options.resume:
            raise
        # the advice may name the preset's points or realizations, which a resume cannot change
        raise RunError(f"{exc} A resume keeps the preset the run was started with: of that advice only the worker "
                       "count applies; otherwise resume it where more memory is available.") from None  # fmt: skip


def memory_check_before_reading(options: RunOptions) -> Callable[[Scene], None] | None:
    """What ``build_scene`` calls before a measured file is read whole: the run's memory
    check (None when ``options.memory_check`` is off), so an oversize map is refused unread."""
    return (lambda scene: check_memory(scene, options)) if options.memory_check else None


def check_one_realization(scene: Scene) -> None:
    """Refuse a scene whose one realization cannot fit even alone in this process (what
    ``validate`` checks, knowing no worker count), before a measured file is read whole."""
    check_fits(scene, workers=1, executor="serial")


def run_to_folder(
    scene: Scene,
    out_dir: str | Path,
    options: RunOptions = RunOptions(),
    *,
    listeners: Iterable[object] = (),
    cancel=None,
    plot: bool = True,
    on_results: Callable[[RunOutcome, dict[str, Path]], None] | None = None,
    drawer: DrawingProcess | None = None,
) -> tuple[RunOutcome, dict[str, Path]]:
    """Run ``scene`` as ``options`` say and write its result files into ``out_dir``.

    ``out_dir`` is also the run directory: it is locked while the run goes on
    (a second run into it is refused), holds the resolved preset from the start
    and every chunk of realizations as it finishes. ``options.resume`` continues a
    run left there (interrupted, killed, crashed) with the same preset,
    computing only what is missing (after verifying every stored chunk).
    ``out_dir`` must be new, empty, or a run of this preset: anything else is
    refused unless ``options.force`` (see ``rundir``). ``options.memory_check``
    refuses, before anything starts, a run whose estimated peak memory exceeds
    what is available (and on Dask, one whose realization exceeds a worker's
    memory limit).

    What finished is written even when the run was cancelled or interrupted.
    The figure comes last: ``on_results(outcome, files)`` is called once the
    numbers are written (a front end prints the fit there, so nobody waits for
    matplotlib), then plot.png is drawn unless ``plot`` is False or the preset
    says ``output.plot: false``: here, matplotlib imported while the workers compute, or by
    ``drawer`` (``figures.DrawingProcess``) where one is given, sent the figure as soon as the
    fit exists. Returns the outcome and the paths of the files written.
    """
    if options.resume:
        refuse_nothing_to_resume(out_dir)
    if options.memory_check:
        check_memory(scene, options)
    check_loads(scene)  # a unit the solver cannot take, a load past its arithmetic: before the folder is touched
    with RunDirectory(out_dir, force=options.force) as run_dir:
        earlier = recorded_seconds(run_dir) if options.resume else 0.0  # read before start() takes the manifest over
        restored = run_dir.start(scene, resume=options.resume)
        awaited = scene.preset.realizations - sum(r.ok for r in restored) if process_limit() else None
        store = BatchedStore(run_dir, workers=options.workers_for(scene.preset.realizations), awaited=awaited)
        outcome = None
        if plot and scene.preset.output.plot and drawer is None:  # matplotlib imported while the workers compute
            listeners = [*listeners, PlotImportAhead()]
        drawing = None
        try:
            outcome = engine.run(scene, options, listeners=listeners, cancel=cancel, store=store, restored=restored)
            if plot and drawer is not None and drawer.send(plot_path(out_dir), scene, outcome):
                drawing = drawer  # drawn there while the numbers are written here
        finally:  # whatever ended the run, what finished is written (a completed run's chunks as one)
            store.flush(merge=outcome is not None and outcome.status == "completed")
        # the sessions' time summed, as summary.json and the manifest record it (within what either holds)
        outcome.extra["recorded_seconds"] = recorded = min(earlier + outcome.elapsed, MAX_WALL_SECONDS)
        files = write_results(out_dir, scene, outcome)
        try:
            if on_results is not None:
                on_results(outcome, files)
            if plot:
                files = add_plot(out_dir, scene, outcome, files, drawing)
            drawn_before = plot_path(out_dir)
            if "plot" not in files and drawn_before.is_file() and not drawn_before.is_symlink():  # an earlier run's
                warn_user(f"{shown_name(drawn_before)} is an earlier run's figure, not this one's (none was drawn): "
                          f"`frictionlab plot {command_word(out_dir)} --force` draws this run's")  # fmt: skip
        finally:  # the numbers are written: the folder records how the run ended, even if the figure failed
            run_dir.finish(scene, outcome.status, seconds=recorded)
    return outcome, files


def recorded_seconds(run_dir: RunDirectory) -> float:
    """The wall time the run's earlier sessions took, as its manifest recorded it when the last
    of them ended (a resume adds its own, so a resume that computes nothing keeps it); before
    the manifest recorded it, the summary.json that session wrote. 0 when neither says (a
    first session killed before it ended) or the value is no time."""
    try:
        state = run_dir.state() or {}
        seconds = state.get("elapsed_seconds")
        if seconds is None and state.get("status") not in (None, "running"):  # a run of an older frictionlab
            seconds = read_summary(run_dir.path)[1].elapsed_seconds
    except RunFolderError:  # start() says what is wrong with the manifest; a damaged summary.json is rewritten
        return 0.0
    number = isinstance(seconds, (int, float)) and not isinstance(seconds, bool)
    if number and 0 <= seconds <= MAX_WALL_SECONDS:
        return float(seconds)
    if seconds is not None:  # a forged or damaged record: said, not lost without a word
        warn_user(f"{shown_name(run_dir.path)}: the run's recorded elapsed_seconds ({short_repr(seconds, 40)}) is no "
                  f"time from 0 to {MAX_WALL_SECONDS:g} s: its earlier sessions' time is not counted")  # fmt: skip
    return 0.0


def read_back(scene: Scene, folder: Path, listeners: Iterable[object] = (), plot: bool = True) -> RunOutcome | None:
    """The outcome of a completed run of ``scene`` found with its files in ``folder``, read back
    (its listeners hear it restored) without writing anything, its ``elapsed`` the wall time its
    summary.json recorded when it was computed and ``extra["read_back"]`` set: None where it must
    run again, which writes them again (``results_on_disk``; a curve.csv or realizations.npz not of
    its results, a damaged summary.json)."""
    if not results_on_disk(folder, scene, plot):
        return None
    done = RunDirectory(folder).completed_results(scene)
    if done is None or not holds_results(folder, scene, engine.run(scene, RunOptions(workers=1), restored=done)):
        return None  # its listeners hear it run again, not restored first
    try:
        recorded = read_summary(folder)[1].elapsed_seconds
    except RunFolderError:
        return None
    outcome = engine.run(scene, RunOptions(workers=1), listeners=listeners, restored=done)
    outcome.elapsed = recorded
    outcome.extra["read_back"] = True
    return outcome
