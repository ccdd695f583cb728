"""What a measured map goes through between the file and the solver (levelling, crop,
spikes, square pixels, downsampling), checked against what each step must keep or remove,
on maps built here with known parts."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest

from frictionlab_spectra import ProfileFile, SurfaceFile
from frictionlab_spectra.scan_shaping import cosine_resample, despike, level, levelling_warning, outlier_warning, spike_warning


def band_limited(ny: int, nx: int, seed: int = 0, modes: int = 40, top: float = 0.6) -> tuple[np.ndarray, callable]:
    """A sum of cosine modes of the even extension (every one below ``top`` times each axis'
    Nyquist wavenumber): its samples on (ny, nx) and the continuous surface z(x, y), x and y in pixels."""
    rng = np.random.default_rng(seed)
    kx, ky = rng.integers(0, int(top * nx), modes), rng.integers(0, int(top * ny), modes)
    amplitude = rng.standard_normal(modes)

    def z(x, y):
        return sum(a * np.cos(np.pi * i * (x + 0.5) / nx) * np.cos(np.pi * j * (y + 0.5) / ny)
                   for a, i, j in zip(amplitude, kx, ky))  # fmt: skip

    y, x = np.mgrid[0:ny, 0:nx].astype(float)
    return z(x, y), z


def rms_gradient(z: np.ndarray, dx: float, dy: float) -> float:
    gy, gx = np.gradient(z, dy, dx)
    return float(np.sqrt(np.mean(gx[1:-1, 1:-1] ** 2 + gy[1:-1, 1:-1] ** 2)))


def test_rectangular_pixels_resampled_keep_the_rms_height_and_gradient_of_a_band_limited_surface():
    """Pixels 0.128 x 0.315 (2.46:1): the coarse axis resampled onto 0.128 by the cosine series
    reproduces the continuous surface at the new points, so its rms height and rms gradient
    are those of the surface sampled finely from the start."""
    dx, dy = 0.128, 0.315
    ny, nx = 40, 64
    z, exact = band_limited(ny, nx, top=0.35)
    fine = cosine_resample(z, 0, dy, dx)
    assert fine.shape == (math.floor((ny - 1) * dy / dx + 1e-9) + 1, nx)
    t = np.arange(fine.shape[0]) * dx / dy  # the new rows, in old pixels
    truth = exact(np.arange(nx)[None, :].astype(float), t[:, None])
    np.testing.assert_allclose(fine, truth, atol=1e-9 * np.abs(truth).max())  # interpolation, not an approximation
    assert np.std(fine) == pytest.approx(np.std(truth), rel=1e-9)
    assert rms_gradient(fine, dx, dx) == pytest.approx(rms_gradient(truth, dx, dx), rel=1e-9)
    # and against a wrong resampling: nearest rows lose the gradient along y
    nearest = z[np.minimum(np.round(t).astype(int), ny - 1)]
    assert abs(rms_gradient(nearest, dx, dx) / rms_gradient(truth, dx, dx) - 1) > 0.01


def test_downsampling_keeps_long_waves_and_removes_short_ones_without_aliasing():
    n = 128
    x = np.arange(n, dtype=float)
    long_wave = np.cos(np.pi * 6 * (x + 0.5) / n)  # 43 pixels: far below the new Nyquist
    short_wave = np.cos(np.pi * 100 * (x + 0.5) / n)  # 2.6 pixels: above the Nyquist of pixels 4 times larger
    coarse = cosine_resample(np.outer(long_wave + short_wave, np.ones(8)), 0, 1.0, 4.0)[:, 0]
    t = np.arange(coarse.size) * 4.0
    np.testing.assert_allclose(coarse, np.cos(np.pi * 6 * (t + 0.5) / n), atol=1e-9)
    plain = (long_wave + short_wave)[::4]  # taking every 4th point folds the short wave back
    assert np.max(np.abs(plain - np.cos(np.pi * 6 * (t + 0.5) / n))) > 0.5


def test_levelling_removes_the_least_squares_plane_and_quadratic_and_says_what_they_carried():
    rng = np.random.default_rng(3)
    ny, nx = 30, 50
    rough = rng.standard_normal((ny, nx))
    y, x = np.mgrid[0:ny, 0:nx].astype(float)
    tilted = rough + 0.5 * x - 0.3 * y + 7.0
    curved = tilted + 0.1 * (x - 20) ** 2 + 0.01 * x * y
    for z, degree in ((tilted, 1), (curved, 2)):
        design = [np.ones_like(x), x, y] + ([x * x, x * y, y * y] if degree == 2 else [])
        A = np.stack([d.ravel() for d in design], axis=1)
        residual = z.ravel() - A @ np.linalg.lstsq(A, z.ravel(), rcond=None)[0]  # brute force
        out = level(z, "plane" if degree == 1 else "quadratic")
        np.testing.assert_allclose(out.heights.ravel(), residual, atol=1e-9)
        assert out.rms_after == pytest.approx(np.std(residual), rel=1e-9)
    tilt = level(tilted, "mean")
    assert tilt.plane_share > 0.9 and "a tilt carries" in levelling_warning(tilt, "mean")
    assert levelling_warning(level(tilted, "plane"), "plane") is None
    bowl = level(curved, "plane")
    assert bowl.curvature_share / (1 - bowl.plane_share) > 0.5 and "detrend: quadratic" in levelling_warning(bowl, "plane")
    assert levelling_warning(level(rough, "mean"), "mean") is None


@pytest.mark.parametrize("rough, bow, seed", [(1e-8, 0.0, 2), (1e-9, 1e-8, 5)])
def test_the_curvature_left_by_a_plane_is_measured_on_what_the_plane_leaves(rough, bow, seed):
    """A tilt that carries all but 1e-16 of a map's height variance: the curvature's share of
    what the plane leaves was curvature / (1 - plane share), and 1 - plane share is rounding
    there (0: 'a curvature carries inf %', with numpy's 'divide by zero' on stderr; or a
    share below 0 or above 100 %). It is measured against the levelled heights' own rms,
    the share brute force gives (a least-squares quadratic fitted to what the plane leaves)."""
    y, x = np.mgrid[0:64, 0:64].astype(float)
    left = rough * np.random.default_rng(seed).standard_normal(x.shape) + bow * (x - 31.5) ** 2
    z = x + 3.0 * y + left
    design = np.stack([d.ravel() for d in (np.ones_like(x), x, y, x * x, x * y, y * y)], axis=1)
    after_plane = level(z, "plane").heights.ravel()
    after_quadratic = after_plane - design @ np.linalg.lstsq(design, after_plane, rcond=None)[0]
    share = 1.0 - np.var(after_quadratic) / np.var(after_plane)  # brute force
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy's divide by zero
        said = levelling_warning(level(z, "plane"), "plane")
    if share <= 0.5:
        assert said is None
    else:
        assert said is not None and f"a curvature carries {100 * share:.1f} % " in said, said


def test_despike_replaces_a_spike_and_nothing_else():
    z, _ = band_limited(40, 48, seed=5, top=0.2)
    spiky = z.copy()
    spiky[20, 30:32] += 13 * np.std(z)
    cleaned, count = despike(spiky, 6.0, float(np.std(z)))
    assert count == 2
    untouched = np.ones(z.shape, bool)
    untouched[20, 30:32] = False
    np.testing.assert_array_equal(cleaned[untouched], z[untouched])
    assert np.max(np.abs(cleaned[20, 30:32] - z[20, 30:32])) < 0.2 * np.std(z)  # smooth surface: Laplace fills it well
    assert despike(z, 6.0, float(np.std(z)))[1] == 0


@pytest.mark.parametrize("where", [(20, slice(30, 32)), (0, slice(0, 1)), (39, slice(46, 48))])  # inside, corners
def test_the_spikes_among_the_highest_points_are_said_as_despike_would_replace_them(where):
    """A spike (13 rms above a smooth surface, inside the map or at its edge) is named, counted
    as despike at 6 counts it (scipy's 5 x 5 median filter, edges reflected: independent of the
    caveat's own windows); a spike of 4 rms, and the smooth surface alone, say nothing. A map
    left with its spikes gave no word at validation: a run's law at small loads was theirs."""
    from scipy import ndimage

    z, _ = band_limited(40, 48, seed=5, top=0.2)
    rms = float(np.std(z))
    assert spike_warning(z, rms) is None
    spiky = z.copy()
    spiky[where] += 13 * rms
    expected = int(np.count_nonzero(spiky - ndimage.median_filter(spiky, size=5, mode="reflect") > 6 * rms))
    assert expected == despike(spiky, 6.0, rms)[1] >= 1
    said = spike_warning(spiky, rms)
    stand, it = ("stands", "replaces it, if it is not") if expected == 1 else ("stand", "replaces them, if they are not")
    assert said.startswith(f"{expected} of the map's 16 highest points {stand} more than 6 rms heights") and it in said
    low = z.copy()
    low[where] += 4 * rms
    assert spike_warning(low, rms) is None


def test_a_spike_caveat_comes_with_the_map_unless_despike_is_set(tmp_path):
    z, _ = band_limited(40, 48, seed=6, top=0.2)
    z[11, 17] += 14 * np.std(z)
    np.save(tmp_path / "map.npy", z)
    said = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5).input_summary()
    assert any("1 of the map's 16 highest points stands" in c and "despike: 6 replaces it, if it is not" in c for c in said["caveats"])
    cleaned = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5, despike=6.0).input_summary()
    assert cleaned["despiked"]["points"] == 1 and "caveats" not in cleaned


