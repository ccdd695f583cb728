"""The half-space and half-plane solvers against closed forms, under both controls.

Known answers used here (E* = E / (1 - nu^2); periodic cells; the solvers measure
the indentation d from the first touch to the mean elastic surface):

* Westergaard, a wave z = h cos(2 pi x / lambda) pressed on a half-space (a
  surface constant along y is a plane-strain problem): full contact from the mean
  pressure p* = pi E* h / lambda; below it, contact strips of half-width a with
  p / p* = sin^2(pi a / lambda), so the contact area fraction is 2 a / lambda.
* Johnson, Greenwood & Higginson (1985), the doubly sinusoidal surface
  z = h cos(2 pi x / lambda) cos(2 pi y / lambda): its single Fourier mode has
  |q| = sqrt(2) 2 pi / lambda, so the full-contact pressure p + (E* |q| / 2) z is
  non-negative everywhere from p* = sqrt(2) pi E* h / lambda. At small loads each of
  its two peaks per lambda x lambda cell is a Hertz contact of curvature radius
  R = lambda^2 / (4 pi^2 h), carrying p lambda^2 / 2.
* Hertz, sphere of radius R on a half-space: F = 4 E* a^3 / (3 R) and, on a
  periodic square cell of side L, d = a^2 / R + Z F / (pi E* L) with
  Z = sum'_{n in Z^2} 1 / |n| (analytically continued) = 4 zeta(1/2) beta(1/2)
  = -3.9003, the Madelung constant of the square lattice, up to O((a / L)^2).
* Hertz, cylinder in plane strain (F per unit length): F = pi E* a^2 / (4 R) and,
  on a periodic line of length L, d = (2 F / (pi E*)) (ln(L / (pi a)) + 1/2): the
  periodic Green's function -(2 F / (pi E*)) ln|2 sin(pi x / L)| integrated against
  the Hertz pressure, up to O((a / L)^2).

Discretisation: a pixel counts as in contact when its centre is; a contact
boundary therefore moves the count by at most the pixels it crosses, which bounds
each radius or half-width read from a count to within one pixel. Forces and
indentations converge like (dx / a)^2 (a smooth pressure sampled at pixel
centres, with a square-root edge spread over one pixel).
"""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab import Profile
from frictionlab_solvers import BEMHalfPlane, BEMHalfSpace

MADELUNG_SQUARE = -3.900264920001955  # 4 zeta(1/2) beta(1/2)


def solve(solver, z, loads, control="force", dx=1.0):
    loads = np.atleast_1d(np.asarray(loads, float))
    return solver.solve(Profile(np.asarray(z, float), dx), loads, control, np.ones(np.shape(z)))


# ------------------------------------------------------------------ Westergaard on the half-space


@pytest.mark.parametrize("control", ["force", "indentation"])
def test_westergaard_wave_on_the_half_space(control):
    columns, rows, dx, h = 128, 4, 0.5, 0.2
    wavelength = columns * dx
    solver = BEMHalfSpace(youngs_modulus=3.0, poisson_ratio=0.25, tolerance=1e-10)
    e_star = solver.stiffness()
    x = np.arange(columns) * dx
    z = np.tile(h * np.cos(2 * np.pi * x / wavelength), (rows, 1))
    p_star = np.pi * e_star * h / wavelength
    ratios = np.array([0.05, 0.2, 0.5, 0.8, 0.95])
    half_width = wavelength / np.pi * np.arcsin(np.sqrt(ratios))
    area = columns * rows * dx**2
    if control == "force":
        curve = solve(solver, z, ratios * p_star * area, dx=dx)
    else:  # the approaches that force control finds give back the forces and the same strips
        by_force = solve(solver, z, ratios * p_star * area, dx=dx)
        curve = solve(solver, z, by_force.indentation, control="indentation", dx=dx)
        np.testing.assert_allclose(curve.force, ratios * p_star * area, rtol=1e-6)
    columns_in_contact = curve.contact_count / rows
    assert np.array_equal(columns_in_contact % 2, np.ones(ratios.size))  # whole columns, symmetric about the crest
    # k pixels either side of the crest: the centres strictly inside (-a, a) give k = floor(a / dx);
    # each edge of the discrete strip may sit one pixel off the continuum's
    assert np.all(np.abs((columns_in_contact - 1) / 2 - np.floor(half_width / dx)) <= 1)


