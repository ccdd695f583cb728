"""Slope estimators against closed forms: periodic sines, and scans whose ends do not meet."""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab.compute import engine
from frictionlab.errors import PresetError
from frictionlab.preset import build_scene
from frictionlab.plugin.registry import validate_plugin_class
from frictionlab.testing import check_plugin
from frictionlab_slopes import CentralDifference, ForwardDifference, Spectral
from frictionlab.options import RunOptions

ESTIMATORS = (ForwardDifference, CentralDifference, Spectral)


def sine(points: int, mode: int, amplitude: float = 0.7, spacing: float = 0.3):
    """A sin(q x) with ``mode`` whole periods on the periodic grid."""
    x = np.arange(points) * spacing
    q = 2.0 * np.pi * mode / (points * spacing)
    return amplitude * np.sin(q * x), x, q, amplitude, spacing


def rms(values):
    return np.sqrt(np.mean(np.square(values)))


# ------------------------------------------------------------------ contract


@pytest.mark.parametrize("cls", ESTIMATORS)
def test_plugin_contract(cls):
    validate_plugin_class("slope", cls)
    assert set(cls.Params.model_fields) == ({"line_end"} if cls is not Spectral else set())
    with pytest.raises(ValueError):
        cls(unknown=1)
    assert {c.name for c in ESTIMATORS} == {"forward-difference", "central-difference", "spectral"}
    check_plugin("slope", cls)
    if cls is not Spectral:
        check_plugin("slope", cls, line_end="undefined")


# ------------------------------------------------------------- closed forms


@pytest.mark.parametrize("points", [256, 255])
@pytest.mark.parametrize("mode", [1, 3, 40])
def test_forward_difference_of_a_sine(points, mode):
    z, x, q, A, dx = sine(points, mode)
    slopes = ForwardDifference().slopes(z, dx)
    # sin(q(x+dx)) - sin(qx) = 2 sin(q dx/2) cos(q(x + dx/2)): a shifted cosine
    gain = 2.0 * np.sin(q * dx / 2.0) / dx
    scale = A / dx  # rounding of the differences is relative to A, then divided by dx
    np.testing.assert_allclose(slopes, A * gain * np.cos(q * (x + dx / 2.0)), rtol=0, atol=1e-13 * scale)
    assert rms(slopes) == pytest.approx(A * gain / np.sqrt(2.0), rel=1e-12)


@pytest.mark.parametrize("points", [256, 255])
@pytest.mark.parametrize("mode", [1, 3, 40])
def test_central_difference_of_a_sine(points, mode):
    z, x, q, A, dx = sine(points, mode)
    slopes = CentralDifference().slopes(z, dx)
    gain = np.sin(q * dx) / dx
    np.testing.assert_allclose(slopes, A * gain * np.cos(q * x), rtol=0, atol=1e-13 * A / dx)
    assert rms(slopes) == pytest.approx(A * gain / np.sqrt(2.0), rel=1e-12)


@pytest.mark.parametrize("points", [256, 255])
@pytest.mark.parametrize("mode", [1, 3, 40, 127])
def test_spectral_derivative_of_a_sine_is_exact(points, mode):
    z, x, q, A, dx = sine(points, mode)
    slopes = Spectral().slopes(z, dx)
    np.testing.assert_allclose(slopes, A * q * np.cos(q * x), rtol=0, atol=1e-12 * A * q)
    assert rms(slopes) == pytest.approx(A * q / np.sqrt(2.0), rel=1e-12)


def test_spectral_drops_the_nyquist_mode():
    z = np.cos(np.pi * np.arange(64))  # (-1)^i: the Nyquist mode of an even grid
    np.testing.assert_allclose(Spectral().slopes(z, 1.0), 0.0, atol=1e-15)
    assert np.all(np.abs(ForwardDifference().slopes(z, 1.0)) == 2.0)
    assert np.all(CentralDifference().slopes(z, 1.0) == 0.0)  # z[i+1] == z[i-1]