def test_a_map_made_flat_by_despike_says_despike_did_it(tmp_path):
    """A flat map with two spikes is refused once despike has replaced them, and the refusal
    said only 'constant (rms height zero after detrend=...)' of a file whose points visibly
    differ; it names despike and the points it replaced. Without despike the map is read."""
    z = np.zeros((32, 32))
    z[5, 5], z[20, 20] = 1.0, -1.0
    np.save(tmp_path / "map.npy", z)
    with pytest.raises(ValueError, match=r"constant \(rms height zero after detrend='mean' and despike 6, which "
                                         r"replaced 2 points\)"):  # fmt: skip
        SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.1, despike=6.0).rms_height()
    assert SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.1).rms_height() > 0


@pytest.mark.parametrize("where", [slice(300, 302), slice(0, 1), slice(511, 512)])  # inside, the ends
def test_a_line_left_with_spikes_says_so_as_a_map_does(tmp_path, where):
    """A profile with a spike 13 rms above it, inside or at an end, was pressed without a word
    (a map's spikes are said): its law at small loads is the spike's. Counted as a median
    filter of 5 points (scipy's, ends reflected: independent of the caveat's own windows)
    counts them; a bump of 4 rms, and the smooth line, say nothing of spikes."""
    from scipy import ndimage

    t = np.arange(512.0)
    z = np.sin(2 * np.pi * t / 97.0) + 0.5 * np.cos(2 * np.pi * t / 41.0)  # smooth: no point stands out
    spiky, low = z.copy(), z.copy()
    spiky[where] += 13 * np.std(z)
    low[where] += 4 * np.std(z)
    for name, line in (("smooth", z), ("spiky", spiky), ("low", low)):
        np.save(tmp_path / f"{name}.npy", line)
    said = {name: ProfileFile(path=str(tmp_path / f"{name}.npy"), spacing=1.0).input_summary()
            for name in ("smooth", "spiky", "low")}  # fmt: skip
    levelled = spiky - spiky.mean()
    rms = float(np.std(levelled))
    expected = int(np.count_nonzero(levelled - ndimage.median_filter(levelled, size=5, mode="reflect") > 6 * rms))
    assert expected == where.stop - where.start
    caveat, *edge = said["spiky"]["caveats"]
    at_end = where.start in (0, 511)  # a point off the rest there is also the line's steep end: the region that crops it
    assert [c.startswith("the line's ") and "crop them with region (x: " in c for c in edge] == [True] * at_end
    assert caveat.startswith(
        f"{expected} of the line's 16 highest points {'stands' if expected == 1 else 'stand'} more than 6 rms heights "
        "above the median of the 5 points around them: spikes (dust, an instrument's artefact) take the first contact "
        "alone, and the law at small loads is theirs; they carry "  # and the rms slope: checked below
    ) and caveat.endswith(
        f"; despike: 6 replaces {'it' if expected == 1 else 'them'}, if {'it is' if expected == 1 else 'they are'} "
        "not the surface's own"
    )
    assert "caveats" not in said["smooth"]
    low = said["low"].get("caveats", ())  # no spike; at an end, its step the line's steep end
    assert [c.startswith("the line's ") and "crop them with region (x: " in c for c in low] == [True] * at_end


