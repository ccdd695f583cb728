"""Measured surfaces: ``surface-file`` (its MDR-equivalent line: ``test_equivalent_line.py``).

Oracles: the arrays written by the test itself (read back exactly), a plane added by the test
(removed exactly), the surface convention <z^2> = integral of C2D over the q plane measured with
the test's own FFTs, the exponent -2H-2 of a power-law map.
"""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest

from frictionlab.compute import engine
from frictionlab.cli import main
from frictionlab.errors import ExitCode, PresetError
from frictionlab.preset import build_scene, load_scene
from frictionlab.testing import check_plugin
from frictionlab_spectra import PowerLawSurface, ProfileFile, SurfaceFile
from frictionlab_spectra.equivalent_line import EquivalentLine
from frictionlab_spectra.instrument_file import scan_header
from frictionlab.options import RunOptions

from .conftest import SMALL_PRESET, merge

TWO_PI = 2.0 * math.pi


def power_law_map(tmp_path, name="map.npy", seed=0, **params):
    params = {"hurst": 0.8, "points": 256, **params}
    heights = PowerLawSurface(**params).generate(np.random.default_rng(seed)).heights
    path = tmp_path / name
    np.save(path, heights)
    return str(path), heights


# ------------------------------------------------------------------ reading


def test_a_power_law_map_reads_back_exactly(tmp_path):
    path, heights = power_law_map(tmp_path, points=200, points_y=160)
    offset = heights + 3.5
    np.save(path, offset)
    gen = SurfaceFile(path=path, spacing=0.25)
    profile = gen.generate(None)
    assert profile.heights.shape == (160, 200) and profile.spacing == 0.25
    np.testing.assert_allclose(profile.heights, offset - offset.mean(), rtol=0, atol=1e-13)
    assert gen.rms_height() == pytest.approx(np.std(heights), rel=1e-12)
    assert profile.periodic is False  # a scan, unless declared periodic
    profile.heights[0, 0] = 99.0  # a copy: the next surface is untouched
    assert gen.generate(np.random.default_rng(5)).heights[0, 0] != 99.0
    none = SurfaceFile(path=path, spacing=0.25, detrend="none").generate(None).heights
    np.testing.assert_array_equal(none, offset)


