"""Instrument exports as users bring them, read as tables: a Gwyddion text export whose header
states an oblong pixel, a profile scanned right to left, points an instrument dropped (NaN, an
empty cell, ***), a footer, a second channel, an x column printed too coarsely, a map of equal
heights or of two points. Each was refused with a misleading message, or read without a word."""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab.io.inputs import describe_input
from frictionlab_spectra import ProfileFile, SurfaceFile


def rough(ny: int, nx: int, seed: int = 1) -> np.ndarray:
    return np.random.default_rng(np.random.SeedSequence(seed)).normal(size=(ny, nx))


def gwyddion_matrix(path, z_um: np.ndarray, pixel_um: tuple[float, float], words=("Width", "Height")):
    """Gwyddion's 'ASCII data matrix' export: the scan's width and height in its header (by the
    ``words`` of its language), heights in um."""
    ny, nx = z_um.shape
    header = (f"# Channel: Height\n# {words[0]}: {nx * pixel_um[0]:.3f} µm\n# {words[1]}: {ny * pixel_um[1]:.3f} µm\n"
              "# Value units: µm\n")  # fmt: skip
    path.write_text(header + "".join("\t".join(f"{v:.6e}" for v in row) + "\n" for row in z_um), encoding="utf-8")
    return path


def test_a_table_whose_header_states_an_oblong_pixel_is_not_squared_without_a_word(tmp_path):
    """Gwyddion's text export of 32 x 16 pixels of 1 x 0.5 um, read with format: table and
    spacing 1: the pixels were squared without a word, every slope along y half what it is."""
    path = gwyddion_matrix(tmp_path / "scan.txt", rough(16, 32), (1.0, 0.5))
    summary = SurfaceFile(path=str(path), format="table", spacing=1.0).input_summary()
    (caveat,) = [said for said in summary["caveats"] if "not square" in said]
    assert "its header's pixel of 1 x 0.5 um (x by y), which is not square" in caveat
    assert "give spacing_y too (0.5 keeps the file's shape), or read it with format: instrument" in caveat
    assert summary["file_spacing"] == pytest.approx([1.0, 0.5], rel=1e-9)
    assert "the file's pixels of 1 x 0.5 um replaced by the preset's spacing, square" in describe_input(summary)
    kept = SurfaceFile(path=str(path), format="table", spacing=1.0, spacing_y=0.5).input_summary()
    assert "replaced" not in describe_input(kept)
    assert not any("not square" in said for said in kept.get("caveats", ()))
    square = gwyddion_matrix(tmp_path / "square.txt", rough(16, 32), (0.5, 0.5))
    said = SurfaceFile(path=str(square), format="table", spacing=0.5).input_summary().get("caveats", ())
    assert not any("not square" in caveat for caveat in said)


LANGUAGES = [("Width", "Height"), ("Breite", "H\u00f6he"), ("Largeur", "Hauteur")]  # Gwyddion's English, German, French


@pytest.mark.parametrize("words", LANGUAGES[1:])  # English: above
def test_a_gwyddion_export_in_another_language_states_its_pixel(tmp_path, words):
    path = gwyddion_matrix(tmp_path / "scan.txt", rough(16, 32), (1.0, 0.5), words)
    summary = SurfaceFile(path=str(path), format="table", spacing=1.0).input_summary()
    assert summary["file_spacing"] == pytest.approx([1.0, 0.5], rel=1e-9)
    assert any("its header's pixel of 1 x 0.5 um (x by y), which is not square" in said for said in summary["caveats"])


@pytest.mark.parametrize("words", LANGUAGES)
def test_a_narrow_gwyddion_matrix_is_refused_as_narrow_not_as_a_damaged_file(tmp_path, words):
    """Three columns of heights under a header stating the map's size: a matrix (its reader's),
    not x, y, z points, whose reader refused it, and the file was called damaged."""
    path = gwyddion_matrix(tmp_path / "narrow.txt", rough(20, 3), (1.0, 1.0), words)
    with pytest.raises(ValueError, match=r"map of 3 x 20 pixels \(x by y\); at least 8 x 8 are needed"):
        SurfaceFile(path=str(path), format="instrument").input_summary()
    with pytest.raises(ValueError, match="a 2D map of 3 x 20 pixels .*too narrow for surface-file"):
        ProfileFile(path=str(path), format="instrument").input_summary()


