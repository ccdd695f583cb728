"""Variant scenes of one preset for the trade-off study, and their measurement.

The variants themselves are made by ``frictionlab.variants.SceneFactory`` (shared
with the other studies); here they are measured.
"""

from __future__ import annotations

import math
import time
import tracemalloc
from dataclasses import dataclass

from ..compute import engine
from ..compute.ensemble import RunOutcome
from ..options import RunOptions
from ..preset import Scene
from ..variants import SceneFactory, force_scale

__all__ = ["Measurement", "SceneFactory", "force_scale", "measure"]  # the factory: re-exported from the core


@dataclass(frozen=True)
class Measurement:
    outcome: RunOutcome
    seconds: float  # wall time, best of the repeats
    peak_bytes: int  # tracemalloc peak above the level before the run


def measure(scene: Scene, repeats: int = 1, listeners=()) -> Measurement:
    """Run ``scene`` serially in this process (so one clock and one allocator
    see all the work) and measure wall time and peak traced memory.

    Memory is tracemalloc's peak, which includes numpy's data buffers (numpy
    reports them to tracemalloc); ru_maxrss would not do: it is the process's
    high-water mark, so any variant smaller than an earlier one would read as
    zero. tracemalloc is started here if it is not running. ``listeners`` hear each
    run (its progress).
    """
    started_tracing = not tracemalloc.is_tracing()
    if started_tracing:
        tracemalloc.start()
    try:
        best, peak, outcome = math.inf, 0, None
        for _ in range(max(1, repeats)):
            tracemalloc.reset_peak()
            floor = tracemalloc.get_traced_memory()[0]
            start = time.perf_counter()
            outcome = engine.run(scene, RunOptions(workers=1), listeners=listeners)
            seconds = time.perf_counter() - start
            peak = max(peak, tracemalloc.get_traced_memory()[1] - floor)
            best = min(best, seconds)
            if outcome.status in ("interrupted", "cancelled"):
                raise KeyboardInterrupt
    finally:
        if started_tracing:
            tracemalloc.stop()
    return Measurement(outcome=outcome, seconds=best, peak_bytes=int(peak))
