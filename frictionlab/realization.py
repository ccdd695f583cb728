"""One realization of a scene: generate -> slopes -> solve -> xi.

Kept apart from the driver so every executor (in-process, a process pool, Dask
workers) imports only this and the scene, nothing of the run's bookkeeping.
"""

from __future__ import annotations

import math
import os
import time
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

from .plugin import force_unit, listening_to_loads
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
    real_area_corrected: np.ndarray | None = None  # kept for the solvers that declare corrected_area
    slope_rms_line: float = math.nan
    points: int = 0
    force_unit: float = math.nan  # k h X of f = F / (k h X) for this realization's profile
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.error is None


LoadListener = Callable[[int, int, int], None]
"""Hears ``(realization index, loads done, loads)`` as a solver reports each load (``plugin.load_finished``)."""


def compute_realization(scene: Scene, index: int, on_load: LoadListener | None = None) -> RealizationResult:
    """Realization ``index`` of ``scene``; ``on_load`` hears its solver's progress per load.
    Never raises: a failure is carried on the result."""
    listener = None if on_load is None else (lambda done, total: on_load(index, done, total))
    with listening_to_loads(listener):
        return _compute(scene, index)


def _compute(scene: Scene, index: int) -> RealizationResult:
    start = time.perf_counter()
    try:
        rng = realization_rng(scene.preset.seed, index)
        profile = scene.generator.generate(rng)
        slopes = scene.slope.slopes(profile.heights, profile.spacing, profile.periodic)
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
            real_area_corrected=np.asarray(curve.real_area_corrected, float) if scene.solver.corrected_area else None,
            slope_rms_line=slope_rms_line,
            points=profile.points,
            force_unit=force_unit(scene.solver, scene.generator.rms_height(), profile),
        )
    except Exception as exc:  # carried, not raised: one bad line must not end the run
        where = traceback.extract_tb(exc.__traceback__)[-1]
        error = f"{type(exc).__name__}: {exc} ({os.path.basename(where.filename)}:{where.lineno})"
        return RealizationResult(index=index, seconds=time.perf_counter() - start, error=error)


def compute_chunk(scene: Scene, indices: Iterable[int], on_load: LoadListener | None = None) -> list[RealizationResult]:
    """The task every executor runs: a chunk of realizations, in order."""
    return [compute_realization(scene, int(i), on_load) for i in indices]