def xz_table(path, x: np.ndarray, z: np.ndarray, header: str = "x [um],z [um]"):
    path.write_text(header + "\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(x.tolist(), z.tolist())), encoding="utf-8")
    return path


def test_a_profile_scanned_right_to_left_is_read_mirrored(tmp_path):
    """A profile exported right to left (x decreasing) was refused ('x must increase'); its line
    read as written is the scan mirrored, which changes no statistic and no contact."""
    x, z = np.arange(64) * 0.5, rough(1, 64, 4)[0]
    backwards = ProfileFile(path=str(xz_table(tmp_path / "back.csv", x[::-1], z)))
    forwards = ProfileFile(path=str(xz_table(tmp_path / "fore.csv", x, z)))
    assert backwards.generate(None).spacing == pytest.approx(0.5, rel=1e-12)
    np.testing.assert_allclose(backwards.generate(None).heights, forwards.generate(None).heights, rtol=0, atol=0)
    assert backwards.input_summary()["x_decreasing"] is True and "x_decreasing" not in forwards.input_summary()
    assert "x decreasing (a scan written right to left)" in describe_input(backwards.input_summary())
    still = xz_table(tmp_path / "still.csv", np.r_[x[:32], x[:32][::-1]], z)
    with pytest.raises(ValueError, match=r"still.csv.*x does not advance from its first row to its last \(x\[0\] = 0, "
                                         r"x\[63\] = 0\); the x column must increase or decrease by one step a row"):
        ProfileFile(path=str(still)).rms_height()


def test_a_text_export_of_a_line_scanned_right_to_left_is_read_with_a_positive_pixel(tmp_path):
    """format: instrument: SurfaceTopography reads x decreasing as a pixel of -0.5; refused
    before ('x must increase'), it is read as the same line mirrored, its pixel 0.5."""
    x, z = np.arange(64) * 0.5, rough(1, 64, 5)[0]
    path = tmp_path / "back.txt"
    path.write_text("".join(f"{a!r}\t{b!r}\n" for a, b in zip(x[::-1].tolist(), z.tolist())), encoding="utf-8")
    line = ProfileFile(path=str(path), format="instrument", unit="um", detrend="mean")
    assert line.generate(None).spacing == pytest.approx(0.5, rel=1e-9)
    np.testing.assert_allclose(line.generate(None).heights, z - z.mean(), rtol=1e-9, atol=1e-12)
    assert line.input_summary()["x_decreasing"] is True


def test_a_tables_nan_is_named_by_its_line_and_column_in_the_file(tmp_path):
    """A NaN (a point an optical profilometer dropped) was named 'at index 50' (its row among the
    heights, from 0) or 'row 3, column 4' (from 0): neither the line nor the column an editor shows."""
    x, z = np.arange(64) * 0.5, rough(1, 64, 6)[0]
    z[50], x[60] = np.nan, np.nan  # the heights' NaN on the file's line 52 (a header, then rows from 0), x's on 62
    path = xz_table(tmp_path / "dropped.csv", x, z)
    with pytest.raises(ValueError, match=r"dropped.csv'?: 1 value\(s\) in heights not finite .* the first at line 52, "
                                         r"column 2 of the file; set undefined: harmonic to fill NaN"):
        ProfileFile(path=str(path)).rms_height()
    z[50] = 0.0
    with pytest.raises(ValueError, match=r"1 value\(s\) in x not finite .* the first at line 62, column 1 of the file"):
        ProfileFile(path=str(xz_table(tmp_path / "x.csv", x, z))).rms_height()
    m = rough(12, 10, 7)
    m[3, 4] = np.nan
    (tmp_path / "map.csv").write_text("# exported\n" + "".join(",".join(map(repr, row.tolist())) + "\n" for row in m))
    with pytest.raises(ValueError, match=r"the first at line 5, column 5 of the file; set undefined: harmonic to fill NaN "
                                         r"\(points not measured\) from their neighbours, or fix them before saving the "
                                         "table, or leave them out with region"):
        SurfaceFile(path=str(tmp_path / "map.csv"), spacing=0.1).rms_height()


@pytest.mark.parametrize("columns", ["z", "x, z"])
def test_a_tables_nan_is_filled_as_an_instrument_files_undefined_points(tmp_path, columns):
    """A NaN in a .csv (an optical profilometer's dropout) was refused, told to fill it before saving
    or to 'read the instrument's own file'; undefined: harmonic fills it as SurfaceTopography fills an
    instrument file's undefined points: on a line, straight between its neighbours."""
    x, z = np.arange(64) * 0.5, rough(1, 64, 8)[0]
    z[20], z[30:33], z[0] = np.nan, np.nan, np.nan
    path = xz_table(tmp_path / "dropped.csv", x, z) if columns == "x, z" else tmp_path / "dropped.csv"
    if columns == "z":
        path.write_text("".join(f"{v!r}\n" for v in z.tolist()))
    line = ProfileFile(path=str(path), spacing=0.5, undefined="harmonic", detrend="none")
    filled = line.generate(None).heights
    assert filled[20] == pytest.approx((z[19] + z[21]) / 2, rel=1e-9)
    np.testing.assert_allclose(filled[30:33], z[29] + (z[33] - z[29]) * np.arange(1, 4) / 4, rtol=1e-9)
    assert filled[0] == pytest.approx(z[1], rel=1e-12)  # level past the first defined point
    summary = line.input_summary()
    assert summary["undefined_points"] == 5 and summary["filled_by"] == "harmonic"
    assert any("were undefined and filled by harmonic interpolation" in c for c in summary["caveats"])  # 7.8 %


@pytest.mark.parametrize("periodic", [False, True])
def test_a_table_maps_nan_are_filled_as_surfacetopography_fills_them(tmp_path, periodic):
    """A map's NaN filled with undefined: harmonic: the solution of Laplace's equation over the holes,
    the same heights as SurfaceTopography's harmonic filling of an instrument file's undefined points
    (a periodic map's holes at an edge filled from the opposite edge too)."""
    from scipy.ndimage import gaussian_filter
    from SurfaceTopography import Topography

    z = gaussian_filter(rough(20, 30, 15), 2, mode="wrap")
    z[3:6, 4:9], z[0, 0], z[19, 10:14], z[10, 29] = np.nan, np.nan, np.nan, np.nan
    (tmp_path / "map.csv").write_text("".join(",".join(map(repr, row.tolist())) + "\n" for row in z))
    read = SurfaceFile(path=str(tmp_path / "map.csv"), spacing=1.0, undefined="harmonic", detrend="none",
                       periodic=periodic)  # fmt: skip
    expected = Topography(np.ma.masked_invalid(z.T), (30.0, 20.0), periodic=periodic).interpolate_undefined_data(
        "harmonic").heights().T  # fmt: skip
    np.testing.assert_allclose(read.generate(None).heights, expected, rtol=0, atol=1e-12)
    assert read.input_summary()["undefined_points"] == 21
    np.save(tmp_path / "none.npy", np.full((10, 10), np.nan))
    with pytest.raises(ValueError, match=r"none.npy'?: all 100 heights are NaN \(not measured\): nothing to press"):
        SurfaceFile(path=str(tmp_path / "none.npy"), spacing=1.0, undefined="harmonic").rms_height()


def test_a_map_whose_header_is_latin1_is_told_to_be_saved_as_utf8(tmp_path):
    """A map's 'z [µm]' saved in Latin-1 was refused as naming 'the unit '\ufffdm', which is no unit
    frictionlab knows': its header's µ undecoded, and the advice to relabel a column it had right."""
    m = rough(10, 10, 9)
    path = tmp_path / "latin1.csv"
    path.write_bytes("# scan\nz [µm]\n".encode("latin-1") + "".join(",".join(map(repr, r.tolist())) + "\n" for r in m).encode())
    with pytest.raises(ValueError, match=r"latin1.csv'?: not UTF-8 at line 2 .* save it so") as refused:
        SurfaceFile(path=str(path), spacing=0.1).rms_height()
    assert "no unit frictionlab knows" not in str(refused.value)


@pytest.mark.parametrize("footer", ["End of data", "Total points: 64"])
def test_a_footer_after_a_tables_numbers_is_named_so(tmp_path, footer):
    """An export's summary line after its numbers was 'non-numeric content at line 66: column 1 is
    not a number', as a bad cell among the numbers is; it is a footer, which is deleted or commented out."""
    x, z = np.arange(64) * 0.5, rough(1, 64, 10)[0]
    path = xz_table(tmp_path / "footer.csv", x, z)
    path.write_text(path.read_text() + footer + "\n\n")
    with pytest.raises(ValueError, match=r"non-numeric content at line 66 .* a footer after the table .* delete it, or "
                                         "start its lines with #"):
        ProfileFile(path=str(path)).rms_height()
    bad_row = xz_table(tmp_path / "bad.csv", x, z)
    bad_row.write_text(bad_row.read_text() + "32.0,x\n")  # a row of numbers with a bad cell: no footer
    with pytest.raises(ValueError, match=r"line 66 .*column 2 is not a number") as refused:
        ProfileFile(path=str(bad_row)).rms_height()
    assert "a footer after the table" not in str(refused.value)


def test_a_file_with_a_second_channel_per_point_is_told_to_export_the_heights_alone(tmp_path):
    """x, z and an intensity per row was told 'a height map is read by surface-file'; x, y, z and an
    intensity per point was 'a map of 4 x 144 pixels; at least 8 x 8': both are channels per column."""
    x, z = np.arange(64) * 0.5, rough(1, 64, 11)[0]
    line = tmp_path / "line.csv"
    line.write_text("x [um],z [um],intensity\n" + "".join(f"{a!r},{b!r},{abs(b)!r}\n" for a, b in zip(x.tolist(), z.tolist())))
    with pytest.raises(ValueError, match=r"3 columns; .* a channel per column \(x, z and an intensity, a second "
                                         r"height\): export x and the heights alone") as refused:
        ProfileFile(path=str(line)).rms_height()
    assert "a height map" not in str(refused.value)
    m = rough(12, 12, 12)
    points = tmp_path / "points.txt"
    points.write_text("".join(f"{i} {j} {float(m[j, i])!r} {abs(float(m[j, i]))!r}\n" for j in range(12) for i in range(12)))
    with pytest.raises(ValueError, match=r"map of 4 x 144 pixels .*; columns of x, y, z and another channel per point "
                                         r"\(an intensity\): export x, y and the heights alone"):
        SurfaceFile(path=str(points), spacing=0.1).rms_height()


@pytest.mark.parametrize("text", ["0.1,0.2\n", "0.1\n0.2\n"])
def test_a_map_of_two_points_is_not_sent_to_profile_file(tmp_path, text):
    """A table of 2 heights was 'one pixel wide: a line; use profile-file', which refuses it as 2 points."""
    (tmp_path / "two.csv").write_text(text)
    with pytest.raises(ValueError, match=r"a map of \d x \d pixels \(x by y\): 2 heights, too few for a map \(at least "
                                         r"8 x 8\) or a line \(profile-file: at least 8 points\)"):
        SurfaceFile(path=str(tmp_path / "two.csv"), spacing=0.1).rms_height()


@pytest.mark.parametrize("cell", ["", " "])
def test_a_tables_empty_last_cell_is_a_point_left_out_not_a_separator_too_many(tmp_path, cell):
    """'0.5,' among rows of x, z (a profilometer's dropout: its z left empty) was 'ends with a separator, an
    empty column after its last number: export the table without a separator at the end of its lines'."""
    x, z = np.arange(64) * 0.5, rough(1, 64, 13)[0]
    path = xz_table(tmp_path / "dropout.csv", x, z)
    lines = path.read_text().splitlines()
    lines[51] = lines[51].split(",")[0] + "," + cell
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"line 52 \(expected numbers separated by commas\): column 2 is empty, a point "
                                         "the export left out; write NaN there to mark it missing"):
        ProfileFile(path=str(path)).rms_height()


