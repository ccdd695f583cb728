"""The MDR-equivalent line of a surface (``frictionlab_spectra.equivalent_line``), for
``power-law-2d``, ``rolloff-2d`` and ``surface-file``.

Oracles: brute-force sums over the surface's own modes; the surface's mean square height and
mean square gradient measured on generated surfaces (its heights, the ``spectral`` estimator);
a single plane wave split by the closed-form shares; a fixed-amplitude map read back as a file
(the same modes as the synthesis, so the same line).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from frictionlab.compute import engine
from frictionlab import mdr_length
from frictionlab.preset import build_scene
from frictionlab.testing import check_plugin
from frictionlab_slopes import ForwardDifference, Spectral
from frictionlab_spectra import PowerLawSurface, RolloffSurface, SurfaceFile
from frictionlab_spectra.equivalent_line import EquivalentLine, line_grid, line_mode_powers
from frictionlab.options import RunOptions

from .conftest import SMALL_PRESET, merge

TWO_PI = 2.0 * math.pi


def mean_square(z):
    return float(np.mean(np.square(z)))


def mean_square_slope(profile):
    return mean_square(Spectral().slopes(profile.heights, profile.spacing))


# ------------------------------------------------------------------ the grid and the shares


@pytest.mark.parametrize("shape,spacing", [((64, 64), 1.0), ((48, 80), 0.5), ((8, 8), 3.0)])
def test_the_line_is_2_sqrt_area_over_pi_long_on_a_grid_no_coarser_than_the_surface(shape, spacing):
    area = shape[0] * shape[1] * spacing**2
    points, line_spacing = line_grid(area, spacing)
    assert points * line_spacing == pytest.approx(2 * math.sqrt(area / math.pi), rel=1e-14)
    assert line_spacing <= spacing and (points - 1) * spacing < mdr_length(area)  # the fewest such points


def test_the_shares_keep_the_mean_square_height_and_gradient_exactly():
    rng = np.random.default_rng(0)
    points, spacing = 101, 0.7
    dq = TWO_PI / (points * spacing)
    q = dq * rng.uniform(1.0, points // 2, 500)  # anywhere between the first and the last line mode
    power = rng.exponential(size=q.size)
    line = line_mode_powers(q, power, points, spacing)
    k = dq * np.arange(1, points // 2 + 1)
    assert line.sum() == pytest.approx(power.sum(), rel=1e-12)
    assert np.sum(k**2 * line) == pytest.approx(np.sum(q**2 * power), rel=1e-12)
    assert np.all(line >= 0)


def test_one_mode_splits_between_its_two_neighbours_linearly_in_q_squared():
    points, spacing = 64, 1.0
    dq = TWO_PI / points
    line = line_mode_powers(np.array([5.25 * dq]), np.array([2.0]), points, spacing)
    upper = (5.25**2 - 25) / (36 - 25)
    np.testing.assert_allclose(line[[4, 5]], [2.0 * (1 - upper), 2.0 * upper], rtol=1e-14)
    assert np.count_nonzero(line) == 2
    exact = line_mode_powers(np.array([7 * dq]), np.array([1.0]), points, spacing)
    assert exact[6] == 1.0 and np.count_nonzero(exact) == 1


def test_modes_below_the_first_and_past_the_last_line_mode():
    points, spacing = 32, 1.0
    dq = TWO_PI / points
    line = line_mode_powers(np.array([0.5 * dq, 20.0 * dq]), np.array([3.0, 5.0]), points, spacing)
    assert line[0] == 3.0 and line.sum() == 3.0  # below: all to k = 1; past the Nyquist mode 16: left out


# ------------------------------------------------------------------ synthetic surfaces


@pytest.mark.parametrize("amplitudes", ["fixed", "rayleigh"])
@pytest.mark.parametrize("points", [256, 1024])
@pytest.mark.parametrize("hurst", [0.3, 0.8])
def test_the_line_keeps_the_surfaces_mean_square_height_and_gradient(hurst, points, amplitudes):
    """Within 3 %: the MDR mapping keeps both moments. Fixed amplitudes: measured on one generated
    surface and one generated line. Rayleigh amplitudes: the expected moments, from the powers
    both draw their modes from (and the line's powers do not depend on the amplitudes option)."""
    surface = PowerLawSurface(hurst=hurst, points=points, rms_height=1.0, amplitudes=amplitudes)
    line = surface.equivalent_line()
    if amplitudes == "fixed":
        z = surface.generate(np.random.default_rng(1))
        drawn = line.generate(np.random.default_rng(2))
        assert mean_square(drawn.heights) == pytest.approx(mean_square(z.heights), rel=0.03)
        assert mean_square_slope(drawn) == pytest.approx(mean_square_slope(z), rel=0.03)
    else:
        fixed = PowerLawSurface(hurst=hurst, points=points, rms_height=1.0).equivalent_line()
        assert line.params.mode_power == fixed.params.mode_power
        assert line.params.amplitudes == "rayleigh"
        power = np.asarray(line.params.mode_power)
        q = TWO_PI / (line.params.points * line.params.spacing) * np.arange(1, power.size + 1)
        assert power.sum() == pytest.approx(surface.rms_height() ** 2, rel=0.03)
        assert np.sum(q**2 * power) == pytest.approx(surface.rms_slope_discrete() ** 2, rel=0.03)


def test_the_rayleigh_line_draws_its_expected_moments():
    line = PowerLawSurface(hurst=0.5, points=128, rms_height=1.0, amplitudes="rayleigh").equivalent_line()
    drawn = [line.generate(np.random.default_rng(seed)) for seed in range(400)]
    heights = np.mean([mean_square(p.heights) for p in drawn])
    assert heights == pytest.approx(1.0, rel=0.1)  # 400 draws: a few % of sampling error
    assert np.std([mean_square(p.heights) for p in drawn]) > 0.05  # random amplitudes indeed


def test_a_rolloff_surface_and_c0_normalisation():
    surface = RolloffSurface(hurst=0.7, points=80, points_y=48, spacing=0.5, c0=2.0, rolloff_wavelength=8.0)
    line = surface.equivalent_line()
    assert isinstance(line, EquivalentLine) and line.dimension == 1
    assert line.rms_height() == surface.rms_height()  # the h of f is the same number
    assert line.params.points * line.params.spacing == pytest.approx(mdr_length(80 * 48 * 0.25), rel=1e-14)
    assert line.rms_slope_discrete() == pytest.approx(surface.rms_slope_discrete(), rel=1e-12)
    z = line.generate(np.random.default_rng(0)).heights
    assert math.sqrt(mean_square(z)) == pytest.approx(line.rms_height(), rel=1e-12)


def test_the_line_follows_pi_q_c2d_in_the_band():
    """C1D(q_k) = pi q_k C2D(q_k) within the lattice's scatter (averaged over 5 neighbouring modes)."""
    surface = PowerLawSurface(hurst=0.6, points=512, c0=1.0)
    line = surface.equivalent_line()
    dq = TWO_PI / (line.params.points * line.params.spacing)
    k = np.arange(10, int(surface.band.q_max / dq) - 5)
    c1d = np.convolve(line.psd(k * dq), np.ones(5) / 5, mode="same")[2:-2]
    expected = np.convolve(math.pi * k * dq * surface.psd(k * dq), np.ones(5) / 5, mode="same")[2:-2]
    np.testing.assert_allclose(c1d, expected, rtol=0.1)


def test_the_equivalent_line_passes_the_conformance_checks():
    line = PowerLawSurface(hurst=0.8, points=32, rms_height=2.0).equivalent_line()
    check_plugin("spectrum", EquivalentLine, **line.params.model_dump())


# ------------------------------------------------------------------ measured surfaces


def test_a_fixed_amplitude_map_read_back_gives_the_synthesis_line(tmp_path):
    """A periodic map's modes are the synthesis' modes: the same line, to rounding."""
    surface = PowerLawSurface(hurst=0.8, points=128, points_y=96, rms_height=1.0, spacing=0.5)
    np.save(tmp_path / "map.npy", surface.generate(np.random.default_rng(4)).heights)
    read = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5, periodic=True).equivalent_line()
    made = surface.equivalent_line()
    assert (read.params.points, read.params.spacing) == (made.params.points, made.params.spacing)
    read_power, made_power = np.asarray(read.params.mode_power), np.asarray(made.params.mode_power)
    np.testing.assert_allclose(read_power / read_power.sum(), made_power / made_power.sum(), rtol=1e-9, atol=1e-15)
    assert read.rms_slope_discrete() == pytest.approx(made.rms_slope_discrete(), rel=1e-9)


