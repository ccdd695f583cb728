"""2D surfaces (issue 4): isotropic spectra, their MDR-equivalent line, Winkler springs per pixel,
slope estimators on surfaces, and how a preset picks the geometry that runs.

Oracles: the documented convention <z^2> = integral of C2D over the q plane (each mode q of the
grid has variance C2D(|q|) dqx dqy), measured with the test's own FFTs; quadrature of psd for
the closed forms; plane waves with known gradients; brute-force spring balance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from frictionlab.compute import engine
from frictionlab.errors import PresetError
from frictionlab.plugin import Profile, SlopeEstimator
from frictionlab.preset import build_scene
from frictionlab.testing import check_plugin
from frictionlab_slopes import CentralDifference, ForwardDifference, Spectral
from frictionlab_solvers import BisectionSprings, MDRSprings, WinklerSprings
from frictionlab_spectra import PowerLawSurface, RolloffSurface
from frictionlab.options import RunOptions

from .conftest import SMALL_PRESET, merge

TWO_PI = 2.0 * math.pi


def rms(a):
    return float(np.sqrt(np.mean(np.square(a))))


def mode_variances(z, dx):
    """(|q|, qx, qy, variance) of every mode of the full FFT plane: mean(z^2) = sum of the variances."""
    ny, nx = z.shape
    qx = TWO_PI * np.fft.fftfreq(nx, dx)
    qy = TWO_PI * np.fft.fftfreq(ny, dx)
    qy, qx = np.meshgrid(qy, qx, indexing="ij")
    variance = np.abs(np.fft.fft2(z)) ** 2 / (nx * ny) ** 2
    return np.hypot(qx, qy), qx, qy, variance


# ---------------------------------------------------------------- spectra

SURFACES = [
    (PowerLawSurface, dict(hurst=0.8, points=64)),
    (PowerLawSurface, dict(hurst=0.3, points=64, short_cutoff=2.0)),  # Nyquist row and column kept
    (PowerLawSurface, dict(hurst=1.0, points=33, points_y=40, short_cutoff=2.0)),  # odd x even y
    (PowerLawSurface, dict(hurst=0.5, points=48, points_y=31, spacing=0.01, c0=3.0, short_cutoff=0.03)),
    (RolloffSurface, dict(hurst=0.7, points=64, rolloff_wavelength=16.0, rms_height=4.0, short_cutoff=3.0)),
    (RolloffSurface, dict(hurst=1.2, points=50, rolloff_wavelength=8.0, c0=1e-3, short_cutoff=2.0)),
]


@pytest.mark.parametrize(("cls", "kwargs"), SURFACES[:3] + SURFACES[4:5])
def test_conformance(cls, kwargs):
    check_plugin("spectrum", cls, **kwargs)
    check_plugin("spectrum", cls, **kwargs, amplitudes="rayleigh")


@pytest.mark.parametrize(("cls", "kwargs"), SURFACES)
def test_fixed_surface_modes_follow_the_psd(cls, kwargs):
    """Each grid mode carries exactly C2D(|q|) dqx dqy, the plane sums to rms_height()^2."""
    gen = cls(**kwargs)
    profile = gen.generate(np.random.default_rng(3))
    z, dx = profile.heights, profile.spacing
    ny, nx = kwargs.get("points_y", kwargs["points"]), kwargs["points"]
    assert z.shape == (ny, nx) and z.dtype == np.float64 and dx == kwargs.get("spacing", 1.0)
    q, _, _, variance = mode_variances(z, dx)
    expected = gen.psd(q) * (TWO_PI / (nx * dx)) * (TWO_PI / (ny * dx))
    np.testing.assert_allclose(variance, expected, rtol=1e-9, atol=1e-12 * variance.max())
    assert rms(z) == pytest.approx(gen.rms_height(), rel=1e-12)
    assert abs(z.mean()) <= 1e-12 * gen.rms_height()
    if "rms_height" in kwargs:
        assert gen.rms_height() == kwargs["rms_height"]
    if "c0" in kwargs:  # the psd itself against the formula C0 q^(-2H-2) above the knee
        top = q >= TWO_PI / kwargs.get("rolloff_wavelength", nx * dx)
        band = (expected > 0) & top
        np.testing.assert_allclose(gen.psd(q[band]), kwargs["c0"] * q[band] ** (-2 * kwargs["hurst"] - 2), rtol=1e-12)


@pytest.mark.parametrize(("cls", "kwargs"), SURFACES)
def test_rms_gradient_of_a_fixed_surface(cls, kwargs):
    gen = cls(**kwargs)
    profile = gen.generate(np.random.default_rng(4))
    q, qx, qy, variance = mode_variances(profile.heights, profile.spacing)
    # the exact derivative of the trigonometric sum, from the modes themselves
    assert math.sqrt(np.sum(q**2 * variance)) == pytest.approx(gen.rms_slope_discrete(), rel=1e-9)
    # isotropy of the mode set: the x and y halves of the gradient carry the same power on a square grid
    if kwargs.get("points_y", kwargs["points"]) == kwargs["points"]:
        assert np.sum(qx**2 * variance) == pytest.approx(np.sum(qy**2 * variance), rel=1e-10)


@pytest.mark.parametrize("hurst", [0.0, 0.05, 0.5, 1.0, 1.5])
@pytest.mark.parametrize("cls", [PowerLawSurface, RolloffSurface])
def test_closed_forms_match_quadrature(cls, hurst):
    gen = cls(hurst=hurst, points=256, short_cutoff=3.0, **({"rolloff_wavelength": 40.0} if cls is RolloffSurface else {}))
    b = gen.band
    edges = sorted({b.q_min, b.q_knee, b.q_max})

    def moment(order):  # 2 pi integral q^(order+1) C2D dq, in ln q
        total = 0.0
        for lo, hi in zip(edges[:-1], edges[1:]):
            val, _ = quad(lambda t: math.exp(t) ** (order + 2) * float(gen.psd(math.exp(t))),
                          math.log(lo) + 1e-13, math.log(hi) - 1e-13, epsabs=0, epsrel=1e-11, limit=200)
            total += val
        return TWO_PI * total

    assert gen.rms_height_continuum() == pytest.approx(math.sqrt(moment(0)), rel=1e-8)
    assert gen.rms_slope() == pytest.approx(math.sqrt(moment(2)), rel=1e-8)


@pytest.mark.parametrize("hurst", [0.3, 0.8, 1.0])
def test_discrete_sums_approach_the_continuum_convention(hurst):
    """<z^2> = integral of C2D over the q plane, no (2 pi)^2: for a band well inside the grid
    the lattice sums and the integrals agree to a few per cent (a 2 pi slip would be 6x)."""
    gen = PowerLawSurface(hurst=hurst, points=512, long_cutoff=64.0, short_cutoff=4.0)
    assert gen.rms_height() == pytest.approx(gen.rms_height_continuum(), rel=0.03)
    assert gen.rms_slope_discrete() == pytest.approx(gen.rms_slope(), rel=0.01)


@pytest.mark.parametrize("amplitudes", ["fixed", "rayleigh"])
@pytest.mark.parametrize("hurst", [0.3, 0.9])
def test_psd_exponent_and_isotropy_recovered(hurst, amplitudes):
    gen = PowerLawSurface(hurst=hurst, points=256, short_cutoff=2.0, amplitudes=amplitudes)
    q, qx, qy, variance = mode_variances(gen.generate(np.random.default_rng(5)).heights, 1.0)
    band = (q > 2 * TWO_PI / 256) & (q < 0.5 * math.pi)
    edges = np.geomspace(q[band].min(), q[band].max(), 12)
    which = np.digitize(q[band], edges)
    centres, power = [], []
    for i in range(1, edges.size):
        inside = which == i
        centres.append(np.exp(np.mean(np.log(q[band][inside]))))
        power.append(np.mean(variance[band][inside] / (q[band][inside] / centres[-1]) ** (-2 * hurst - 2)))
    slope = np.polyfit(np.log(centres), np.log(power), 1)[0]
    assert slope == pytest.approx(-2 * hurst - 2, abs=0.03 if amplitudes == "fixed" else 0.15)
    # isotropy: the power along the two axes' directions and the diagonals agree
    angle = np.arctan2(np.abs(qy[band]), np.abs(qx[band]))
    scaled = variance[band] / gen.psd(q[band])
    sectors = [scaled[(angle >= a) & (angle < a + math.pi / 8)].mean() for a in np.arange(4) * math.pi / 8]
    assert max(sectors) / min(sectors) < (1 + 1e-9 if amplitudes == "fixed" else 1.15)


def test_determinism_and_edits():
    gen = PowerLawSurface(hurst=0.8, points=32, amplitudes="rayleigh")
    a = gen.generate(np.random.default_rng(1)).heights
    np.testing.assert_array_equal(a, gen.generate(np.random.default_rng(1)).heights)
    assert not np.array_equal(a, gen.generate(np.random.default_rng(2)).heights)
    gen.params.rms_height = 2.0  # edited in place (the TUI does): the cache follows
    np.testing.assert_allclose(gen.generate(np.random.default_rng(1)).heights, 2.0 * a, rtol=1e-12, atol=1e-14)
    assert gen.rms_height() == 2.0


def test_bad_surfaces_name_the_field():
    with pytest.raises(ValueError, match="long_cutoff=40.0 must not exceed the shorter side"):
        PowerLawSurface(hurst=0.5, points=64, points_y=32, long_cutoff=40.0)
    with pytest.raises(ValueError, match="Nyquist"):
        PowerLawSurface(hurst=0.5, points=64, short_cutoff=1.5)
    with pytest.raises(ValueError, match="give at most one of rms_height and c0"):
        PowerLawSurface(hurst=0.5, points=64, c0=1.0, rms_height=1.0)
    with pytest.raises(ValueError, match="points_y"):
        PowerLawSurface(hurst=0.5, points=64, points_y=4)


# ---------------------------------------------------------------- scenes

SURFACE_PRESET = merge(SMALL_PRESET, {
    "realizations": 3,
    "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 48, "rms_height": 1.0}},
    "loading": {"start": 0.02, "stop": 2.0, "steps": 6},
    "fit": {"bootstrap": 0},
})


def test_winkler_on_a_surface_runs_the_surface(registry):
    scene = build_scene({**SURFACE_PRESET, "solver": {"name": "winkler"}}, registry=registry)
    assert scene.equivalent_line is None and scene.geometry == "surface"
    outcome = engine.run(scene, RunOptions(workers=1))
    assert not outcome.failures
    assert outcome.extent == 48 * 48  # f = F / (k h A) on a surface
    assert outcome.per_realization["contact_count"].max() <= 48 * 48


def test_dimension_mismatches_are_preset_errors(register_plugin):
    class LineSlope(SlopeEstimator):
        name = "line-only-slope"
        summary = "forward difference on lines only"

        def slopes(self, heights, spacing, periodic=True):
            return ForwardDifference().slopes(heights, spacing, periodic)

    class SurfaceSolver(WinklerSprings):
        name = "surface-only-springs"
        dimensions = (2,)
        normalisations = {2: WinklerSprings.normalisations[2]}

    reg = register_plugin(LineSlope)
    register_plugin(SurfaceSolver)
    with pytest.raises(PresetError, match="slope.name: line-only-slope takes lines only, but the surface"):
        build_scene({**SURFACE_PRESET, "solver": {"name": "winkler"}, "slope": {"name": "line-only-slope"}},
                    registry=reg)
    # MDR maps the surface to a line first: then a line-only estimator is fine
    assert build_scene(merge(SURFACE_PRESET, {"slope": {"name": "line-only-slope"}}), registry=reg).geometry
    with pytest.raises(PresetError, match="surface-only-springs presses surfaces only, but spectrum power-law makes lines"):
        build_scene({**SMALL_PRESET, "solver": {"name": "surface-only-springs"}}, registry=reg)


# ---------------------------------------------------------------- springs per pixel


def test_winkler_surface_is_one_spring_per_pixel():
    z = PowerLawSurface(hurst=0.6, points=24, points_y=20, short_cutoff=2.0).generate(np.random.default_rng(6)).heights
    dx, modulus = 0.3, 2.5
    slopes = ForwardDifference().slopes(z, dx)
    solver = WinklerSprings(modulus=modulus)
    depths = np.geomspace(1e-3, 3.0, 15)
    surface = solver.solve(Profile(z, dx), depths, "indentation", slopes)
    u = z.max() - z
    for d, force, count, slope in zip(depths, surface.force, surface.contact_count, surface.slope_rms_contact):
        touching = u < d
        assert force == pytest.approx(modulus * dx**2 * np.sum(np.maximum(d - u, 0.0)), rel=1e-12)
        assert count == touching.sum() and slope == pytest.approx(rms(slopes[touching]), rel=1e-12)
    # force control inverts it; the flattened pixels as a line of spacing dx^2 are the same springs
    back = solver.solve(Profile(z, dx), surface.force, "force", slopes)
    np.testing.assert_allclose(back.indentation, depths, rtol=1e-9)
    flat = solver.solve(Profile(z.ravel(), dx**2), surface.force, "force", slopes.ravel())
    for name in ("indentation", "contact_count", "slope_rms_contact"):
        np.testing.assert_array_equal(getattr(flat, name), getattr(back, name))


@pytest.mark.parametrize("cls", [MDRSprings, BisectionSprings])
def test_mdr_presses_lines_only(cls):
    assert cls.dimensions == (1,)
    with pytest.raises(ValueError, match=r"presses a line: heights must have shape \(N,\)"):
        cls().solve(Profile(np.zeros((8, 8)), 1.0), np.array([1.0]), "force", np.zeros((8, 8)))


# ---------------------------------------------------------------- slopes on surfaces

NY, NX, DX = 24, 40, 0.2  # not square: an axis mix-up changes the answer


def plane_wave(kx, ky, amplitude=0.7, phase=0.3):
    y, x = np.meshgrid(np.arange(NY) * DX, np.arange(NX) * DX, indexing="ij")
    qx, qy = TWO_PI * kx / (NX * DX), TWO_PI * ky / (NY * DX)
    return amplitude * np.sin(qx * x + qy * y + phase), qx, qy, x, y


@pytest.mark.parametrize("kx, ky", [(1, 0), (0, 2), (3, 5), (-2, 7)])
def test_gradient_magnitude_of_a_plane_wave(kx, ky):
    z, qx, qy, x, y = plane_wave(kx, ky)
    arg = qx * x + qy * y + 0.3
    exact = 0.7 * np.hypot(qx, qy) * np.abs(np.cos(arg))
    np.testing.assert_allclose(Spectral().slopes(z, DX), exact, atol=1e-12)
    # the difference schemes, each along both axes, in closed form for a sine
    fx = 0.7 * (np.sin(arg + qx * DX) - np.sin(arg)) / DX
    fy = 0.7 * (np.sin(arg + qy * DX) - np.sin(arg)) / DX
    np.testing.assert_allclose(ForwardDifference().slopes(z, DX), np.hypot(fx, fy), atol=1e-12)
    cx = 0.7 * np.cos(arg) * np.sin(qx * DX) / DX
    cy = 0.7 * np.cos(arg) * np.sin(qy * DX) / DX
    np.testing.assert_allclose(CentralDifference().slopes(z, DX), np.hypot(cx, cy), atol=1e-12)


def test_sum_of_sines_and_the_surface_rms_gradient():
    y, x = np.meshgrid(np.arange(NY) * DX, np.arange(NX) * DX, indexing="ij")
    q1, q2 = TWO_PI * 3 / (NX * DX), TWO_PI * 2 / (NY * DX)
    z = 0.5 * np.sin(q1 * x) + 1.5 * np.cos(q2 * y)
    exact = np.hypot(0.5 * q1 * np.cos(q1 * x), 1.5 * q2 * np.sin(q2 * y))
    slopes = Spectral().slopes(z, DX)
    np.testing.assert_allclose(slopes, exact, atol=1e-12)
    # whole-surface rms slope = rms gradient = sqrt((a1 q1)^2 / 2 + (a2 q2)^2 / 2)
    assert rms(slopes) == pytest.approx(math.sqrt((0.5 * q1) ** 2 / 2 + (1.5 * q2) ** 2 / 2), rel=1e-12)


def test_spectral_rms_gradient_of_a_generated_surface():
    gen = PowerLawSurface(hurst=0.8, points=64, points_y=48, spacing=0.5)
    z = gen.generate(np.random.default_rng(8)).heights
    assert rms(Spectral().slopes(z, 0.5)) == pytest.approx(gen.rms_slope_discrete(), rel=1e-10)