@pytest.mark.parametrize("hurst", [0.3, 0.7, 1.0])
def test_self_affine_surfaces_draw_no_caveat_of_points_far_from_the_rest(registry, hurst):
    """The surfaces a run makes (power-law-2d, rolloff-2d): none draws the caveat."""
    from frictionlab.preset.seeds import realization_rng

    for name, rolloff in (("power-law-2d", {}), ("rolloff-2d", {"rolloff_wavelength": 32.0})):
        generator = registry.get("spectrum", name)(hurst=hurst, points=128, short_cutoff=4.0, spacing=1.0, **rolloff)
        for index in range(3):
            z = generator.generate(realization_rng(7, index)).heights
            assert outlier_warning(z - z.mean(), "map") is None


@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("scale", [1e-9, 1.0, 1e200])
def test_a_value_written_for_a_missing_pixel_is_said_up_or_down_and_at_any_scale(sign, scale):
    """One pixel of -9999 (or +9999) in a map of Gaussian heights of rms 1: its rms height is
    that pixel's. Said whatever the unit (no overflow at 1e200), for a pit as for a peak, with
    the ratio of the rms height to the robust one (1.4826 median absolute deviations)."""
    z = np.random.default_rng(3).standard_normal((96, 80))
    assert outlier_warning(scale * z, "map") is None
    z[40, 33] = sign * 9999.0
    said = outlier_warning(scale * z, "map")
    deviation = np.median(np.abs(z - np.median(z)))
    ratio = np.sqrt(np.mean(np.square(z))) / (1.4826 * deviation)
    said_ratio = re.match(r"the map's rms height is (\S+) times what most of its points say", said or "")
    # compared with a tolerance: its median of an even count is one of the middle two, numpy's their mean
    assert said_ratio is not None and float(said_ratio[1]) == pytest.approx(ratio, rel=1e-2)
    line = np.random.default_rng(4).standard_normal(500)
    line[[17, 18, 300]] = sign * 1e4  # three pixels: a few, not only one
    assert outlier_warning(scale * line, "line").startswith("the line's rms height is ")


