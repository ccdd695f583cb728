"""Freed blocks are kept for reuse (glibc): the next realization's arrays of the same size
do not fault in fresh pages, in the command's process and in the pool's workers."""

from __future__ import annotations

import multiprocessing
import platform
import resource
import subprocess
import sys
import threading

import numpy as np
import pytest

from frictionlab.compute.heap import keep_freed_memory
from frictionlab.compute.pool import WorkerPool

ROUNDS = 40


def faults_per_round(_job=None) -> float:
    """Minor page faults of one round as a realization of a 1e5-point line has them:
    three arrays of 0.8 MB allocated, then freed together."""
    for _ in range(3):  # past the first rounds, which fault in the heap's pages once
        _ = [np.ones(100_000) for _ in range(3)]
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(ROUNDS):
        arrays = [np.ones(100_000) for _ in range(3)]
        del arrays
    return (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / ROUNDS


glibc_only = pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="mallopt's thresholds are glibc's; other C libraries decide alone")


@glibc_only
def test_freed_blocks_are_reused_instead_of_faulted_in_afresh():
    """In a fresh process: each round faults in its 2.4 MB (some 600 pages) under glibc's
    defaults, and almost none once ``keep_freed_memory`` has set the thresholds."""
    code = (
        "from tests.test_heap import faults_per_round\n"
        "from frictionlab.compute.heap import keep_freed_memory\n"
        "before = faults_per_round()\n"
        "kept = keep_freed_memory()\n"
        "print(before, kept, faults_per_round())\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    before, kept, after = float(out[0]), out[1], float(out[2])
    assert kept == "True"
    assert before > 100, f"glibc's defaults were expected to fault in each round's pages ({before} per round)"
    assert after < 10, f"{after} page faults per round once freed blocks are kept (before: {before})"


@glibc_only
def test_a_pool_worker_keeps_freed_blocks_whatever_its_start_method():
    """A worker started by a fork server inherits nothing from this process: it sets the thresholds itself."""
    pool = WorkerPool(1, multiprocessing.get_context("forkserver"), faults_per_round)
    results = dict(pool.run({0: "a job"}, threading.Event()))  # (None would tell the worker to stop)
    assert results[0] < 10, f"{results[0]} page faults per round in a worker"


def test_elsewhere_it_says_it_changed_nothing(monkeypatch):
    """A C library without mallopt (macOS, Windows) leaves the allocator alone, quietly."""

    class NoMallopt:
        def __init__(self, name):
            pass

    monkeypatch.setattr("ctypes.CDLL", NoMallopt)
    assert keep_freed_memory() is False
