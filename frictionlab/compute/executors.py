"""Where realizations run: in this process, in a local process pool, or on Dask.

An executor takes a list of chunks (lists of realization indices) and yields
``(chunk, results)`` as each chunk finishes, in completion order. Numbers never
depend on the executor: every realization draws from its own seed, and the
statistics are formed by index afterwards.

* ``serial``: in this process, realization by realization.
* ``processes``: a pool of worker processes on this machine (``pool``). A
  worker that dies at any moment (killed, out of memory, even while it sends
  its result) is replaced and its chunk runs again, a bounded number of times.
* ``dask``: a ``distributed.Client`` on an existing scheduler, or on a
  ``LocalCluster`` of this user's own on loopback, reached over TLS with
  credentials made for the run (``dask_security``). A small scene travels
  inside each task, a large one is broadcast once; Dask itself reschedules the tasks
  of a worker that dies.
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import math
import multiprocessing
import os
import pickle
import queue
import signal
import sys
import threading
import time
import uuid
from collections.abc import Iterator, Sequence

from .dask_security import DASK_MISSING, connect_scheduler, import_distributed, start_local_cluster
from .dask_session import current_session
from ..errors import RunError, shown_name, warn_user
from ..options import RunOptions
from .pool import JobFailed, PoolNotStarted, WorkerLost, WorkerPool, send_progress, stop_event
from ..preset import Scene
from .realization import UNHEARD, RealizationResult, SolveListeners, compute_chunk, compute_chunk_here

__all__ = ["DASK_MISSING", "connect_scheduler", "import_distributed"]  # re-exported from dask_security

Chunk = list[int]


# ------------------------------------------------------------------ chunking

TARGET_CHUNK_SECONDS = 0.5  # a chunk's length when there is work enough: resume and progress granularity
CHUNKS_PER_WORKER = 4  # at most this many per worker when chunks are short, for load balance and progress
MAX_CHUNKS = 4096  # at most this many per run: the run folder's manifest lists every chunk
MAX_OVERHEAD_SHARE = 0.02  # a task lasts at least 50 times its executor's overhead per task


def plan_chunks(
    indices: Sequence[int],
    workers: int,
    seconds_each: float,
    target: float = TARGET_CHUNK_SECONDS,
    per_worker: int = CHUNKS_PER_WORKER,
    max_chunks: int = MAX_CHUNKS,
    overhead: float = 0.0,
) -> list[Chunk]:
    """Split ``indices`` into consecutive chunks of about ``target`` seconds each
    (from the measured ``seconds_each`` of one realization), but into up to
    ``per_worker`` chunks per worker while there are enough indices, and into
    no more than ``max_chunks``.

    ``overhead``: what the executor spends per task (submitting it, sending its
    results). Chunks are never made so short that it exceeds ``MAX_OVERHEAD_SHARE``
    of their work: a short run gets fewer chunks per worker, down to one each
    (a whole number per worker keeps equal realizations balanced)."""
    indices = list(indices)
    if not indices:
        return []
    seconds_each = max(seconds_each, 1e-9)
    workers = max(1, workers)
    by_cost = max(1, int(target / seconds_each))
    if overhead > 0:
        shortest = overhead / MAX_OVERHEAD_SHARE
        per_worker = max(1, min(per_worker, int(len(indices) * seconds_each / (workers * shortest))))
    by_balance = max(1, math.ceil(len(indices) / (workers * per_worker)))
    size = max(min(by_cost, by_balance), math.ceil(len(indices) / max_chunks))
    return [indices[i : i + size] for i in range(0, len(indices), size)]


def chunk_label(chunk: Sequence[int]) -> str:
    return f"{chunk[0]}" if len(chunk) == 1 else f"{chunk[0]}-{chunk[-1]}"


# ------------------------------------------------------------------ serial


class SerialExecutor:
    """In this process (``compute_chunk_here``). A cancel returns at once: a cancelled
    chunk yields what it finished."""

    name = "serial"
    task_overhead = 0.0  # seconds per chunk (see ``plan_chunks``)

    def __init__(self):
        self.workers = 1

    def map_chunks(
        self, scene: Scene, chunks: list[Chunk], cancel, listeners: SolveListeners = UNHEARD
    ) -> Iterator[tuple[Chunk, list[RealizationResult]]]:
        for chunk in chunks:
            done = compute_chunk_here(scene, chunk, listeners, cancel) if not cancel.is_set() else []
            if done:
                yield chunk[: len(done)], done
            if cancel.is_set():
                return


# ------------------------------------------------------------------ process pool

_worker_scene: Scene | None = None
_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    """Linux: have the kernel kill this worker when the process that made it
    dies (the main process, or the forkserver, which ends with the main
    process), so kill -9 of ``frictionlab run`` leaves no worker computing."""
    parent = os.getppid()
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):  # not Linux: workers end when their queue closes
        return
    if os.getppid() != parent:  # the parent died before prctl took effect
        os._exit(1)


def _init_worker(scene: Scene) -> None:
    global _worker_scene
    _worker_scene = scene
    _die_with_parent()


def _send_load(index: int, done: int, total: int) -> None:
    send_progress(("load", index, done, total))


def _send_iteration(index: int, load: int, iteration: int, residual: float) -> None:
    send_progress(("iteration", index, load, iteration, residual))


_WORKER_LISTENERS = SolveListeners(_send_load, _send_iteration)


def _run_chunk(indices: Chunk) -> list[RealizationResult]:
    return compute_chunk(_worker_scene, indices, _WORKER_LISTENERS, cancel=stop_event())


def pool_context():
    # fork is the cheapest start on Linux but unsafe with threads (the TUI runs the
    # engine in one; a Dask client runs an event loop): use forkserver there.
    methods = multiprocessing.get_all_start_methods()
    if "fork" in methods and threading.active_count() == 1:
        return multiprocessing.get_context("fork")
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


def _unguarded_script(context, how: str) -> str:
    """Advice for workers that exit 1 where they start by importing the main script again
    (forkserver or spawn: chosen while a thread runs beside the run) and the script has no
    ``if __name__ == "__main__":``: each worker ran its run again, and died starting a pool."""
    script = getattr(sys.modules.get("__main__"), "__file__", None)
    if context.get_start_method() == "fork" or not script or "exit code 1" not in how:
        return ""
    try:
        with open(script, encoding="utf-8", errors="replace") as fh:
            if "__main__" in fh.read(1 << 20):
                return ""  # guarded: the workers died of something else
    except OSError:
        return ""
    return (f"; the workers start by importing {shown_name(script)} again (a thread of its own runs beside the run, so "
            "they are not forked) and run what its top level does: put the run under `if __name__ == \"__main__\":`")


def pool_refused() -> str | None:
    """Why this system starts no process pool, or None. The pool's stop event is a POSIX
    semaphore, which a system without a usable /dev/shm (some containers and batch nodes) refuses."""
    try:
        pool_context().Event()
    except OSError as exc:
        return (f"worker processes need a POSIX semaphore, which this system refuses: {exc.strerror or exc}; "
                "is /dev/shm missing or read-only?")
    return None


class ProcessExecutor:
    """A local pool of worker processes. ``retries``: how many times a chunk
    runs again after its worker died (then the run fails, naming the chunk)."""

    name = "processes"
    task_overhead = 0.5e-3  # measured 0.2 ms per task, pool start included (benchmarks/bench_scale.py)

    def __init__(self, workers: int, retries: int = 2):
        self.workers = workers
        self.retries = retries

    def map_chunks(
        self, scene: Scene, chunks: list[Chunk], cancel, listeners: SolveListeners = UNHEARD
    ) -> Iterator[tuple[Chunk, list[RealizationResult]]]:
        """A cancel reaches the workers (``WorkerPool.run``): a chunk then yields what it finished."""
        jobs = dict(enumerate(chunks))
        heard = {"load": listeners.on_load, "iteration": listeners.on_iteration}

        def on_progress(payload) -> None:
            listener = heard[payload[0]]
            if listener is not None:
                listener(*payload[1:])

        context = pool_context()
        pool = WorkerPool(
            min(self.workers, len(chunks)), context, _run_chunk, _init_worker, (scene.for_pressing(),),
            retries=self.retries,
        )
        ended = set()
        try:
            for key, results in pool.run(jobs, cancel, on_progress):
                ended.add(key)
                if results:  # none: cancelled within its first realization
                    yield jobs[key][: len(results)], results
            if pool.short:
                self.workers = pool.size  # what the outcome tells of the run
        except PoolNotStarted as refused:  # not one worker runs (at the start, or none came back after deaths)
            warn_user(f"worker processes could not start ({refused.reason}): the run goes on in this process")
            self.name, self.workers = SerialExecutor.name, 1  # what the outcome tells of the run
            rest = [chunk for key, chunk in jobs.items() if key not in ended]
            yield from SerialExecutor().map_chunks(scene, rest, cancel, listeners)
        except WorkerLost as lost:
            raise RunError(
                f"a worker process died {lost.deaths} times while running realizations "
                f"{chunk_label(jobs[lost.key])} ({lost.how}); giving up{_unguarded_script(context, lost.how)}"
            ) from None
        except JobFailed as failed:
            raise RunError(
                f"realizations {chunk_label(jobs[failed.key])} failed in a worker process: {failed.error}"
            ) from None


# ------------------------------------------------------------------ dask


def dask_memory_limits(scheduler: str | None, workers: int = 1) -> tuple[dict[str, int | None], float]:
    """Each worker's memory limit on the cluster at ``scheduler`` (bytes by
    address; 0 or None: no limit), or without one those the ``LocalCluster`` of
    ``workers`` single-thread processes will get (Dask's "auto": the machine's
    memory over its cores, each); and the fraction of it at which Dask's nanny
    kills a worker (this process's ``distributed.worker.memory.terminate``;
    1 when it is off: the operating system's OOM killer is then the limit)."""
    import_distributed()  # the memory check comes first: a missing Dask is said here
    import dask

    if scheduler:
        with connect_scheduler(scheduler) as client:
            found = client.scheduler_info().get("workers", {})
            limits = {address: info.get("memory_limit") for address, info in found.items()}
    else:
        try:
            from distributed.worker_memory import parse_memory_limit

            each = parse_memory_limit("auto", 1, logger=logging.getLogger(__name__))
        except (ImportError, TypeError):  # another Dask version: its limit is unknown here
            each = None
        limits = {f"{i} of the LocalCluster on 127.0.0.1": each for i in range(1, workers + 1)}
    terminate = dask.config.get("distributed.worker.memory.terminate", 0.95)
    return limits, float(terminate) if terminate else 1.0


class DaskExecutor:
    """Chunks as Dask tasks. With ``scheduler`` (``tcp://`` or ``tls://HOST:PORT``)
    the run uses that cluster's workers; without, a ``LocalCluster`` of
    ``workers`` single-thread processes on 127.0.0.1 reached over TLS
    (``dask_security``), dashboard off unless ``dashboard``, closed at the end.
    ``retries``: Dask retries of a task that raised (a task whose worker died is
    rescheduled by Dask up to its ``allowed-failures``). With ``session``
    (``dask_session.DaskSession``) the run uses, and leaves open, the client of its command."""

    name = "dask"
    task_overhead = 5e-3  # measured 3.5-4.7 ms per task on a LocalCluster of 2 (benchmarks/bench_scale.py)

    def __init__(
        self, workers: int, scheduler: str | None = None, retries: int = 2, dashboard: bool = False, session=None
    ):
        self.workers = workers
        self.scheduler = scheduler
        self.retries = retries
        self.dashboard = dashboard
        self.session = session

    def _connect(self):
        """The client, and the ``LocalCluster`` this run started (None: it uses a scheduler's,
        or its command's session's)."""
        if self.session is not None:
            client, cluster = self.session.connect(), None
        elif self.scheduler:
            client, cluster = connect_scheduler(self.scheduler), None
        else:
            return start_local_cluster(self.workers, dashboard=self.dashboard)
        if self.scheduler:
            self.workers = max(1, len(client.scheduler_info().get("workers", {})))
        return client, cluster

    def map_chunks(
        self, scene: Scene, chunks: list[Chunk], cancel, listeners: SolveListeners = UNHEARD
    ) -> Iterator[tuple[Chunk, list[RealizationResult]]]:
        """``listeners`` are not told: a Dask worker reports whole chunks
        only. A cancel returns at once, and reaches the running tasks through the run's
        Dask ``Event``: they stop within their solve (``DaskStop``)."""
        import_distributed()
        client, cluster = self._connect()
        futures = []
        finished: queue.SimpleQueue = queue.SimpleQueue()  # filled by the client's event loop
        run_id = uuid.uuid4().hex[:8]
        stop_name = f"frictionlab-{run_id}-stop"
        try:
            scene_arg = _scene_argument(client, scene.for_pressing(), len(chunks))
            keys = [f"frictionlab-{run_id}-{chunk_label(chunk)}" for chunk in chunks]
            chunk_of = dict(zip(keys, chunks))
            # one graph for all the chunks (a submit each is a scheduler round trip each:
            # the second worker started 10-20 ms after the first)
            futures = client.map(
                _packed_chunk, [scene_arg] * len(chunks), chunks, [stop_name] * len(chunks),
                key=keys, retries=self.retries, pure=False,
            )  # fmt: skip
            for future in futures:
                future.add_done_callback(finished.put)
            # Waiting on a queue, not polling Dask: a poll every few ms took a tenth of a
            # core from the workers on a machine with as many cores as workers.
            for _ in range(len(futures)):
                future = _next_finished(finished, cancel)
                if future is None:
                    import distributed

                    distributed.Event(stop_name, client=client).set()
                    return
                try:
                    results = pickle.loads(future.result())
                except Exception as exc:  # KilledWorker, a plugin missing on a worker, ...
                    raise RunError(
                        f"Dask task for realizations {chunk_label(chunk_of[future.key])} failed: "
                        f"{type(exc).__name__}: {exc}"
                    ) from None
                yield chunk_of[future.key], results
        finally:
            if futures:
                client.cancel([f for f in futures if not f.done()])
            if self.session is None:  # else its command closes it
                client.close()
            if cluster is not None:
                cluster.close()


CANCEL_POLL_SECONDS = 0.1  # how often a run waiting for Dask tasks looks at its cancel
INLINE_SCENE_BYTES = 1024 * 1024  # the scene travels inside each task while its copies come to at most this


def _next_finished(finished: queue.SimpleQueue, cancel):
    """The next future the client's loop put in ``finished``; None once ``cancel`` is set."""
    while not cancel.is_set():
        try:
            return finished.get(timeout=CANCEL_POLL_SECONDS)
        except queue.Empty:
            continue
    return None


def _scene_argument(client, scene: Scene, tasks: int):
    """What the ``tasks`` tasks get as their scene: the scene itself when its copies pickle
    small (a preset's numbers and what its spectrum derived from them: no scatter round
    trips), else a future of it broadcast to every worker once (a measured surface's heights)."""
    if _pickles_within(scene, INLINE_SCENE_BYTES // max(1, tasks)):
        return scene
    return client.scatter(scene, broadcast=True, hash=False)


class _TooLarge(Exception):
    pass


def _pickles_within(obj, limit: int) -> bool:
    """Whether ``obj`` pickles to at most ``limit`` bytes, counted as they are written and
    given up past the limit: a measured surface of gigabytes is never copied to find out."""
    written = 0

    class Counter:
        @staticmethod
        def write(data) -> None:
            nonlocal written
            written += memoryview(data).nbytes
            if written > limit:
                raise _TooLarge

    try:
        pickle.Pickler(Counter(), protocol=pickle.HIGHEST_PROTOCOL).dump(obj)
    except _TooLarge:
        return False
    return True


STOP_POLL_SECONDS = 0.25  # how often a Dask task asks the scheduler whether its run was cancelled


class DaskStop:
    """In a Dask task: whether the run's ``distributed.Event`` named ``name`` is set, asked
    of the scheduler at most every ``STOP_POLL_SECONDS`` (a short task never asks)."""

    def __init__(self, name: str):
        self.name, self.stopped = name, False
        self.next_poll = time.monotonic() + STOP_POLL_SECONDS

    def is_set(self) -> bool:
        if not self.stopped and time.monotonic() >= self.next_poll:
            import distributed

            self.stopped = distributed.Event(self.name).is_set()
            self.next_poll = time.monotonic() + STOP_POLL_SECONDS
        return self.stopped


def _packed_chunk(scene: Scene, indices: Chunk, stop_name: str) -> bytes:
    """A Dask task: ``compute_chunk``'s results as one pickle (those finished when the run's
    stop event was seen). Dask sends each of a result's arrays as a message part of its
    own: 40 ms for a chunk of 150 line realizations against 12 ms for the same numbers in
    one piece."""
    with contextlib.redirect_stdout(sys.stderr):  # a plugin's print is no part of a command's output (--json)
        results = compute_chunk(scene, indices, cancel=DaskStop(stop_name))
    return pickle.dumps(results, protocol=pickle.HIGHEST_PROTOCOL)


# starting and ending a local pool of 2 workers: two one-realization chunks took 55-60 ms more
# on a pool than here, on the 2-core machine under load (load average 12)
POOL_START_SECONDS = 0.05


def sized_executor(executor, options: RunOptions, remaining: int, seconds_each: float):
    """``executor``, or this process instead of the default process pool when the work left
    (``remaining`` realizations of ``seconds_each``, the first one's time) would not repay the
    pool's start: shared among its workers it would save less than twice that start. An
    executor asked for by name is kept. The numbers are the same either way."""
    if options.executor is not None or executor.name != "processes":
        return executor
    saved = remaining * seconds_each * (1.0 - 1.0 / max(1, executor.workers))
    return executor if saved > 2 * POOL_START_SECONDS else SerialExecutor()


def make_executor(options: RunOptions, workers: int):
    """The executor ``options`` ask for (``RunOptions.executor_for``) with ``workers``."""
    name = options.executor_for(workers)
    if name == "serial":
        return SerialExecutor()
    if name == "processes":
        if (refused := pool_refused()) is None:
            return ProcessExecutor(workers, retries=options.retries)
        if options.executor is not None:  # asked for by name: said, not replaced
            raise RunError(f"executor 'processes' cannot start here: {refused}; the serial executor runs in this process")
        warn_user(f"{workers} worker processes cannot start here ({refused}): the run goes on in this process")
        return SerialExecutor()
    import_distributed()  # fail before anything starts
    if not options.scheduler and (refused := pool_refused()) is not None:  # its own local cluster's processes
        raise RunError(f"executor 'dask' cannot start its local cluster here: {refused}")
    return DaskExecutor(
        workers,
        scheduler=options.scheduler,
        retries=options.retries,
        dashboard=options.dashboard,
        session=current_session(options),
    )