def test_the_caveat_is_said_past_five_times_the_robust_rms_height_and_not_before():
    """Its criterion, counted plainly: Gaussian heights with 20 of 2000 points lifted to make
    the rms height 4.5 or 5.5 times the robust one (which those 20 hardly move)."""
    z = np.random.default_rng(5).standard_normal(2000)
    for target, said in ((4.5, False), (5.5, True)):
        lifted = z.copy()
        robust = 1.4826 * np.median(np.abs(lifted - np.median(lifted)))
        # 20 points at height c: the mean square (sum of the rest + 20 c^2) / 2000 = (target robust)^2
        rest = np.sum(np.square(lifted[20:]))
        lifted[:20] = np.sqrt(((target * robust) ** 2 * 2000 - rest) / 20)
        robust = 1.4826 * np.median(np.abs(lifted - np.median(lifted)))  # moved a little by the 20
        ratio = np.sqrt(np.mean(np.square(lifted))) / robust
        assert (outlier_warning(lifted, "line") is not None) == (ratio > 5) == said, ratio


def test_the_caveat_takes_one_copy_of_the_map():
    import tracemalloc

    z = np.random.default_rng(6).standard_normal((512, 512))
    tracemalloc.start()
    try:
        outlier_warning(z, "map")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1.2 * z.nbytes


def test_a_file_with_a_missing_pixels_value_says_its_rms_height_is_that_pixels(tmp_path):
    z, _ = band_limited(40, 48, seed=6, top=0.2)
    np.save(tmp_path / "clean.npy", z)
    z[3, 5] = -9999.0
    np.save(tmp_path / "sentinel.npy", z)
    line = np.sin(np.arange(300) / 5.0)
    np.save(tmp_path / "clean-line.npy", line)
    line[[30, 31]] = 1e38  # another instrument's sentinel
    np.save(tmp_path / "sentinel-line.npy", line)

    def caveats(reader, name):
        return reader(path=str(tmp_path / name), spacing=0.5).input_summary().get("caveats", [])

    for reader, what in ((SurfaceFile, "map"), (ProfileFile, "line")):
        stem = "" if what == "map" else "-line"
        assert not any("rms height is" in caveat for caveat in caveats(reader, f"clean{stem}.npy"))
        assert any(caveat.startswith(f"the {what}'s rms height is ") and "f's unit E* h L, theirs" in caveat
                   for caveat in caveats(reader, f"sentinel{stem}.npy"))  # fmt: skip


def test_region_and_downsample_in_the_summary(tmp_path):
    z, _ = band_limited(60, 80, seed=1, top=0.3)
    np.save(tmp_path / "map.npy", z)
    whole = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5, unit="um")
    crop = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5, unit="um", detrend="none",
                       region={"x": [10, 50], "y": [5, 45]})  # fmt: skip
    by_length = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5, unit="um", detrend="none",
                            region={"x": [5.0, 25.0], "y": [2.5, 22.5], "units": "length"})  # fmt: skip
    np.testing.assert_array_equal(crop.generate(None).heights, z[5:45, 10:50])
    np.testing.assert_array_equal(by_length.generate(None).heights, z[5:45, 10:50])
    assert crop.input_summary()["region_pixels"] == [[10, 50], [5, 45]] and crop.grid_shape() == (40, 40)
    down = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5, unit="um", downsample={"factor": 2})
    made = down.generate(None)
    assert made.spacing == 1.0 and made.heights.shape == (30, 40) == down.grid_shape()
    assert down.input_summary()["downsampled"] == {"from_pixel": 0.5, "to_pixel": 1.0}
    assert whole.input_summary()["detrend"] == "mean" and whole.input_summary()["detrend_from"] == "default"
    with pytest.raises(ValueError, match=r"region.x = \[10, 500\] \(pixels\) is not inside the map, 80 pixels"):
        SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5, region={"x": [10, 500]}).generate(None)
    with pytest.raises(ValueError, match="downsample takes one of factor"):
        SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5, downsample={"factor": 2, "pixel": 1.0})


