"""Helpers of the trade-off study's tests: tiny scenes throughout; ``mdr-bisection``
stands in for the exact reference where the machinery is tested (it solves the same
springs as ``mdr`` by another route, so their agreement is a known answer)."""


import pytest

from frictionlab.plugin.registry import Registry
from frictionlab.tradeoff.axes import Study
from frictionlab.tradeoff.options import StudyOptions
from frictionlab.tradeoff.scenes import SceneFactory

# A small line whose preset gives `spacing` (not `length`): shrinking N shortens the
# line, so keeping the f range needs the loads rescaled.
TINY = {
    "name": "tiny",
    "seed": 11,
    "realizations": 8,
    "spectrum": {"name": "power-law", "params": {"hurst": 0.8, "points": 256, "spacing": 1.0, "rms_height": 2.0}},
    "solver": {"name": "mdr", "params": {"youngs_modulus": 3.0, "poisson_ratio": 0.3}},
    "loading": {"start": 1.0, "stop": 60.0, "steps": 12, "spacing": "log"},
    "fit": {"bootstrap": 100},
}

TINY_OPTIONS = dict(
    reference="mdr-bisection",
    grid_factors=(0.5, 1, 2),
    grid_realizations=4,
    realizations_min=2,
    step_levels=(3, 6),
    compare_points=128,
    compare_realizations=4,
    compare_steps=8,
    tolerances=(1e-2, 1e-9),
)


@pytest.fixture(scope="package")
def builtins():
    return Registry(discover=False)


def study_of(data, registry, **options):
    return Study(SceneFactory(data, registry, "test"), StudyOptions(**{**TINY_OPTIONS, **options}))


@pytest.fixture(scope="package")
def tiny_study(builtins):
    study = study_of(TINY, builtins)
    study.run()
    return study


def by_axis(study, axis):
    return [r for r in study.rows if r.axis == axis]
