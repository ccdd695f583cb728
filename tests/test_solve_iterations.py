"""The exact solvers' CG loop reports every iteration through
``frictionlab.iteration_done`` and stops at once when it raises ``SolveCancelled``;
and the stop and preconditioner of the default CG against the baseline CG."""

from __future__ import annotations

import contextlib
import importlib.util
from pathlib import Path

import numpy as np
import pytest

import frictionlab.plugin
from frictionlab import Profile, SolveCancelled
from frictionlab.preset.seeds import realization_rng
from frictionlab_solvers import BEMHalfPlane, BEMHalfSpace
from frictionlab_solvers.contact_cg import ProjectedCG, cold_start
from frictionlab_solvers.elastic import PeriodicHalfSpace
from frictionlab_spectra.surface import PowerLawSurface


def _benchmark_baseline():
    """The Polonsky-Keer CG that benchmarks/bench_bem.py measures against (a benchmark's module)."""
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "polonsky_keer.py"
    spec = importlib.util.spec_from_file_location("polonsky_keer", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.PolonskyKeerCG


PolonskyKeerCG = _benchmark_baseline()


def surface(points=64, seed=3):
    return PowerLawSurface(hurst=0.8, points=points, spacing=1.0).generate(realization_rng(seed, 0))


@pytest.fixture
def listen():
    """``listen(listener)``: ``iteration_done`` calls ``listener`` in this thread until the test ends."""
    with contextlib.ExitStack() as stack:
        yield lambda listener: stack.enter_context(frictionlab.plugin.listening_to_iterations(listener))


class Baseline(BEMHalfSpace):
    contact_cg = PolonskyKeerCG


@pytest.mark.parametrize(
    "solver", [BEMHalfSpace(stop="tolerance"), BEMHalfSpace(stop="certified"), Baseline(stop="tolerance")]
)
@pytest.mark.parametrize("control", ["force", "indentation"])
def test_every_iteration_of_every_load_is_reported(listen, solver, control):
    calls = []
    listen(lambda i, r: calls.append((i, r)))
    profile = surface()
    loads = np.array([5.0, 50.0, 200.0]) if control == "force" else np.array([0.2, 0.5, 0.9])
    curve = solver.solve(profile, loads, control, np.ones_like(profile.heights))
    iterations = curve.extras["iterations"]
    assert iterations.min() > 0
    # each load's calls count 0, 1, ... up to its iterations - 1, in order
    expected = [i for n in iterations for i in range(n)]
    assert [i for i, _ in calls] == expected
    residuals = np.array([r for _, r in calls])
    assert np.all(np.isfinite(residuals)) and np.all(residuals > 0)


@pytest.mark.parametrize("cg_class", [ProjectedCG, PolonskyKeerCG])
def test_a_cancel_raised_by_the_listener_stops_the_solve_at_that_iteration(listen, cg_class):
    calls = []

    def listener(iteration, residual):
        calls.append(iteration)
        if iteration == 3:
            raise SolveCancelled

    listen(listener)
    z = surface(128).heights
    depth = (z.max() - z) / (z.max() - z.min())
    cg = cg_class(PeriodicHalfSpace(depth.shape), depth)
    with pytest.raises(SolveCancelled):
        cg.solve(cold_start(depth, 1e-3), mean_pressure=1e-3, tolerance=1e-12, max_iterations=10_000)
    assert calls == [0, 1, 2, 3]


def test_a_cancelled_run_solve_leaves_no_answer(listen):
    """Through the plugin: the cancel propagates out of solve (nothing is returned
    for the run to store), on the half-plane as on the half-space."""
    def cancel(iteration, residual):
        raise SolveCancelled

    listen(cancel)
    rng = np.random.default_rng(5)
    z = np.cumsum(rng.normal(size=256))
    z -= np.linspace(0, z[-1], 256)
    with pytest.raises(SolveCancelled):
        BEMHalfPlane().solve(Profile(z, 1.0), np.array([1.0]), "force", np.ones_like(z))


@pytest.mark.parametrize("control", ["force", "indentation"])
def test_the_preconditioned_cg_needs_fewer_fft_pairs_than_the_baseline_for_the_same_answer(monkeypatch, control):
    pairs = []
    apply = PeriodicHalfSpace._apply
    monkeypatch.setattr(PeriodicHalfSpace, "_apply", lambda self, *args: pairs.append(1) or apply(self, *args))
    profile = surface(128, seed=8)
    loads = np.array([20.0, 200.0, 800.0]) if control == "force" else np.array([0.3, 0.6, 1.0])
    slopes = np.ones_like(profile.heights)
    new = BEMHalfSpace(tolerance=1e-10, stop="tolerance").solve(profile, loads, control, slopes)
    new_pairs = len(pairs)
    old = Baseline(tolerance=1e-10, stop="tolerance").solve(profile, loads, control, slopes)
    old_pairs = len(pairs) - new_pairs
    assert np.array_equal(new.contact_count, old.contact_count)
    assert new.force == pytest.approx(old.force, rel=1e-8)
    assert new.indentation == pytest.approx(old.indentation, rel=1e-8)
    assert new_pairs < 0.8 * old_pairs
