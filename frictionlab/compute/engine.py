"""The ensemble engine: runs the realizations of a scene on an executor and fans
lifecycle events out to listeners.

Seeding is per realization (see ``seeds``), so numbers do not depend on the
order, the worker count or the executor. Statistics are formed from arrays
indexed by realization, never in completion order.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Iterable
from dataclasses import dataclass, field

import pluggy

from .ensemble import Accumulator, RunOutcome
from .heap import hand_back_freed_memory
from ..errors import RunError
from .executors import make_executor, plan_chunks, sized_executor
from ..plugin.hookspecs import PROJECT_NAME
from ..plugin.listeners import RunListener
from ..options import RunOptions, default_workers
from ..preset import Scene
from .realization import RealizationResult, SolveListeners, compute_chunk_here
from .signals import CancelOnSignals, stop_if_interrupted

__all__ = ["RunInfo", "run"]


@dataclass(frozen=True)
class RunInfo:
    """What a run's listeners are told when it starts (``run_started``)."""

    scene: Scene
    total: int  # realizations of the run, including those restored on a resume
    workers: int
    executor: str = "serial"
    resumed: int = 0  # realizations restored from the run directory, not recomputed
    cores: int = 0  # the cores this process may use where the run started; 0: not known (a run replayed from its log)
    retried: int = 0  # realizations that had failed before the resume and run again
    # the default pool, which the first realization's time may still replace by this process
    # (``executors.sized_executor``): its workers are the most the run takes
    sized: bool = False
    # the restored results themselves (by index): a listener's running sums start from them
    restored: tuple[RealizationResult, ...] = field(default=(), repr=False)


def listener_manager(listeners: Iterable[object]) -> pluggy.PluginManager:
    pm = pluggy.PluginManager(PROJECT_NAME)
    pm.add_hookspecs(RunListener)
    for listener in listeners:
        pm.register(listener)
    pm.check_pending()
    return pm


def run(
    scene: Scene,
    options: RunOptions = RunOptions(),
    *,
    listeners: Iterable[object] = (),
    cancel=None,
    store=None,
    restored: Iterable[RealizationResult] = (),
    registry=None,
) -> RunOutcome:
    """Run the ensemble of ``scene`` as ``options`` say (workers, executor), telling
    ``listeners`` (``listeners.RunListener``) as it goes.

    ``restored``: results already finished (a resume): only the missing
    realizations, and those that had failed, are computed. ``store``: anything
    with ``save_chunk(results)``, called as each chunk finishes, before its
    listeners hear of it (the store decides when to write it).

    The first missing realization runs in this process; its time sizes the chunks and,
    for the default executor, says whether a process pool repays its start
    (``executors.sized_executor``): the outcome names the executor and workers that ran.

    The installed plugins that implement lifecycle hooks (of ``registry``, by default the
    process-wide one) hear the run as ``listeners`` do.

    ``cancel`` (anything with ``set()``/``is_set()``), Ctrl-C or SIGTERM ends the
    run at once: the realizations being solved are abandoned (they stop at their
    solver's next ``plugin.iteration_done`` and run again on resume); what finished is
    kept and summarised, and ``outcome.status``
    says ``cancelled`` or ``interrupted`` (``outcome.extra["signal"]``: which).
    """
    stop_if_interrupted()  # a command of several runs whose Ctrl-C was dropped (in a finalizer) starts no more
    hand_back_freed_memory()  # what the checks before the run freed: not kept beside its first realization
    total = scene.preset.realizations
    workers = options.workers_for(total)
    pool = make_executor(options, workers)
    accumulator = Accumulator(scene)
    retried = 0
    for result in restored:
        if result.ok:
            accumulator.add(result)
        else:
            retried += 1  # a failure is not kept: the realization runs again
    resumed = accumulator.done
    todo = [i for i in range(total) if i not in accumulator.results]
    info = RunInfo(
        scene=scene, total=total, workers=pool.workers, executor=pool.name, resumed=resumed, retried=retried,
        cores=default_workers(), sized=options.executor is None and pool.name == "processes",
        restored=tuple(accumulator.results[i] for i in sorted(accumulator.results)),
    )  # fmt: skip
    from ..plugin.registry import default_registry

    hooks = listener_manager([*listeners, *(registry or default_registry()).run_listeners()]).hook
    cancel = threading.Event() if cancel is None else cancel
    started = time.perf_counter()
    hooks.run_started(run=info)

    def load_done(index: int, done: int, total_loads: int) -> None:
        hooks.load_done(run=info, index=index, done=done, total=total_loads)

    def iteration_done(index: int, load: int, iteration: int, residual: float) -> None:
        hooks.iteration_done(run=info, index=index, load=load, iteration=iteration, residual=residual)

    listeners = SolveListeners(load_done, iteration_done)

    def record(results: list[RealizationResult]) -> None:
        if store is not None:
            store.save_chunk(results)
        for result in sorted(results, key=lambda r: r.index):
            accumulator.add(result)
            event = hooks.realization_done if result.ok else hooks.realization_failed
            event(run=info, result=result, done=accumulator.done, total=total)

    status, error = "completed", None
    with CancelOnSignals(cancel) as signals:
        try:
            if todo and not cancel.is_set():
                # The first missing realization runs here: its time sizes the chunks.
                first = compute_chunk_here(scene, todo[:1], listeners, cancel)
                if first:  # else cancelled within it
                    record(first)
                    pool = sized_executor(pool, options, len(todo) - 1, first[0].seconds)
                    chunks = plan_chunks(todo[1:], pool.workers, first[0].seconds, overhead=pool.task_overhead)
                    for _, results in pool.map_chunks(scene, chunks, cancel, listeners):
                        record(results)
        except KeyboardInterrupt:  # the second Ctrl-C or SIGTERM (Terminated)
            pass
        except RunError as exc:  # keep what finished before the executor failed
            status, error = "failed", str(exc)
        if status == "completed" and accumulator.done < total:
            status = "interrupted" if signals.pressed else "cancelled"
        # The fit, still under the signal handlers: a first Ctrl-C or SIGTERM during it lets it
        # finish, so that what finished is summarised and written (a second one stops it).
        outcome = accumulator.finish(
            status=status, elapsed=time.perf_counter() - started, workers=pool.workers, error=error
        )
    outcome.extra.update(executor=pool.name, resumed=resumed, retried=retried)
    if signals.pressed:
        outcome.extra["signal"] = signal.Signals(signals.signal).name
    hooks.run_finished(run=info, outcome=outcome)
    return outcome