@pytest.mark.parametrize("height", [1e-3, 0.3, 7.7])
def test_a_map_of_equal_heights_is_refused_as_flat_not_as_an_internal_error(tmp_path, height):
    """A map whose every height is 0.001 (its mean's rounding leaves an rms of 4e-19, not 0) was refused
    as 'zero-size array to reduction operation minimum which has no identity', numpy's words."""
    np.save(tmp_path / "flat.npy", np.full((16, 32), height))
    with pytest.raises(ValueError, match=r"flat.npy'?: the map is constant \(rms height zero after detrend='mean'\); "
                                         "a flat surface has no roughness"):
        SurfaceFile(path=str(tmp_path / "flat.npy"), spacing=0.1).rms_height()


def test_a_cell_that_marks_a_point_not_measured_is_told_to_be_nan(tmp_path):
    """'***' (or N/A, --) where a profilometer did not measure was 'column 2 is not a number', as a typo is."""
    x, z = np.arange(64) * 0.5, rough(1, 64, 14)[0]
    path = xz_table(tmp_path / "stars.csv", x, z)
    lines = path.read_text().splitlines()
    lines[51], lines[53] = lines[51].split(",")[0] + ",***", lines[53].split(",")[0] + ",1.2.3"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"line 52 .*: column 2 is not a number, and holds no digit: if it marks a point "
                                         r"not measured \(as \*\*\*, N/A or -- do\), write NaN there, which undefined: harmonic fills$"):
        ProfileFile(path=str(path)).rms_height()
    lines[51] = lines[51].split(",")[0] + ",0.5"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"line 54 .*: column 2 is not a number$"):  # a typo: no such guess
        ProfileFile(path=str(path)).rms_height()


