"""Instrument files (the extra ``topography``) read by surface-file and profile-file.

The files are written here by the writers that exist, with known heights and pixel
sizes: X3P by x3pio (ISO 5436-2000 revision, heights and sizes in metres), NetCDF
and Gwyddion by SurfaceTopography, ISO 25178-71 SDF (text and binary) by hand. What is checked:

* the numbers read are the numbers written, in the unit the preset asks for;
* f and xi do not depend on the unit: the same scan in um and in nm, pressed with
  loads scaled as the unit of a force (E* h L: length^2), gives the same f and xi;
* a scan and the same heights as a .npy with the matching spacing give identical
  results from a preset, end to end;
* undefined points are refused, or filled and recorded; without the extra a file
  of such a format gets a message naming it, exit 2.
"""

from __future__ import annotations

import json
import struct
import sys
import warnings
import zipfile

import numpy as np
import pytest
import x3pio
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode, PresetError
from frictionlab.preset import build_scene
from frictionlab.testing import check_plugin
from frictionlab_spectra import ProfileFile, SurfaceFile

PIXEL_UM = 0.125  # exact in float32, which NetCDF stores sizes in
ROWS, COLUMNS = 24, 32


def scan_um(seed=0):
    """A rough map z[row, column] in um (rows along y, columns along x)."""
    rng = np.random.default_rng(seed)
    z = np.cumsum(np.cumsum(rng.standard_normal((ROWS, COLUMNS)), axis=0), axis=1)
    return 0.05 * (z - z.mean()) / z.std()


def write_x3p(path, z_um, pixel_um=PIXEL_UM):
    x3pio.write(path, z_um * 1e-6, x_scale=pixel_um * 1e-6, y_scale=pixel_um * 1e-6,
                revision=x3pio.Revision.ISO5436_2000)  # the revision SurfaceTopography 1.27 reads  # fmt: skip


def write_topography(path, z, pixel, unit, writer):
    """Through SurfaceTopography, which lays a map out as heights[x, y]."""
    from SurfaceTopography import Topography  # here, not at the top: its import takes seconds, paid only where a test writes such a file

    topography = Topography(z.T.copy(), (z.shape[1] * pixel, z.shape[0] * pixel), unit=unit)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        getattr(topography, writer)(str(path))


def write_sdf(path, z_um, binary: bool, pixel_um=PIXEL_UM):
    """ISO 25178-71 SDF, by hand: metres, one profile (row) after another, as text or as binary
    (its header packed little endian; DataType 7: float64)."""
    ny, nx = z_um.shape
    if binary:
        header = struct.pack("<8s10s12s12sHHddddBBB", b"bISO-1.0", b"frictionlb", b"010120261200", b"010120261200", nx, ny,
                             pixel_um * 1e-6, pixel_um * 1e-6, 1e-6, -1.0, 0, 7, 0)  # fmt: skip
        path.write_bytes(header + z_um.astype("<f8").tobytes())
        return
    head = ["aISO-1.0", "ManufacID = frictionlab", f"NumPoints = {nx}", f"NumProfiles = {ny}", f"Xscale = {pixel_um * 1e-6!r}",
            f"Yscale = {pixel_um * 1e-6!r}", "Zscale = 1e-06", "Zresolution = -1", "Compression = 0", "DataType = 7",
            "CheckType = 0", "*"]  # fmt: skip
    path.write_text("\n".join(head + [" ".join(map(repr, row)) for row in z_um.tolist()] + ["*"]) + "\n")


WRITERS = {
    "x3p": lambda path, z: write_x3p(path, z),
    "nc": lambda path, z: write_topography(path, z, PIXEL_UM, "um", "to_netcdf"),
    "gwy": lambda path, z: write_topography(path, z * 1e3, PIXEL_UM * 1e3, "nm", "to_gwy"),
    "sdf": lambda path, z: write_sdf(path, z, binary=False),
    "binary.sdf": lambda path, z: write_sdf(path, z, binary=True),  # was refused as 'not text'
}