def test_a_despike_that_would_replace_the_scan_itself_is_refused():
    """despike 0.001 took 96 % of a map for spikes and replaced them (the rms fell sixfold), and
    built one Python equation per point: a large map ran for hours. More than 5 % is refused,
    before any equation, naming the count."""
    z = np.random.default_rng(3).standard_normal((32, 32))
    with pytest.raises(ValueError, match=r"despike 0.001 takes \d+ of 1024 points \(9\d\.\d %\) for spikes.*more than 5 %"):
        despike(z, 0.001, float(np.std(z)))
    assert despike(z, 6.0, float(np.std(z)))[1] == 0  # a usual k leaves white noise alone


def test_the_levelling_record_survives_despike(tmp_path):
    """With despike set, the summary gave the rms of the map already levelled as the rms
    before levelling, and said a tilt carrying most of the height had removed 0 % of it: the
    despiked map was levelled a second time and that record replaced the first. The record is
    the levelling of the file's map with its spikes replaced."""
    z, _ = band_limited(40, 48, seed=6, top=0.2)
    z[11, 17] += 14 * np.std(z)
    y, x = np.mgrid[0:40, 0:48].astype(float)
    tilted = z + 0.2 * np.std(z) * x
    np.save(tmp_path / "map.npy", tilted)
    plain = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5, detrend="plane").input_summary()
    cleaned = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.5, detrend="plane", despike=6.0).input_summary()
    assert cleaned["despiked"]["points"] == 1
    assert cleaned["rms_removed_fraction"] > 0.5
    assert cleaned["rms_removed_fraction"] == pytest.approx(plain["rms_removed_fraction"], abs=0.05)
    assert cleaned["rms_before_detrend"] == pytest.approx(plain["rms_before_detrend"], rel=0.05)
    assert cleaned["rms_height"] < plain["rms_height"]


@pytest.mark.parametrize("what", ["map", "line"])
def test_a_form_kept_that_is_mostly_a_curvature_is_told_the_levelling_that_removes_it(tmp_path, what):
    """A bowed scan levelled by its mean was told 'detrend: plane (or quadratic) levels it' (tilt,
    for a line): the plane or the tilt keeps the bow, and the run said so in a second caveat. The
    remedy named is the one that leaves no caveat; a tilt kept is still told plane (or tilt)."""
    x = np.arange(200) * 0.1
    bow, tilt = (x - x.mean()) ** 2 / 20.0, 0.3 * x
    from scipy.ndimage import uniform_filter

    # roughness whose neighbours are correlated, as a measured map's are (white noise is said to be noise)
    rough_part = uniform_filter(np.random.default_rng(3).normal(size=(40, 200)), 3) * 0.03
    for name, form, remedy in (("bowed", bow, "quadratic"), ("tilted", tilt, "plane (or quadratic)")):
        z = rough_part + form[None, :] if what == "map" else rough_part[0] + form
        np.save(tmp_path / f"{name}.npy", z)
        plugin = SurfaceFile if what == "map" else ProfileFile
        caveats = plugin(path=str(tmp_path / f"{name}.npy"), spacing=0.1).input_summary()["caveats"]
        expected = remedy if what == "map" else remedy.replace("plane", "tilt")
        assert caveats[0].endswith(f"not on the roughness; detrend: {expected} levels it"), caveats
        levelled = plugin(path=str(tmp_path / f"{name}.npy"), spacing=0.1, detrend=expected.split(" ")[0])
        assert "caveats" not in levelled.input_summary(), levelled.input_summary()


@pytest.mark.parametrize("what", ["map", "line"])
def test_heights_in_steps_coarser_than_the_roughness_between_pixels_are_said(tmp_path, what):
    """A smooth scan stored at a coarse height resolution: rounded to steps of a quarter of its rms
    height, 85 % of its neighbouring pixels had one height, their slopes zero, and MDR's b fell from
    0.09 to 0.04 without a caveat. Said, with the smallest step; the same scan unrounded is not."""
    smooth, _ = band_limited(64, 96, seed=4, top=0.1)
    z = smooth if what == "map" else smooth[7]
    step = 0.25 * float(np.std(z))
    np.save(tmp_path / "fine.npy", z)
    np.save(tmp_path / "steps.npy", np.round(z / step) * step)
    plugin = SurfaceFile if what == "map" else ProfileFile
    said = plugin(path=str(tmp_path / "steps.npy"), spacing=0.1, detrend="mean").input_summary().get("caveats", [])
    points = "pixels" if what == "map" else "points"
    flat = [caveat for caveat in said if f"the {what}'s neighbouring {points} have exactly the same height" in caveat]
    assert len(flat) == 1, said
    assert re.search(rf"steps \(the smallest {step:.3g}, 0\.2\d rms heights\)", flat[0]), flat[0]
    fine = plugin(path=str(tmp_path / "fine.npy"), spacing=0.1, detrend="mean").input_summary().get("caveats", [])
    assert not any("neighbouring pixels" in caveat for caveat in fine), fine