def test_an_x_column_printed_too_coarsely_is_told_so(tmp_path):
    """A profilometer's x in mm to 3 decimals, its step 0.0025 mm: the rounding alone put points 0.4
    steps off a uniform grid, refused with the deviation and nothing to do."""
    x, z = np.arange(100) * 0.0025, rough(1, 100, 16)[0]
    path = tmp_path / "coarse.csv"
    path.write_text("".join(f"{a:.3f},{b!r}\n" for a, b in zip(x.tolist(), z.tolist())))
    with pytest.raises(ValueError, match=r"x is not uniformly spaced: .*; x is written to 3 decimals \(0.001\), too coarse "
                                         r"for its step of about 0.0025: export x with more digits, or the heights alone"):
        ProfileFile(path=str(path)).rms_height()
    x[50:] += 0.1  # a jump: no rounding's
    path.write_text("".join(f"{a:.4f},{b!r}\n" for a, b in zip(x.tolist(), z.tolist())))
    with pytest.raises(ValueError, match=r"x is not uniformly spaced: .*: export the scan on a uniform grid"):
        ProfileFile(path=str(path)).rms_height()


def test_undefined_points_cropped_out_keep_the_caveat_of_a_square_spacing(tmp_path):
    """An instrument file's undefined points left out by region replaced its summary's caveats by the
    region's: the caveat of spacing squaring its oblong pixel was dropped without a word."""
    z = rough(16, 32, 17)
    z[2, 3] = np.nan  # outside the region
    path = gwyddion_matrix(tmp_path / "scan.txt", z, (1.0, 0.5))
    summary = SurfaceFile(path=str(path), format="instrument", unit="um", spacing=1.0,
                          region={"x": [8, 32], "y": [8, 16]}).input_summary()  # fmt: skip
    assert summary["undefined_outside_region"] == 1
    assert any("which is not square" in caveat for caveat in summary["caveats"])