@pytest.mark.parametrize("suffix", sorted(WRITERS))
@pytest.mark.parametrize("unit, factor", [("um", 1.0), ("nm", 1e3), (None, None)])
def test_the_numbers_read_are_the_numbers_written_in_the_unit_asked(tmp_path, suffix, unit, factor):
    z = scan_um()
    path = tmp_path / f"scan.{suffix}"
    WRITERS[suffix](path, z)
    surface = SurfaceFile(path=str(path), unit=unit, detrend="none")
    made = surface.generate(None)
    summary = surface.input_summary()
    if unit is None:  # the file's own unit
        factor = {"x3p": 1e-6, "nc": 1.0, "gwy": 1e-6}.get(suffix, 1.0)  # X3P and Gwyddion store metres; SDF is read in um
        assert summary["unit_from"] == "file"
    else:
        assert summary["unit"] == unit and summary["unit_from"] == "preset"
    assert made.heights.shape == (ROWS, COLUMNS)
    np.testing.assert_allclose(made.heights, z * factor, rtol=1e-12, atol=1e-15 * factor)
    assert made.spacing == pytest.approx(PIXEL_UM * factor, rel=1e-12)
    assert summary["spacing_from"] == "file" and summary["shape"] == [ROWS, COLUMNS]
    assert summary["rms_height"] == pytest.approx(np.std(z) * factor, rel=1e-12)
    assert made.periodic is False and summary["periodic_from"] == "file"


def test_the_preset_may_override_the_pixel_size_and_says_so(tmp_path):
    write_x3p(tmp_path / "scan.x3p", scan_um())
    surface = SurfaceFile(path=str(tmp_path / "scan.x3p"), unit="um", spacing=0.5)
    assert surface.generate(None).spacing == 0.5
    summary = surface.input_summary()
    assert summary["spacing_from"] == "preset" and summary["file_spacing"] == pytest.approx(PIXEL_UM, rel=1e-12)
    assert SurfaceFile(path=str(tmp_path / "scan.x3p"), periodic=True).periodic() is True


