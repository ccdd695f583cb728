"""Numerical extremes (issue 4): each gives the right answer, checked against a known value or
limit, or a clear error; never a NaN, an overflow, a hang or a traceback.

The "Numerical extremes" page (docs/explanation/extremes.md) lists each case with the test that checks it here
(or in the older test files, where the case was already covered).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml

from frictionlab.compute import engine
from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab.plugin import Profile
from frictionlab.preset import build_scene
from frictionlab.preset.seeds import realization_rng
from frictionlab_slopes import CentralDifference, ForwardDifference, Spectral
from frictionlab_solvers import BisectionSprings, MDRSprings, WinklerSprings
from frictionlab_spectra import PowerLaw, PowerLawSurface, ProfileFile, Rolloff, RolloffSurface
from frictionlab.options import RunOptions

from .conftest import SMALL_PRESET, merge

TWO_PI = 2.0 * math.pi

LINE = merge(SMALL_PRESET, {"realizations": 3, "fit": {"bootstrap": 0}, "output": {"plot": False}})
SURFACE = {**LINE, "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 32}}}


def rms(a):
    return float(np.sqrt(np.mean(np.square(a))))


def run_preset(tmp_path, data, capsys, *extra):
    """``frictionlab run`` in-process; (exit code, summary or None, stderr)."""
    path = tmp_path / "preset.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    code = main(["run", str(path), "--out", str(out), "--quiet", "--workers", "1", *extra])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    summary = out / "summary.json"
    return code, (json.loads(summary.read_text()) if summary.exists() else None), err


def finite_run(tmp_path, data, capsys):
    code, summary, err = run_preset(tmp_path, data, capsys)
    assert code == ExitCode.OK, err
    text = json.dumps(summary)
    assert "NaN" not in text and "Infinity" not in text, text[:500]
    curve = np.genfromtxt(tmp_path / "out" / "curve.csv", delimiter=",", names=True)
    for name in curve.dtype.names:
        assert np.all(np.isfinite(curve[name])), name
    return summary, curve


# ---------------------------------------------------------------- spectra: Hurst and the band


@pytest.mark.parametrize("hurst", [0.01, 0.05, 1.0, 1.2, 1.5])
@pytest.mark.parametrize("base", [LINE, SURFACE], ids=["line", "surface-mdr"])
def test_extreme_hurst_runs_through_the_cli(tmp_path, capsys, base, hurst):
    finite_run(tmp_path, merge(base, {"spectrum": {"params": {"hurst": hurst}}}), capsys)


@pytest.mark.parametrize("base", [LINE, SURFACE], ids=["line", "surface"])
def test_hurst_past_the_bound_is_a_usage_error(tmp_path, capsys, base):
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(merge(base, {"spectrum": {"params": {"hurst": 1.6}}})))
    assert main(["validate", str(path)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "spectrum.params.hurst: must be <= 1.5, got 1.6" in err and "Traceback" not in err


@pytest.mark.parametrize("hurst", [0.0, 0.01, 0.05, 1.0, 1.2, 1.5])
@pytest.mark.parametrize("scale", [1e-12, 1e12])
def test_extreme_hurst_surfaces_are_exact(hurst, scale):
    """Fixed amplitudes: rms height exactly the nominal one, closed-form moments finite, the log
    case H = 1 continuous with its neighbours (1D lines: tests/test_spectra.py::test_extremes)."""
    gen = PowerLawSurface(hurst=hurst, points=32, short_cutoff=2.0, rms_height=scale)
    z = gen.generate(np.random.default_rng(0)).heights
    assert np.all(np.isfinite(z)) and rms(z) == pytest.approx(scale, rel=1e-12)
    for value in (gen.rms_height_continuum(), gen.rms_slope(), gen.rms_slope_discrete()):
        assert math.isfinite(value) and value > 0
    if hurst == 1.0:
        near = [PowerLawSurface(hurst=h, points=32, short_cutoff=2.0, rms_height=scale).rms_slope() for h in (1 - 1e-7, 1 + 1e-7)]
        assert near == pytest.approx([gen.rms_slope()] * 2, rel=1e-6)


@pytest.mark.parametrize("line, surface", [(Rolloff, RolloffSurface)])
def test_rolloff_at_the_ends_of_the_band(line, surface):
    """At the lowest wave vector the rolloff is the pure power law; at the highest the spectrum is flat."""
    for cls, plain, points in ((line, PowerLaw, 512), (surface, PowerLawSurface, 48)):
        low = cls(hurst=0.7, points=points, rolloff_wavelength=float(points))
        np.testing.assert_allclose(
            low.generate(np.random.default_rng(1)).heights,
            plain(hurst=0.7, points=points).generate(np.random.default_rng(1)).heights, rtol=1e-12, atol=1e-14,
        )
        high = cls(hurst=0.7, points=points, rolloff_wavelength=10.0)  # = the default short cut-off
        b = high.band
        q = np.geomspace(b.q_min, b.q_max, 30)
        psd = high.psd(q)  # C1D resp. C2D flat over the whole band
        np.testing.assert_allclose(psd, psd[0], rtol=1e-12)
        assert rms(high.generate(np.random.default_rng(2)).heights) == pytest.approx(1.0, rel=1e-12)
    for cls in (line, surface):
        with pytest.raises(ValueError, match="rolloff_wavelength=9.0 must lie between short_cutoff"):
            cls(hurst=0.7, points=64, rolloff_wavelength=9.0)


@pytest.mark.parametrize("base", [LINE, SURFACE], ids=["line", "surface"])
def test_short_cutoff_at_and_below_the_nyquist_limit(tmp_path, capsys, base):
    finite_run(tmp_path, merge(base, {"spectrum": {"params": {"short_cutoff": 2.0}}}), capsys)
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(merge(base, {"spectrum": {"params": {"short_cutoff": 1.9}}})))
    assert main(["validate", str(path)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "spectrum.params: short_cutoff=1.9 is below the Nyquist wavelength 2 * spacing = 2.0" in err


# ---------------------------------------------------------------- loads


def test_one_pixel_in_contact_on_a_surface():
    z = PowerLawSurface(hurst=0.8, points=40).generate(np.random.default_rng(3)).heights
    slopes = Spectral().slopes(z, 0.5)
    top = np.unravel_index(np.argmax(z), z.shape)
    curve = WinklerSprings(modulus=4.0).solve(Profile(z, 0.5), np.array([1e-12, 1e-9]), "force", slopes)
    np.testing.assert_array_equal(curve.contact_count, 1)
    np.testing.assert_array_equal(curve.slope_rms_contact, slopes[top])
    np.testing.assert_allclose(curve.indentation, np.array([1e-12, 1e-9]) / (4.0 * 0.25), rtol=1e-9)


FULL = [
    ("mdr", LINE),
    ("mdr-bisection", LINE),
    ("winkler", LINE),
    ("winkler", SURFACE),
]


@pytest.mark.parametrize("solver, base", FULL, ids=[f"{s}-{'surface' if b is SURFACE else 'line'}" for s, b in FULL])
def test_far_past_full_contact(registry, solver, base):
    """Every point touches: xi = 1 to the last bit, and the indentation is the closed form
    d = F / (K N) + max(z) - mean(z), K = k dx^ndim, from sum_i (d - u_i) = F / K."""
    data = {**base, "solver": {"name": solver}, "loading": {"start": 1e6, "stop": 1e12, "steps": 3, "spacing": "log"}}
    scene = build_scene(data, registry=registry)
    outcome = engine.run(scene, RunOptions(workers=1))
    assert not outcome.failures
    np.testing.assert_array_equal(outcome.per_realization["xi"], 1.0)
    np.testing.assert_array_equal(outcome.contact_fraction, 1.0)
    for index, indentation in zip(outcome.indices, outcome.per_realization["indentation"]):
        profile = scene.spectrum.generate(realization_rng(scene.preset.seed, int(index)))
        z = profile.heights
        spring = scene.solver.stiffness() * profile.spacing**z.ndim
        closed = scene.loads / (spring * z.size) + (z.max() - z.mean())
        np.testing.assert_allclose(indentation, closed, rtol=1e-9)


@pytest.mark.parametrize("start", [0.0, -2.0])
def test_a_force_of_zero_or_below_is_a_usage_error(tmp_path, capsys, start):
    code, summary, err = run_preset(tmp_path, merge(LINE, {"loading": {"start": start}}), capsys)
    assert code == ExitCode.USAGE and summary is None
    assert f"loading.start: must be > 0.0, got {start}" in err


# ---------------------------------------------------------------- grids and scales


@pytest.mark.parametrize("base", [LINE, SURFACE], ids=["line", "surface"])
def test_the_smallest_grid(tmp_path, capsys, base):
    finite_run(tmp_path, merge(base, {"spectrum": {"params": {"points": 8, "short_cutoff": 2.0}}}), capsys)


def check_large_line(points):
    """A sweep on a large line against brute-force counts and the full-contact closed form."""
    gen = PowerLaw(hurst=0.8, points=points)
    z = gen.generate(np.random.default_rng(9)).heights
    slopes = ForwardDifference().slopes(z, 1.0)
    depths = np.array([1e-6, 1e-3, 0.1, 1.0, 10.0])
    curve = MDRSprings().solve(Profile(z, 1.0), depths, "indentation", slopes)
    u = z.max() - z
    np.testing.assert_array_equal(curve.contact_count, [(u < d).sum() for d in depths])
    forces = curve.force
    back = MDRSprings().solve(Profile(z, 1.0), forces, "force", slopes)
    np.testing.assert_array_equal(back.contact_count, curve.contact_count)
    np.testing.assert_allclose(back.indentation, depths, rtol=1e-9)
    assert np.all(np.isfinite(back.slope_rms_contact))


def test_a_million_points():
    check_large_line(10**6)


@pytest.mark.slow
def test_ten_million_points():
    check_large_line(10**7)


SCALES = [1e-12, 1e12]


@pytest.mark.parametrize("scale", SCALES)
@pytest.mark.parametrize("solver, base", [("mdr", LINE), ("mdr", SURFACE), ("winkler", SURFACE)],
                         ids=["line", "surface-mdr", "surface-winkler"])
def test_results_do_not_depend_on_the_height_scale(registry, scale, solver, base):
    """z -> s z, F -> s F (an exact scaling law): counts identical, xi and f within rounding."""
    def run(s):
        data = merge({**base, "solver": {"name": solver}}, {
            "spectrum": {"params": {"rms_height": s}},
            "loading": {"start": 0.01 * s, "stop": 3.0 * s, "steps": 12, "spacing": "log"},
        })
        return engine.run(build_scene(data, registry=registry), RunOptions(workers=1))

    one, scaled = run(1.0), run(scale)
    np.testing.assert_array_equal(scaled.per_realization["contact_count"], one.per_realization["contact_count"])
    np.testing.assert_allclose(scaled.xi, one.xi, rtol=1e-11)
    np.testing.assert_allclose(scaled.f, one.f, rtol=1e-12)
    np.testing.assert_allclose(scaled.indentation, scale * one.indentation, rtol=1e-11)


@pytest.mark.parametrize("scale", [1e99, 1e-99])
def test_heights_over_spacing_past_the_square_root_of_double_precision(registry, scale):
    """z -> s z, x -> x / s (each within a preset's range): slopes of s^2 ~ 1e198, whose squares
    overflow, made every realization fail; on a line of springs f and xi are exactly unchanged."""
    def run(s):
        data = merge(LINE, {"spectrum": {"params": {"rms_height": s, "spacing": 1 / s}}})
        return engine.run(build_scene(data, registry=registry), RunOptions(workers=1))

    one, scaled = run(1.0), run(scale)
    assert scaled.status == "completed"
    np.testing.assert_array_equal(scaled.per_realization["contact_count"], one.per_realization["contact_count"])
    np.testing.assert_allclose(scaled.xi, one.xi, rtol=1e-12)
    np.testing.assert_allclose(scaled.f, one.f, rtol=1e-12)
    np.testing.assert_allclose(scaled.per_realization["slope_rms_line"],  # kept in the run's units
                               scale**2 * one.per_realization["slope_rms_line"], rtol=1e-12)


# ---------------------------------------------------------------- float32 and ties


def test_float32_profile_file_is_read_as_its_exact_values(tmp_path):
    rng = np.random.default_rng(4)
    z32 = (np.cumsum(rng.standard_normal(512)) * 1e3).astype(np.float32)
    np.save(tmp_path / "scan32.npy", z32)
    np.save(tmp_path / "scan64.npy", z32.astype(np.float64))
    a = ProfileFile(path=str(tmp_path / "scan32.npy"), spacing=0.5, detrend="tilt").generate(None)
    b = ProfileFile(path=str(tmp_path / "scan64.npy"), spacing=0.5, detrend="tilt").generate(None)
    assert a.heights.dtype == np.float64
    np.testing.assert_array_equal(a.heights, b.heights)


@pytest.mark.parametrize(
    "solver,shape",
    [(solver, shape) for solver in (MDRSprings(), BisectionSprings(), WinklerSprings())
     for shape in ((400,), (20, 24)) if len(shape) in solver.dimensions],  # each shape the solver presses
)  # fmt: skip
def test_float32_heights_and_slopes_give_the_float64_answer(solver, shape):
    rng = np.random.default_rng(5)
    z = rng.standard_normal(shape).astype(np.float32)
    for estimator in (ForwardDifference(), CentralDifference(), Spectral()):
        s32 = estimator.slopes(z, 0.25)
        assert s32.dtype == np.float64
        np.testing.assert_array_equal(s32, estimator.slopes(z.astype(np.float64), 0.25))
    slopes = ForwardDifference().slopes(z, 0.25).astype(np.float32)
    forces = np.geomspace(1e-3, 1e3, 9)
    a = solver.solve(Profile(z, 0.25), forces, "force", slopes)
    b = solver.solve(Profile(z.astype(np.float64), 0.25), forces, "force", slopes.astype(np.float64))
    for name in ("indentation", "contact_count", "slope_rms_contact"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def nested_set_answer(z, forces, spring):
    """The exact answer from the definition alone: d solves F / K = sum max(0, d - u) piecewise
    linearly between the distinct depth levels; contact = {u < d}."""
    u = np.sort(z.max() - z.ravel())
    levels = np.unique(u)
    out = []
    for force in forces:
        target = force / spring
        for lo, hi in zip(levels, np.append(levels[1:], np.inf)):
            touching = u[u <= lo]
            at_hi = np.sum(hi - touching) if np.isfinite(hi) else np.inf
            if at_hi >= target:  # d in (lo, hi]
                d = lo + (target - np.sum(lo - touching)) / touching.size
                break
        out.append((d, int(np.sum(u < d))))
    return out


@pytest.mark.parametrize("shape", [(3000,), (50, 60)])
def test_a_clipped_profile_gives_the_exact_nested_set_answer(shape):
    """Many points at exactly the maximum (a clipped scan) and a second plateau below it."""
    rng = np.random.default_rng(6)
    z = rng.standard_normal(shape)
    z = np.minimum(z, np.quantile(z, 0.9))  # 10 % of the points on the top plateau
    z[(z > 0.5) & (z < 0.6)] = 0.55  # a second plateau
    slopes = np.abs(rng.standard_normal(shape))
    solvers = [WinklerSprings(modulus=2.0)] + ([MDRSprings(youngs_modulus=2.0), BisectionSprings(youngs_modulus=2.0)]
                                               if len(shape) == 1 else [])
    plateau = int(np.sum(z == z.max()))
    forces = 2.0 * np.array([1e-9, 1.0, 0.5 * plateau * (z.max() - 0.55), plateau * (z.max() - 0.55), 50.0, 500.0])
    expected = nested_set_answer(z, forces, 2.0)
    for solver in solvers:
        curve = solver.solve(Profile(z, 1.0), forces, "force", slopes)
        assert list(curve.contact_count) == [n for _, n in expected], solver.name
        np.testing.assert_allclose(curve.indentation, [d for d, _ in expected], rtol=1e-9)
        assert curve.contact_count[0] == plateau  # the whole top plateau touches at once
        flat = z.ravel()
        for n, d, value in zip(curve.contact_count, curve.indentation, curve.slope_rms_contact):
            assert value == pytest.approx(rms(slopes.ravel()[flat > flat.max() - d]), rel=1e-12)