@pytest.mark.parametrize("hurst", [0.3, 0.8])
def test_a_non_periodic_scan_gives_its_own_rms_gradient(tmp_path, hurst):
    """A scan cut out of a larger surface: its edges do not meet. The line of its reflected copy
    keeps the scan's rms gradient (within 2 %); without the reflection the step between opposite
    edges would add a q^-2 tail (measured: 1.3 to 3.3 times the scan's)."""
    big = PowerLawSurface(hurst=hurst, points=512, rms_height=1.0, long_cutoff=256.0)
    scan = big.generate(np.random.default_rng(3)).heights[:256, :200]
    np.save(tmp_path / "scan.npy", scan)
    gen = SurfaceFile(path=str(tmp_path / "scan.npy"), spacing=1.0)
    assert gen.periodic() is False and gen.generate(None).periodic is False
    line = gen.equivalent_line()
    detrended = gen.generate(None).heights
    gradient = mean_square(ForwardDifference().slopes(detrended, 1.0, periodic=False))
    assert line.rms_slope_discrete() ** 2 == pytest.approx(gradient, rel=0.04)
    wrapped = SurfaceFile(path=str(tmp_path / "scan.npy"), spacing=1.0, periodic=True).equivalent_line()
    assert wrapped.rms_slope_discrete() ** 2 > 1.2 * gradient  # what the reflection removes