def test_a_map_most_of_whose_points_share_one_height_is_said_in_words_not_infinitely(tmp_path):
    z = np.zeros((32, 32))
    z[10, 10], z[20, 5] = 1.0, -1.0
    said = outlier_warning(z, "map")
    assert "infinitely" not in said
    assert said.startswith("the map's rms height is more than 5 times what most of its points say") and \
        "here zero: more than half of them have one height" in said  # fmt: skip


@pytest.mark.parametrize("hurst", [0.3, 0.8, 1.0])
def test_scan_line_offsets_are_said_and_self_affine_surfaces_draw_no_such_caveat(registry, hurst):
    """An AFM leaves its scan lines offset from one another unless they are aligned: offsets of a
    twentieth of the rms height took 40 % off MDR's b (0.092 to 0.056 on a 256 x 128 scan), without
    a caveat. Offsets as large as the rows' own differences are said, of rows, or of columns for the
    map transposed; the surfaces a run makes, whole, cropped or oversampled (their shortest wave 64
    pixels), draw none."""
    from frictionlab.preset.seeds import realization_rng
    from frictionlab_spectra.scan_shaping import line_offset_warning

    for cutoff in (2.0, 64.0):
        generator = registry.get("spectrum", "power-law-2d")(hurst=hurst, points=256, short_cutoff=cutoff, spacing=1.0)
        z = generator.generate(realization_rng(3, 0)).heights
        for piece in (z, z[:, :64], z[:64, :], z.T):
            assert line_offset_warning(piece - piece.mean()) is None
        offsets = np.random.default_rng(5).normal(size=(256, 1)) * float(np.std(np.diff(z, axis=0)))  # as the rows differ
        rows = line_offset_warning(z + offsets)
        assert rows is not None and rows.startswith("the map's rows stand apart: ") and "grooves along x" in rows
        columns = line_offset_warning((z + offsets).T)
        assert columns is not None and columns.startswith("the map's columns stand apart: ")
    sheet = np.cumsum(np.cumsum(np.random.default_rng(1).normal(size=(256, 264)), axis=0), axis=1)
    assert line_offset_warning(sheet) is None and line_offset_warning(sheet.T) is None  # lines apart by a wandering height



def test_a_scan_with_its_lines_offset_says_so_when_validated(tmp_path):
    z, _ = band_limited(64, 96, seed=6, top=0.2)
    np.save(tmp_path / "aligned.npy", z)
    np.save(tmp_path / "offset.npy", z + np.random.default_rng(2).normal(size=(64, 1)) * np.std(np.diff(z, axis=0)))
    said = SurfaceFile(path=str(tmp_path / "offset.npy"), spacing=0.1).input_summary()["caveats"]
    assert [caveat for caveat in said if caveat.startswith("the map's rows stand apart")], said
    aligned = SurfaceFile(path=str(tmp_path / "aligned.npy"), spacing=0.1).input_summary().get("caveats", [])
    assert not [caveat for caveat in aligned if "stand apart" in caveat], aligned


def test_a_scan_in_single_precision_far_from_zero_is_said_to_be_in_steps(tmp_path):
    """An interferometer's absolute heights (5 mm, in um) stored as float32 keep steps of 0.0005 um
    on a roughness of 0.0005 um: MDR's b came out 0.03 instead of 0.09, without a caveat; in double
    precision the plane is levelled off exactly and nothing is said."""
    smooth, _ = band_limited(64, 96, seed=8, top=0.3)
    z = 5000.0 + 5e-4 * smooth / np.std(smooth) + 1e-3 * np.arange(96)[None, :]
    np.save(tmp_path / "single.npy", z.astype(np.float32))
    np.save(tmp_path / "double.npy", z)
    single = SurfaceFile(path=str(tmp_path / "single.npy"), spacing=0.1, detrend="plane").input_summary()
    assert any("neighbouring pixels have exactly the same height" in c and "single precision" in c
               for c in single.get("caveats", [])), single  # fmt: skip
    double = SurfaceFile(path=str(tmp_path / "double.npy"), spacing=0.1, detrend="plane")
    assert "caveats" not in double.input_summary()
    np.testing.assert_allclose(double.generate(None).heights, 5e-4 * (smooth - smooth.mean()) / np.std(smooth),
                               rtol=0, atol=1e-10)  # fmt: skip