def test_westergaard_wave_is_in_full_contact_exactly_from_p_star():
    columns, rows, h = 64, 2, 1.0
    solver = BEMHalfSpace(tolerance=1e-10)
    z = np.tile(h * np.cos(2 * np.pi * np.arange(columns) / columns), (rows, 1))
    p_star = np.pi * h / columns
    curve = solve(solver, z, np.array([0.999, 1.001]) * p_star * z.size)
    assert curve.contact_count[0] < z.size and curve.contact_count[1] == z.size


# ------------------------------------------------------------------ Johnson, Greenwood & Higginson


def doubly_sinusoidal(points, h):
    y, x = np.mgrid[0:points, 0:points] * (2 * np.pi / points)
    return h * np.cos(x) * np.cos(y)


def test_doubly_sinusoidal_full_contact_pressure():
    points, h = 64, 0.5
    solver = BEMHalfSpace(youngs_modulus=2.0, tolerance=1e-10)
    z = doubly_sinusoidal(points, h)
    p_star = np.sqrt(2) * np.pi * solver.stiffness() * h / points
    curve = solve(solver, z, np.array([0.99, 1.001]) * p_star * z.size)
    assert 0 < z.size - curve.contact_count[0]  # the troughs still open just below p*
    assert curve.contact_count[1] == z.size


@pytest.mark.parametrize("radius_pixels", [6.0, 9.0])
def test_doubly_sinusoidal_small_loads_are_hertzian(radius_pixels):
    """Each peak is a Hertz contact while a << lambda. Beyond the pixel bound, the
    cosine's quartic term flattens the peak: curvature radius R (1 + O((q a)^2 / 8)),
    so a is held to one pixel plus (q a)^2 / 8 of itself, and the neighbours' pressure
    (a smooth field over the contact) shifts the approach, not the area, to this order."""
    points, h = 128, 1.0
    solver = BEMHalfSpace(tolerance=1e-10)
    e_star = solver.stiffness()
    z = doubly_sinusoidal(points, h)
    q = 2 * np.pi / points
    radius = 1.0 / (q**2 * h)  # R = lambda^2 / (4 pi^2 h)
    peak_force = 4 * e_star * radius_pixels**3 / (3 * radius)
    curve = solve(solver, z, 2 * peak_force)  # two peaks share the cell's load
    measured = np.sqrt(curve.contact_count[0] / (2 * np.pi))
    assert abs(measured - radius_pixels) <= 1.0 + (q * radius_pixels) ** 2 / 8 * radius_pixels


# ------------------------------------------------------------------ Hertz, both controls


@pytest.mark.parametrize("control", ["force", "indentation"])
@pytest.mark.parametrize("radius_pixels", [8.0, 12.0])
def test_hertz_sphere_on_periodic_half_space(radius_pixels, control):
    points, dx, curvature_radius = 128, 0.25, 40.0
    solver = BEMHalfSpace(youngs_modulus=1.5, poisson_ratio=0.25, tolerance=1e-10)
    e_star = solver.stiffness()
    cell = points * dx
    y, x = (np.mgrid[0:points, 0:points] - points / 2) * dx
    z = -(x**2 + y**2) / (2 * curvature_radius)

    def approach(force):
        a = (3 * force * curvature_radius / (4 * e_star)) ** (1 / 3)
        return a**2 / curvature_radius + MADELUNG_SQUARE * force / (np.pi * e_star * cell)

    a = radius_pixels * dx
    force = 4 * e_star * a**3 / (3 * curvature_radius)
    if control == "force":
        curve = solve(solver, z, force, dx=dx)
        assert curve.indentation[0] == pytest.approx(approach(force), rel=5e-3)
        # without the periodic correction the answer would be off by more than 5 %
        assert abs(curve.indentation[0] / (a**2 / curvature_radius) - 1) > 0.05
    else:
        curve = solve(solver, z, approach(force), control="indentation", dx=dx)
        # F ~ d^(3/2) near the Hertz law: a relative error e in d is 1.5 e in F; e <= 2 (dx / a)^2
        assert curve.force[0] == pytest.approx(force, rel=3 * (dx / a) ** 2)
    assert abs(np.sqrt(curve.contact_count[0] / np.pi) - radius_pixels) <= 1.0


