"""The ensemble engine: a lazy iterator of realizations, and a driver that fans
lifecycle events out to listeners.

Seeding is per realization (see ``seeds``), so numbers do not depend on the
order, the worker count or the executor. Statistics are formed from arrays
indexed by realization, never in completion order.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import signal
import threading
import time
import traceback
from collections.abc import Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass

import numpy as np
import pluggy

from .ensemble import Accumulator, RunOutcome
from .errors import RunError
from .hookspecs import PROJECT_NAME, LifecycleSpecs
from .preset import Scene
from .seeds import realization_rng

@dataclass(frozen=True)
class RealizationResult:
    """What one realization gives. Arrays have one entry per load step; a failed
    realization carries ``error`` and no arrays."""

    index: int
    seconds: float
    xi: np.ndarray | None = None
    contact_count: np.ndarray | None = None
    indentation: np.ndarray | None = None
    force: np.ndarray | None = None  # kept only under indentation control (forces vary)
    slope_rms_line: float = math.nan
    points: int = 0
    length: float = math.nan
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.error is None


def compute_realization(scene: Scene, index: int) -> RealizationResult:
    """Generate -> slopes -> solve -> xi for realization ``index``. Never raises:
    a failure is carried on the result."""
    start = time.perf_counter()
    try:
        rng = realization_rng(scene.preset.seed, index)
        profile = scene.spectrum.generate(rng)
        slopes = scene.slope.slopes(profile.heights, profile.spacing)
        slope_rms_line = float(np.sqrt(np.mean(np.square(slopes))))
        if not (math.isfinite(slope_rms_line) and slope_rms_line > 0):
            raise ValueError(
                f"the rms slope of the whole line is {slope_rms_line}: xi is undefined (is the line constant?)"
            )
        curve = scene.solver.solve(profile, scene.loads, scene.control, slopes)
        return RealizationResult(
            index=index,
            seconds=time.perf_counter() - start,
            xi=curve.slope_rms_contact / slope_rms_line,
            contact_count=np.asarray(curve.contact_count),
            indentation=np.asarray(curve.indentation),
            force=np.asarray(curve.force) if scene.control == "indentation" else None,
            slope_rms_line=slope_rms_line,
            points=profile.points,
            length=profile.length,
        )
    except Exception as exc:  # carried, not raised: one bad line must not end the run
        where = traceback.extract_tb(exc.__traceback__)[-1]
        error = f"{type(exc).__name__}: {exc} ({os.path.basename(where.filename)}:{where.lineno})"
        return RealizationResult(index=index, seconds=time.perf_counter() - start, error=error)


# ------------------------------------------------------------------ executors

_worker_scene: Scene | None = None


def _init_worker(scene: Scene) -> None:
    global _worker_scene
    _worker_scene = scene
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle


def _run_chunk(indices: list[int]) -> list[RealizationResult]:
    return [compute_realization(_worker_scene, i) for i in indices]


def default_workers() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def chunked(indices: list[int], workers: int, per_worker: int = 16, largest: int = 256) -> list[list[int]]:
    """Split into about ``per_worker`` chunks per worker: small enough to stream
    progress, balance load and stop soon after a cancel, large enough that task
    overhead stays small. ``largest`` caps a chunk for very long runs."""
    size = min(largest, max(1, math.ceil(len(indices) / (workers * per_worker))))
    return [indices[i : i + size] for i in range(0, len(indices), size)]


def _pool_context():
    # fork is the cheapest start on Linux but unsafe with threads (the TUI runs the
    # engine in one): use forkserver there.
    methods = multiprocessing.get_all_start_methods()
    if "fork" in methods and threading.active_count() == 1:
        return multiprocessing.get_context("fork")
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


def iter_realizations(
    scene: Scene, indices: Iterable[int], *, workers: int = 1, cancel=None
) -> Iterator[RealizationResult]:
    """Yield one result per realization as it finishes (completion order).

    ``workers == 1`` runs in this process; more use a process pool. ``cancel``
    is anything with ``is_set()``: once set, no new chunk starts and the
    iterator ends after what is running.
    """
    indices = list(indices)
    if workers <= 1 or len(indices) <= 1:
        for index in indices:
            if cancel is not None and cancel.is_set():
                return
            yield compute_realization(scene, index)
        return
    chunks = chunked(indices, workers)
    with ProcessPoolExecutor(
        max_workers=min(workers, len(chunks)),
        mp_context=_pool_context(),
        initializer=_init_worker,
        initargs=(scene,),
    ) as pool:
        pending = {pool.submit(_run_chunk, chunk) for chunk in chunks}
        try:
            while pending:
                if cancel is not None and cancel.is_set():
                    # Chunks already running finish and are kept; the rest never start.
                    running = {future for future in pending if not future.cancel()}
                    finished, pending = wait(running).done, set()
                else:
                    finished, pending = wait(pending, timeout=0.1, return_when=FIRST_COMPLETED)
                for future in finished:
                    try:
                        yield from future.result()
                    except BrokenProcessPool as exc:
                        raise RunError(f"a worker process died: {exc}") from None
        finally:
            for future in pending:
                future.cancel()


# ------------------------------------------------------------------ the driver


@dataclass(frozen=True)
class RunInfo:
    scene: Scene
    total: int
    workers: int


def _listener_manager(listeners: Iterable[object]) -> pluggy.PluginManager:
    pm = pluggy.PluginManager(PROJECT_NAME)
    pm.add_hookspecs(LifecycleSpecs)
    for listener in listeners:
        pm.register(listener)
    pm.check_pending()
    return pm


class _CtrlCToCancel:
    """The first Ctrl-C sets ``cancel`` (running work finishes and is kept); a
    second one interrupts at once. Only in the main thread, where signals land."""

    def __init__(self, cancel):
        self.cancel = cancel
        self.pressed = False
        self.previous = None

    def _handle(self, signum, frame):
        if self.pressed:
            raise KeyboardInterrupt
        self.pressed = True
        self.cancel.set()

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self.previous = signal.signal(signal.SIGINT, self._handle)
        return self

    def __exit__(self, *exc):
        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)
        return False


def run(
    scene: Scene,
    *,
    workers: int | None = None,
    listeners: Iterable[object] = (),
    cancel=None,
) -> RunOutcome:
    """Run the ensemble of ``scene``, telling ``listeners`` as it goes.

    ``cancel`` (anything with ``set()``/``is_set()``) or Ctrl-C ends the run
    early; what finished is kept and summarised, and ``outcome.status`` says
    ``cancelled`` or ``interrupted``.
    """
    total = scene.preset.realizations
    workers = min(total, default_workers() if workers is None else max(1, int(workers)))
    info = RunInfo(scene=scene, total=total, workers=workers)
    hooks = _listener_manager(listeners).hook
    accumulator = Accumulator(scene)
    cancel = threading.Event() if cancel is None else cancel
    started = time.perf_counter()
    hooks.run_started(run=info)
    status, error = "completed", None
    with _CtrlCToCancel(cancel) as ctrl_c:
        try:
            for result in iter_realizations(scene, range(total), workers=workers, cancel=cancel):
                accumulator.add(result)
                event = hooks.realization_done if result.ok else hooks.realization_failed
                event(run=info, result=result, done=accumulator.done, total=total)
        except KeyboardInterrupt:  # the second Ctrl-C
            pass
        except RunError as exc:  # keep what finished before the pool broke
            status, error = "failed", str(exc)
        if status == "completed" and accumulator.done < total:
            status = "interrupted" if ctrl_c.pressed else "cancelled"
    outcome = accumulator.finish(
        status=status, elapsed=time.perf_counter() - started, workers=workers, error=error
    )
    hooks.run_finished(run=info, outcome=outcome)
    return outcome