@pytest.mark.parametrize("span, said", [("[.nan, 10]", "region.x[0]: must be a finite number, got nan"),
                                        ("[0, .inf]", "region.x[1]: must be a finite number, got inf")])  # fmt: skip
def test_a_region_bound_not_finite_is_one_problem(tmp_path, capsys, span, said):
    """A NaN in region.x was told twice: as not finite, and as 'region.x = [nan, 10]: needs
    0 <= start < stop', the order check run on it."""
    from frictionlab.cli import main

    np.save(tmp_path / "map.npy", np.random.default_rng(1).normal(size=(16, 16)))
    (tmp_path / "p.yaml").write_text(
        "name: r\nrealizations: 1\nsolver: {name: mdr}\nloading: {start: 0.001, stop: 1, steps: 3}\n"
        f"spectrum: {{name: surface-file, params: {{path: map.npy, spacing: 1.0, region: {{x: {span}}}}}}}\n"
    )
    assert main(["validate", str(tmp_path / "p.yaml")]) == 2
    out = "".join(capsys.readouterr())
    assert "1 problem in preset" in out and f"spectrum.params.{said}" in out, out


def _clause(spiky: np.ndarray, smooth: np.ndarray, dx: float, dy: float, what: str) -> str:
    """The spike caveat's slope clause, by hand: forward differences over the pixel's sides."""
    def square(z):
        return sum(np.mean((np.diff(z, axis=a) / d) ** 2) for a, d in ((1, dx), (0, dy)) if z.shape[a] > 1)

    with_, without = square(spiky), square(smooth)
    return (f"they carry {100 * (1 - without / with_):.0f} % of the {what}'s mean squared slope (its rms slope is "
            f"{np.sqrt(with_):.3g}, {np.sqrt(with_ / without):.3g} times what it is without them), so the rms slope xi "
            "divides by, and the full-contact estimate p = E* g, are theirs too")


def test_a_spike_that_makes_the_rms_slope_says_so_with_the_slope_on_the_files_pixels(tmp_path):
    """One spike 20 rms high on a smooth map of 0.05 x 0.125 pixels (x by y) carries most of the
    mean squared slope: the rms slope that xi divides by and the full-contact estimate E* g were the
    spike's, and the caveat said only that the law at small loads was. The rms slope is the
    file's, on its own pixels (with the spike, and without it as despike: 6 replaces it); a spike
    of 7 rms on a rough map, which carries little of the slope, adds no such clause."""
    z, _ = band_limited(40, 48, seed=5, top=0.2)
    z -= z.mean()
    spiky = z.copy()
    spiky[20, 30] += 20 * np.std(z)
    np.save(tmp_path / "map.npy", spiky)
    said = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.05, spacing_y=0.125).input_summary()["caveats"]
    levelled = spiky - spiky.mean()
    smooth = despike(levelled, 6.0, float(np.std(levelled)))[0]
    assert any(_clause(levelled, smooth, 0.05, 0.125, "map") in c and "despike: 6 replaces it" in c for c in said)
    rough, _ = band_limited(64, 64, seed=5, top=0.9, modes=200)
    rough -= rough.mean()
    rough[np.unravel_index(np.argmax(rough), rough.shape)] += 7 * np.std(rough)
    caveat = spike_warning(rough, float(np.std(rough)))
    assert caveat.startswith("1 of the map's 16 highest points stands") and "slope" not in caveat


def test_a_spike_that_makes_a_lines_rms_slope_says_so_in_the_lines_length_unit(tmp_path):
    """A profile's spike 13 rms high on a smooth line of points 0.2 apart: the clause gives the rms
    slope over 0.2, not over one point."""
    t = np.arange(512.0)
    z = np.sin(2 * np.pi * t / 97.0) + 0.5 * np.cos(2 * np.pi * t / 41.0)
    z[300] += 13 * np.std(z)
    np.save(tmp_path / "line.npy", z)
    (caveat,) = ProfileFile(path=str(tmp_path / "line.npy"), spacing=0.2).input_summary()["caveats"]
    levelled = (z - z.mean()).reshape(1, -1)
    smooth = despike(levelled, 6.0, float(np.std(levelled)))[0]
    assert _clause(levelled, smooth, 0.2, 0.2, "line") in caveat


