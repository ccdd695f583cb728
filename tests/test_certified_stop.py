"""The certified stop finds the contact set of a tolerance-1e-12 solve, pixel for pixel.

``stop: certified`` ends a load once its contact set has been unchanged for two CG
steps and every point's margin (pressure on contact, gap off it) exceeds ten times
its last change. That is a rule of thumb, not a theorem, so it is held here to the
contact sets of the same loads solved alone to a residual of 1e-12 (where the set is
final): on random surfaces of several Hurst exponents and sizes, from about 0.5 to
30 % contact, under force control (the only control it stops), in warm-started
sweeps (as a run solves them), on the half-space and on the half-plane. A reduced
set runs in the suite; the full validation (216 loads: 27 sweeps of 8 loads on
128^2 to 512^2 surfaces; 72 loads on lines of 1024 to 16384 points) is marked slow:

    pytest -m slow tests/test_certified_stop.py -s -p no:cacheprovider
"""

from __future__ import annotations

import numpy as np
import pytest

import frictionlab_solvers.contact_cg as contact_cg
from frictionlab.preset.seeds import realization_rng
from frictionlab_solvers import BEMHalfPlane, BEMHalfSpace
from frictionlab_spectra.power_law import PowerLaw
from frictionlab_spectra.surface import PowerLawSurface

FRACTIONS = np.geomspace(0.005, 0.3, 8)  # contact fractions the loads aim at


def contact_sets(monkeypatch, solver, profile, loads, control):
    """The contact set of every load as the solver finds it, and its curve."""
    sets = []
    solve = contact_cg.ProjectedCG.solve

    def recording(self, pressure, **kwargs):
        answer = solve(self, pressure, **kwargs)
        sets.append(answer[0] > 0.0)
        return answer

    with monkeypatch.context() as patch:
        patch.setattr(contact_cg.ProjectedCG, "solve", recording)
        curve = solver.solve(profile, loads, control, np.ones_like(profile.heights))
    return sets, curve


def scene(hurst, points, seed, dimension):
    """A random self-affine surface (the half-space) or line (the half-plane), spacing 1."""
    spectrum = PowerLawSurface if dimension == 2 else PowerLaw
    profile = spectrum(hurst=hurst, points=points, spacing=1.0).generate(realization_rng(seed, 0))
    return profile, BEMHalfSpace if dimension == 2 else BEMHalfPlane


def loads_for(profile, control, solver_class=BEMHalfSpace):
    """Forces (or approaches) that put about FRACTIONS of the profile in contact:
    A/A0 ~ 2 p / (E* grad h) at small loads (E* = 1, spacing 1)."""
    z = profile.heights
    axes = range(z.ndim)
    slope = np.sqrt(sum(np.mean(np.square(np.diff(z, axis=a, append=np.take(z, [0], axis=a)))) for a in axes))
    forces = FRACTIONS * slope / 2 * z.size
    if control == "force":
        return forces
    reference = solver_class().solve(profile, forces, "force", np.ones_like(z))
    return reference.indentation


def differing_pixels(monkeypatch, hurst, points, seed, control="force", dimension=2):
    """Per load: pixels whose contact state differs between the certified sweep and
    cold solves at tolerance 1e-12; and the certified sweep's curve and the reference's."""
    profile, solver_class = scene(hurst, points, seed, dimension)
    loads = loads_for(profile, control, solver_class)
    certified, curve = contact_sets(monkeypatch, solver_class(stop="certified"), profile, loads, control)
    exact = solver_class(tolerance=1e-12, stop="tolerance")
    references = [contact_sets(monkeypatch, exact, profile, loads[j : j + 1], control) for j in range(loads.size)]
    differ = [int(np.count_nonzero(mine != sets[0])) for mine, (sets, _) in zip(certified, references)]
    return differ, curve, [c for _, c in references]


def check(monkeypatch, hurst, points, seed, control, dimension=2):
    differ, curve, references = differing_pixels(monkeypatch, hurst, points, seed, control, dimension)
    counts = np.array([c.contact_count[0] for c in references])
    quantity = "indentation" if control == "force" else "force"
    exact = np.array([getattr(c, quantity)[0] for c in references])
    error = np.abs(getattr(curve, quantity) / exact - 1)
    size = points**dimension
    print(f"H {hurst} {points}^{dimension} seed {seed} {control}: contact {counts.min() / size:.2%} .. "
          f"{counts.max() / size:.2%}, differing pixels {differ}, iterations {curve.extras['iterations'].tolist()}, "
          f"largest relative {quantity} error {error.max():.1e}")  # fmt: skip
    assert differ == [0] * len(differ)
    assert np.array_equal(curve.contact_count, counts)
    assert error.max() < 1e-4  # what the docs promise


@pytest.mark.parametrize(
    ("hurst", "points", "seed", "control"),
    [(0.8, 64, 1, "force"), (0.3, 64, 2, "force"), (0.5, 128, 3, "force"), (0.8, 96, 4, "force")],
)
def test_certified_sweeps_find_the_exact_contact_sets(monkeypatch, hurst, points, seed, control):
    check(monkeypatch, hurst, points, seed, control)


@pytest.mark.parametrize(("hurst", "points", "seed"), [(0.8, 2048, 1), (0.3, 1024, 2)])
def test_certified_sweeps_on_the_half_plane_find_the_exact_contact_sets(monkeypatch, hurst, points, seed):
    check(monkeypatch, hurst, points, seed, "force", dimension=1)


@pytest.mark.slow
@pytest.mark.parametrize("hurst", [0.3, 0.5, 0.8])
@pytest.mark.parametrize(
    ("points", "seed"), [(128, s) for s in range(4)] + [(256, s) for s in range(3)] + [(512, s) for s in range(2)]
)
def test_certified_stop_validation_force(monkeypatch, hurst, points, seed):
    check(monkeypatch, hurst, points, 100 + seed, "force")


@pytest.mark.slow
@pytest.mark.parametrize("hurst", [0.3, 0.5, 0.8])
@pytest.mark.parametrize(("points", "seed"), [(1024, 0), (4096, 1), (16384, 2)])
def test_certified_stop_validation_half_plane(monkeypatch, hurst, points, seed):
    check(monkeypatch, hurst, points, 300 + seed, "force", dimension=1)


def test_under_indentation_control_the_tolerance_stops():
    """The force is the answer of an indentation sweep: the certified stop would leave
    it 1e-3 off, so the solver stops on the tolerance whatever ``stop`` says."""
    profile = PowerLawSurface(hurst=0.8, points=64, spacing=1.0).generate(realization_rng(9, 0))
    loads = loads_for(profile, "indentation")
    slopes = np.ones_like(profile.heights)
    certified = BEMHalfSpace(stop="certified").solve(profile, loads, "indentation", slopes)
    tolerance = BEMHalfSpace(stop="tolerance").solve(profile, loads, "indentation", slopes)
    assert np.array_equal(certified.force, tolerance.force)
    assert np.array_equal(certified.extras["iterations"], tolerance.extras["iterations"])
    assert np.all(certified.extras["residual"] <= 1e-8)


def test_the_stop_is_a_checked_parameter():
    assert BEMHalfSpace().params.stop in ("certified", "tolerance")
    with pytest.raises(ValueError, match="stop"):
        BEMHalfSpace(stop="sometimes")
