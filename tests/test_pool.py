"""The worker pool keeps its workers busy while the caller handles what they send."""

from __future__ import annotations

import threading
import time
from pathlib import Path

from frictionlab.compute.executors import pool_context
from frictionlab.compute.pool import WorkerPool


def _mark_start(path: str) -> str:
    Path(path).touch()  # the job has reached a worker
    return path


def _waited_for(path: Path, seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while not path.exists():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True


def test_a_worker_gets_its_next_job_before_the_caller_handles_its_result(tmp_path):
    """The caller's work with a result (a run writes a chunk: an fsync, slow on a busy
    machine) overlaps the worker's next job, instead of leaving the worker idle."""
    first, second = tmp_path / "first", tmp_path / "second"
    pool = WorkerPool(1, pool_context(), _mark_start)
    results = pool.run({1: str(first), 2: str(second)}, threading.Event())
    try:
        assert next(results) == (1, str(first))
        # the generator is paused here, as while the engine writes the chunk: the next job runs anyway
        assert _waited_for(second, 30.0), "the second job waited for the caller to ask for more"
        assert list(results) == [(2, str(second))]
    finally:
        results.close()  # its workers stop