@pytest.mark.parametrize("depth", [-20.0, -100.0])  # a pit; a dropout written as a height
def test_a_pit_that_makes_the_rms_slope_says_so_and_despike_is_named(tmp_path, depth):
    """A pixel far below a smooth map (a dropout the instrument wrote as a height, not NaN) is no
    spike up, and nothing was said, though it made the map's rms slope, xi's denominator and the
    full-contact estimate E* g. The caveat counts it, gives the rms slope on the file's pixels with
    and without it, and names despike, for a line as for a map."""
    z, _ = band_limited(40, 48, seed=5, top=0.2)
    z[20, 30] += depth * np.std(z)
    np.save(tmp_path / "map.npy", z)
    said = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.05, spacing_y=0.125).input_summary()["caveats"]
    (caveat,) = [c for c in said if "of the map's points" in c]  # at 100 rms, the outlier caveat too
    levelled = z - z.mean()
    smooth = despike(levelled, 6.0, float(np.std(levelled)))[0]
    assert caveat.startswith("1 of the map's points stands more than 6 rms heights from the median of the 5 x 5 pixels")
    assert _clause(levelled, smooth, 0.05, 0.125, "map") in caveat and caveat.endswith("; despike: 6 replaces it, if it is not the surface's own")
    t = np.arange(512.0)
    line = np.sin(2 * np.pi * t / 97.0) + 0.5 * np.cos(2 * np.pi * t / 41.0)
    line[200:202] += depth * np.std(line)
    np.save(tmp_path / "line.npy", line)
    said = ProfileFile(path=str(tmp_path / "line.npy"), spacing=0.2).input_summary()["caveats"]
    (caveat,) = [c for c in said if "of the line's points" in c]
    assert caveat.startswith("2 of the line's points stand more than 6 rms heights from the median of the 5 points")
    assert caveat.endswith("; despike: 6 replaces them, if they are not the surface's own")
    cleaned = ProfileFile(path=str(tmp_path / "line.npy"), spacing=0.2, despike=6.0).input_summary()
    assert cleaned["despiked"]["points"] == 2 and not any("of the line's points" in c for c in cleaned.get("caveats", ()))


@pytest.mark.parametrize("hurst", [0.3, 0.8])
def test_self_affine_surfaces_draw_no_spike_or_pit_caveat(registry, hurst):
    """The surfaces a run makes, rough down to two pixels: their largest slopes are their own."""
    from frictionlab.preset.seeds import realization_rng

    generator = registry.get("spectrum", "power-law-2d")(hurst=hurst, points=128, short_cutoff=2.0, spacing=1.0)
    for index in range(3):
        z = generator.generate(realization_rng(3, index)).heights
        assert spike_warning(z - z.mean(), float(np.std(z))) is None


def test_a_spike_on_a_line_level_but_for_rounding_says_the_rest_level_not_a_ratio_of_1e15():
    """A line flat but for a spike and a step of 1e-14: despiked, its mean squared slope is rounding's
    residue, and the caveat said the rms slope was 4.24e+15 times what it is without the spike."""
    from frictionlab_spectra.scan_shaping import line_spike_warning

    z = np.r_[np.zeros(200), np.full(200, 1e-14)]
    z[100] += 30.0
    z -= z.mean()
    said = line_spike_warning(z, float(np.sqrt(np.mean(z**2))), 1.0)
    assert f"(its rms slope is {np.sqrt(np.mean(np.diff(z) ** 2)):.3g}, the rest level)" in said, said
    assert "times what it is without them" not in said


@pytest.mark.parametrize("line", [False, True])
def test_a_spike_that_alone_makes_a_scan_steep_is_not_called_a_unit_mismatch(line):
    """One spike 1000 rms heights high made the rms slope 20 or more: the units caveat then advised
    converting a file whose heights and pixels agreed. A scan steep without its spike still gets it."""
    from frictionlab_spectra.scan_shaping.height_caveats import SLOPES, units_warning
    from frictionlab_spectra.scan_shaping.spikes import mean_square_slope

    rng = np.random.default_rng(np.random.SeedSequence(5))
    z = rng.standard_normal(4096 if line else (128, 128))  # rms slope about 2: a rough, plausible scan
    z -= z.mean()
    spiked = z.copy()
    spiked[(2000,) if line else (40, 60)] += 1000.0
    rows = spiked.reshape(1, -1) if line else spiked
    assert math.sqrt(mean_square_slope(rows, (1.0, 1.0))) > SLOPES[1]  # steep by its spike alone
    summary = {"unit": "um", "unit_from": "preset", "spacing_from": "preset"}
    what = "line" if line else "map"
    assert units_warning(spiked, 1.0, summary, what) is None
    assert "different units" in units_warning(spiked * 1e6, 1.0, summary, what)  # heights 1e6 times: steep without it
    assert "different units" in units_warning(spiked * 1e-8, 1.0, summary, what)  # flat: below the range