def test_all_three_agree_at_small_q_dx():
    points, dx = 4096, 1.0
    x = np.arange(points) * dx
    rng = np.random.default_rng(5)
    modes = np.arange(1, 9)
    q = 2 * np.pi * modes / (points * dx)  # q dx <= 0.0123
    amplitude = rng.normal(size=modes.size)
    phase = rng.uniform(0, 2 * np.pi, size=modes.size)
    z = sum(a * np.sin(qm * x + p) for a, qm, p in zip(amplitude, q, phase))
    fwd, ctr, spc = (cls().slopes(z, dx) for cls in ESTIMATORS)
    weight = np.abs(amplitude) * q
    # per mode: central = spectral * sin(q dx)/(q dx), |1 - sinc| <= (q dx)^2 / 6
    assert np.max(np.abs(ctr - spc)) <= np.sum(weight * (q * dx) ** 2 / 6)
    # forward = spectral half a cell later, times sin(q dx/2)/(q dx/2): first order pointwise
    assert np.max(np.abs(fwd - spc)) <= np.sum(weight * (q * dx / 2 + (q * dx) ** 2 / 24))
    # rms: distinct modes are orthogonal on the grid, so the gains enter directly (second order)
    qdx = q.max() * dx
    assert rms(fwd) == pytest.approx(rms(spc), rel=qdx**2 / 24)
    assert rms(ctr) == pytest.approx(rms(spc), rel=qdx**2 / 6)
    assert rms(spc) == pytest.approx(np.sqrt(np.sum((amplitude * q) ** 2) / 2), rel=1e-12)


# --------------------------------------------------------- definitions, scaling


def test_forward_difference_is_the_periodic_definition():
    rng = np.random.default_rng(0)
    z = rng.normal(size=1001)
    expected = (np.roll(z, -1) - z) / 0.25
    np.testing.assert_array_equal(ForwardDifference().slopes(z, 0.25), expected)
    assert ForwardDifference().slopes(z, 0.25)[-1] == (z[0] - z[-1]) / 0.25


def test_central_difference_wraps_both_ends():
    z = np.array([0.0, 1.0, 4.0, 9.0, 16.0])
    expected = (np.roll(z, -1) - np.roll(z, 1)) / (2 * 0.5)
    np.testing.assert_array_equal(CentralDifference().slopes(z, 0.5), expected)


# --------------------------------------------------------- scans: not periodic


def test_on_a_scan_no_difference_crosses_the_ends():
    z = np.array([0.0, 1.0, 4.0, 9.0, 16.0])
    # forward: the last point takes its segment's slope; central: one-sided at both ends
    np.testing.assert_array_equal(ForwardDifference().slopes(z, 0.5, periodic=False), [2, 6, 10, 14, 14])
    np.testing.assert_array_equal(CentralDifference().slopes(z, 0.5, periodic=False), [2, 4, 8, 12, 14])
    surface = np.add.outer(np.arange(4.0) * 3, np.arange(5.0))  # z = 3 y + x
    for cls in (ForwardDifference, CentralDifference):
        np.testing.assert_allclose(cls().slopes(surface, 1.0, periodic=False), np.hypot(3.0, 1.0), rtol=1e-15)
    with pytest.raises(ValueError, match="spectral slopes need a periodic profile"):
        Spectral().slopes(z, 0.5, periodic=False)


def test_line_end_undefined_leaves_the_ends_without_a_slope():
    z = np.array([0.0, 1.0, 4.0, 9.0, 16.0])
    np.testing.assert_array_equal(ForwardDifference(line_end="undefined").slopes(z, 0.5, periodic=False),
                                  [2, 6, 10, 14, np.nan])  # fmt: skip
    np.testing.assert_array_equal(CentralDifference(line_end="undefined").slopes(z, 0.5, periodic=False),
                                  [np.nan, 4, 8, 12, np.nan])  # fmt: skip
    # a periodic line has no end: the choice changes nothing there
    for cls in (ForwardDifference, CentralDifference):
        np.testing.assert_array_equal(cls(line_end="undefined").slopes(z, 0.5), cls().slopes(z, 0.5))
        assert cls(line_end="undefined").undefined_points(False) and not cls(line_end="undefined").undefined_points(True)
        assert not cls().undefined_points(False)
    surface = np.add.outer(np.arange(4.0) * 3, np.arange(5.0))  # z = 3 y + x
    slopes = ForwardDifference(line_end="undefined").slopes(surface, 1.0, periodic=False)
    assert np.isnan(slopes[-1]).all() and np.isnan(slopes[:, -1]).all()
    np.testing.assert_allclose(slopes[:-1, :-1], np.hypot(3.0, 1.0), rtol=1e-15)


TOP_LAST = np.array([0.0, 1.0, 0.5, 2.0, 0.0, 2.5, 1.0, 3.0])  # dx = 1: the top is the last point


