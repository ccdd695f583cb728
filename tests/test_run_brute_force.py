"""A whole MDR run against a brute-force recomputation written from the physics alone.

Each realization's line is regenerated from its seed; then, with nothing of the solvers:
the points sorted by height, the level c at force F from F = E* dx sum_i max(0, z_i - c)
(cumulative sums over the sorted heights), the contact set z > c, the forward-difference
slopes with the wrap-around of a periodic line, xi = rms slope over the set / rms slope
of the line, the indentation max z - c and f = F / (E* h L), E* = E / (1 - nu^2). The
run's table (means over the realizations) must agree to rounding.
"""

from __future__ import annotations

import numpy as np
import pytest

import frictionlab
from frictionlab.preset.seeds import realization_rng
from frictionlab_spectra import PowerLaw

LINE = {"hurst": 0.7, "points": 2000, "spacing": 0.37, "rms_height": 0.8}
YOUNG, POISSON = 2.6, 0.3


def brute_force(z: np.ndarray, dx: float, e_star: float, forces: np.ndarray):
    """(contact counts, xi, indentations) of the line ``z`` at each force."""
    slopes = (np.roll(z, -1) - z) / dx
    top_down = np.sort(z)[::-1]
    total = np.cumsum(top_down)
    counts, xi, depth = [], [], []
    for force in forces:
        levels = (total - force / (e_star * dx)) / np.arange(1, z.size + 1)  # c if the n highest touch
        n = int(np.argmax(levels[:-1] >= top_down[1:])) + 1  # the first n whose level leaves the next out
        contact = z > levels[n - 1]
        counts.append(contact.sum())
        xi.append(np.sqrt(np.mean(slopes[contact] ** 2) / np.mean(slopes**2)))
        depth.append(z.max() - levels[n - 1])
    return np.array(counts), np.array(xi), np.array(depth)


def test_an_mdr_run_is_its_brute_force_recomputation():
    realizations = 3
    result = frictionlab.run(
        "quickstart",
        {"spectrum.params": LINE, "solver.params": {"youngs_modulus": YOUNG, "poisson_ratio": POISSON},
         "loading.start": 0.02, "loading.stop": 5.0, "loading.steps": 9, "fit.bootstrap": 0},
        realizations=realizations, workers=1, progress=False, plot=False,
    )  # fmt: skip
    e_star = YOUNG / (1 - POISSON**2)
    forces = result.table["F"]
    length = LINE["points"] * LINE["spacing"]
    np.testing.assert_allclose(result.table["f"], forces / (e_star * LINE["rms_height"] * length), rtol=1e-14)
    answers = []
    for index in range(realizations):
        z = PowerLaw(**LINE).generate(realization_rng(result.preset["seed"], index)).heights
        assert np.std(z) == pytest.approx(LINE["rms_height"], rel=1e-12)  # h of f is the line's own rms
        answers.append(brute_force(z, LINE["spacing"], e_star, forces))
    counts, xi, depth = (np.mean(a, axis=0) for a in zip(*answers))
    assert np.all(counts < LINE["points"]) and counts[0] >= 1  # partial contact throughout
    np.testing.assert_array_equal(result.table["contact_count"], counts)
    np.testing.assert_allclose(result.table["xi"], xi, rtol=1e-12)
    np.testing.assert_allclose(result.table["indentation"], depth, rtol=1e-10)
