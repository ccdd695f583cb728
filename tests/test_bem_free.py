"""The free-boundary half-space (bem-halfspace-free) against closed forms.

Known answers used here (E* = E / (1 - nu^2); an infinite half-space loaded only
inside the scan; the indentation d is the approach from the first touch against
the body far away):

* Love (1929): a uniform pressure p on a square of side c displaces its centre by
  (4 ln(1 + sqrt 2) / pi) p c / E*; far away the square acts as a point force
  p c^2, whose displacement is p c^2 / (pi E* r) (Boussinesq).
* Hertz, sphere of radius R: F = 4 E* a^3 / (3 R) and d = a^2 / R, with no
  correction for the domain (the periodic solver's has the images' Z F / (pi E* L)).
* A single asperity on a periodic map: as the map grows, the periodic solution
  tends to the free one. In the frame both share (the approach to the mean
  deformed surface of the map) they differ by the images' field, O(F / (E* L)):
  the difference halves when L doubles.

Discretisation: a pixel counts as in contact when its centre is, so a radius read
from a count is within one pixel of the continuum's; the approach converges like
(dx / a)^2.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from frictionlab import Profile
from frictionlab.plugin.registry import Registry
from frictionlab.testing import check_plugin
from frictionlab_solvers import BEMHalfSpace, BEMHalfSpaceFree
from frictionlab_solvers.bem_free import FreeHalfSpace, pixel_influence


def solve(solver, z, loads, control="force", dx=1.0, periodic=False):
    z = np.asarray(z, float)
    return solver.solve(Profile(z, dx, periodic), np.atleast_1d(np.asarray(loads, float)), control, np.ones(z.shape))


def sphere(points, radius, dx=1.0, cap=None):
    """A paraboloid of curvature radius ``radius`` centred on the map (flat beyond ``cap``)."""
    x = (np.arange(points) - points // 2) * dx
    r2 = x[:, None] ** 2 + x[None, :] ** 2
    return -(r2 if cap is None else np.minimum(r2, cap**2)) / (2 * radius)


@pytest.mark.parametrize("params", [{}, {"youngs_modulus": 3.0, "poisson_ratio": 0.5, "tolerance": 1e-12}])
def test_conformance(params):
    check_plugin("solver", BEMHalfSpaceFree, **params)


def test_registered_beside_the_periodic_solver():
    registry = Registry(discover=False)
    assert registry.get("solver", "bem-halfspace-free") is BEMHalfSpaceFree
    assert BEMHalfSpaceFree.dimensions == (2,) and not BEMHalfSpaceFree.periodic_only
    assert BEMHalfSpaceFree.indentation_reference == "undeformed body"
    assert BEMHalfSpaceFree.normalisation(2) == BEMHalfSpace.normalisation(2)  # same problem, same f


def test_pixel_influence_is_love_at_the_centre_and_boussinesq_far_away():
    influence = pixel_influence((16, 16))
    assert influence.shape == (32, 32)
    assert influence[0, 0] == pytest.approx(4 * math.log(1 + math.sqrt(2)) / math.pi, rel=1e-12)
    # even in both offsets: offset -k sits at index 2N - k
    assert influence[3, 5] == pytest.approx(influence[-3, 5], rel=1e-12) == pytest.approx(influence[3, -5], rel=1e-12)
    assert influence[5, 3] == pytest.approx(influence[3, 5], rel=1e-12)
    r = math.hypot(12, 9)  # the square's own size enters as 1 / (24 r^2) relative to the point force
    assert influence[12, 9] == pytest.approx(1 / (math.pi * r), rel=1 / (10 * r**2))


def test_the_pixel_influence_is_even_to_rounding_on_a_large_grid():
    """Far from the pixel, y + sqrt(x^2 + y^2) cancels for y < 0 unless formed stably: the
    offsets -k and k then differed by 1.3e-7 relative on a 1200^2 grid. What is left is the
    four terms of Love's form, each O(1), cancelling to O(1 / r): rounding of 1e-16 r^2."""
    influence = pixel_influence((600, 600))
    np.testing.assert_allclose(influence[1:600, 1:600], influence[-1:-600:-1, 1:600], rtol=1e-9)
    np.testing.assert_allclose(influence[1:600, 1:600], influence[1:600, -1:-600:-1], rtol=1e-9)
    np.testing.assert_allclose(influence[1:600, 1:600], influence[1:600, 1:600].T, rtol=1e-9)


def test_the_operator_is_the_direct_sum_over_loaded_pixels_without_wrapping():
    """Brute force on a small grid: u_i = sum_j K(i - j) p_j over the grid only."""
    shape = (6, 5)
    operator = FreeHalfSpace(shape)
    influence = pixel_influence(shape)  # offsets -N..N-1 each way: every difference on the grid
    pressure = np.random.default_rng(1).random(shape)
    direct = np.zeros(shape)
    for (i, j), p in np.ndenumerate(pressure):
        for (k, m), _ in np.ndenumerate(direct):
            direct[k, m] += influence[k - i, m - j] * p
    np.testing.assert_allclose(operator.displacement(pressure, np.empty(shape)), direct, rtol=1e-12)
    assert operator.point_stiffness == pytest.approx(1 / influence[0, 0], rel=1e-15)


