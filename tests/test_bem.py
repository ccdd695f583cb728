"""Boundary-element solvers (bem-halfplane, bem-halfspace) against closed forms.

Known answers used here:

* Westergaard: z = h0 cos(2 pi x / lambda) on a half-plane is in full contact
  from the mean pressure p* = pi E* h0 / lambda; below it the contact half-width
  a obeys p / p* = sin^2(pi a / lambda), with pressure
  p(x) = 2 p cos(pi x / lambda) / sin^2(pi a / lambda) * sqrt(sin^2(pi a / lambda) - sin^2(pi x / lambda)).
* Hertz (sphere and cylinder, both controls): tests/test_bem_closed_forms.py.
* One point in contact on a line of N pixels: the pressure F/dx on one pixel
  displaces it by w = (F / (pi E*)) * sum over modes m != 0 of 1/|m|.
"""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab import Profile
from frictionlab.plugin.registry import Registry
from frictionlab.testing import check_plugin
from frictionlab_solvers import BEMHalfPlane, BEMHalfSpace

def solve(solver, z, loads, control="force", dx=1.0, slopes=None):
    z = np.asarray(z)
    slopes = np.ones(z.shape) if slopes is None else slopes
    return solver.solve(Profile(z, dx), np.atleast_1d(np.asarray(loads, float)), control, slopes)