@pytest.mark.parametrize("control", ["force", "indentation"])
@pytest.mark.parametrize("half_width_pixels", [10.0, 20.0])
def test_hertz_cylinder_on_periodic_half_plane(half_width_pixels, control):
    points, dx, curvature_radius = 1024, 2.0, 5000.0
    solver = BEMHalfPlane(youngs_modulus=0.7, tolerance=1e-10)
    e_star = solver.stiffness()
    length = points * dx
    x = (np.arange(points) - points / 2) * dx
    z = -(x**2) / (2 * curvature_radius)

    def approach(force):
        a = np.sqrt(4 * force * curvature_radius / (np.pi * e_star))
        return 2 * force / (np.pi * e_star) * (np.log(length / (np.pi * a)) + 0.5)

    a = half_width_pixels * dx
    force = np.pi * e_star * a**2 / (4 * curvature_radius)
    if control == "force":
        curve = solve(solver, z, force, dx=dx)
        assert curve.indentation[0] == pytest.approx(approach(force), rel=2e-3)
    else:
        curve = solve(solver, z, approach(force), control="indentation", dx=dx)
        # d grows like F (ln(1 / F) + const): F is within the relative order of d, (dx / a)^2
        assert curve.force[0] == pytest.approx(force, rel=2 * (dx / a) ** 2)
    assert abs(curve.contact_count[0] / 2 - half_width_pixels) <= 1.0


def converged_pressure(solver, z, force, dx):
    """The pressure field of the solver's own CG at ``force``, in the units of E*."""
    from frictionlab_solvers.contact_cg import ProjectedCG
    from frictionlab_solvers.elastic import PeriodicHalfSpace

    depth = z.max() - z
    scale = depth.max()
    unit = solver.stiffness() * scale / dx  # the CG's pressure unit (bem.py)
    mean = force / (z.size * dx**z.ndim) / unit
    cg = ProjectedCG(PeriodicHalfSpace(z.shape), depth / scale)
    p, *_ = cg.solve(np.full(z.shape, mean), mean_pressure=mean, tolerance=1e-11, max_iterations=10_000)
    return p * unit


@pytest.mark.parametrize("sphere, contact_pixels", [(True, 8.0), (True, 12.0), (False, 10.0), (False, 40.0)])
def test_hertz_pressure_is_the_half_ellipse_of_peak_p0(sphere, contact_pixels):
    """p = p0 sqrt(1 - (r / a)^2), p0 = 3 F / (2 pi a^2) (sphere) or 2 F' / (pi a) (cylinder),
    inside 0.8 a (the square-root edge spreads over a pixel). Errors: the sampling, of the
    relative order (dx / a)^2, and the periodic images, whose smooth displacement adds a
    curvature of relative order (a / L)^2 (pi^2 / 6 for the cylinder, less in 3D)."""
    if sphere:
        points, dx, radius = 128, 0.25, 40.0
        solver = BEMHalfSpace(youngs_modulus=1.5, poisson_ratio=0.25)
        y, x = (np.mgrid[0:points, 0:points] - points / 2) * dx
        r = np.hypot(x, y)
    else:
        points, dx, radius = 1024, 2.0, 5000.0
        solver = BEMHalfPlane(youngs_modulus=0.7)
        r = np.abs((np.arange(points) - points / 2) * dx)
    e_star, a = solver.stiffness(), contact_pixels * dx
    force = 4 * e_star * a**3 / (3 * radius) if sphere else np.pi * e_star * a**2 / (4 * radius)
    peak = 3 * force / (2 * np.pi * a**2) if sphere else 2 * force / (np.pi * a)
    p = converged_pressure(solver, -(r**2) / (2 * radius), force, dx)
    inner = r < 0.8 * a
    error = np.max(np.abs(p[inner] - peak * np.sqrt(1 - (r[inner] / a) ** 2))) / peak
    assert error <= 3 * (dx / a) ** 2 + 2 * (a / (points * dx)) ** 2
    assert np.all(p[r > 1.1 * a] == 0.0)  # no pressure a pixel past the edge