def test_a_tables_nan_outside_the_region_is_counted_there_when_filled(tmp_path):
    """A table's NaN outside region, under undefined: harmonic, was counted as filled in the map pressed."""
    z = rough(16, 16, 18)
    z[2, 3] = np.nan
    np.save(tmp_path / "map.npy", z)
    for x, inside in (([8, 16], 0), ([2, 16], 1)):
        summary = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=1.0, undefined="harmonic",
                              region={"x": x, "y": [1, 16]}).input_summary()  # fmt: skip
        assert (summary["undefined_points"], summary["undefined_outside_region"]) == (inside, 1 - inside)
        assert summary["filled_by"] == ("harmonic" if inside else None)


def test_a_lines_outlier_caveat_names_what_a_line_has(tmp_path):
    """A profile's dropout written as -999999 was told to 'remove them (despike, region)' when a line
    had neither. It now has despike, which replaces it, and a region that crops its ends alone; or the
    value is written NaN in the file, which undefined: harmonic fills."""
    x, z = np.arange(128) * 0.5, rough(1, 128, 19)[0]
    z[40] = -999999.0
    table = str(xz_table(tmp_path / "sentinel.csv", x, z))
    caveats = ProfileFile(path=table).input_summary()["caveats"]
    (said,) = [caveat for caveat in caveats if "rms height is" in caveat]
    assert "remove them (despike; region at its ends), or write NaN in their place in the file, which undefined: " \
        "harmonic fills" in said
    despiked = ProfileFile(path=table, despike=6.0).input_summary()
    assert despiked["despiked"]["points"] == 1 and not any("rms height is" in c for c in despiked.get("caveats", ()))
    filled = ProfileFile(path=str(xz_table(tmp_path / "nan.csv", x, np.where(z < -1e5, np.nan, z))), undefined="harmonic")
    assert not any("rms height is" in caveat for caveat in filled.input_summary().get("caveats", ()))


@pytest.mark.parametrize("plugin", [ProfileFile, SurfaceFile])
def test_a_header_of_several_lines_is_told_to_be_commented_out(tmp_path, plugin):
    """An export's header of settings (Instrument, Date, then the labels) was 'non-numeric content at
    line 2: column 1 is not a number', as a bad cell is; a table has one header line at most."""
    z = rough(16, 16, 20) if plugin is SurfaceFile else rough(1, 64, 20)[0][:, None]
    rows = "".join(",".join(map(repr, row.tolist())) + "\n" for row in z)
    (tmp_path / "export.csv").write_text("Instrument,VK-X\nDate,2024/01/01\nz\n" + rows)
    with pytest.raises(ValueError, match=r"line 2 .*: a second line of text before the numbers; a table has one header "
                                         "line at most: start the others with #, or read an instrument's export"):
        plugin(path=str(tmp_path / "export.csv"), spacing=0.1).rms_height()
    (tmp_path / "export.csv").write_text("# Instrument,VK-X\n# Date,2024/01/01\nz\n" + rows)
    assert plugin(path=str(tmp_path / "export.csv"), spacing=0.1).rms_height() > 0