def rough_line(points, seed, smooth=8):
    rng = np.random.default_rng(seed)
    k = np.arange(1, points // 2 + 1)
    spectrum = np.zeros(points // 2 + 1, complex)
    spectrum[1:] = k**-1.5 * (k <= points / smooth) * np.exp(2j * np.pi * rng.random(k.size))
    z = np.fft.irfft(spectrum, n=points)
    return z / z.std()


def rough_surface(points, seed, smooth=6):
    rng = np.random.default_rng(seed)
    qy = np.fft.fftfreq(points)[:, None] * points
    qx = np.fft.rfftfreq(points)[None, :] * points
    q = np.hypot(qx, qy)
    amplitude = np.where((q > 0) & (q <= points / smooth), q, np.inf) ** -1.8
    z = np.fft.irfft2(amplitude * np.exp(2j * np.pi * rng.random(q.shape)), s=(points, points))
    return z / z.std()


def gradient_magnitude(z):
    return np.hypot(np.roll(z, -1, 0) - z, np.roll(z, -1, 1) - z)


# ------------------------------------------------------------------ contract


@pytest.mark.parametrize("cls", [BEMHalfPlane, BEMHalfSpace])
@pytest.mark.parametrize("params", [{}, {"youngs_modulus": 3.0, "poisson_ratio": 0.5, "tolerance": 1e-12}])
def test_conformance(cls, params):
    check_plugin("solver", cls, **params)


def test_interface_promised_to_the_study():
    registry = Registry(discover=False)
    assert registry.get("solver", "bem-halfplane") is BEMHalfPlane
    assert registry.get("solver", "bem-halfspace") is BEMHalfSpace
    assert (BEMHalfPlane.dimensions, BEMHalfSpace.dimensions) == ((1,), (2,))
    for cls in (BEMHalfPlane, BEMHalfSpace):
        assert set(cls.Params.model_fields) == {"youngs_modulus", "poisson_ratio", "tolerance", "max_iterations", "stop", "device", "fft_workers"}
        assert cls(youngs_modulus=2.0, poisson_ratio=0.5).stiffness() == pytest.approx(2.0 / 0.75, rel=1e-15)
    curve = solve(BEMHalfPlane(), rough_line(64, 1), [0.1, 0.3])
    assert set(curve.extras) == {"iterations", "residual"}
    assert curve.extras["iterations"].shape == curve.extras["residual"].shape == (2,)


# ------------------------------------------------------------------ Westergaard


def test_westergaard_contact_width_pressure_and_full_contact():
    points, dx, h0 = 256, 0.5, 0.3
    solver = BEMHalfPlane(youngs_modulus=2.0, poisson_ratio=0.3, tolerance=1e-10)
    e_star = solver.stiffness()
    wavelength = points * dx
    x = np.arange(points) * dx
    z = h0 * np.cos(2 * np.pi * x / wavelength)
    p_star = np.pi * e_star * h0 / wavelength
    ratios = np.array([0.1, 0.3, 0.6, 0.9, 0.999, 1.001, 3.0])
    slopes = -h0 * 2 * np.pi / wavelength * np.sin(2 * np.pi * x / wavelength)
    curve = solve(solver, z, ratios * p_star * wavelength, dx=dx, slopes=slopes)

    partial = ratios < 1
    half_width = wavelength / np.pi * np.arcsin(np.sqrt(ratios[partial]))
    # points strictly inside (-a, a): within one of 2a/dx, plus one for the edge pixel
    assert np.all(np.abs(curve.contact_count[partial] - 2 * half_width / dx) <= 2)
    assert np.all(curve.contact_count[partial] < points)
    assert np.all(curve.contact_count[~partial] == points)
    line_rms = np.sqrt(np.mean(slopes**2))
    assert np.all(curve.slope_rms_contact[~partial] == line_rms)  # xi = 1 exactly
    # the contact set is the interval around the crest: the slopes over it
    centred = np.minimum(x, wavelength - x)
    for count, rms in zip(curve.contact_count[partial], curve.slope_rms_contact[partial]):
        assert count % 2 == 1  # symmetric about the crest point
        nearest = np.argsort(centred, kind="stable")[:count]
        assert rms == pytest.approx(np.sqrt(np.mean(slopes[nearest] ** 2)), rel=1e-12)
    # full contact: the rigid line sits at the mean height, d = max z - mean z = h0
    assert curve.indentation[~partial] == pytest.approx(h0, rel=1e-12)

    # the pressure field at p = 0.6 p*: against the closed form, away from the sqrt edges
    mean_pressure = 0.6 * p_star
    s_a = 0.6  # sin^2(pi a / lambda)
    exact = (2 * mean_pressure * np.cos(np.pi * centred / wavelength) / s_a
             * np.sqrt(np.clip(s_a - np.sin(np.pi * centred / wavelength) ** 2, 0, None)))
    pressure = _pressure(solver, z, mean_pressure * wavelength, dx)
    assert np.max(np.abs(pressure - exact)) < 0.03 * exact.max()
    assert np.sqrt(np.mean((pressure - exact) ** 2)) < 0.01 * exact.max()


def _pressure(solver, z, force, dx):
    """The converged pressure field, through the solver's own CG (scaled back)."""
    from frictionlab_solvers.contact_cg import ProjectedCG
    from frictionlab_solvers.elastic import PeriodicHalfSpace

    z = np.asarray(z, float)
    depth = z.max() - z
    scale = depth.max()
    cg = ProjectedCG(PeriodicHalfSpace(z.shape), depth / scale)
    unit = solver.stiffness() * scale / dx
    mean = force / (z.size * dx ** z.ndim) / unit
    p, *_ = cg.solve(np.full(z.shape, mean), mean_pressure=mean, tolerance=1e-10, max_iterations=10_000)
    return p * unit


def test_the_cg_carries_the_requested_load_whatever_pressure_it_starts_from():
    from frictionlab_solvers.contact_cg import ProjectedCG
    from frictionlab_solvers.elastic import PeriodicHalfSpace

    x = np.arange(64)
    depth = 1.0 - np.cos(2 * np.pi * x / 64)  # one touching crest
    depth /= depth.max()
    answers = []
    for start in (np.full(64, 0.01), np.full(64, 5.0), np.zeros(64)):
        # the same converged pressure however far the start's mean is from the load
        p, *_ = ProjectedCG(PeriodicHalfSpace(depth.shape), depth).solve(start, mean_pressure=0.01, tolerance=1e-11, max_iterations=10_000)
        assert p.mean() == pytest.approx(0.01, rel=1e-12)
        answers.append(p.copy())
    assert np.allclose(answers[1], answers[0], rtol=0, atol=1e-9) and np.allclose(answers[2], answers[0], rtol=0, atol=1e-9)


# ------------------------------------------------------------------ one point


def test_one_point_in_contact_matches_the_lattice_sum():
    points, dx = 100, 0.1
    z = rough_line(points, 3)
    solver = BEMHalfPlane(youngs_modulus=4.0)
    force = 1e-9
    curve = solve(solver, z, force, dx=dx)
    assert curve.contact_count[0] == 1
    modes = np.arange(-points // 2 + 1, points // 2 + 1)
    modes = modes[modes != 0]
    expected = force / (np.pi * solver.stiffness()) * np.sum(1.0 / np.abs(modes))
    assert curve.indentation[0] == pytest.approx(expected, rel=1e-9)


# ------------------------------------------------------------------ the two solvers agree


def test_surface_constant_along_y_is_the_line_on_a_half_plane():
    line = rough_line(128, 5)
    rows = 8
    dx = 0.5
    surface = np.tile(line, (rows, 1))
    loads_line = np.array([0.02, 0.1, 0.4]) * line.std() * 128 * dx  # F per unit length
    params = {"youngs_modulus": 2.0, "tolerance": 1e-11}
    slopes_line = np.abs(np.gradient(line, dx))
    on_plane = solve(BEMHalfPlane(**params), line, loads_line, dx=dx, slopes=slopes_line)
    on_space = solve(BEMHalfSpace(**params), surface, loads_line * rows * dx, dx=dx,
                     slopes=np.tile(slopes_line, (rows, 1)))
    assert np.array_equal(on_space.contact_count, rows * on_plane.contact_count)
    np.testing.assert_allclose(on_space.indentation, on_plane.indentation, rtol=1e-8)
    np.testing.assert_allclose(on_space.slope_rms_contact, on_plane.slope_rms_contact, rtol=1e-12)
    np.testing.assert_allclose(on_space.force / (rows * dx), on_plane.force, rtol=1e-14)

    p_line = _pressure(BEMHalfPlane(**params), line, loads_line[1], dx)
    p_surface = _pressure(BEMHalfSpace(**params), surface, loads_line[1] * rows * dx, dx)
    np.testing.assert_allclose(p_surface, np.tile(p_line, (rows, 1)), rtol=0, atol=1e-8 * p_line.max())


# ------------------------------------------------------------------ convergence, warm start


def test_answer_and_residual_improve_as_the_tolerance_tightens():
    z = rough_surface(48, 7)
    load = 0.1 * 48 * 48  # mean pressure 0.1 E* h / dx
    reference = solve(BEMHalfSpace(tolerance=1e-13, stop="tolerance"), z, load)
    errors, residuals, iterations = [], [], []
    for tolerance in (1e-2, 1e-5, 1e-8):
        curve = solve(BEMHalfSpace(tolerance=tolerance, stop="tolerance"), z, load)
        assert curve.extras["residual"][0] <= tolerance
        residuals.append(curve.extras["residual"][0])
        iterations.append(curve.extras["iterations"][0])
        errors.append(abs(curve.indentation[0] - reference.indentation[0]) / reference.indentation[0])
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 1e-7
    assert residuals[0] > residuals[1] > residuals[2]
    assert iterations[0] < iterations[1] < iterations[2]


@pytest.mark.parametrize("cls, z", [(BEMHalfPlane, rough_line(256, 11)), (BEMHalfSpace, rough_surface(32, 11))])
def test_warm_started_sweep_equals_cold_solves(cls, z):
    solver = cls(tolerance=1e-11, stop="tolerance")
    slope = np.sqrt(np.mean(np.square(np.diff(z, axis=-1))))  # contact fraction ~ 2 p / (E* slope)
    loads = np.linspace(0.02, 0.3, 6) * slope * z.size
    sweep = solve(solver, z, loads)
    assert sweep.contact_count[-1] < z.size
    for j, load in enumerate(loads):
        cold = solve(solver, z, load)
        assert cold.contact_count[0] == sweep.contact_count[j]
        assert cold.indentation[0] == pytest.approx(sweep.indentation[j], rel=1e-8)
    assert np.all(np.diff(sweep.contact_count) >= 0) and np.all(np.diff(sweep.indentation) > 0)


def test_indentation_control_inverts_force_control():
    z = rough_surface(32, 2)
    solver = BEMHalfSpace(tolerance=1e-11, stop="tolerance")
    forces = np.array([0.02, 0.1, 0.3]) * z.size
    by_force = solve(solver, z, forces)
    assert by_force.contact_count[-1] < z.size  # past full contact the approach stops growing
    by_indentation = solve(solver, z, by_force.indentation, control="indentation")
    np.testing.assert_allclose(by_indentation.force, forces, rtol=1e-7)
    assert np.array_equal(by_indentation.contact_count, by_force.contact_count)


# ------------------------------------------------------------------ extremes and errors


@pytest.mark.parametrize("s", [1e-12, 1e12, 3.7])
def test_scale_invariance(s):
    z = rough_surface(32, 4)
    slopes = gradient_magnitude(z)
    loads = np.array([0.01, 0.1, 0.5]) * z.size
    base = solve(BEMHalfSpace(tolerance=1e-11), z, loads, slopes=slopes)
    scaled = solve(BEMHalfSpace(tolerance=1e-11), s * z + 5 * s, s * loads, slopes=s * slopes)
    assert np.array_equal(scaled.contact_count, base.contact_count)
    np.testing.assert_allclose(scaled.slope_rms_contact / s, base.slope_rms_contact, rtol=1e-12)
    np.testing.assert_allclose(scaled.indentation / s, base.indentation, rtol=1e-8)


def test_float32_profile_gives_the_float64_answer():
    z32 = rough_line(128, 9).astype(np.float32)
    loads = [0.05 * 128, 0.3 * 128]
    a = solve(BEMHalfPlane(), z32, loads)
    b = solve(BEMHalfPlane(), z32.astype(np.float64), loads)
    assert np.array_equal(a.contact_count, b.contact_count)
    assert np.array_equal(a.indentation, b.indentation)


def test_non_convergence_is_reported_with_the_residual():
    z = rough_surface(32, 1)
    with pytest.raises(ValueError, match=r"did not converge at load 1 \(force .*\): residual .* after 2 iterations"):
        solve(BEMHalfSpace(max_iterations=2), z, [1e6, 0.1 * z.size])  # load 0 is full contact: exact


def test_full_contact_needs_no_iterations_and_gives_xi_one():
    z = rough_line(64, 8)
    slopes = np.gradient(z)
    curve = solve(BEMHalfPlane(), z, [1e3 * 64], slopes=slopes)
    assert curve.contact_count[0] == 64 and curve.contact_fraction[0] == 1.0
    assert curve.extras["iterations"][0] == 0
    assert curve.slope_rms_contact[0] == np.sqrt(np.mean(np.square(slopes)))
    assert curve.indentation[0] == pytest.approx(z.max() - z.mean(), rel=1e-12)


def test_flat_profile_exact_under_force_and_error_under_indentation():
    flat = np.full((4, 6), 2.5)
    curve = solve(BEMHalfSpace(), flat, [1.0, 2.0])
    assert np.array_equal(curve.contact_count, [24, 24]) and np.array_equal(curve.indentation, [0.0, 0.0])
    with pytest.raises(ValueError, match="flat"):
        solve(BEMHalfSpace(), flat, [0.1], control="indentation")


def test_clear_errors():
    line = rough_line(64, 0)
    with pytest.raises(ValueError, match=r"indentation [0-9.e+-]+ \(load 1\) is at or past the full-contact approach"):
        solve(BEMHalfPlane(), line, [0.1, line.max() - line.mean()], control="indentation")  # a number, not np.float64(...)
    with pytest.raises(ValueError, match=r"shape \(Ny, Nx\)"):
        solve(BEMHalfSpace(), line, [1.0])
    with pytest.raises(ValueError, match=r"shape \(N,\)"):
        solve(BEMHalfPlane(), np.tile(line, (2, 1)), [1.0])
    for bad in (0.0, -1.0, np.nan, np.inf):
        with pytest.raises(ValueError, match="load 0"):
            solve(BEMHalfPlane(), line, [bad])
    with pytest.raises(ValueError, match="finite"):
        solve(BEMHalfPlane(), np.where(np.arange(64) == 3, np.nan, line), [1.0])
    with pytest.raises(ValueError, match="tolerance"):
        BEMHalfPlane(tolerance=0.0)


@pytest.mark.parametrize("cls, z", [(BEMHalfPlane, rough_line(64, 3)), (BEMHalfSpace, rough_surface(32, 5))])
def test_the_indentation_no_load_reaches_is_the_approach_at_full_contact(cls, z):
    """``full_contact_indentation``, which validate checks the loads against, is where a solve
    under force control stops approaching, and what a solve under indentation control cannot pass."""
    solver = cls(tolerance=1e-11, stop="tolerance")
    full = solver.full_contact_indentation(Profile(z, 1.0))
    assert full == pytest.approx(float(solve(solver, z, [1e4 * z.size]).indentation[0]), rel=1e-12)
    nearly = solve(solver, z, [0.999 * full], control="indentation")
    assert 0.9 * z.size < nearly.contact_count[0] < z.size
    with pytest.raises(ValueError, match="at or past the full-contact approach"):
        solve(solver, z, [full], control="indentation")
    assert solver.full_contact_indentation(Profile(z, 1.0, periodic=False)) is None