def _hand_made_line_run(tmp_path, registry, line_end, loads):
    np.save(tmp_path / "line.npy", TOP_LAST)
    data = {
        "name": "top-last", "realizations": 1,
        "spectrum": {"name": "profile-file", "params": {"path": str(tmp_path / "line.npy"), "spacing": 1.0,
                                                        "detrend": "none"}},
        "solver": {"name": "mdr"}, "slope": {"name": "forward-difference", "params": {"line_end": line_end}},
        "loading": {"start": loads[0], "stop": loads[-1], "steps": len(loads), "spacing": "log"},
        "fit": {"bootstrap": 0}, "output": {"plot": False},
    }  # fmt: skip
    return engine.run(build_scene(data, registry=registry), RunOptions(workers=1))


def test_a_line_whose_top_is_its_last_point_has_no_xi_until_another_point_touches(tmp_path, registry):
    """E* = 1, dx = 1: the top (3.0) alone touches up to F = 0.5 (the next point, 2.5, is 0.5 lower);
    at F = 0.8 the indentation is (0.8 + 0.5) / 2 = 0.65 < 1 (depth of the 2.0): the top and the 2.5 touch."""
    slopes = np.diff(TOP_LAST)  # the forward slopes of the first 7 points
    line_rms_defined = np.sqrt(np.mean(slopes**2))  # the last point has none
    undefined = _hand_made_line_run(tmp_path, registry, "undefined", (0.25, 0.8))
    np.testing.assert_array_equal(undefined.per_realization["contact_count"][0], [1, 2])
    assert undefined.per_realization["slope_rms_line"][0] == pytest.approx(line_rms_defined, rel=1e-15)
    xi = undefined.per_realization["xi"][0]
    assert np.isnan(xi[0])  # only the last point in contact: no slope there
    # at F = 0.8: the rms over the defined one, the 2.5 (slope 1.0 - 2.5 = -1.5)
    assert xi[1] == pytest.approx(1.5 / line_rms_defined, rel=1e-15)
    np.testing.assert_array_equal(undefined.lines_used, [0, 1])
    assert np.isnan(undefined.xi[0]) and undefined.xi[1] == xi[1]
    assert undefined.status == "failed" and "xi is defined at 1 of 2 load steps" in undefined.error
    # today's convention: the top takes the last segment's slope (3.0 - 1.0 = 2)
    segment = _hand_made_line_run(tmp_path, registry, "last-segment", (0.25, 0.8))
    line_rms_segment = np.sqrt(np.mean(np.append(slopes, slopes[-1]) ** 2))
    np.testing.assert_allclose(segment.per_realization["xi"][0],
                               [2.0 / line_rms_segment, np.sqrt((4.0 + 1.5**2) / 2) / line_rms_segment], rtol=1e-15)  # fmt: skip
    np.testing.assert_array_equal(segment.lines_used, [1, 1])


def test_undefined_slopes_need_a_solver_that_takes_them(tmp_path, register_plugin):
    np.save(tmp_path / "line.npy", TOP_LAST)
    data = {
        "name": "top-last", "realizations": 1,
        "spectrum": {"name": "profile-file", "params": {"path": str(tmp_path / "line.npy"), "spacing": 1.0}},
        "solver": {"name": "mdr"}, "slope": {"name": "forward-difference", "params": {"line_end": "undefined"}},
        "loading": {"start": 1.0, "stop": 2.0, "steps": 2},
    }  # fmt: skip
    from frictionlab_solvers import MDRSprings

    class NoUndefined(MDRSprings):
        name = "mdr-finite-only"
        undefined_slopes = False

    registry = register_plugin(NoUndefined)
    data["solver"] = {"name": "mdr-finite-only"}
    with pytest.raises(PresetError) as info:
        build_scene(data, registry=registry)
    assert info.value.problems[0].startswith(
        "slope.params: forward-difference leaves points of this non-periodic profile without a slope, which solver "
        "mdr-finite-only cannot take: use solver mdr or mdr-bisection or winkler, or"
    )


RAMP = 0.1  # the scan's grade
ROUGHNESS = ((0.4, 173.0, 0.3), (0.25, 61.0, 1.1), (0.1, 29.0, 2.0))  # amplitude, wavelength, phase


def ramp_scan(points=4000, spacing=0.5):
    """A tilted scan with small roughness (wavelengths incommensurate with its length), and its
    exact derivative at the grid points."""
    x = np.arange(points) * spacing
    z = RAMP * x + sum(a * np.sin(2 * np.pi * x / w + p) for a, w, p in ROUGHNESS)
    dz = RAMP + sum(a * 2 * np.pi / w * np.cos(2 * np.pi * x / w + p) for a, w, p in ROUGHNESS)
    return x, z, dz