def test_a_file_that_says_it_is_periodic_is_periodic_unless_the_preset_says_otherwise(tmp_path):
    from SurfaceTopography import Topography

    z = scan_um()
    topography = Topography(z.T.copy(), (COLUMNS * PIXEL_UM, ROWS * PIXEL_UM), unit="um", periodic=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        topography.to_netcdf(str(tmp_path / "tile.nc"))
    surface = SurfaceFile(path=str(tmp_path / "tile.nc"))
    assert surface.periodic() is True and surface.generate(None).periodic is True
    assert surface.input_summary()["periodic_from"] == "file"
    scene = build_scene(preset(tmp_path / "tile.nc", "um", solver="bem-halfspace"))  # the periodic solver takes it
    assert scene.spectrum.periodic() is True
    overridden = SurfaceFile(path=str(tmp_path / "tile.nc"), periodic=False)
    assert overridden.periodic() is False and overridden.input_summary()["periodic_from"] == "preset"
    with pytest.raises(PresetError, match="bem-halfspace presses periodic profiles only.*bem-halfspace-free"):
        build_scene(preset(tmp_path / "tile.nc", "um", solver="bem-halfspace", periodic=False))


def test_conformance_with_an_instrument_file(tmp_path):
    write_x3p(tmp_path / "scan.x3p", scan_um())
    check_plugin("spectrum", SurfaceFile, deterministic=True, path=str(tmp_path / "scan.x3p"), unit="nm")


def preset(path, unit, loads=(0.005, 0.2), solver="mdr", **params):  # f from 0.02 to 1 in um
    return {
        "name": "scan", "seed": 1, "realizations": 1, "fit": {"bootstrap": 0},
        "spectrum": {"name": "surface-file",
                     "params": {"path": str(path), **({"unit": unit} if unit else {}), **params}},
        "solver": {"name": solver}, "slope": {"name": "forward-difference"},
        "loading": {"start": loads[0], "stop": loads[1], "steps": 4, "spacing": "log"},
    }  # fmt: skip


def run(tmp_path, data, name):
    from frictionlab.api import run_scene
    from frictionlab.options import RunOptions

    return run_scene(build_scene(data), tmp_path / name, RunOptions(workers=1), plot=False)


@pytest.mark.parametrize("solver", ["mdr", "bem-halfspace-free"])
def test_f_and_xi_do_not_depend_on_the_unit(tmp_path, solver):
    """um to nm: every length x 1e3, so a force (E* h L, E* unchanged) x 1e6."""
    write_x3p(tmp_path / "scan.x3p", scan_um())
    loads = (0.005, 0.2)
    in_um = run(tmp_path, preset(tmp_path / "scan.x3p", "um", loads, solver), "um")
    in_nm = run(tmp_path, preset(tmp_path / "scan.x3p", "nm", tuple(1e6 * f for f in loads), solver), "nm")
    np.testing.assert_allclose(in_nm.table["f"], in_um.table["f"], rtol=1e-12)
    np.testing.assert_allclose(in_nm.table["xi"], in_um.table["xi"], rtol=1e-9)
    np.testing.assert_array_equal(in_nm.table["contact_count"], in_um.table["contact_count"])
    np.testing.assert_allclose(in_nm.table["indentation"], 1e3 * in_um.table["indentation"], rtol=1e-9)
    assert in_um.table["contact_count"][0] >= 3  # the loads press more than a point


@pytest.mark.parametrize("suffix", sorted(WRITERS))
@pytest.mark.parametrize("solver", ["mdr", "bem-halfspace-free"])
def test_a_scan_and_its_heights_as_npy_give_identical_results(tmp_path, suffix, solver):
    path = tmp_path / f"scan.{suffix}"
    WRITERS[suffix](path, scan_um())
    read = SurfaceFile(path=str(path), unit="um", detrend="none").generate(None)
    np.save(tmp_path / "scan.npy", read.heights)
    from_file = run(tmp_path, preset(path, "um", solver=solver), "file")
    # an instrument file is levelled by a plane unless told otherwise; the table, as told
    from_npy = run(tmp_path, preset(tmp_path / "scan.npy", "um", solver=solver, spacing=read.spacing, detrend="plane"),
                   "npy")  # fmt: skip
    for column in ("f", "xi", "contact_count", "indentation"):
        np.testing.assert_array_equal(from_file.table[column], from_npy.table[column])
    assert from_file.fit.a == from_npy.fit.a and from_file.fit.b == from_npy.fit.b
    summary = json.loads((tmp_path / "file" / "summary.json").read_text())
    assert summary["input"]["unit"] == "um" and summary["input"]["spacing_from"] == "file"
    assert summary["input"]["shape"] == [ROWS, COLUMNS]


def test_a_line_scan_reads_as_a_profile(tmp_path):
    from SurfaceTopography import UniformLineScan

    z = scan_um()[0]
    line = UniformLineScan(z, z.size * PIXEL_UM, unit="um")
    line.to_netcdf(str(tmp_path / "line.nc"))
    profile = ProfileFile(path=str(tmp_path / "line.nc"), unit="nm", detrend="none")
    made = profile.generate(None)
    np.testing.assert_allclose(made.heights, 1e3 * z, rtol=1e-12)
    assert made.spacing == pytest.approx(1e3 * PIXEL_UM, rel=1e-12)
    assert profile.input_summary()["shape"] == [z.size]
    with pytest.raises(ValueError, match="holds a 2D map; use surface-file"):
        write_x3p(tmp_path / "map.x3p", scan_um())
        ProfileFile(path=str(tmp_path / "map.x3p")).generate(None)



def test_a_periodic_map_is_levelled_by_its_mean_and_refused_where_it_would_stop_tiling(tmp_path):
    """A plane taken off a map that tiles the plane leaves a step where it repeats: a periodic
    file is levelled by its mean unless the preset asks otherwise. A crop or a resampling
    would leave it no longer tiling: refused, naming what."""
    from SurfaceTopography import Topography

    z = scan_um()
    topography = Topography(z.T.copy(), (COLUMNS * PIXEL_UM, ROWS * PIXEL_UM), unit="um", periodic=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        topography.to_netcdf(str(tmp_path / "tile.nc"))
    tile = SurfaceFile(path=str(tmp_path / "tile.nc"), unit="um")
    assert tile.input_summary()["detrend"] == "mean" and tile.input_summary()["detrend_from"] == "default"
    np.testing.assert_allclose(tile.generate(None).heights, z - z.mean(), rtol=0, atol=1e-12 * np.abs(z).max())
    assert SurfaceFile(path=str(tmp_path / "tile.nc"), unit="um", periodic=False).input_summary()["detrend"] == "plane"
    with pytest.raises(ValueError, match="detrend: 'plane' on a periodic map .* leaves a step where the map repeats"):
        SurfaceFile(path=str(tmp_path / "tile.nc"), unit="um", detrend="plane").input_summary()
    for changed, said in (({"region": {"x": [0, 16]}}, "once cropped to region"),
                          ({"downsample": {"factor": 2}}, "once downsampled")):  # fmt: skip
        with pytest.raises(ValueError, match=f"a periodic map .* no longer tiles the plane {said}; set periodic: false"):
            SurfaceFile(path=str(tmp_path / "tile.nc"), unit="um", **changed).generate(None)
        SurfaceFile(path=str(tmp_path / "tile.nc"), unit="um", periodic=False, **changed).generate(None)  # read
    rectangular = Topography(z.T.copy(), (COLUMNS * PIXEL_UM, 2 * ROWS * PIXEL_UM), unit="um", periodic=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rectangular.to_netcdf(str(tmp_path / "rect.nc"))
    with pytest.raises(ValueError, match=r"no longer tiles the plane once resampled from pixels of \S+ x \S+ onto square"):
        SurfaceFile(path=str(tmp_path / "rect.nc"), unit="um").generate(None)


def test_a_periodic_line_is_levelled_by_its_mean(tmp_path):
    from SurfaceTopography import UniformLineScan

    z = scan_um()[0] + 0.3 * np.arange(COLUMNS)
    UniformLineScan(z, z.size * PIXEL_UM, unit="um", periodic=True).to_netcdf(str(tmp_path / "ring.nc"))
    ring = ProfileFile(path=str(tmp_path / "ring.nc"), unit="um")
    assert ring.input_summary()["detrend"] == "mean"
    np.testing.assert_allclose(ring.generate(None).heights, z - z.mean(), rtol=0, atol=1e-12 * np.abs(z).max())
    assert ProfileFile(path=str(tmp_path / "ring.nc"), unit="um", periodic=False).input_summary()["detrend"] == "tilt"

@pytest.mark.parametrize("kind", ["map", "line"])
def test_a_periodic_sine_has_no_tilt_said_and_a_tilt_taken_off_it_is_refused(tmp_path, kind):
    """A map (line) that repeats has no tilt: the least-squares plane of sin(2 pi x / L) carries
    half its variance, which was said as 'a tilt carries 56.1 % ... detrend: plane levels it'; the
    plane taken off, as advised, left a step of 2.6 rms heights where it repeats, and the rms
    slope over the map went from 0.55 to 1.05 without a word."""
    n = 64
    x = np.arange(n) / n
    z = np.sin(2 * np.pi * x)[None, :] + 0.3 * np.cos(6 * np.pi * x + 1)[:, None] if kind == "map" else np.sin(2 * np.pi * x)
    np.save(tmp_path / "tile.npy", z)
    reader = SurfaceFile if kind == "map" else ProfileFile
    keys = {"path": str(tmp_path / "tile.npy"), "spacing": 1.0}
    tile = reader(**keys, periodic=True)
    assert tile.input_summary()["detrend"] == "mean"
    assert not any("tilt" in caveat or "curvature" in caveat for caveat in tile.input_summary().get("caveats", ()))
    said = reader(**keys, periodic=False).input_summary()["caveats"]  # not periodic: a form the run should know of
    assert any(caveat.startswith("a tilt carries") for caveat in said)
    form = "plane" if kind == "map" else "tilt"
    for detrend in (form, "quadratic"):
        with pytest.raises(ValueError, match=rf"detrend: '{detrend}' on a periodic {kind} \(periodic: true, or as the "
                                             rf"file says\) takes off a {form} .* give detrend: mean or none, or set periodic: false"):
            reader(**keys, periodic=True, detrend=detrend).generate(None)
    reader(**keys, periodic=True, detrend="none").generate(None)  # read


def test_a_form_kept_in_a_map_is_said_with_the_tilt_s_and_the_curvature_s_own_shares():
    """'a tilt carries 54.9 %' was the tilt's and the curvature's shares together (the tilt's own: 47.5 %)."""
    from frictionlab_spectra.scan_shaping.levelling import _form_kept

    said = _form_kept(0.475, 0.074, "map", "mean", "plane")
    assert said.startswith("a tilt carries 47.5 % and a curvature 7.4 % more of the map's height variance (detrend: mean)")
    assert _form_kept(0.95, 0.0, "line", "none", "tilt").startswith("a tilt carries 95.0 % of the line's")


def test_undefined_points_are_refused_or_filled_and_recorded(tmp_path):
    z = scan_um()
    holes = z.copy()
    holes[5, 7] = holes[10, 20] = np.nan  # x3pio writes NaN as a point not measured
    write_x3p(tmp_path / "holes.x3p", holes)
    with pytest.raises(ValueError, match="2 of 768 points are undefined .* undefined: harmonic"):
        SurfaceFile(path=str(tmp_path / "holes.x3p")).rms_height()
    surface = SurfaceFile(path=str(tmp_path / "holes.x3p"), unit="um", undefined="harmonic", detrend="none")
    filled = surface.generate(None).heights
    defined = ~np.isnan(holes)
    np.testing.assert_allclose(filled[defined], z[defined], rtol=1e-12, atol=1e-15)
    for row, column in ((5, 7), (10, 20)):  # harmonic: the mean of its four neighbours
        around = filled[row - 1, column] + filled[row + 1, column] + filled[row, column - 1] + filled[row, column + 1]
        assert filled[row, column] == pytest.approx(around / 4, rel=1e-6)
    summary = surface.input_summary()
    assert summary["undefined_points"] == 2 and summary["filled_by"] == "harmonic"



def test_a_large_filled_share_is_a_caveat_beside_the_levelling_one(tmp_path, capsys):
    """Filled points have the interpolation's smooth slopes: from 5 % of the file on, said so;
    the two filled points above (0.26 %) say nothing."""
    holes = scan_um() + 0.5 * np.arange(COLUMNS)  # a tilt, left in by detrend: mean
    holes[2:8, 3:10] = np.nan  # 42 of 768 points: 5.47 %
    write_x3p(tmp_path / "holes.x3p", holes)
    surface = SurfaceFile(path=str(tmp_path / "holes.x3p"), unit="um", undefined="harmonic", detrend="mean")
    caveats = surface.input_summary()["caveats"]
    assert len(caveats) == 2 and "5.47 % of the file's points were undefined and filled" in caveats[0]
    assert "crop the map to its measured part (region)" in caveats[0]
    assert "a tilt carries" in caveats[1]
    levelled = SurfaceFile(path=str(tmp_path / "holes.x3p"), unit="um", undefined="harmonic")
    assert [caveat[:4] for caveat in levelled.input_summary()["caveats"]] == ["5.47"]
    holes[2:8, 3:10] = scan_um()[2:8, 3:10]
    holes[2, 3] = holes[7, 9] = np.nan
    write_x3p(tmp_path / "two.x3p", holes)
    assert "caveats" not in SurfaceFile(path=str(tmp_path / "two.x3p"), unit="um", undefined="harmonic").input_summary()


def test_a_line_with_a_large_filled_share_says_so_beside_its_own_caveats(tmp_path):
    from SurfaceTopography import UniformLineScan

    z = np.cumsum(np.random.default_rng(0).standard_normal(200))
    z[50:65] = np.nan  # 7.5 %
    UniformLineScan(z, z.size * PIXEL_UM, unit="um").to_netcdf(str(tmp_path / "line.nc"))
    caveats = ProfileFile(path=str(tmp_path / "line.nc"), unit="um", undefined="harmonic").input_summary()["caveats"]
    assert caveats[0].startswith("7.5 % of the file's points were undefined and filled")
    assert "crop the line to its measured part (region)" in caveats[0]
    assert any("a curvature carries" in caveat for caveat in caveats[1:])  # the line's own caveat kept beside it


def test_a_line_scans_undefined_points_outside_its_region_are_left_out_inside_refused_or_filled(tmp_path):
    from SurfaceTopography import UniformLineScan

    z = np.cumsum(np.random.default_rng(0).standard_normal(200))
    z[[3, 150]] = np.nan
    UniformLineScan(z, z.size * PIXEL_UM, unit="um").to_netcdf(str(tmp_path / "line.nc"))
    kept = ProfileFile(path=str(tmp_path / "line.nc"), unit="um", detrend="mean", region={"x": [10, 140]})
    np.testing.assert_allclose(kept.generate(None).heights, z[10:140] - z[10:140].mean(), rtol=0, atol=1e-9)
    summary = kept.input_summary()
    assert (summary["undefined_points"], summary["undefined_outside_region"], summary["filled_by"]) == (0, 2, None)
    with pytest.raises(ValueError, match=r"1 of 190 points of the region are undefined in the file"):
        ProfileFile(path=str(tmp_path / "line.nc"), unit="um", region={"x": [10, 200]}).generate(None)
    filled = ProfileFile(path=str(tmp_path / "line.nc"), unit="um", region={"x": [10, 200]}, undefined="harmonic")
    assert np.isfinite(filled.generate(None).heights).all() and filled.input_summary()["undefined_points"] == 1

@pytest.mark.parametrize("pixel, writer, unit, said", [
    (1e99, "to_gwy", "pm", "pixels of 1e+102 pm"),  # 1e90 m in the file: in range, beyond it once converted
    (np.inf, "to_netcdf", None, "pixels of inf nm"),
])
def test_a_pixel_size_beyond_a_presets_range_is_refused_before_the_run(tmp_path, capsys, pixel, writer, unit, said):
    """Not a realization failing (exit 70): the file is refused as a preset's spacing would be."""
    write_topography(tmp_path / "far.scan", scan_um(), pixel, "nm", writer)
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset(tmp_path / "far.scan", unit, solver="winkler")))
    assert main(["run", str(tmp_path / "p.yaml"), "--out", str(tmp_path / "out"), "--no-plot"]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert said in err and "between 1e-100 and 1e+100" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("pixel, said", [(-PIXEL_UM, "must be > 0"), (np.nan, "must be > 0")])
def test_a_pixel_size_not_positive_is_named(tmp_path, pixel, said):
    write_topography(tmp_path / "neg.nc", scan_um(), pixel, "um", "to_netcdf")
    with pytest.raises(ValueError, match=f"pixels of .*; a pixel's size {said}"):
        SurfaceFile(path=str(tmp_path / "neg.nc")).rms_height()


def test_a_scan_with_no_defined_point_is_refused_even_when_filling(tmp_path):
    """Harmonic filling has nothing to fill from: the file is refused as empty, not read as flat."""
    write_x3p(tmp_path / "empty.x3p", np.full((ROWS, COLUMNS), np.nan))
    for undefined in ("refuse", "harmonic"):
        with pytest.raises(ValueError, match="all 768 points are undefined in the file"):
            SurfaceFile(path=str(tmp_path / "empty.x3p"), undefined=undefined).rms_height()


def test_validate_says_when_an_instrument_file_states_no_unit(tmp_path, capsys):
    """The preset's unit is then an assumption about the file, not a conversion: said so."""
    write_topography(tmp_path / "bare.nc", scan_um(), PIXEL_UM, None, "to_netcdf")
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset(tmp_path / "bare.nc", "um", detrend="mean")))
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.OK
    assert "rms height 0.05 um, the file states no unit: its numbers taken as um" in capsys.readouterr().out