def test_the_preconditioner_is_symmetric_keeps_the_mean_and_works_in_place():
    """To single precision: the periodic stiffness it uses is applied in float32."""
    operator = FreeHalfSpace((12, 10))
    rng = np.random.default_rng(2)
    a, b = rng.random((12, 10)), rng.random((12, 10))
    pa = operator.precondition(a, np.empty(a.shape))
    pb = operator.precondition(b, np.empty(b.shape))
    assert np.dot(pa.ravel(), b.ravel()) == pytest.approx(np.dot(a.ravel(), pb.ravel()), rel=1e-6)
    uniform = np.ones((12, 10))  # a uniform displacement needs the body's uniform-pressure stiffness
    expected = operator.mean_stiffness * uniform
    np.testing.assert_allclose(operator.precondition(uniform, np.empty(uniform.shape)), expected, rtol=1e-6)
    in_place = a.copy()
    np.testing.assert_array_equal(operator.precondition(in_place, in_place), pa)  # the CG calls it in place


@pytest.mark.parametrize("control", ["force", "indentation"])
def test_hertz_sphere_in_the_middle_of_a_non_periodic_map(control):
    """Contact radius within one pixel, approach and force within 0.5 % (the error at this
    resolution, a / dx = 21, is 0.15 %), with no correction for the domain."""
    points, radius, dx = 128, 50.0, 0.5
    solver = BEMHalfSpaceFree(youngs_modulus=2.0, poisson_ratio=0.3, tolerance=1e-10, stop="tolerance")
    e_star = solver.stiffness()
    a = np.array([6.0, 10.5])  # contact radii, 12 and 21 pixels
    d, force = a**2 / radius, 4 * e_star * a**3 / (3 * radius)
    z = sphere(points, radius, dx)
    if control == "force":
        curve = solve(solver, z, force, dx=dx)
        np.testing.assert_allclose(curve.indentation, d, rtol=5e-3)
    else:
        curve = solve(solver, z, d, control="indentation", dx=dx)
        np.testing.assert_allclose(curve.force, force, rtol=5e-3)
    radius_read = np.sqrt(curve.contact_count / np.pi) * dx
    assert np.all(np.abs(radius_read - a) <= dx)
    assert np.all(curve.extras["residual"] <= 1e-10)
    if control == "force":  # the certified stop (the default) finds the same contact, sooner
        certified = solve(BEMHalfSpaceFree(youngs_modulus=2.0, poisson_ratio=0.3), z, force, dx=dx)
        np.testing.assert_array_equal(certified.contact_count, curve.contact_count)
        np.testing.assert_allclose(certified.indentation, curve.indentation, rtol=1e-4)


def test_the_approach_does_not_depend_on_the_domain_unlike_the_periodic_one():
    radius, force = 20.0, 40.0
    exact = BEMHalfSpaceFree(tolerance=1e-10, stop="tolerance")
    free = [solve(exact, sphere(n, radius, cap=12), force).indentation[0] for n in (32, 64)]
    periodic = [solve(BEMHalfSpace(tolerance=1e-10, stop="tolerance"), sphere(n, radius, cap=12), force, periodic=True).indentation[0]
                for n in (32, 64)]  # fmt: skip
    e_star = BEMHalfSpaceFree().stiffness()
    hertz = (3 * force * radius / (4 * e_star)) ** (2 / 3) / radius
    assert free[0] == pytest.approx(free[1], rel=1e-9)  # the flat around the cap never touches
    assert free[1] == pytest.approx(hertz, rel=5e-3)
    assert abs(periodic[0] - periodic[1]) > 0.1 * hertz  # the periodic approach moves with L


def test_free_and_periodic_agree_on_a_single_asperity_as_the_map_grows():
    """A capped sphere on a periodic map of side L: in the frame both solvers share, the
    approach to the map's mean deformed surface, the difference halves as L doubles."""
    radius, force = 20.0, 40.0
    differences = []
    for points in (32, 64, 128):
        z = sphere(points, radius, cap=12)
        free = solve(BEMHalfSpaceFree(tolerance=1e-10, stop="tolerance"), z, force, periodic=True)
        periodic = solve(BEMHalfSpace(tolerance=1e-10, stop="tolerance"), z, force, periodic=True)
        to_mean_surface = free.indentation - free.extras["mean_displacement"]
        differences.append(abs(float(periodic.indentation[0] - to_mean_surface[0])))
        assert abs(int(free.contact_count[0]) - int(periodic.contact_count[0])) <= 8  # one symmetric ring of ties
    ratios = np.array(differences[1:]) / np.array(differences[:-1])
    assert np.all((ratios > 0.4) & (ratios < 0.65)), differences


def test_the_mean_displacement_is_that_of_the_elastic_surface_on_the_map():
    """extras["mean_displacement"]: the elastic surface's mean over the map. In full contact
    the surface takes the rigid one's shape, so it is d - mean(max z - z)."""
    z = 1e-3 * np.random.default_rng(4).random((16, 16))
    curve = solve(BEMHalfSpaceFree(tolerance=1e-10, stop="tolerance"), z, [0.5], control="indentation")
    assert curve.contact_count[0] == z.size
    assert curve.extras["mean_displacement"][0] == pytest.approx(0.5 - np.mean(z.max() - z), rel=1e-9)


def test_a_flat_map_is_refused_with_a_reason():
    with pytest.raises(ValueError, match="flat"):
        solve(BEMHalfSpaceFree(), np.zeros((16, 16)), [1.0])