def test_text_and_npy_agree(tmp_path):
    path, heights = power_law_map(tmp_path, points=24, points_y=16)
    comma = tmp_path / "map.csv"
    comma.write_text("# an AFM export\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in heights) + "\n")
    spaces = tmp_path / "map.txt"
    np.savetxt(spaces, heights, header="z[row, column]")
    ints = tmp_path / "ints.npy"
    np.save(ints, np.rint(1000 * heights).astype(np.int32))
    from_npy = SurfaceFile(path=path, spacing=1.0).generate(None).heights
    for text in (comma, spaces):
        np.testing.assert_allclose(SurfaceFile(path=str(text), spacing=1.0).generate(None).heights,
                                   from_npy, rtol=0, atol=1e-14)
    counts = SurfaceFile(path=str(ints), spacing=1.0).generate(None).heights
    assert counts.dtype == np.float64
    np.testing.assert_allclose(counts, 1000 * from_npy, rtol=0, atol=0.51)  # rounding to integers only


def test_plane_detrend_removes_an_added_plane_exactly(tmp_path):
    _, heights = power_law_map(tmp_path, points=64, points_y=40)
    rows, cols = np.mgrid[0:40, 0:64]
    # the map is periodic and zero-mean: it has no plane of its own to within its sampling,
    # so remove the map's own least-squares plane first, then add a known one
    design = np.column_stack([np.ones(rows.size), cols.ravel(), rows.ravel()])
    coef, *_ = np.linalg.lstsq(design, heights.ravel(), rcond=None)
    flat = heights - (design @ coef).reshape(heights.shape)
    tilted = flat + 7.0 + 0.3 * cols - 0.05 * rows
    np.save(tmp_path / "tilted.npy", tilted)
    plane = SurfaceFile(path=str(tmp_path / "tilted.npy"), spacing=1.0, detrend="plane")
    np.testing.assert_allclose(plane.generate(None).heights, flat, rtol=0, atol=1e-12)
    assert plane.rms_height() == pytest.approx(np.std(flat), rel=1e-12)
    mean = SurfaceFile(path=str(tmp_path / "tilted.npy"), spacing=1.0).generate(None).heights
    assert np.std(mean) > 5 * np.std(flat)  # the mean detrend leaves the tilt in


# ------------------------------------------------------------------ spectra


def test_radial_psd_recovers_the_power_law_exponent(tmp_path):
    hurst = 0.7
    path, heights = power_law_map(tmp_path, hurst=hurst, amplitudes="rayleigh", seed=3)
    psd = SurfaceFile(path=path, spacing=1.0).radial_psd()
    # the convention: the annuli's power adds up to mean(z^2)
    assert np.sum(TWO_PI * psd.wavenumber * (psd.wavenumber[0]) * psd.psd) == pytest.approx(np.var(heights), rel=1e-10)
    band = PowerLawSurface(hurst=hurst, points=256).band
    fit = (psd.wavenumber > 4 * band.q_min) & (psd.wavenumber < 0.9 * band.q_max)
    slope = np.polyfit(np.log(psd.wavenumber[fit]), np.log(psd.psd[fit]), 1)[0]
    assert slope == pytest.approx(-2 * hurst - 2, abs=0.15)
    assert np.all(psd.psd[psd.wavenumber > 1.05 * band.q_max * math.sqrt(2)] < 1e-20)  # nothing past the band


def test_a_single_wave_lands_in_its_annulus(tmp_path):
    """z = 2 cos(2 pi (3 x + 4 y) / 64) on 64 x 64 pixels: all power 2 at |q| = 5 dq, dq = 2 pi / 64."""
    rows, cols = np.mgrid[0:64, 0:64]
    np.save(tmp_path / "wave.npy", 2.0 * np.cos(TWO_PI * (3 * cols + 4 * rows) / 64))
    gen = SurfaceFile(path=str(tmp_path / "wave.npy"), spacing=1.0)
    psd, dq = gen.radial_psd(), TWO_PI / 64
    np.testing.assert_allclose(psd.wavenumber[:6], dq * np.arange(1, 7), rtol=1e-15)
    expected = np.zeros(psd.psd.size)
    expected[4] = 2.0 / (TWO_PI * 5 * dq * dq)  # annulus power / annulus area 2 pi q width
    np.testing.assert_allclose(psd.psd, expected, rtol=1e-12, atol=1e-12 * expected[4])


# ------------------------------------------------------------------ conformance and runs


@pytest.mark.parametrize("periodic", [False, True])
def test_both_classes_pass_the_conformance_checks(tmp_path, periodic):
    path, _ = power_law_map(tmp_path, points=32, points_y=24)
    detrend = "mean" if periodic else "plane"  # a periodic map takes no plane off (a step where it repeats)
    check_plugin("spectrum", SurfaceFile, deterministic=True, path=path, spacing=0.5, detrend=detrend, periodic=periodic)
    line = SurfaceFile(path=path, spacing=0.5, periodic=periodic).equivalent_line()
    check_plugin("spectrum", EquivalentLine, **line.params.model_dump())


def surface_preset(path, solver, periodic=False):
    data = merge(SMALL_PRESET, {"realizations": 2, "loading": {"start": 0.05, "stop": 1.0, "steps": 3},
                                "fit": {"bootstrap": 0}})
    data["spectrum"] = {"name": "surface-file", "params": {"path": path, "spacing": 1.0, "periodic": periodic}}
    data["solver"] = {"name": solver, "params": {"youngs_modulus": 1.0}}
    return data


def test_bem_halfspace_runs_on_the_measured_surface(tmp_path, registry):
    path, heights = power_law_map(tmp_path, points=16, hurst=0.8)
    with pytest.raises(PresetError, match="bem-halfspace presses periodic profiles only, but spectrum surface-file is "
                                          "not periodic .* set spectrum.params.periodic: true"):  # fmt: skip
        build_scene(surface_preset(path, "bem-halfspace"), registry=registry)
    scene = build_scene(surface_preset(path, "bem-halfspace", periodic=True), registry=registry)
    assert scene.geometry == "surface" and scene.spectrum.name == "surface-file"
    outcome = engine.run(scene, RunOptions(workers=1))
    assert outcome.status == "completed" and not outcome.failures
    assert outcome.rms_height == pytest.approx(np.std(heights), rel=1e-12)
    assert outcome.extent == pytest.approx(2 * math.sqrt(256 / math.pi), rel=1e-15)
    counts = outcome.per_realization["contact_count"]
    np.testing.assert_array_equal(counts[0], counts[1])  # the same surface twice
    assert np.all(np.diff(counts[0]) >= 0) and 0 < counts[0, -1] <= 256
    assert np.all(np.isfinite(outcome.xi))


def test_mdr_runs_the_measured_equivalent_line(tmp_path, registry):
    path, heights = power_law_map(tmp_path, points=64, hurst=0.8)
    preset = tmp_path / "mdr.yaml"
    import yaml

    preset.write_text(yaml.safe_dump(surface_preset(path, "mdr")))
    scene = load_scene(preset, [], registry)
    assert isinstance(scene.equivalent_line, EquivalentLine) and scene.spectrum.name == "surface-file"
    assert scene.resolved()["spectrum"]["name"] == "surface-file"  # re-runnable as written
    outcome = engine.run(scene, RunOptions(workers=1))
    assert outcome.status == "completed" and not outcome.failures
    assert outcome.extent == pytest.approx(2 * math.sqrt(64 * 64 / math.pi), rel=1e-14)
    assert outcome.rms_height == pytest.approx(np.std(heights), rel=1e-12)
    assert np.all(outcome.per_realization["contact_count"] <= scene.equivalent_line.params.points)
    assert np.all(np.isfinite(outcome.xi))


# ------------------------------------------------------------------ bad input


def surface_error(path, **params) -> str:
    gen = SurfaceFile(path=str(path), spacing=1.0, **params)  # construction reads nothing
    with pytest.raises(ValueError) as info:
        gen.generate(np.random.default_rng(0))
    message = str(info.value)
    assert message.startswith(f"surface-file {str(path)!r}: ")
    return message


def test_bad_maps_are_named_with_what_is_wrong(tmp_path):
    assert "no such file" in surface_error(tmp_path / "missing.npy")
    np.save(tmp_path / "line.npy", np.arange(64.0))
    assert "shape (64,)" in surface_error(tmp_path / "line.npy") and "2D" in surface_error(tmp_path / "line.npy")
    (tmp_path / "column.txt").write_text("\n".join(str(v) for v in range(20)))
    column = surface_error(tmp_path / "column.txt")
    assert "a map of 1 x 20 pixels (x by y), one pixel wide: a line; use profile-file" in column
    bad = np.random.default_rng(0).standard_normal((12, 10))
    bad[3, 4], bad[7, 1] = np.nan, np.inf
    np.save(tmp_path / "nan.npy", bad)
    message = surface_error(tmp_path / "nan.npy")
    assert "2 value(s) in heights not finite" in message and "row 3, column 4" in message
    np.save(tmp_path / "flat.npy", np.full((10, 10), 2.5))
    assert "constant" in surface_error(tmp_path / "flat.npy")
    rows, cols = np.mgrid[0:10, 0:12]
    np.save(tmp_path / "plane.npy", 1.0 + 0.2 * rows - 0.1 * cols)
    assert "constant" in surface_error(tmp_path / "plane.npy", detrend="plane")
    np.save(tmp_path / "small.npy", np.random.default_rng(1).standard_normal((7, 40)))
    assert "40 x 7 pixels (x by y)" in surface_error(tmp_path / "small.npy") and "8 x 8" in surface_error(tmp_path / "small.npy")
    (tmp_path / "map.xyz").write_text("1 2\n3 4\n")  # an instrument's text line scan (x, z)
    assert "holds a line scan; use profile-file" in surface_error(tmp_path / "map.xyz")
    (tmp_path / "noise.sur").write_bytes(bytes(range(256)) * 4)
    assert "suffix .sur names Digital Surf SUR, but its first bytes are not that format's: a damaged file" in \
        surface_error(tmp_path / "noise.sur")  # a damaged file of a known format, named as one


def test_validate_rejects_a_bad_map_for_mdr_without_a_traceback(tmp_path, capsys):
    import yaml

    np.save(tmp_path / "nan.npy", np.full((10, 10), np.nan))
    preset = tmp_path / "bad.yaml"
    preset.write_text(yaml.safe_dump(surface_preset(str(tmp_path / "nan.npy"), "mdr")))
    assert main(["validate", str(preset)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "surface-file" in err and "nan.npy" in err and "not finite" in err and "Traceback" not in err
    with pytest.raises(PresetError):
        load_scene(preset)


def test_a_npy_whose_header_asks_for_more_than_it_holds_is_refused_with_its_size(tmp_path):
    """A header announcing 2^23 x 2^22 doubles (256 TiB, beyond any address space) over a
    64-byte body: the message gives the shape and size announced and what the file holds,
    before anything is allocated, not a bare MemoryError (nor 'does not fit in memory':
    no memory would hold what the file does not have)."""
    path = tmp_path / "claims.npy"
    with path.open("wb") as fh:
        np.lib.format.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False, "shape": (2**23, 2**22)})
        fh.write(bytes(64))
    with pytest.raises(ValueError, match=r"a damaged .npy file: its header declares an array of shape \(8388608, 4194304\) "
                                         r"of float64 \(281,474,976,710,656 bytes\), but the file holds 64 bytes after it"):
        SurfaceFile(path=str(path), spacing=1.0).rms_height()


@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_a_npy_whose_header_declares_itself_longer_than_the_file_is_damage_not_memory(tmp_path, plugin):
    """A 20-byte .npy (format 2.0) whose header length field says 2^31 bytes: numpy reads that
    many bytes into one buffer before looking at them, so it was 'its array does not fit in this
    process's memory; crop or resample the map' under ulimit -v, and 'not a readable .npy array
    (ValueError)' after a 2 GiB allocation without one. It is named as damage, nothing allocated."""
    path = tmp_path / "forged.npy"
    path.write_bytes(b"\x93NUMPY\x02\x00" + (2**31).to_bytes(4, "little") + b"{'descr'")
    tracemalloc.start()
    try:
        with pytest.raises(ValueError) as info:
            plugin(path=str(path), spacing=1.0).rms_height()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert ("a damaged .npy file: its header declares a length of 2,147,483,648 bytes, but the file holds 8 bytes "
            "after it; save the array again") in str(info.value)
    assert peak < 2**26


@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_a_npy_past_the_memory_left_is_said_with_advice_for_a_line_and_a_map(tmp_path, plugin, monkeypatch):
    """A .npy numpy cannot allocate (as under ulimit -v) was told 'crop or resample the map', of
    a line too, whose region is cut from the file read whole."""
    path = tmp_path / "big.npy"
    np.save(path, np.zeros((16, 16) if plugin is SurfaceFile else 256))

    def no_memory(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(np, "load", no_memory)
    with pytest.raises(ValueError) as info:
        plugin(path=str(path), spacing=1.0).rms_height()
    said = str(info.value)
    shape = "(16, 16)" if plugin is SurfaceFile else "(256,)"
    assert f"its array of shape {shape} (" in said and "does not fit in this process's memory" in said
    assert "save a part of it (a crop, or every n-th point) to a file of its own" in said and "the map" not in said


@pytest.mark.parametrize(("region", "said"), [
    ({"x": [True, 20]}, "spectrum.params.region.x[0]: must be a number, not true or false, got true"),
    ({"y": [0, False]}, "spectrum.params.region.y[1]: must be a number, not true or false, got false"),
    ({"x": [0, float("nan")], "units": "length"}, "spectrum.params.region.x[1]: must be a finite number, got nan"),
    # pydantic's own words were 'tuple should have at most 2 items after validation, not 3'
    ({"x": [0, 4, 8]}, "spectrum.params.region.x: must hold at most 2 items, got [0, 4, 8]"),
    # each item missing was its own line, 'region.x.1: is required' (and x.0 too for [])
    ({"x": [4]}, "spectrum.params.region.x: must hold at least 2 items, got [4]"),
    ({"y": []}, "1 problem in preset\n  spectrum.params.region.y: must hold at least 2 items, got []"),
])  # fmt: skip
def test_a_region_bound_of_true_false_or_nan_is_refused_by_its_place(tmp_path, registry, region, said):
    """A region's bounds are an optional pair (tuple | None): true was taken as pixel 1 before
    the number check looked inside optional lists and tuples."""
    path, _ = power_law_map(tmp_path, points=16)
    data = surface_preset(path, "mdr")
    data["spectrum"]["params"]["region"] = region
    with pytest.raises(PresetError) as info:
        build_scene(data, registry=registry)
    assert said in str(info.value)


def test_a_map_of_heights_below_1e_minus_100_is_named_too_small_not_constant(tmp_path):
    """Heights of 1e-300 vary, but their squares underflow: the rms was 0 and the map was called
    constant; it is named for its size."""
    np.save(tmp_path / "tiny.npy", np.random.default_rng(2).standard_normal((16, 16)) * 1e-300)
    message = surface_error(tmp_path / "tiny.npy")
    assert "every value in heights is below 1e-100 in magnitude" in message and "constant" not in message
    np.save(tmp_path / "zero.npy", np.zeros((16, 16)))
    assert "the map is constant" in surface_error(tmp_path / "zero.npy")  # a flat map stays flat


@pytest.mark.parametrize("downsample", [{"factor": 1_000_000}, {"pixel": 1e9}])
def test_a_map_downsampled_to_one_pixel_is_named_too_small_not_constant(tmp_path, downsample):
    """The size after downsampling was checked after the rms: one pixel left has rms 0, and the
    map was called constant."""
    path, _ = power_law_map(tmp_path, points=32)
    message = surface_error(path, downsample=downsample)
    assert "after the crop, resampling and downsampling the map has 1 x 1 pixels (x by y); at least 8 x 8" in message
    assert "constant" not in message


@pytest.mark.parametrize(("channel", "said"), [
    (-1, "spectrum.params.channel: must be >= 0, got -1"),
    (1.5, "spectrum.params.channel: must be text or a whole number, got 1.5"),
    ([0], "spectrum.params.channel: must be text or a whole number, got [0]"),
    (True, "spectrum.params.channel: must be text or a number, not true or false, got true"),
])  # fmt: skip
def test_a_bad_channel_is_named_at_its_own_path(tmp_path, registry, channel, said):
    """channel is text or an index >= 0 (Annotated[int, Field(ge=0)]): -1 was said at
    'channel.constrained-int', pydantic's tag of the index, and true was taken as channel 1."""
    path, _ = power_law_map(tmp_path, points=16)
    data = surface_preset(path, "mdr")
    data["spectrum"]["params"]["channel"] = channel
    with pytest.raises(PresetError) as info:
        build_scene(data, registry=registry)
    assert said in str(info.value) and "constrained" not in str(info.value)


@pytest.mark.parametrize("plugin, name", [("surface-file", "map.npy"), ("surface-file", "map.csv"), ("profile-file", "line.npy"),
                                          ("profile-file", "line.txt")])
def test_a_channel_asked_of_a_table_is_refused_naming_it(tmp_path, registry, plugin, name):
    """A table holds one array of heights: channel: 'Z Sensor' (or 3) was ignored without a
    word and the run went on with exit 0."""
    heights = np.random.default_rng(0).standard_normal((16, 16) if plugin == "surface-file" else 64)
    path = tmp_path / name
    np.save(path, heights) if name.endswith(".npy") else np.savetxt(path, heights, delimiter=",")
    data = surface_preset(path, "mdr")
    data["spectrum"] = {"name": plugin, "params": {"path": str(path), "spacing": 1.0, "channel": "Z Sensor"}}
    with pytest.raises(PresetError) as info:
        build_scene(data, registry=registry)
    said = str(info.value)
    assert f"channel 'Z Sensor' picks a channel of an instrument file, but {name!r} is read as a table" in said
    data["spectrum"]["params"]["format"] = "instrument"  # an instrument's export of that suffix may have channels
    try:
        build_scene(data, registry=registry)
    except PresetError as exc:  # its reader's word on the channel, not this refusal
        assert "picks a channel of an instrument file" not in str(exc)


@pytest.mark.parametrize("name", ["map.npy", "map.csv", "map.sur", "map.dat"])
def test_an_empty_file_is_named_empty_whatever_its_suffix(tmp_path, registry, name):
    """A 0-byte file was 'not a readable .npy array (EOFError)', 'array of shape (0, 1)' or 'a
    damaged Digital Surf SUR file', by suffix; it is refused as empty before any reader."""
    (tmp_path / name).write_bytes(b"")
    with pytest.raises(PresetError) as info:
        build_scene(surface_preset(str(tmp_path / name), "mdr"), registry=registry)
    assert f"spectrum.params.path: is empty (0 bytes), it holds no heights, got '{tmp_path / name}'" in str(info.value)


def save_bare(path, z):
    """``z`` saved as numpy, MATLAB or HDF5 save a map: a bare array, no axes."""
    if path.suffix == ".npz":
        np.savez(path, z)
    elif path.suffix == ".mat":
        import scipy.io

        scipy.io.savemat(path, {"z": z})
    else:
        import h5py

        with h5py.File(path, "w") as fh:
            fh["z"] = z
    return path


@pytest.mark.parametrize("suffix", [".npz", ".mat", ".h5"])
def test_a_bare_array_is_a_map_of_rows_along_y_as_a_npy_is(tmp_path, suffix):
    """A map saved from numpy into .npz, .mat or .h5 was read transposed to the same map saved as
    .npy (its first index taken as x): its rows are y, its columns x, whatever the format."""
    z = np.random.default_rng(3).normal(size=(16, 24))  # 24 x 16 pixels (x by y)
    np.save(tmp_path / "map.npy", z)
    bare = save_bare(tmp_path / f"map{suffix}", z)
    made = {}
    for path in (tmp_path / "map.npy", bare):
        surface = SurfaceFile(path=str(path), spacing=0.5, spacing_y=1.0, detrend="mean")  # dy = 2 dx
        made[path.suffix] = (surface.generate(None).heights, surface.input_summary())
    (npy, npy_summary), (read, summary) = made[".npy"], made[suffix]
    assert read.shape == npy.shape and npy.shape[1] == 24 and npy.shape[0] > 16  # y resampled onto square pixels
    np.testing.assert_allclose(read, npy, rtol=1e-12, atol=1e-12)
    assert summary["shape"] == npy_summary["shape"]
    assert scan_header(bare, "map", dimension=2).shape == z.shape  # what the memory estimate reads ahead: (Ny, Nx)
