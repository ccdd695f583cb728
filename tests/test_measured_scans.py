"""Scans as instruments leave them, each read as it is and told what in it can mislead."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from frictionlab_spectra import ProfileFile, SurfaceFile

from .test_scan_shaping import band_limited


@pytest.mark.parametrize("side", ["highest", "lowest"])
def test_a_scan_clipped_at_its_instruments_range_is_said(tmp_path, side):
    """An AFM out of its z range writes its limit: 20 % of a map at one height, its peaks cut flat
    where the contact starts, too few neighbours alike for the steps' caveat: read without a word."""
    z, _ = band_limited(64, 64, seed=3, top=0.3)
    limit = np.quantile(z, 0.8 if side == "highest" else 0.2)
    clipped = np.minimum(z, limit) if side == "highest" else np.maximum(z, limit)
    np.save(tmp_path / "clipped.npy", clipped)
    np.save(tmp_path / "whole.npy", z)
    caveats = SurfaceFile(path=str(tmp_path / "clipped.npy"), spacing=1.0).input_summary()["caveats"]
    assert any(f"% of the map's points sit at exactly its {side} height" in c and "part out (region)" in c
               for c in caveats), caveats  # fmt: skip
    assert "caveats" not in SurfaceFile(path=str(tmp_path / "whole.npy"), spacing=1.0).input_summary()
    np.savetxt(tmp_path / "line.csv", clipped[:8].ravel())
    line = ProfileFile(path=str(tmp_path / "line.csv"), spacing=1.0).input_summary()
    assert any(f"of the line's points sit at exactly its {side} height" in c and "part out (of the profile)" in c
               for c in line["caveats"]), line  # a line has no region  # fmt: skip


def test_a_short_lines_few_equal_tops_are_not_called_clipped(tmp_path):
    line = np.round(np.random.default_rng(4).normal(size=64), 1)  # one or two points at the top: rounding
    np.savetxt(tmp_path / "line.csv", line)
    said = ProfileFile(path=str(tmp_path / "line.csv"), spacing=0.1).input_summary().get("caveats", ())
    assert not any("clipped (" in c for c in said), said


def test_a_table_exported_with_its_axes_is_said_to_hold_positions(tmp_path):
    """A matrix with x positions over its columns and y beside its rows (or a spreadsheet's row
    numbers) was read whole as heights: a ramp along two edges, the rms height and the spikes theirs."""
    z, _ = band_limited(32, 32, seed=6, top=0.3)
    x = np.round(np.arange(32) * 0.0390625, 6)  # as an export prints them: 6 digits
    with_axes = np.block([[np.zeros((1, 1)), x[None, :]], [x[:, None], z]])
    np.savetxt(tmp_path / "axes.csv", with_axes, delimiter=",", fmt="%.6g")
    np.savetxt(tmp_path / "numbered.csv", np.c_[np.arange(32), z], delimiter=",")
    np.savetxt(tmp_path / "plain.csv", z, delimiter=",")
    said = SurfaceFile(path=str(tmp_path / "axes.csv"), spacing=1.0).input_summary()["caveats"][0]
    assert "the table's first row (0 to 1.21094) and first column (0 to 1.21094) are evenly spaced" in said, said
    assert "region: {x: [1, 33], y: [1, 33]}" in said
    said = SurfaceFile(path=str(tmp_path / "numbered.csv"), spacing=1.0).input_summary()["caveats"][0]
    assert "the table's first column (0 to 31) is evenly spaced" in said and "region: {x: [1, 33]}" in said, said
    assert "caveats" not in SurfaceFile(path=str(tmp_path / "plain.csv"), spacing=1.0).input_summary()
    cropped = SurfaceFile(path=str(tmp_path / "axes.csv"), spacing=1.0, region={"x": [1, 33], "y": [1, 33]})
    assert "caveats" not in cropped.input_summary()


