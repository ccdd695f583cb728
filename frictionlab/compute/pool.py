"""A pool of worker processes that notices a worker's death at any moment.

``concurrent.futures.ProcessPoolExecutor`` sends every worker's results
through one shared queue: a worker killed while it writes its result leaves
half a message in the queue (and the queue's write lock taken), and the pool
waits for the rest forever. Here each worker has a pipe of its own for its
results, and the parent holds no copy of its write end: a worker that dies
mid-send is an end of file on its own pipe, seen at once, like a death at any
other moment (its process sentinel). Its job is then given to a fresh worker,
a bounded number of times.
"""

from __future__ import annotations

import pickle
import signal
import sys
import time
from collections import Counter, deque
from collections.abc import Callable, Hashable, Iterator
from multiprocessing.connection import wait

from ..errors import warn_user
from .heap import keep_freed_memory

WAIT_SECONDS = 0.2  # how often a cancel is looked at while every worker computes
STOP_GRACE_SECONDS = 0.5  # after a cancel, a job's time to end by itself before its worker is killed
ERROR_CHARS = 500  # an error carried back from a worker is cut to this
HELD_SIGNALS = {getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name)}


class WorkerLost(Exception):
    """A job whose worker died more often than ``retries`` allows."""

    def __init__(self, key: Hashable, deaths: int, how: str):
        super().__init__(f"{deaths} deaths, the last {how}")
        self.key, self.deaths, self.how = key, deaths, how


class JobFailed(Exception):
    """The job raised in its worker (not a death: retrying would fail again)."""

    def __init__(self, key: Hashable, error: str):
        super().__init__(error)
        self.key, self.error = key, error