@pytest.mark.parametrize("slope", ["forward-difference", "central-difference"])
@pytest.mark.parametrize("detrend", ["mean", "tilt"])
def test_a_scan_on_a_ramp_has_its_true_rms_slope(tmp_path, registry, slope, detrend):
    """A profile-file scan (not periodic by default) run end to end: the whole-line rms slope is
    the rms of the exact derivative within 1 % (of what is left after detrend: the grade, unless
    the tilt is removed). Declared periodic, the jump between the ends inflates it many times."""
    x, z, dz = ramp_scan()
    np.savetxt(tmp_path / "scan.csv", np.column_stack([x, z]), delimiter=",", header="x,z", comments="")
    if detrend == "tilt":
        dz = dz - np.polyfit(x, z, 1)[0]  # the least-squares grade goes with the tilt
    truth = rms(dz)
    data = {
        "name": "scan", "realizations": 1,
        "spectrum": {"name": "profile-file", "params": {"path": str(tmp_path / "scan.csv"), "detrend": detrend}},
        "slope": {"name": slope},
        "loading": {"start": 1.0, "stop": 10.0, "steps": 3}, "fit": {"bootstrap": 0}, "output": {"plot": False},
    }  # fmt: skip
    outcome = engine.run(build_scene(data, registry=registry), RunOptions(workers=1))
    assert not outcome.failures
    assert outcome.per_realization["slope_rms_line"][0] == pytest.approx(truth, rel=0.01)
    data["spectrum"]["params"].update(periodic=True, detrend="mean")  # a tilt is not taken off a periodic line
    wrapped = engine.run(build_scene(data, registry=registry), RunOptions(workers=1))
    assert wrapped.per_realization["slope_rms_line"][0] > 1.1 * truth


def test_a_scan_is_refused_by_spectral_slopes_and_periodic_solvers(tmp_path, registry):
    _, z, _ = ramp_scan(points=64)
    np.save(tmp_path / "scan.npy", z)
    data = {
        "name": "scan", "realizations": 1,
        "spectrum": {"name": "profile-file", "params": {"path": str(tmp_path / "scan.npy"), "spacing": 0.5}},
        "solver": {"name": "bem-halfplane"}, "slope": {"name": "spectral"},
        "loading": {"start": 1.0, "stop": 10.0, "steps": 3},
    }  # fmt: skip
    with pytest.raises(PresetError) as info:
        build_scene(data, registry=registry)
    problems = info.value.problems
    assert problems[0].startswith("solver.name: bem-halfplane presses periodic profiles only, but spectrum "
                                  "profile-file is not periodic (periodic: false")  # fmt: skip
    assert problems[1].startswith("slope.name: spectral differentiates periodic profiles only")
    assert all("set spectrum.params.periodic: true" in p for p in problems)
    data["spectrum"]["params"]["periodic"] = True
    assert build_scene(data, registry=registry).spectrum.periodic()


def test_a_cosine_line_given_to_a_periodic_solver_is_told_the_parameter_that_exists(registry):
    """A synthesised line has no ``periodic`` parameter: the advice names ``series``, and
    following it builds."""
    data = {
        "name": "cosine", "realizations": 1,
        "spectrum": {"name": "power-law", "params": {"hurst": 0.8, "points": 64, "series": "cosine"}},
        "solver": {"name": "bem-halfplane"}, "slope": {"name": "forward-difference"},
        "loading": {"start": 1.0, "stop": 10.0, "steps": 3},
    }  # fmt: skip
    with pytest.raises(PresetError) as info:
        build_scene(data, registry=registry)
    (problem,) = info.value.problems
    assert "is not periodic (series: cosine" in problem and "set spectrum.params.series: fft" in problem
    assert "spectrum.params.periodic" not in problem
    data["spectrum"]["params"]["series"] = "fft"
    assert build_scene(data, registry=registry).spectrum.periodic()


@pytest.mark.parametrize("cls", ESTIMATORS)
def test_shape_dtype_and_input_untouched(cls):
    z = np.random.default_rng(1).normal(size=100)
    before = z.copy()
    slopes = cls().slopes(z, 2.0)
    assert slopes.shape == z.shape and slopes.dtype == np.float64
    np.testing.assert_array_equal(z, before)
    # integer input is fine too
    assert cls().slopes(np.arange(10) % 3, 1.0).shape == (10,)