def test_validate_shows_what_was_read(tmp_path, capsys):
    write_x3p(tmp_path / "scan.x3p", scan_um())
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset(tmp_path / "scan.x3p", "nm", detrend="mean")))
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.OK
    out = capsys.readouterr().out
    assert "32 x 24 pixels (x by y) of 125 nm (from the file)" in out and "converted from the file's m" in out
    assert "rms height 50 nm" in out


def test_without_the_extra_the_message_names_it_and_exits_2(tmp_path, capsys, monkeypatch):
    write_x3p(tmp_path / "scan.x3p", scan_um())
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset(tmp_path / "scan.x3p", "um")))
    monkeypatch.setitem(sys.modules, "SurfaceTopography", None)  # import SurfaceTopography: ImportError
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert 'pip install "frictionlab[topography]"' in err and "Traceback" not in err
    with pytest.raises(PresetError, match="optional extra topography"):
        build_scene(preset(tmp_path / "scan.x3p", "um"))


def test_a_table_still_needs_its_spacing(tmp_path):
    np.save(tmp_path / "scan.npy", scan_um())
    with pytest.raises(PresetError, match="spacing .* is required"):
        build_scene(preset(tmp_path / "scan.npy", "um"))


def test_a_table_does_not_import_the_extra(tmp_path):
    import subprocess

    np.save(tmp_path / "scan.npy", scan_um())
    code = (
        "import sys, frictionlab_spectra as s; "
        f"s.SurfaceFile(path={str(tmp_path / 'scan.npy')!r}, spacing=1.0).rms_height(); "
        "print('SurfaceTopography' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_the_api_shows_what_was_read_before_and_after_the_run(tmp_path):
    import frictionlab

    write_x3p(tmp_path / "scan.x3p", scan_um())
    checked = frictionlab.validate(preset(tmp_path / "scan.x3p", "nm", detrend="mean"))
    assert checked["input"]["shape"] == [ROWS, COLUMNS] and checked["input"]["unit"] == "nm"
    assert checked["input"]["spacing"] == pytest.approx(1e3 * PIXEL_UM, rel=1e-12)
    assert checked["input"]["rms_height"] == pytest.approx(50.0, rel=1e-12)  # scan_um's 0.05 um
    result = frictionlab.run(preset(tmp_path / "scan.x3p", "um"), out=tmp_path / "run", workers=1, progress=False,
                             plot=False)  # fmt: skip
    assert result.input["unit"] == "um" and frictionlab.load(tmp_path / "run").input == result.input
    with pytest.raises(PresetError, match="spectrum.params.unit"):
        frictionlab.validate(preset(tmp_path / "scan.x3p", "inch"))


def test_the_memory_estimate_counts_the_file_and_the_padded_solver(tmp_path, monkeypatch):
    """The map's points from the file (grid_shape), times the free solver's bytes per point
    (its padded grids), plus the profile and slopes; a run that does not fit is refused
    before it starts."""
    from frictionlab.compute import memory
    from frictionlab.errors import RunError
    from frictionlab_solvers import BEMHalfSpace, BEMHalfSpaceFree

    write_x3p(tmp_path / "scan.x3p", scan_um())
    scene = build_scene(preset(tmp_path / "scan.x3p", "um", solver="bem-halfspace-free"))
    assert memory.grid_points(scene) == ROWS * COLUMNS and scene.spectrum.grid_shape() == (ROWS, COLUMNS)
    per_point = memory.bytes_per_point(scene)
    assert per_point == BEMHalfSpaceFree.bytes_per_point + memory.PROFILE_BYTES_PER_POINT
    assert BEMHalfSpaceFree.bytes_per_point > BEMHalfSpace.bytes_per_point  # the padding counts
    one = memory.estimate(scene, workers=1, executor="serial")
    monkeypatch.setattr(memory, "available_memory", lambda: (one.total - 1, "a test"))
    with pytest.raises(RunError, match="scan|memory"):
        memory.check_fits(scene, workers=1, executor="serial")


def test_validate_says_a_table_has_no_unit_unless_the_preset_gives_one(tmp_path, capsys):
    np.save(tmp_path / "scan.npy", scan_um())
    for unit, expected in ((None, "of 0.125 (from the preset), rms height 0.05, no unit (bare numbers)"),
                           ("um", "of 0.125 um (from the preset), rms height 0.05 um, not periodic")):  # fmt: skip
        (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset(tmp_path / "scan.npy", unit, spacing=PIXEL_UM)))
        assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.OK
        assert f"read scan.npy (.npy): 32 x 24 pixels (x by y) {expected}" in capsys.readouterr().out