@pytest.mark.parametrize("region, kept", [({"y": [0, 1]}, "64 x 1"), ({"x": [0.04, 0.06], "units": "length"}, "1 x 64")])
def test_a_region_one_pixel_wide_is_refused_without_numpys_warnings(tmp_path, region, kept):
    """Its levelling divided by zero first: 'warning: invalid value encountered in scalar divide' and
    'Mean of empty slice' were printed above the refusal."""
    np.save(tmp_path / "map.npy", band_limited(64, 64, seed=2, top=0.3)[0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=f"region keeps {kept} pixels \\(x by y\\) of the map, one pixel wide: a line"):
            SurfaceFile(path=str(tmp_path / "map.npy"), spacing=0.1, region=region).rms_height()


def test_pixels_many_times_longer_one_way_say_the_map_pressed_is_mostly_interpolated(tmp_path):
    """Rows 5 times apart the columns': 60 of the 76 rows pressed are the cosine series between the
    16 measured, smooth along y, and that was said only as '64 x 16 -> 64 x 76 pixels'."""
    np.save(tmp_path / "rows.npy", np.random.default_rng(8).normal(size=(16, 64)))
    said = SurfaceFile(path=str(tmp_path / "rows.npy"), spacing=0.1, spacing_y=0.5).input_summary()["caveats"]
    assert any("the file's pixels are 5 times longer along y: 16 of the 76 rows pressed were measured" in c
               and "shorter than two measured rows (1)" in c for c in said), said  # fmt: skip
    said = SurfaceFile(path=str(tmp_path / "rows.npy"), spacing=0.1, spacing_y=0.25).input_summary().get("caveats", ())
    assert not any("times longer" in c for c in said), said


def test_a_map_of_two_lines_is_not_sent_from_one_plugin_to_the_other(tmp_path):
    """profile-file said 'the file holds a 2D map; use surface-file', and surface-file 'at least 8 x 8
    are needed': each sent the user to the other."""
    from SurfaceTopography import Topography

    Topography(np.random.default_rng(5).normal(size=(256, 2)), (25.6, 0.2), unit="µm").to_x3p(str(tmp_path / "two.x3p"))
    with pytest.raises(ValueError, match=r"a 2D map of 256 x 2 pixels \(x by y\): too narrow for surface-file \(at least "
                       r"8 x 8\), and profile-file reads a line \(a map one pixel wide\); export one of its lines"):  # fmt: skip
        ProfileFile(path=str(tmp_path / "two.x3p"), unit="um").rms_height()
    with pytest.raises(ValueError, match=r"map of 256 x 2 pixels \(x by y\); at least 8 x 8 are needed"):
        SurfaceFile(path=str(tmp_path / "two.x3p"), unit="um").rms_height()
    Topography(np.random.default_rng(5).normal(size=(16, 16)), (1.6, 1.6), unit="µm").to_x3p(str(tmp_path / "map.x3p"))
    with pytest.raises(ValueError, match="the file holds a 2D map; use surface-file"):
        ProfileFile(path=str(tmp_path / "map.x3p"), unit="um").rms_height()


def test_a_text_export_cut_short_is_refused_not_stretched(tmp_path):
    """Gwyddion's text export cut two thirds of the way (a copy stopped): its reader dropped the cut
    row, the 42 rows left were stretched over the 6.4 um its header states, pixels of 0.1 x 0.152 um
    resampled onto 63 rows, and the map read without a word."""
    from .test_table_header_units import gwyddion_text

    whole = gwyddion_text(tmp_path / "scan.txt", band_limited(64, 64, seed=4, top=0.3)[0], 0.1).read_text(encoding="utf-8")
    assert SurfaceFile(path=str(tmp_path / "scan.txt"), format="instrument", unit="um").grid_shape() == (64, 64)
    (tmp_path / "cut.txt").write_text(whole[: 2 * len(whole) // 3], encoding="utf-8")
    with pytest.raises(ValueError, match=r"its last line holds \d+ numbers and the line before it 64: a .* file cut short"):
        SurfaceFile(path=str(tmp_path / "cut.txt"), format="instrument", unit="um").rms_height()


def test_a_map_of_white_noise_is_said_to_be_noise(tmp_path):
    """An int16 map saved with its bytes swapped (a raw binary read in the wrong byte order) is white
    noise, rms 19000 for 1000: it was pressed without a word. A surface's neighbours are correlated."""
    z, _ = band_limited(64, 64, seed=7, top=0.3)
    heights = np.round(1000 * z / z.std()).astype("<i2")
    np.save(tmp_path / "swapped.npy", heights.byteswap().view("<i2"))
    np.save(tmp_path / "right.npy", heights)
    said = SurfaceFile(path=str(tmp_path / "swapped.npy"), spacing=1000.0).input_summary()["caveats"]
    assert any(c.startswith("the signs of the map's neighbouring heights are uncorrelated (") and "wrong order" in c
               for c in said), said  # fmt: skip
    assert "caveats" not in SurfaceFile(path=str(tmp_path / "right.npy"), spacing=1000.0).input_summary()
    dropouts = z.copy()
    dropouts[[5, 20, 33, 47, 60], [7, 50, 21, 40, 3]] = -9999.0  # their power is most of the map's: not noise
    np.save(tmp_path / "dropouts.npy", dropouts)
    said = SurfaceFile(path=str(tmp_path / "dropouts.npy"), spacing=1000.0).input_summary()["caveats"]
    assert len(said) == 2 and not any("uncorrelated" in c for c in said), said  # the dropouts' caveats


@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_heights_that_are_no_numbers_in_double_precision_are_refused_without_numpys_warnings(tmp_path, plugin):
    """A float32 map with its bytes swapped holds signalling NaNs, and a float128 one heights past
    double precision: numpy's 'invalid value encountered in cast' (and, in the check of the table's
    first row, 'in scalar subtract') was printed above the refusal that names them."""
    shape = (16, 16) if plugin is SurfaceFile else (64,)
    signalling = np.random.default_rng(1).normal(size=shape).astype(np.float32)
    signalling.reshape(-1)[5] = np.array([0x7F800001], dtype=np.uint32).view(np.float32)[0]
    np.save(tmp_path / "snan.npy", signalling)
    np.save(tmp_path / "huge.npy", np.random.default_rng(2).normal(size=shape).astype(np.longdouble) * np.longdouble("1e400"))
    for name in ("snan.npy", "huge.npy"):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with pytest.raises(ValueError, match=r"value\(s\) in heights not finite"):
                plugin(path=str(tmp_path / name), spacing=0.1).rms_height()


def _units_caveat(caveats) -> str | None:
    said = [c for c in caveats if "rms slope is" in c and "different units" in c]
    assert len(said) <= 1, said
    return said[0] if said else None


def _said_slope(caveat: str) -> float:
    return float(caveat.split("rms slope is ", 1)[1].split(",", 1)[0])


@pytest.mark.parametrize("factor, side", [(1e-6, "below"), (1e3, "above")])
def test_heights_in_another_unit_than_the_pixels_are_said_with_the_slope_they_make(tmp_path, factor, side):
    """A map in um saved in m (or in nm) beside pixels in um, and a line alike: its rms slope is
    the surface's times 1e-6 (1e3), which no measured surface has; xi against f does not see it,
    but F and p/E* are off by that ratio, and it was pressed without a word. The slope said is
    the forward differences' of the map in its own units, times the factor."""
    z, _ = band_limited(64, 64, seed=11, top=0.3)
    z *= 0.05 / z.std()  # rms height 0.05 um on pixels of 0.5 um
    slope = np.sqrt(np.mean((np.diff(z, axis=1) / 0.5) ** 2) + np.mean((np.diff(z, axis=0) / 0.5) ** 2))
    assert 1e-3 < slope < 1  # a surface's: no caveat in the right unit
    np.savetxt(tmp_path / "um.csv", z, delimiter=",")
    np.savetxt(tmp_path / "mixed.csv", z * factor, delimiter=",")
    assert _units_caveat(SurfaceFile(path=str(tmp_path / "um.csv"), spacing=0.5, unit="um").input_summary().get(
        "caveats", ())) is None  # fmt: skip
    said = _units_caveat(SurfaceFile(path=str(tmp_path / "mixed.csv"), spacing=0.5, unit="um").input_summary()["caveats"])
    assert said is not None and f"{side} any measured surface's" in said, said
    assert "heights in um (the preset's unit)" in said and "pixels 0.5 um apart (the preset's spacing)" in said, said
    assert _said_slope(said) == pytest.approx(factor * slope, rel=2e-3)  # printed to 3 digits
    line = z[:8].ravel()  # consecutive rows: one profile, its jumps between rows a surface's too
    line_slope = np.sqrt(np.mean((np.diff(line) / 0.5) ** 2))
    np.save(tmp_path / "line.npy", line * factor)
    said = _units_caveat(ProfileFile(path=str(tmp_path / "line.npy"), spacing=0.5, unit="um", detrend="none")
                         .input_summary()["caveats"])  # fmt: skip
    assert said is not None and said.startswith("the line's rms slope is") and "points 0.5 um apart" in said, said
    assert _said_slope(said) == pytest.approx(factor * line_slope, rel=2e-3)


def test_the_tui_says_what_validate_says_of_the_file_read(tmp_path, capsys):
    """The TUI's edit panel showed the line on what was read, but not the caveats of the file
    (heights in another unit than the pixels, a tilt, spikes) that validate prints under it."""
    import yaml

    from frictionlab.cli import main
    from frictionlab.registry import default_registry
    from frictionlab.tui.fields import validation_of

    z, _ = band_limited(64, 64, seed=11, top=0.3)
    np.save(tmp_path / "mixed.npy", z * 0.05 / z.std() * 1e-6)  # um written in m, pixels in um
    preset = {"name": "mixed", "realizations": 1, "solver": {"name": "mdr"},
              "spectrum": {"name": "surface-file", "params": {"path": str(tmp_path / "mixed.npy"), "spacing": 0.5,
                                                              "unit": "um"}},
              "loading": {"start": 1e-4, "stop": 1e-3, "steps": 3}}  # fmt: skip
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset))
    assert main(["validate", str(tmp_path / "p.yaml")]) == 0
    printed = [line.strip() for line in capsys.readouterr().out.splitlines() if "caveat: the map's rms slope" in line]
    problems, shown = validation_of(preset, default_registry())
    assert problems == [] and len(printed) == 1, printed
    assert printed[0] in shown.splitlines(), shown


def test_a_square_spacing_over_a_file_of_oblong_pixels_is_said(tmp_path):
    """spacing alone replaced a Gwyddion scan's 0.1 x 0.2 um pixels by squares of 0.1 without a
    word: the map squashed to half its length along y, its slopes along y doubled."""
    from .test_scan_edge_cases import rough, write_gwy

    z = rough(32, 48, 5) * 1e-8
    write_gwy(tmp_path / "oblong.gwy", z, 1e-7, 2e-7)
    caveats = SurfaceFile(path=str(tmp_path / "oblong.gwy"), unit="um", spacing=0.1).input_summary()["caveats"]
    assert any("replaces the file's pixel of 0.1 x 0.2 um (x by y), which is not square" in c and "spacing_y too (0.2 "
               in c for c in caveats)  # fmt: skip
    for kept in ({}, {"spacing": 0.1, "spacing_y": 0.2}):  # the file's pixel, or both sides given: nothing to say
        summary = SurfaceFile(path=str(tmp_path / "oblong.gwy"), unit="um", **kept).input_summary()
        assert not any("not square" in c for c in summary.get("caveats", ()))
    write_gwy(tmp_path / "square.gwy", z, 1e-7, 1e-7)
    summary = SurfaceFile(path=str(tmp_path / "square.gwy"), unit="um", spacing=0.05).input_summary()
    assert not any("not square" in c for c in summary.get("caveats", ()))


def test_a_map_given_to_profile_file_and_a_line_to_surface_file_are_sent_to_the_other(tmp_path):
    """A map given to profile-file was 'array of shape (64, 96); expected (N,), (N, 2) or (2, N)'
    (or '96 columns'), and an x, z line saved as .npy given to surface-file 'a map of 2 x 500
    pixels': neither said which plugin reads the file (a .csv line did)."""
    rng = np.random.default_rng(4)
    np.save(tmp_path / "map.npy", rng.normal(size=(16, 24)))
    np.savetxt(tmp_path / "map.csv", rng.normal(size=(16, 24)), delimiter=",")
    for name in ("map.npy", "map.csv"):
        with pytest.raises(ValueError, match=r"expected .*; a height map \(rows of heights.*\) is read by surface-file"):
            ProfileFile(path=str(tmp_path / name), spacing=0.1).rms_height()
    np.save(tmp_path / "line.npy", np.c_[0.1 * np.arange(50), rng.normal(size=50)])
    with pytest.raises(ValueError, match=r"map of 2 x 50 pixels .*; columns of x and z \(a line\) are read by profile-file"):
        SurfaceFile(path=str(tmp_path / "line.npy"), spacing=0.1).rms_height()