@pytest.mark.parametrize("cls", ESTIMATORS)
def test_height_scaling_is_exact_for_powers_of_two(cls):
    z = np.random.default_rng(2).normal(size=128)
    s = 2.0**-37
    np.testing.assert_array_equal(cls().slopes(s * z, 1.5), s * cls().slopes(z, 1.5))


@pytest.mark.parametrize("cls", ESTIMATORS)
def test_two_points_is_the_minimum(cls):
    assert cls().slopes(np.array([0.0, 1.0]), 1.0).shape == (2,)
    with pytest.raises(ValueError, match="at least 2 points"):
        cls().slopes(np.array([1.0]), 1.0)
    with pytest.raises(ValueError, match="at least 2 points"):
        cls().slopes(np.array([]), 1.0)


@pytest.mark.parametrize("cls", ESTIMATORS)
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_heights_are_rejected(cls, bad):
    z = np.zeros(16)
    z[5] = bad
    with pytest.raises(ValueError, match="point 5"):
        cls().slopes(z, 1.0)


@pytest.mark.parametrize("cls", ESTIMATORS)
def test_bad_spacing_and_shape_are_rejected(cls):
    for spacing in (0.0, -1.0, np.nan, np.inf):
        with pytest.raises(ValueError, match="spacing"):
            cls().slopes(np.zeros(8), spacing)
    with pytest.raises(ValueError, match="shape"):
        cls().slopes(np.zeros((4, 4, 4)), 1.0)  # lines and surfaces only
    with pytest.raises(ValueError, match="at least 2 points"):
        cls().slopes(np.zeros((1, 8)), 1.0)


# ------------------------------------------------------------------ xi on a surface, by brute force


def brute_force_gradient(z, dx, scheme):
    """|grad z| pixel by pixel with explicit loops and wrap-around indices."""
    ny, nx = z.shape
    out = np.empty_like(z)
    for i in range(ny):
        for j in range(nx):
            if scheme == "forward-difference":
                gx = (z[i, (j + 1) % nx] - z[i, j]) / dx
                gy = (z[(i + 1) % ny, j] - z[i, j]) / dx
            else:
                gx = (z[i, (j + 1) % nx] - z[i, (j - 1) % nx]) / (2 * dx)
                gy = (z[(i + 1) % ny, j] - z[(i - 1) % ny, j]) / (2 * dx)
            out[i, j] = np.sqrt(gx * gx + gy * gy)
    return out


@pytest.mark.parametrize("scheme", ["forward-difference", "central-difference"])
def test_xi_on_a_surface_is_the_rms_gradient_over_contact_pixels_over_the_whole_one(registry, monkeypatch, scheme):
    """An exact half-space run on a 24 x 20 surface: the engine's xi at each load equals
    rms |grad z| (both components) over the pixels the solver put in contact, over rms
    |grad z| of every pixel, both formed here by loops."""
    import frictionlab_solvers.contact_cg as contact_cg

    from frictionlab.compute.realization import compute_realization
    from frictionlab.preset.seeds import realization_rng

    contact_sets = []
    solve = contact_cg.ProjectedCG.solve

    def recording(self, pressure, **kwargs):
        answer = solve(self, pressure, **kwargs)
        contact_sets.append(answer[0] > 0.0)
        return answer

    monkeypatch.setattr(contact_cg.ProjectedCG, "solve", recording)
    data = {"name": "xi", "seed": 5, "realizations": 1,
            "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.7, "points": 24, "points_y": 20,
                                                            "spacing": 0.5, "short_cutoff": 2.0, "rms_height": 3.0}},
            "solver": {"name": "bem-halfspace", "params": {"youngs_modulus": 2.0}}, "slope": {"name": scheme},
            "loading": {"control": "force", "start": 0.5, "stop": 60.0, "steps": 6, "spacing": "log"}}  # fmt: skip
    scene = build_scene(data, registry=registry)
    result = compute_realization(scene, 0)
    assert result.ok, result.error
    heights = scene.spectrum.generate(realization_rng(5, 0)).heights
    assert heights.shape == (20, 24)
    gradient = brute_force_gradient(heights, 0.5, scheme)
    whole = np.sqrt(np.mean(gradient**2))
    assert result.slope_rms_line == pytest.approx(whole, rel=1e-12)
    assert len(contact_sets) == 6
    counts = [int(c.sum()) for c in contact_sets]
    assert counts == list(result.contact_count) and 0 < counts[0] < counts[-1] < heights.size
    for j, contact in enumerate(contact_sets):
        in_contact = np.sqrt(np.mean(gradient[contact] ** 2))
        assert result.xi[j] == pytest.approx(in_contact / whole, rel=1e-12)