@pytest.mark.parametrize("declared", ["NumProfiles = 20", "NumPoints = 31"])
def test_an_sdf_whose_data_holds_more_numbers_than_its_header_declares_is_named_damaged(tmp_path, capsys, declared):
    """SurfaceTopography's SDF reader reads lines until it has NumPoints x NumProfiles numbers:
    a header declaring 20 profiles of a map of 24 was read as a map of 20 rows, the last 4
    dropped without a word (a header of 31 points a profile, as the reader's own damage)."""
    write_sdf(tmp_path / "scan.sdf", scan_um(), binary=False)
    key = declared.split()[0]
    text = (tmp_path / "scan.sdf").read_text().splitlines()
    (tmp_path / "forged.sdf").write_text("\n".join(declared if line.startswith(key) else line for line in text) + "\n")
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset(tmp_path / "forged.sdf", "um")))
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.USAGE
    err = capsys.readouterr().err
    points = 20 * COLUMNS if key == "NumProfiles" else 31 * ROWS
    assert f"its data holds {ROWS * COLUMNS} numbers, {ROWS * COLUMNS - points} more" in err and "Traceback" not in err, err


@pytest.mark.parametrize("name", ["empty.npz", "empty.x3p"])
def test_an_empty_archive_is_said_to_hold_no_file_not_to_be_damaged(tmp_path, name):
    with zipfile.ZipFile(tmp_path / name, "w"):  # as np.savez() with no array writes it
        pass
    with pytest.raises(ValueError, match="an empty ZIP archive: it holds no file") as refused:
        SurfaceFile(path=str(tmp_path / name)).rms_height()
    assert "damaged" not in str(refused.value)