def test_mdr_on_a_surface_runs_its_line_at_the_surfaces_3d_f(registry):
    data = merge(SMALL_PRESET, {
        "realizations": 3,
        "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 48, "rms_height": 1.0}},
        "loading": {"start": 0.02, "stop": 2.0, "steps": 6},
        "fit": {"bootstrap": 0},
    })  # fmt: skip
    scene = build_scene(data, registry=registry)
    assert isinstance(scene.equivalent_line, EquivalentLine) and scene.generator is scene.equivalent_line
    assert scene.spectrum.name == "power-law-2d"
    assert scene.geometry == "mdr-equivalent line of a surface"
    assert scene.resolved()["spectrum"]["name"] == "power-law-2d"  # what the user wrote, re-runnable
    outcome = engine.run(scene, RunOptions(workers=1))
    assert outcome.status == "completed" and not outcome.failures
    assert outcome.extent == pytest.approx(2 * math.sqrt(48 * 48 / math.pi), rel=1e-14)  # f = F / (E* h L)
    np.testing.assert_allclose(outcome.f, outcome.loads / (1.0 * 1.0 * outcome.extent), rtol=1e-14)
    assert np.all(outcome.per_realization["contact_count"] <= scene.equivalent_line.params.points)
    again = build_scene(scene.resolved(), registry=registry)
    np.testing.assert_array_equal(engine.run(again, RunOptions(workers=1)).xi, outcome.xi)


def test_f_of_an_mdr_equivalent_line_is_said_for_the_surface_and_its_length_is_2_sqrt_area_over_pi(registry):
    data = merge(SMALL_PRESET, {"spectrum": {"name": "power-law-2d", "params": {"points": 32, "length": 64.0}}})
    scene = build_scene(data, registry=registry)
    assert scene.pressed == "MDR-equivalent lines of power-law-2d surfaces"
    n = scene.normalisation
    assert n.extent == "length" and "L = 2 sqrt(A / pi) the MDR-equivalent line's length" in n.definition
    profile = scene.generator.generate(np.random.default_rng(0))
    assert n.extent_of(profile) == pytest.approx(mdr_length(64.0**2), rel=1e-12)


def test_a_solver_of_lines_not_declaring_mdr_lines_is_refused_a_surface(register_plugin):
    """Taken as it came, a third party's solver of lines pressed the surface's MDR-equivalent
    line, which only MDR's springs take for the surface (a half-plane's line is not the surface)."""
    from frictionlab.errors import PresetError

    from .testing.fakes import GoodSolver

    registry = register_plugin(GoodSolver)
    data = {**SMALL_PRESET, "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 32}},
            "solver": {"name": "good-solver"}}
    with pytest.raises(PresetError, match=r"solver.name: good-solver presses lines only, but spectrum power-law-2d "
                                          r"makes surfaces: use solver .*\bmdr\b"):  # fmt: skip
        build_scene(data, registry=registry)
    declared = type("MDRLike", (GoodSolver,), {"name": "mdr-like", "mdr_lines": True})
    registry = register_plugin(declared)
    scene = build_scene({**data, "solver": {"name": "mdr-like"}}, registry=registry)
    assert scene.geometry == "mdr-equivalent line of a surface"
