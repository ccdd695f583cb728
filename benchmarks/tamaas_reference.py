"""Tamaas, the benchmarks' outside reference: its PolonskyKeerRey solver over a sweep of
loads (``pip install tamaas``, the ``bench`` extra)."""

from __future__ import annotations

import time

import numpy as np


def load_tamaas():
    """Tamaas set to one thread (as frictionlab's solve) and quiet, or None where it is not installed."""
    try:
        import tamaas
    except ImportError:
        return None
    tamaas.initialize(1)
    tamaas.set_log_level(tamaas.LogLevel.error)
    return tamaas


def tamaas_sweep(tamaas, heights, forces):
    """Tamaas's PolonskyKeerRey over ``forces`` on one solver object (each load
    starts from the last one's state), tolerance 1e-10: ((CPU, wall) seconds, None, counts)."""
    z = np.ascontiguousarray(heights, dtype=float)
    ny, nx = z.shape
    model = tamaas.ModelFactory.createModel(tamaas.model_type.basic_2d, [float(ny), float(nx)], [ny, nx])
    model.E, model.nu = 1.0, 0.0
    solver = tamaas.PolonskyKeerRey(model, z, 1e-10)
    solver.max_iter = 100_000
    counts = []
    cpu, wall = time.process_time(), time.perf_counter()
    for force in forces:
        solver.solve(force / z.size)  # Tamaas loads by mean pressure
        counts.append(int(np.count_nonzero(np.asarray(model.traction) > 0)))
    return (time.process_time() - cpu, time.perf_counter() - wall), None, np.array(counts)
