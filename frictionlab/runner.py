"""Run one scene into one output folder: the single path every front end uses
(``frictionlab run``, the TUI, each point of a sweep), so they all write the
same files, hold the same lock and can all be resumed."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from . import engine
from .ensemble import RunOutcome
from .executors import dask_memory_limits, default_workers
from .memory import check_fits, check_worker_limits
from .preset import Scene
from .results import write_results
from .rundir import RunDirectory


def run_to_folder(
    scene: Scene,
    out_dir: str | Path,
    *,
    workers: int | None = None,
    listeners: Iterable[object] = (),
    cancel=None,
    executor: str | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    memory_check: bool = True,
    retries: int = 2,
    force: bool = False,
    dashboard: bool = False,
) -> tuple[RunOutcome, dict[str, Path]]:
    """Run ``scene`` and write its result files into ``out_dir``.

    ``out_dir`` is also the run directory: it is locked while the run goes on
    (a second run into it is refused), holds the resolved preset from the start
    and every chunk of realizations as it finishes. ``resume=True`` continues a
    run left there (interrupted, killed, crashed) with the same preset,
    computing only what is missing (after verifying every stored chunk).
    ``out_dir`` must be new, empty, or a run of this preset: anything else is
    refused unless ``force`` (see ``rundir``). ``memory_check`` refuses, before
    anything starts, a run whose estimated peak memory exceeds what is
    available (and on Dask, one whose realization exceeds a worker's memory
    limit). ``dashboard``: serve the Dask dashboard of the local cluster.

    What finished is written even when the run was cancelled or interrupted.
    Returns the outcome and the paths of the files written.
    """
    total = scene.preset.realizations
    count = min(total, default_workers() if workers is None else max(1, int(workers)))
    if memory_check:
        kind = executor or ("dask" if scheduler else "processes" if count > 1 else "serial")
        check_fits(scene, workers=count, executor=kind, remote_workers=bool(scheduler))
        if kind == "dask" and total > 1:  # each Dask worker (the first realization runs here)
            limits, usable = dask_memory_limits(scheduler, count)
            check_worker_limits(scene, limits, usable=usable)
    with RunDirectory(out_dir, force=force) as run_dir:
        restored = run_dir.start(scene, resume=resume)
        outcome = engine.run(
            scene,
            workers=workers,
            listeners=listeners,
            cancel=cancel,
            executor=executor,
            scheduler=scheduler,
            retries=retries,
            dashboard=dashboard,
            store=run_dir,
            restored=restored,
        )
        files = write_results(out_dir, scene, outcome)
        run_dir.finish(scene, outcome.status)
    return outcome, files