def test_an_sdf_with_a_byte_order_mark_is_named_as_such_not_as_another_format(tmp_path):
    """A text SDF saved by an editor with a byte-order mark before its magic 'aISO-1.0' was told
    'its first bytes are not that format's: a damaged file, or another format under that suffix'."""
    write_sdf(tmp_path / "plain.sdf", scan_um(), binary=False)
    (tmp_path / "marked.sdf").write_bytes(b"\xef\xbb\xbf" + (tmp_path / "plain.sdf").read_bytes())
    with pytest.raises(ValueError, match="starts with a UTF-8 byte-order mark .* save it without one") as refused:
        SurfaceFile(path=str(tmp_path / "marked.sdf")).rms_height()
    assert "damaged" not in str(refused.value) and "another format" not in str(refused.value)


def test_a_damaged_file_whose_reader_logs_its_bytes_is_said_in_one_problem_only(tmp_path, caplog):
    """igor2 logs 'could not reshape data from (N,) to b'...'' (the file's bytes, 5 kB a line)
    before it raises; with no logging set up, Python printed that twice on stderr."""
    import io
    import logging

    from igor2 import binarywave

    damaged = b"\x05\x00" + np.random.default_rng(3).bytes(2000)  # a version 5 wave's first bytes, then noise
    with caplog.at_level(logging.ERROR, logger="igor2"), pytest.raises(Exception):
        binarywave.load(io.BytesIO(damaged))
    assert any("could not reshape" in record.getMessage() for record in caplog.records)  # the reader does log
    (tmp_path / "wave.ibw").write_bytes(damaged)
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset(tmp_path / "wave.ibw", "um")))
    import subprocess  # a process of its own: pytest's log capture would hide logging's last resort

    done = subprocess.run([sys.executable, "-m", "frictionlab", "validate", str(tmp_path / "p.yaml")],
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    assert done.returncode == ExitCode.USAGE
    err = done.stderr + done.stdout
    assert "could not reshape" not in err and "\\x" not in err
    assert "a damaged Igor binary wave file" in err and len(err.splitlines()) <= 3