class PoolNotStarted(Exception):
    """Not one worker process could start (out of file descriptors or processes: ``ulimit -n``, ``-u``)."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


def start_failure(exc: OSError) -> str:
    """Why a worker process did not start, with the process limit that ran out where one did."""
    import errno
    import resource

    limits = {errno.EMFILE: ("RLIMIT_NOFILE", "-n"), errno.EAGAIN: ("RLIMIT_NPROC", "-u")}
    name, flag = limits.get(exc.errno, (None, None))
    pids = cgroup_pids_limit() if exc.errno == errno.EAGAIN else None
    if pids is not None:  # a container's or a job scheduler's limit, not the user's ulimit -u
        return f"{exc.strerror or exc}; the control group's process limit (pids.max) is {pids} here"
    soft = resource.getrlimit(getattr(resource, name))[0] if name and hasattr(resource, name) else None
    limit = f"; ulimit {flag} is {soft} here" if soft is not None and soft != resource.RLIM_INFINITY else ""
    return f"{exc.strerror or exc}{limit}"


def cgroup_pids_limit(root: str = "/sys/fs/cgroup", own: str = "/proc/self/cgroup") -> int | None:
    """The pids.max of this process's control group where it is reached (a fork refused
    by it, not by ``ulimit -u``), else None: cgroup v1's pids hierarchy, or v2's."""
    try:
        with open(own) as fh:
            lines = fh.read().splitlines()
    except OSError:
        return None
    for line in lines:
        _, controllers, path = line.split(":", 2)
        if controllers not in ("pids", ""):
            continue
        for folder in (f"{root}/pids{path}", f"{root}{path}", f"{root}/unified{path}"):
            try:
                with open(f"{folder}/pids.max") as fh, open(f"{folder}/pids.current") as now:
                    limit, current = fh.read().strip(), int(now.read())
            except (OSError, ValueError):
                continue
            if limit.isdigit() and current >= int(limit):
                return int(limit)
    return None


_results = None  # in a worker: the pipe of its results, for ``send_progress``
_stop = None  # in a worker: the event its parent sets when the run is cancelled, for ``stop_event``


def send_progress(payload) -> None:
    """In a worker, during a job: send ``payload`` to the parent's ``on_progress``
    (``WorkerPool.run``) at once. Elsewhere it does nothing."""
    if _results is not None:
        _results.send_bytes(pickle.dumps(("progress", payload), protocol=pickle.HIGHEST_PROTOCOL))


def stop_event():
    """In a worker, during a job: the event (``is_set()``) its pool sets once the run is
    cancelled, for a long job to end early with what it finished. Elsewhere None."""
    return _stop


def _serve(tasks, results, stop, initializer, initargs, function) -> None:
    """A worker: run each job received on ``tasks``, send back ``("ok", result)``
    or ``("error", text)`` on ``results`` (after any ``("progress", payload)`` the job
    sent); stop on None or when ``tasks`` closes."""
    global _results, _stop
    _results, _stop = results, stop
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C and SIGTERM are the parent's to handle:
    signal.signal(signal.SIGTERM, signal.SIG_IGN)  # it sets ``stop``, then stops workers
    if hasattr(signal, "SIGHUP"):  # a closed terminal hangs up the whole job: the parent's to handle too
        signal.signal(signal.SIGHUP, signal.SIG_IGN)
    keep_freed_memory()  # a fork has its parent's setting; a forkserver's or spawned worker not
    sys.stdout = sys.stderr  # a plugin's print is no part of a command's output (--json: one JSON object)
    if initializer is not None:
        initializer(*initargs)
    while True:
        try:
            job = tasks.recv()
        except EOFError:
            return
        if job is None:
            return
        try:
            reply = pickle.dumps(("ok", function(job)), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception as exc:  # the job raised, or its result does not pickle
            reply = pickle.dumps(("error", f"{type(exc).__name__}: {exc}"[:ERROR_CHARS]))
        results.send_bytes(reply)


def _how(exitcode: int | None) -> str:
    if exitcode is None:
        return "still running"
    if exitcode < 0:
        try:
            return f"killed by {signal.Signals(-exitcode).name}"
        except ValueError:
            return f"killed by signal {-exitcode}"
    return f"exit code {exitcode}"


class _Worker:
    def __init__(self, context, stop, initializer, initargs, function):
        task_read, self.tasks = context.Pipe(duplex=False)
        self.results, result_write = context.Pipe(duplex=False)
        self.process = context.Process(
            target=_serve, args=(task_read, result_write, stop, initializer, initargs, function), daemon=True
        )
        self.process.start()
        task_read.close()  # the worker's ends: the parent keeps none, so a dead
        result_write.close()  # worker's pipe reaches end of file
        self.job: Hashable | None = None

    def give(self, key: Hashable, payload) -> bool:
        """Send a job; False if the worker is already gone."""
        try:
            self.tasks.send(payload)
        except (BrokenPipeError, ConnectionResetError, OSError):
            return False
        self.job = key
        return True

    def ask_stop(self) -> None:
        """Tell it to stop (it ends after its job), without waiting."""
        try:
            self.tasks.send(None)
        except OSError:
            pass

    def stop(self, timeout: float = 2.0) -> None:
        """Ask it to stop, and kill it if it has not within ``timeout`` (at once for 0)."""
        self.ask_stop()
        if timeout:
            self.process.join(timeout)
        if self.process.is_alive():
            self.process.kill()
            self.process.join()
        self.tasks.close()
        self.results.close()


class WorkerPool:
    """``size`` worker processes started from ``context``, each running
    ``initializer(*initargs)`` once, then ``function(payload)`` per job."""

    def __init__(self, size: int, context, function: Callable, initializer=None, initargs=(), retries: int = 2):
        self.size, self.context, self.function = max(1, size), context, function
        self.initializer, self.initargs, self.retries = initializer, initargs, retries
        self.short = False  # fewer workers started than asked for (``ulimit -n`` or ``-u`` reached)

    def _start(self, stop) -> _Worker:
        return _Worker(self.context, stop, self.initializer, self.initargs, self.function)

    def _give_out(self, pending: deque, jobs: dict, workers: list[_Worker], stop) -> None:
        """A pending job to each idle worker, starting workers up to ``size``."""
        while pending and (len(workers) < self.size or any(w.job is None for w in workers)):
            worker = next((w for w in workers if w.job is None), None)
            if worker is None:
                try:
                    worker = self._start(stop)
                except OSError as exc:  # ulimit -n or -u reached: the workers started go on alone
                    if not workers:
                        raise PoolNotStarted(start_failure(exc)) from None
                    warn_user(f"{len(workers)} of {self.size} worker processes started ({start_failure(exc)}): "
                              f"the run goes on with {len(workers)}")  # fmt: skip
                    self.size, self.short = len(workers), True
                    continue
                workers.append(worker)
            key = pending.popleft()
            if not worker.give(key, jobs[key]):  # it died idle: no charge to the job
                pending.appendleft(key)
                workers.remove(worker)
                worker.stop(0)

    def run(self, jobs: dict[Hashable, object], cancel, on_progress=None) -> Iterator[tuple[Hashable, object]]:
        """Yield ``(key, result)`` as each job finishes; ``on_progress(payload)`` hears what
        a job sends on the way (``send_progress``). After ``cancel.set()``
        no job starts, and running ones see ``stop_event()`` set (within ``WAIT_SECONDS``):
        those that end within ``STOP_GRACE_SECONDS`` are yielded, the others' workers are
        killed (a step of a large solve cannot be interrupted). A job whose worker
        dies runs again on a fresh worker, at most ``retries`` more times
        (then WorkerLost); a job that raises ends the run (JobFailed)."""
        pending = deque(jobs)
        deaths: Counter = Counter()
        workers: list[_Worker] = []
        stop = self.context.Event()
        cancelled_at = None
        try:
            while True:
                if cancel.is_set():
                    pending.clear()
                    stop.set()
                    cancelled_at = time.monotonic() if cancelled_at is None else cancelled_at
                    if time.monotonic() - cancelled_at >= STOP_GRACE_SECONDS:
                        return  # the workers still busy are killed below: their jobs abandoned
                self._give_out(pending, jobs, workers, stop)
                busy = [w for w in workers if w.job is not None]
                if not busy:
                    return
                ready = set(wait([w.results for w in busy] + [w.process.sentinel for w in workers], WAIT_SECONDS))
                for worker in list(workers):
                    died = worker.process.sentinel in ready
                    if worker.job is not None and worker.results in ready:
                        try:
                            status, value = pickle.loads(worker.results.recv_bytes())
                        except (EOFError, OSError):  # it died while sending: half a message, then end of file
                            died = True
                        else:
                            if status == "progress":
                                if on_progress is not None:
                                    on_progress(value)
                                continue  # the job goes on; its next message wakes the wait again
                            key, worker.job = worker.job, None
                            if status == "error":
                                raise JobFailed(key, value)
                            if not cancel.is_set():  # its next job first: what the caller does
                                self._give_out(pending, jobs, workers, stop)  # with the result (a write) overlaps it
                            yield key, value
                            continue  # had it died too, its sentinel stays ready for the next round
                    if died:
                        workers.remove(worker)
                        worker.stop()  # it has ended, or ends now (its pipe is closed)
                        if worker.job is not None:
                            deaths[worker.job] += 1
                            if deaths[worker.job] > self.retries:
                                raise WorkerLost(worker.job, deaths[worker.job], _how(worker.process.exitcode))
                            if not cancel.is_set():
                                pending.appendleft(worker.job)
        finally:  # idle workers stop; busy ones (an error or an interrupt got here) are killed
            _stop_all(workers)


def _stop_all(workers: list[_Worker]) -> None:
    """Every worker told to stop (a busy one killed) before any wait, with signals held
    meanwhile: a second Ctrl-C that interrupts the waits leaves no worker waiting for a
    job. It ignores SIGTERM, so the command's exit would wait for it forever."""
    held = signal.pthread_sigmask(signal.SIG_BLOCK, HELD_SIGNALS) if hasattr(signal, "pthread_sigmask") else None
    try:
        for worker in workers:
            if worker.job is not None:
                worker.process.kill()
            else:
                worker.ask_stop()
    finally:
        if held is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, held)
    for worker in workers:
        worker.stop(0 if worker.job is not None else 2.0)

