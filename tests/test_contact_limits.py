"""The two ends of every solver's curve, through the engine, for every slope estimator (no law
is fitted to a curve with xi the same at every load, so ``frictionlab.run`` reports those as failed).

* Far past full contact every point touches, so xi = rms slope over the contact / rms
  slope of the whole profile is 1 exactly (the same numbers averaged the same way).
* At a load far below the first point's share, one point touches: the highest one, and xi
  is |its slope| / rms slope of the profile (docs/explanation/extremes.md), checked here
  against the slopes recomputed from the regenerated profile.
"""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab.compute import engine
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.preset.seeds import realization_rng

LINE = {"name": "power-law", "params": {"hurst": 0.7, "points": 256, "spacing": 0.5, "rms_height": 0.2}}
SURFACE = {"name": "power-law-2d",
           "params": {"hurst": 0.7, "points": 32, "spacing": 0.5, "rms_height": 0.2, "short_cutoff": 2.0}}  # fmt: skip
CASES = [("mdr", LINE), ("mdr-bisection", LINE), ("winkler", LINE), ("winkler", SURFACE), ("bem-halfplane", LINE),
         ("bem-halfspace", SURFACE), ("bem-halfspace-free", SURFACE)]  # fmt: skip
IDS = [f"{s}-{'surface' if b is SURFACE else 'line'}" for s, b in CASES]
SLOPES = ("forward-difference", "central-difference", "spectral")


def _preset(solver: str, spectrum: dict, slope: str, start: float, stop: float) -> dict:
    return {
        "name": "limits",
        "seed": 5,
        "realizations": 2,
        "spectrum": spectrum,
        "solver": {"name": solver},
        "slope": {"name": slope},
        "loading": {"control": "force", "start": start, "stop": stop, "steps": 2, "spacing": "log"},
        "fit": {"bootstrap": 0},
        "output": {"plot": False},
    }


@pytest.mark.parametrize("slope", SLOPES)
@pytest.mark.parametrize("solver, spectrum", CASES, ids=IDS)
def test_full_contact_gives_xi_one_exactly(solver, spectrum, slope):
    outcome = engine.run(build_scene(_preset(solver, spectrum, slope, 1e6, 1e8)), RunOptions(workers=1))
    assert not outcome.failures, outcome.failures
    np.testing.assert_array_equal(outcome.contact_fraction, 1.0)
    np.testing.assert_array_equal(outcome.per_realization["xi"], 1.0)
    np.testing.assert_array_equal(outcome.xi, 1.0)


@pytest.mark.parametrize("slope", SLOPES)
@pytest.mark.parametrize("solver, spectrum", CASES, ids=IDS)
def test_one_point_in_contact_gives_its_own_slope_over_the_profiles(solver, spectrum, slope):
    scene = build_scene(_preset(solver, spectrum, slope, 1e-12, 1e-10))
    outcome = engine.run(scene, RunOptions(workers=1))
    assert not outcome.failures, outcome.failures
    np.testing.assert_array_equal(outcome.per_realization["contact_count"], 1)
    for index, xi in zip(outcome.indices, outcome.per_realization["xi"]):
        profile = scene.spectrum.generate(realization_rng(scene.preset.seed, int(index)))
        slopes = np.abs(scene.slope.slopes(profile.heights, profile.spacing))
        top = np.unravel_index(np.argmax(profile.heights), profile.heights.shape)
        expected = slopes[top] / np.sqrt(np.mean(slopes**2))
        np.testing.assert_allclose(xi, expected, rtol=1e-12)
