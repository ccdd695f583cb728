"""Scans at the edges of what a file may say, written here byte by byte: a Gwyddion file
whose channels are not heights, tables as spreadsheets save them (a byte-order mark,
semicolons, decimal commas), a map one pixel wide, a pixel size that makes the resampled
map enormous, X3P files of a kind SurfaceTopography does not read. Each is read with the
right numbers, or refused with a message that names what is wrong and what to do."""

from __future__ import annotations

import re

import numpy as np
import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab_spectra import ProfileFile, SurfaceFile


def rough(ny: int, nx: int, seed: int = 1) -> np.ndarray:
    return np.random.default_rng(np.random.SeedSequence(seed)).normal(size=(ny, nx))


def xyz_lines(ny: int, nx: int, seed: int, sep: str = " ", intensity: bool = False) -> tuple[list[str], np.ndarray]:
    """An instrument's x, y, z export of a rough ny x nx map on 0.1 um pixels (in m): its lines,
    a point each (with an intensity column of ones), and the heights z[y, x]."""
    y, x = np.mgrid[0:ny, 0:nx] * 1e-7
    z = rough(ny, nx, seed) * 1e-8
    columns = (x.ravel(), y.ravel(), z.ravel()) + ((np.ones(z.size),) if intensity else ())
    return [sep.join(f"{v:.9e}" for v in row) + "\n" for row in zip(*columns)], z


def write_gwy(path, z, dx, dy, *, unit_xy="m", unit_z="m", xreal=None, xres=None, more=(), title="Height"):
    """A Gwyddion file of the map z[y, x] (channel 0, ``title``) on pixels dx x dy (in unit_xy), and more channels
    (title, map, unit of values) on the same grid."""
    from SurfaceTopography.IO.GWY import _gwy_write_object  # here: its import takes seconds

    ny, nx = z.shape

    def field(values, unit):
        return ("o", ("GwyDataField", {
            "xres": ("i", nx if xres is None else xres), "yres": ("i", ny), "xreal": ("d", nx * dx if xreal is None else xreal),
            "yreal": ("d", ny * dy), "xoff": ("d", 0.0), "yoff": ("d", 0.0),
            "si_unit_xy": ("o", ("GwySIUnit", {"unitstr": ("s", unit_xy)})),
            "si_unit_z": ("o", ("GwySIUnit", {"unitstr": ("s", unit)})), "data": ("D", values.astype("<f8").ravel()),
        }))  # fmt: skip

    container = {"/0/data/title": ("s", title), "/0/data": field(z, unit_z)}
    for index, (title, values, unit) in enumerate(more, start=1):
        container[f"/{index}/data/title"] = ("s", title)
        container[f"/{index}/data"] = field(values, unit)
    with open(path, "wb") as fh:
        fh.write(b"GWYP")
        _gwy_write_object(fh, "GwyContainer", container)
    return path


def preset(path, **params) -> dict:
    return {
        "name": "edge", "seed": 1, "realizations": 1,
        "spectrum": {"name": "surface-file", "params": {"path": str(path), **params}},
        "solver": {"name": "mdr", "params": {"youngs_modulus": 1.0, "poisson_ratio": 0.0}},
        "loading": {"start": 1e-3, "stop": 1e-2, "steps": 3, "spacing": "log"},
    }  # fmt: skip


def validate(tmp_path, capsys, path, **params) -> tuple[int, str]:
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset(path, **params)))
    code = main(["validate", str(tmp_path / "p.yaml")])
    captured = capsys.readouterr()
    return code, captured.out + captured.err


# ------------------------------------------------------------ channels that are not heights


@pytest.mark.parametrize("unit_z", ["V", "deg", ""])
def test_a_file_with_no_channel_of_heights_is_refused_by_name_not_as_an_internal_error(tmp_path, capsys, unit_z):
    """SurfaceTopography's Gwyddion reader keeps only channels whose values are lengths: a file
    of phase, amplitude or unitless channels has none, and its reader's default channel does
    not exist (an IndexError, the catch-all internal error, exit 70, before)."""
    path = write_gwy(tmp_path / "phase.gwy", rough(16, 16) * 1e-9, 1e-7, 1e-7, unit_z=unit_z,
                     more=[("Amplitude", rough(16, 16), unit_z)])  # fmt: skip
    code, text = validate(tmp_path, capsys, path)
    assert code == ExitCode.USAGE, text
    assert "holds no channel of heights that SurfaceTopography reads" in text and "internal error" not in text
    assert "Traceback" not in text


def test_the_channels_of_heights_are_read_beside_ones_that_are_not(tmp_path):
    z = rough(16, 20, 2) * 1e-9
    path = write_gwy(tmp_path / "mixed.gwy", z, 1e-7, 1e-7, more=[("Phase", rough(16, 20), "deg"), ("Z", 2 * z, "m")])
    read = SurfaceFile(path=str(path), unit="nm", detrend="mean", channel="Z").generate(None).heights
    np.testing.assert_allclose(read, 2e9 * (z - z.mean()), rtol=1e-12, atol=1e-12)



def test_a_channel_title_of_any_length_is_quoted_cut_in_the_middle(tmp_path, capsys):
    """A file's channel titles are the file's: a title of 100,000 characters was printed whole
    by validate (in the line of what was read and in the list of channels) and in a refusal
    that lists the channels. Each is quoted cut in the middle; the title is still matched whole."""
    z = rough(16, 20, 2) * 1e-9
    long = "Height " + "x" * 100_000 + " end"
    path = write_gwy(tmp_path / "long.gwy", z, 1e-7, 1e-7, more=[(long, 2 * z, "m"), (long, 3 * z, "m")])
    for channel in (1, long):
        code, text = validate(tmp_path, capsys, path, channel=channel)
        assert code == ExitCode.OK, text[:2000]
        assert "channel 1 'Height xxx" in text and "2 channels are named 'Height xxx" in text, text[:2000]
        assert max(map(len, text.splitlines())) < 500, [len(line) for line in text.splitlines()]
    code, text = validate(tmp_path, capsys, path, channel="Phase")
    assert code == ExitCode.USAGE and "no channel named 'Phase'; the file has 0: 'Height', 1: 'Height xxx" in text
    assert len(text) < 1000, len(text)

# ------------------------------------------------------------ tables as spreadsheets save them


def matrix_text(z, separator=",", decimal=".") -> str:
    return "\n".join(separator.join(f"{v:.9f}".replace(".", decimal) for v in row) for row in z) + "\n"


@pytest.mark.parametrize("header", ["", "z\n", "z [nm]\r\n"])
def test_a_byte_order_mark_is_no_header_and_drops_no_row(tmp_path, header):
    """A spreadsheet's 'CSV UTF-8' starts with the byte-order mark U+FEFF. Read as part of
    the first number it made the first row a 'header': a row of the map silently dropped
    (11 of 12 rows read, before), or with a real header line, the file refused."""
    z = rough(12, 10, 3)
    plain, marked = tmp_path / "plain.csv", tmp_path / "marked.csv"
    plain.write_text(matrix_text(z))
    marked.write_bytes(b"\xef\xbb\xbf" + (header + matrix_text(z)).replace("\n", "\r\n").encode())
    expected = SurfaceFile(path=str(plain), spacing=0.1).generate(None).heights
    read = SurfaceFile(path=str(marked), spacing=0.1).generate(None).heights
    assert read.shape == (12, 10)
    np.testing.assert_array_equal(read, expected)


def test_a_profile_with_a_byte_order_mark_keeps_its_first_point(tmp_path):
    x = np.arange(40) * 0.5
    z = rough(1, 40, 4)[0]
    (tmp_path / "p.csv").write_bytes(b"\xef\xbb\xbf" + "".join(f"{a},{float(b)!r}\n" for a, b in zip(x, z)).encode())
    line = ProfileFile(path=str(tmp_path / "p.csv")).generate(None)
    assert line.heights.size == 40 and line.spacing == pytest.approx(0.5, rel=1e-12)
    np.testing.assert_allclose(line.heights, z - z.mean(), rtol=0, atol=1e-12)


@pytest.mark.parametrize("header", ["", "x;z\n"])
def test_semicolons_separate_numbers(tmp_path, header):
    """A European spreadsheet separates its columns by semicolons: read as such (refused as
    'non-numeric content at line 2 (expected numbers separated by spaces)', before)."""
    z = rough(12, 10, 5)
    (tmp_path / "s.csv").write_text(header + matrix_text(z, ";"))
    (tmp_path / "c.csv").write_text(matrix_text(z, ","))
    read = SurfaceFile(path=str(tmp_path / "s.csv"), spacing=0.1).generate(None).heights
    np.testing.assert_array_equal(read, SurfaceFile(path=str(tmp_path / "c.csv"), spacing=0.1).generate(None).heights)


def test_a_header_over_a_matrix_of_commas_is_skipped(tmp_path):
    """The separator is the data's, not the header's: a one-word header over comma-separated
    rows (refused before: the header, with no comma, set whitespace as the separator)."""
    z = rough(9, 8, 6)
    (tmp_path / "h.csv").write_text("height\n" + matrix_text(z))
    read = SurfaceFile(path=str(tmp_path / "h.csv"), spacing=0.1, detrend="none").generate(None).heights
    np.testing.assert_allclose(read, z, rtol=0, atol=1e-9)


@pytest.mark.parametrize("bad", ["x", "", "1.2.3"])
@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_a_first_row_of_heights_with_a_bad_cell_is_refused_not_skipped_as_a_header(tmp_path, bad, plugin):
    """A first line that was not all numbers was taken for a header and dropped without a word:
    a map of 12 rows whose first held one cell 'x' (or an empty cell) was read as 11 rows, the
    first row of heights lost; a profile given as one row of heights was 'a table of no numbers'.
    A line more numbers than text is a row of data: refused by its line, as any later row with
    such a cell is. A header (more text than numbers) is skipped still."""
    z = rough(12, 10, 8) if plugin is SurfaceFile else rough(1, 40, 8)
    rows = matrix_text(z).splitlines()
    rows[0] = ",".join([*rows[0].split(",")[:3], bad, *rows[0].split(",")[4:]])
    (tmp_path / "bad.csv").write_text("\n".join(rows) + "\n")
    with pytest.raises(ValueError, match=r"non-numeric content at line 1 \(expected numbers separated by commas\)"):
        plugin(path=str(tmp_path / "bad.csv"), spacing=0.1).rms_height()
    for header in ("x,z\n", "z [nm]\n", "Height 1\n"):
        (tmp_path / "h.csv").write_text(header + matrix_text(z))
        assert plugin(path=str(tmp_path / "h.csv"), spacing=0.1).generate(None).heights.size == z.size


@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_a_bad_cell_past_the_first_line_is_named_by_its_column_and_an_empty_one_as_missing(tmp_path, plugin):
    """An export's empty cell (a point it left out, '0.1,,0.3') was 'non-numeric content at line
    4', naming neither the cell nor what it is; a cell of text was not found in a line of 200."""
    z = rough(12, 10, 8) if plugin is SurfaceFile else rough(1, 40, 8)
    rows = matrix_text(z).splitlines()
    if plugin is ProfileFile:
        rows = [f"{0.1 * i:.1f},{row}" for i, row in enumerate(rows[0].split(","))]  # x, z rows
    for bad, said in (("", r"column 1 is empty, a point the export left out; write NaN"), ("n/a", r"column 1 is not a number")):
        edited = [*rows[:3], ",".join([bad, *rows[3].split(",")[1:]]), *rows[4:]]
        (tmp_path / "bad.csv").write_text("\n".join(edited) + "\n")
        with pytest.raises(ValueError, match=r"non-numeric content at line 4 \(expected numbers separated by commas\): " + said):
            plugin(path=str(tmp_path / "bad.csv"), spacing=0.1).rms_height()


def test_an_empty_line_among_a_columns_heights_is_a_point_left_out_not_skipped(tmp_path):
    """A column of heights with an empty line among them (a spreadsheet's empty cell: a point not
    measured) was read without that line: 39 points, each after it one point along. Empty lines
    before or after the heights, and the same column written with NaN, are read as they were."""
    z = rough(1, 40, 8)[0]
    rows = [repr(float(v)) for v in z]
    path = tmp_path / "gap.csv"
    path.write_text("\n".join([*rows[:11], "", *rows[12:]]) + "\n")
    with pytest.raises(ValueError, match=r"line 12 is empty, between heights: .* write NaN there to mark it missing"):
        ProfileFile(path=str(path), spacing=0.1).rms_height()
    path.write_text("z\n\n" + "\n".join(rows) + "\n\n\n")
    assert ProfileFile(path=str(path), spacing=0.1).generate(None).heights.size == 40
    path.write_text("\n".join([*rows[:11], "nan", *rows[12:]]) + "\n")
    assert ProfileFile(path=str(path), spacing=0.1, undefined="harmonic").generate(None).heights.size == 40


@pytest.mark.parametrize("separator", [";", "\t"])
def test_decimal_commas_are_named(tmp_path, separator):
    """At their first line: the first was skipped as a header, and line 2 named."""
    (tmp_path / "d.csv").write_text(matrix_text(rough(9, 8, 7), separator, decimal=","))
    with pytest.raises(ValueError, match=r"decimal commas at line 1 \(as 1,5\); .* export the table with decimal points"):
        SurfaceFile(path=str(tmp_path / "d.csv"), spacing=0.1).rms_height()



@pytest.mark.parametrize("kind", ["xyz", "matrix", "gwyddion"])
@pytest.mark.parametrize("separator", [";", "\t"])
def test_decimal_commas_of_an_instrument_export_are_named(tmp_path, kind, separator):
    """An export in a European locale (x, y, z points, a matrix, Gwyddion's text export with its
    header) writes 1,5e-07: SurfaceTopography's readers took the commas for separators, and the
    scan was 'a damaged file (6 columns)' or held 'no channel of heights ... a spelling such as
    micron'. The same scan with decimal points is read, with its heights."""
    z = rough(9, 8, 7) * 1e-7
    y, x = np.mgrid[0:9, 0:8] * 1e-7
    header = "# Channel: Height\n# Width: 0.8 µm\n# Height: 0.9 µm\n# Value units: m\n" if kind == "gwyddion" else ""
    rows = zip(x.ravel(), y.ravel(), z.ravel()) if kind == "xyz" else z
    text = header + "".join(separator.join(f"{v:.9e}" for v in row) + "\n" for row in rows)
    (tmp_path / "comma.txt").write_text(text.replace(".", ",").replace("0,8 µm", "0.8 µm").replace("0,9 µm", "0.9 µm"))
    (tmp_path / "point.txt").write_text(text if kind == "xyz" else text.replace(separator, "\t"))  # a matrix: whitespace
    spacing = {"spacing": 0.1} if kind == "matrix" else {}
    line = 5 if kind == "gwyddion" else 1
    with pytest.raises(ValueError, match=rf"decimal commas at line {line} \(as 1,5\); .* export the scan with decimal points"):
        SurfaceFile(path=str(tmp_path / "comma.txt"), format="instrument", **spacing).rms_height()
    read = SurfaceFile(path=str(tmp_path / "point.txt"), format="instrument", detrend="mean", **spacing).generate(None)
    np.testing.assert_allclose(read.heights, z - z.mean(), rtol=1e-6, atol=1e-6 * np.abs(z).max())



def test_a_gwyddion_export_whose_header_sizes_have_decimal_commas_is_named(tmp_path):
    """Gwyddion's text export in a European locale writes '# Width: 0,800 µm': the reader took
    ',800 µm' for an unknown lateral unit ('write it as one it knows: m, mm, µm'). With points,
    the same export is read on pixels of 0.1 um, its heights the file's."""
    z = rough(9, 8, 7) * 1e-7
    matrix = "".join("\t".join(f"{v:.9e}" for v in row) + "\n" for row in z)
    header = "# Channel: Height\n# Width: 0.800 µm\n# Height: 0.900 µm\n# Value units: m\n"
    (tmp_path / "comma.txt").write_text(header.replace("0.", "0,") + matrix)
    with pytest.raises(ValueError, match=r"its header writes a size with a decimal comma .* export it with decimal points"):
        SurfaceFile(path=str(tmp_path / "comma.txt"), format="instrument").rms_height()
    (tmp_path / "point.txt").write_text(header + matrix)
    read = SurfaceFile(path=str(tmp_path / "point.txt"), format="instrument", unit="um", detrend="none").generate(None)
    assert read.spacing == pytest.approx(0.1, rel=1e-9)
    np.testing.assert_allclose(read.heights, z * 1e6, rtol=1e-8)

@pytest.mark.parametrize("suffix, separator, name", [(".csv", ",", "commas"), (".txt", ";", "semicolons"),
                                                     (".txt", ",", "commas")])
def test_a_matrix_export_separated_by_commas_is_named_as_such(tmp_path, suffix, separator, name):
    """SurfaceTopography reads a matrix (format: instrument, a Gwyddion text export) between tabs
    or spaces only: a .csv matrix went to its reader of x, y, z points ('a damaged file: 8
    columns'), a .txt one was 'no channel of heights ... a spelling such as micron'. Read as a
    table, its heights are the file's."""
    z = rough(9, 8, 7)
    path = tmp_path / f"m{suffix}"
    path.write_text("".join(separator.join(f"{v:.9e}" for v in row) + "\n" for row in z))
    with pytest.raises(ValueError, match=f"line 1 holds 8 numbers separated by {name}, .* format: table and spacing"):
        SurfaceFile(path=str(path), format="instrument", spacing=0.1).rms_height()
    read = SurfaceFile(path=str(path), format="table", spacing=0.1, detrend="mean").generate(None)
    np.testing.assert_allclose(read.heights, z - z.mean(), rtol=1e-8, atol=1e-8)



@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-16-be"])
def test_a_text_export_in_utf16_is_told_to_be_saved_as_utf8(tmp_path, encoding):
    """A Windows program's 'Unicode text' (UTF-16, with or without its byte-order mark) sent to
    SurfaceTopography was 'a .txt file that is not text (binary bytes at its start): give a binary
    format its own suffix'. The same export in UTF-8 is read, its heights the file's."""
    lines, z = xyz_lines(9, 8, 7, sep="\t")
    text = "".join(lines)
    (tmp_path / "wide.txt").write_bytes(text.encode(encoding))
    with pytest.raises(ValueError, match="a text export in UTF-16 .* save it as UTF-8") as refused:
        SurfaceFile(path=str(tmp_path / "wide.txt"), format="instrument").rms_height()
    assert "not text" not in str(refused.value)
    (tmp_path / "plain.txt").write_text(text)
    read = SurfaceFile(path=str(tmp_path / "plain.txt"), format="instrument", detrend="mean").generate(None)
    np.testing.assert_allclose(read.heights, z - z.mean(), rtol=1e-6, atol=1e-15)


@pytest.mark.parametrize("left_out, said", [([5, 40, 41], "3 of its points missing"), ([], "1 listed twice")])
def test_an_xyz_export_with_points_left_out_is_told_which_grid_they_lie_on(tmp_path, left_out, said):
    """An optical profilometer's x, y, z export leaves out the points it did not measure: 'not on
    a regular grid: export the map on the instrument's grid', which it was. The grid and the
    points missing (or listed twice) are named, and the same export with those points written
    with a NaN height is read, filled by undefined: harmonic, the other heights the file's."""
    rows, z = xyz_lines(9, 8, 7)
    kept = [row for i, row in enumerate(rows) if i not in left_out] + ([] if left_out else rows[10:11])
    (tmp_path / "gaps.txt").write_text("".join(kept))
    with pytest.raises(ValueError, match=f"lie on a grid of 8 x 9 points \\(x by y\\), {said}; write each point"):
        SurfaceFile(path=str(tmp_path / "gaps.txt"), format="instrument").rms_height()
    nan = [row.rsplit(" ", 1)[0] + " nan\n" if i in left_out else row for i, row in enumerate(rows)]
    (tmp_path / "nan.txt").write_text("".join(nan))
    read = SurfaceFile(path=str(tmp_path / "nan.txt"), format="instrument", undefined="harmonic", detrend="none")
    measured = np.ones(z.size, bool)
    measured[left_out] = False
    np.testing.assert_allclose(read.generate(None).heights.ravel()[measured], z.ravel()[measured], rtol=1e-6)

def test_an_xyz_export_with_a_fourth_column_is_told_to_keep_x_y_and_the_heights(tmp_path):
    """x, y, z and an intensity per point was 'a damaged Plain text file (4 columns): copy it again'."""
    lines, _ = xyz_lines(9, 8, 7, sep=",", intensity=True)
    (tmp_path / "xyzi.csv").write_text("".join(lines))
    with pytest.raises(ValueError, match="line 1 holds 4 numbers separated by commas, .* export x, y and the heights alone"):
        SurfaceFile(path=str(tmp_path / "xyzi.csv"), format="instrument").rms_height()

# ------------------------------------------------------------ pixels far from square


def test_a_map_too_large_once_on_square_pixels_is_refused_before_it_is_built(tmp_path, capsys, monkeypatch):
    """Pixels 2000 times longer along x than along y make a 32 x 24 scan 62001 x 24 pixels on
    square ones (a header that lies makes more: Gwyddion reads a zero width as 1 m, 312500:1
    here). Refused from the shapes, naming the pixels, the map it would make and the remedy;
    before, the map was built, and a process short of memory failed on the cosine series'
    basis with a generic 'out of memory'."""
    from frictionlab_spectra import instrument_reader

    monkeypatch.setattr(instrument_reader, "room_to_read", lambda: (32 * 2**20, "a test limit of 32 MiB"))
    path = write_gwy(tmp_path / "wide.gwy", rough(24, 32) * 1e-9, 2e-4, 1e-7)
    code, text = validate(tmp_path, capsys, path)
    assert code == ExitCode.USAGE, text
    assert "pixels of 0.0002 x 1e-07 m, 2000 times longer along x, make the map on square pixels 62001 x 24" in text
    assert "a test limit of 32 MiB" in text and "crop it with region" in text and "give spacing" in text
    code, text = validate(tmp_path, capsys, path, spacing=1e-7)  # the remedy it names
    assert code == ExitCode.OK, text


@pytest.mark.parametrize("xreal, said", [(1e300, "pixels of 3.125e+298"), (1e-320, "pixels of 3.1")])
def test_a_pixel_side_past_what_a_run_takes_is_named_not_an_internal_error(tmp_path, capsys, xreal, said):
    """A header whose width makes a pixel of 3e298 m, or a subnormal 3e-322 m, beside one of
    1e-7 m: their ratio overflowed while the shape on square pixels was worked out for the
    memory estimate (exit code 70, 'OverflowError: int too large to convert to float', or
    'cannot convert float infinity to integer'). Refused by the read's own check of a side."""
    path = write_gwy(tmp_path / "wide.gwy", rough(24, 32) * 1e-9, 1e-7, 1e-7, xreal=xreal)
    code, text = validate(tmp_path, capsys, path)
    assert code == ExitCode.USAGE, text
    assert said in text and "a spacing must be between 1e-100 and 1e+100" in text, text


def test_a_spacing_that_replaces_the_files_own_pixels_says_what_they_were(tmp_path, capsys):
    """spacing given for an instrument file replaces its pixels and declares them square: a
    scan of 0.1 x 0.25 um pixels given spacing 0.1 was pressed 2.5 times shorter along y, and
    validate said only 'of 1e-07 m (from the preset)'. The file's pixels are named beside it;
    a spacing equal to the file's own square pixel adds nothing."""
    z = rough(24, 32) * 1e-9
    code, text = validate(tmp_path, capsys, write_gwy(tmp_path / "rect.gwy", z, 1e-7, 2.5e-7), spacing=1e-7)
    assert code == ExitCode.OK, text
    assert "the file's pixels of 1e-07 x 2.5e-07 m replaced by the preset's spacing, square" in text, text
    code, text = validate(tmp_path, capsys, write_gwy(tmp_path / "square.gwy", z, 1e-7, 1e-7), spacing=1e-7)
    assert code == ExitCode.OK and "replaced by the preset's spacing" not in text, text


# ------------------------------------------------------------ a line stored as a map


@pytest.mark.parametrize("shape, pixel, spacing_nm", [((1, 40), (1e-7, 3e-7), 100.0), ((40, 1), (1e-7, 3e-7), 300.0)])
def test_a_map_one_pixel_wide_is_read_by_profile_file_along_its_long_side(tmp_path, shape, pixel, spacing_nm):
    """An instrument that stores a line as a map one pixel wide: surface-file sends it to
    profile-file, which reads it along its long side with that side's pixel (before, each
    sent it to the other: 'use profile-file', then 'the file holds a 2D map; use surface-file')."""
    z = rough(*shape, seed=8) * 1e-8
    path = write_gwy(tmp_path / "line.gwy", z, *pixel)
    with pytest.raises(ValueError, match=r"a map of \d+ x \d+ pixels \(x by y\), one pixel wide: a line; use profile-file"):
        SurfaceFile(path=str(path)).rms_height()
    line = ProfileFile(path=str(path), unit="nm", detrend="mean")
    made = line.generate(None)
    assert made.spacing == pytest.approx(spacing_nm, rel=1e-12) and line.grid_shape() == (40,)
    np.testing.assert_allclose(made.heights, 1e9 * (z.ravel() - z.mean()), rtol=1e-12, atol=1e-9)


# ------------------------------------------------------------ valid files SurfaceTopography does not read


def test_an_x3p_of_another_revision_or_a_profile_is_named_not_called_damaged(tmp_path, capsys):
    """x3pio writes ISO 25178-72:2017 by default, and a line as a profile (feature type PRF):
    both valid X3P files that SurfaceTopography's reader refuses. They were called 'a damaged
    X3P file ... copy it again from the instrument', which no copy mends."""
    import x3pio

    x3pio.write(tmp_path / "new.x3p", rough(16, 16) * 1e-6, x_scale=1e-7, y_scale=1e-7)
    code, text = validate(tmp_path, capsys, tmp_path / "new.x3p")
    assert code == ExitCode.USAGE and "damaged" not in text, text
    assert "is of a revision SurfaceTopography does not read" in text and "ISO 5436-2 (2000)" in text
    x3pio.write(tmp_path / "line.x3p", rough(1, 64)[0] * 1e-6, x_scale=1e-7, revision=x3pio.Revision.ISO5436_2000)
    with pytest.raises(ValueError, match="is not an areal map .* export a profile as a .csv of x, z") as refused:
        ProfileFile(path=str(tmp_path / "line.x3p")).rms_height()
    assert "damaged" not in str(refused.value)


def test_a_text_export_with_a_byte_order_mark_is_named(tmp_path):
    """SurfaceTopography's XYZ reader fails on a leading byte-order mark as on damage ('a damaged
    Plain text file ... copy it again'); the mark is named, and the same file without it is read."""
    lines, z = xyz_lines(10, 12, 9, sep=",")
    text = "".join(lines)
    (tmp_path / "marked.csv").write_bytes(b"\xef\xbb\xbf" + text.encode())
    with pytest.raises(ValueError, match="starts with a UTF-8 byte-order mark .* save it without one") as refused:
        SurfaceFile(path=str(tmp_path / "marked.csv"), format="instrument").rms_height()
    assert "damaged" not in str(refused.value)
    (tmp_path / "plain.csv").write_text(text)
    read = SurfaceFile(path=str(tmp_path / "plain.csv"), format="instrument", detrend="mean").generate(None)
    np.testing.assert_allclose(read.heights, z - z.mean(), rtol=1e-6, atol=1e-15)


def test_a_region_narrower_than_a_pixel_is_named_as_such(tmp_path):
    """[0, 0.04] um of a 2 um map on pixels of 0.1 um is inside the map, but no pixel: it was
    'not inside the map, 2 (the run's length unit) along x'."""
    path = write_gwy(tmp_path / "m.gwy", rough(16, 20) * 1e-9, 1e-7, 1e-7)
    with pytest.raises(ValueError, match=r"region.x = \[0, 0.04\] \(length\) is narrower than one pixel, 0.1 "):
        SurfaceFile(path=str(path), unit="um", region={"x": [0.0, 0.04], "units": "length"}).rms_height()
    with pytest.raises(ValueError, match=r"region.x = \[0, 3\] \(length\) is not inside the map, 2 "):
        SurfaceFile(path=str(path), unit="um", region={"x": [0.0, 3.0], "units": "length"}).rms_height()
    kept = SurfaceFile(path=str(path), unit="um", region={"x": [0.0, 1.0], "units": "length"}).generate(None)
    assert kept.heights.shape == (16, 10)


# ------------------------------------------------------------ a file that states no physical size


def write_netcdf_without_size(path, z):
    """A NetCDF map z[y, x] in um whose x and y state a unit and no length (SurfaceTopography's layout)."""
    from scipy.io import netcdf_file

    ny, nx = z.shape
    with netcdf_file(str(path), "w") as nc:
        nc.createDimension("x", nx)
        nc.createDimension("y", ny)
        heights = nc.createVariable("heights", "d", ("x", "y"))
        heights[:] = z.T
        heights.unit = "um"
        for axis, n in (("x", nx), ("y", ny)):
            coordinate = nc.createVariable(axis, "d", (axis,))
            coordinate[:] = np.arange(n, dtype=np.float64)
            coordinate.unit = "um"  # a unit, and no length
    return path


def test_spacing_gives_the_pixel_size_a_file_does_not_state(tmp_path):
    """The preset's spacing replaces a file's pixel size; a file that states none was refused
    even with spacing given ('export the scan with its pixel size, or as a .npy map with
    spacing', which loses the unit the file states). Now it is read, its heights converted
    from its unit, and the summary says the pixel size came from the preset, not the file."""
    z = rough(12, 16, 10)
    path = write_netcdf_without_size(tmp_path / "bare.nc", z)
    with pytest.raises(ValueError, match="does not state its physical size; give spacing"):
        SurfaceFile(path=str(path)).rms_height()
    surface = SurfaceFile(path=str(path), spacing=40.0, unit="nm", detrend="mean")
    made = surface.generate(None)
    assert made.spacing == 40.0 and made.heights.shape == (12, 16)
    np.testing.assert_allclose(made.heights, 1e3 * (z - z.mean()), rtol=1e-12, atol=1e-9)
    summary = surface.input_summary()
    assert summary["spacing_from"] == "preset" and summary["file_spacing"] is None and summary["file_unit"] == "µm"


# ------------------------------------------------------------ an X3P whose payload is not what it declares


def rewritten_x3p(source, path, *, xml=lambda text: text, data=lambda payload: payload):
    """``source`` (an X3P) with its main.xml and its binary heights passed through ``xml`` and ``data``."""
    import zipfile

    with zipfile.ZipFile(source) as old, zipfile.ZipFile(path, "w") as new:
        for item in old.infolist():
            content = old.read(item)
            content = xml(content) if item.filename == "main.xml" else content
            new.writestr(item.filename, data(content) if item.filename == "bindata/data.bin" else content)
    return path


@pytest.mark.parametrize("axis", ["X", "Y"])
def test_an_x3p_with_positions_given_point_by_point_is_named_not_damaged(tmp_path, axis):
    """An X3P whose x (or y) axis is absolute (AxisType A: a position stored for every point) is
    a valid file SurfaceTopography does not read; it was 'a damaged ... file: copy it again'."""
    import x3pio

    x3pio.write(tmp_path / "good.x3p", rough(16, 20) * 1e-6, x_scale=1e-7, y_scale=1e-7,
                revision=x3pio.Revision.ISO5436_2000)  # fmt: skip
    absolute = rb"\1A"
    rewritten_x3p(tmp_path / "good.x3p", tmp_path / "absolute.x3p",
                  xml=lambda text: re.sub(rb"(<C" + axis.encode() + rb">\s*<AxisType>)I", absolute, text))
    with pytest.raises(ValueError, match=rf"gives its {axis.lower()} positions point by point .* \(not damage\)") as refused:
        SurfaceFile(path=str(tmp_path / "absolute.x3p")).rms_height()
    assert "damaged" not in str(refused.value) and "copy it again" not in str(refused.value)


@pytest.mark.parametrize("lie, said", [
    ({"data": lambda payload: payload + payload[:80]}, "take 2640 bytes, and its description declares 320 points "
                                                       "of data type D (8 bytes each: 2560 bytes)"),
    ({"xml": lambda text: re.sub(rb"(<CZ>\s*<AxisType>A</AxisType>\s*<DataType>)D", rb"\1F", text)},
     "320 points of data type F (4 bytes each: 1280"),
])  # fmt: skip
def test_an_x3p_whose_heights_are_not_the_size_it_declares_is_refused(tmp_path, lie, said):
    """SurfaceTopography's X3P reader reads the first points it needs: a payload longer than
    declared was read without a word, and doubles declared as floats gave heights of 1e37 m."""
    import x3pio

    x3pio.write(tmp_path / "good.x3p", rough(16, 20) * 1e-6, x_scale=1e-7, y_scale=1e-7,
                revision=x3pio.Revision.ISO5436_2000)  # fmt: skip
    assert SurfaceFile(path=str(tmp_path / "good.x3p")).rms_height() < 1e-5
    path = rewritten_x3p(tmp_path / "good.x3p", tmp_path / "lie.x3p", **lie)
    with pytest.raises(ValueError, match=f"a damaged .* file: its binary heights .*{re.escape(said)}"):
        SurfaceFile(path=str(path)).rms_height()


@pytest.mark.parametrize("increment, said", [(b"0", "pixels of 0 x 1e-07 m"), (b"-1e-7", "pixels of -1e-07 x 1e-07 m")])
def test_a_pixel_side_of_zero_or_below_is_named_with_its_unit(tmp_path, increment, said):
    """An X3P whose x increment is 0 or negative: refused as 'pixels of 0 x 1e-07; a pixel's
    size must be > 0', in a unit it did not name (the file's, not the run's: 1e-07 of what?)."""
    import x3pio

    x3pio.write(tmp_path / "good.x3p", rough(16, 20) * 1e-6, x_scale=1e-7, y_scale=1e-7,
                revision=x3pio.Revision.ISO5436_2000)  # fmt: skip
    path = rewritten_x3p(tmp_path / "good.x3p", tmp_path / "zero.x3p",
                         xml=lambda text: re.sub(rb"(<CX>.*?<Increment>)[^<]*", rb"\g<1>" + increment, text, flags=re.S))
    with pytest.raises(ValueError, match=re.escape(said) + r" \(x by y, as the file states them\); a pixel's size must be > 0"):
        SurfaceFile(path=str(path), unit="um").rms_height()


def test_an_x3p_whose_heights_are_not_the_bytes_its_checksum_declares_is_refused(tmp_path):
    """One byte changed in the heights (a damaged copy; the heights still finite) was read
    without a word: SurfaceTopography's reader does not check the MD5 checksum main.xml gives.
    The same file with its checksum mended, or with none declared, is read."""
    import hashlib
    import zipfile

    import x3pio

    x3pio.write(tmp_path / "good.x3p", rough(16, 20) * 1e-6, x_scale=1e-7, y_scale=1e-7,
                revision=x3pio.Revision.ISO5436_2000)  # fmt: skip

    def flipped(payload: bytes) -> bytes:  # the lowest mantissa byte of the first height: still finite
        return bytes([payload[0] ^ 0x01]) + payload[1:]

    damaged = rewritten_x3p(tmp_path / "good.x3p", tmp_path / "damaged.x3p", data=flipped)
    with pytest.raises(ValueError, match=r"a damaged .* file: its binary heights' MD5 checksum is [0-9a-f]{32}, and "
                                         r"its description declares [0-9a-f]{32}; copy it again"):  # fmt: skip
        SurfaceFile(path=str(damaged)).rms_height()
    payload = flipped(zipfile.ZipFile(tmp_path / "good.x3p").read("bindata/data.bin"))
    mended = rewritten_x3p(tmp_path / "good.x3p", tmp_path / "mended.x3p", data=flipped, xml=lambda text: re.sub(
        rb"(<MD5ChecksumPointData>)[0-9a-fA-F]+", rb"\g<1>" + hashlib.md5(payload).hexdigest().upper().encode(), text))
    unsigned = rewritten_x3p(tmp_path / "good.x3p", tmp_path / "unsigned.x3p", data=flipped,
                             xml=lambda text: re.sub(rb"<MD5ChecksumPointData>[^<]*</MD5ChecksumPointData>", b"", text))
    for path in (mended, unsigned):
        assert 0 < SurfaceFile(path=str(path)).rms_height() < 1e-5


# ------------------------------------------------------------ the MDR line of a large scan


def full_plane_line_powers(heights, spacing, periodic):
    """The MDR line's mode powers from every mode of the (reflected, unless periodic) map at once (fft2)."""
    from frictionlab_spectra.equivalent_line import line_grid, line_mode_powers

    extended = heights if periodic else np.block([[heights, heights[:, ::-1]], [heights[::-1, :], heights[::-1, ::-1]]])
    ny, nx = extended.shape
    power = np.abs(np.fft.fft2(extended)) ** 2
    power[0, 0] = 0.0
    wavenumber = np.hypot((2 * np.pi / (ny * spacing) * np.fft.fftfreq(ny, 1.0 / ny))[:, None],
                          (2 * np.pi / (nx * spacing) * np.fft.fftfreq(nx, 1.0 / nx))[None, :])  # fmt: skip
    points, line_spacing = line_grid(heights.size * spacing**2, spacing)
    return line_mode_powers(wavenumber, power, points, line_spacing)


@pytest.mark.parametrize("shape, periodic", [((384, 512), False), ((301, 257), False), ((301, 257), True)])
def test_the_mdr_line_of_a_scan_is_built_in_half_the_memory_with_the_same_modes(tmp_path, monkeypatch, shape, periodic):
    """Every mode of the reflected map at once, the line's allocations peaked at 250 to 310 bytes
    per point of the map (tracemalloc): a 4096 x 2048 scan, ordinary for an AFM, ran out of
    memory under ulimit -v 2 GiB. Half the plane (the map is real), a block of rows at a time,
    gives the same mode powers at about 120. Blocks of 2^14 modes here, so that the rows are
    split into several blocks, one of them short."""
    import tracemalloc

    from frictionlab_spectra import surface_file

    monkeypatch.setattr(surface_file, "MODES_PER_BLOCK", 2**14, raising=False)
    z = rough(*shape, seed=11)
    np.save(tmp_path / "scan.npy", z)
    surface = SurfaceFile(path=str(tmp_path / "scan.npy"), spacing=0.5, periodic=periodic)  # odd sides unreflected
    heights = surface.generate(None).heights
    tracemalloc.start()
    try:
        line = surface.equivalent_line()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    expected = full_plane_line_powers(heights, 0.5, periodic)
    np.testing.assert_allclose(line.params.mode_power, expected, rtol=1e-9, atol=1e-12 * expected.max())
    assert peak < 160 * z.size, f"{peak / z.size:.0f} bytes per point"


# ------------------------------------------------------------ a tilt left in a line


def test_a_line_whose_height_is_mostly_a_tilt_says_so_as_a_map_does(tmp_path):
    """A profile read from a table is levelled by its mean only (the default); a map whose tilt
    carries most of its height variance gets a caveat, a line got none."""
    x = np.arange(300) * 0.2
    z = np.cumsum(rough(1, 300, 12)[0]) * 1e-3 + 0.01 * x
    (tmp_path / "line.csv").write_text("x,z\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(x, z)))
    summary = ProfileFile(path=str(tmp_path / "line.csv")).input_summary()
    share = 1.0 - np.var(z - np.polyval(np.polyfit(x, z, 2), x)) / np.var(z)  # independent: least squares
    assert share > 0.5
    assert summary["detrend"] == "mean" and summary["caveats"] == [
        f"a tilt carries {100 * share:.1f} % of the line's height variance (detrend: mean): the contact sits where "
        "the tilt or the form puts it, not on the roughness; detrend: tilt (or quadratic) levels it"
    ]
    assert "caveats" not in ProfileFile(path=str(tmp_path / "line.csv"), detrend="tilt").input_summary()
    (tmp_path / "level.csv").write_text("".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(x, z - 0.01 * x)))
    assert "caveats" not in ProfileFile(path=str(tmp_path / "level.csv")).input_summary()


def test_a_bowed_line_is_levelled_by_detrend_quadratic_and_a_curvature_left_in_is_said(tmp_path):
    """A bowed scan (a parabola over the roughness): detrend: tilt leaves the bow and says so,
    naming its share of the levelled variance; detrend: quadratic removes the least-squares
    parabola (checked against numpy's polyfit) and says nothing. profile-file had no quadratic
    detrend, so a bowed line could not be levelled."""
    x = np.arange(400) * 0.25
    z = rough(1, 400, 15)[0] + 3e-3 * (x - 37.0) ** 2  # the bow: most, not all, of the variance
    (tmp_path / "bowed.csv").write_text("x,z\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(x, z)))
    path = str(tmp_path / "bowed.csv")
    tilted = ProfileFile(path=path, detrend="tilt").input_summary()
    after_tilt = z - np.polyval(np.polyfit(x, z, 1), x)
    after_bow = z - np.polyval(np.polyfit(x, z, 2), x)
    share = 1.0 - np.var(after_bow) / np.var(after_tilt)
    assert 0.5 < share < 0.95
    assert tilted["caveats"] == [
        f"a curvature carries {100 * share:.1f} % of the levelled line's height variance: the contact sits where the "
        "form puts it; detrend: quadratic removes it, if it is not the surface's own shape"
    ]
    levelled = ProfileFile(path=path, detrend="quadratic")
    assert "caveats" not in levelled.input_summary()
    np.testing.assert_allclose(levelled.generate(None).heights, after_bow, rtol=0, atol=1e-12)
    assert levelled.input_summary()["rms_height"] == pytest.approx(np.std(after_bow), rel=1e-12)
    mean_only = ProfileFile(path=path).input_summary()["caveats"][0]  # tilt and bow left: each its own share
    joint = 1.0 - np.var(after_bow) / np.var(z)
    shares = re.match(r"a (?:curvature|tilt) carries ([\d.]+) % and a (?:tilt|curvature) ([\d.]+) % more of the line's "
                      r"height variance \(detrend: mean\)", mean_only)  # fmt: skip
    assert 0.5 < joint < 0.99 and shares is not None, mean_only
    assert float(shares[1]) + float(shares[2]) == pytest.approx(100 * joint, abs=0.11)


@pytest.mark.parametrize("bow", [0.0, 1e-9])
def test_a_steep_line_with_little_roughness_is_read_not_an_internal_error(tmp_path, capsys, bow):
    """A line whose tilt carries all but 1e-16 of its height variance (3 per point, roughness
    1e-9): the bow's share of what the tilt leaves was curvature / (1 - tilt share), a
    division by rounding; 1 - tilt share was 0 and validate ended in the catch-all internal
    error (exit code 70: ZeroDivisionError). The share is measured on what the tilt leaves:
    none said of a rough line, the share brute force gives of a bowed one."""
    t = np.arange(256.0)
    z = 3.0 * t + 1e-9 * np.random.default_rng(np.random.SeedSequence(0)).standard_normal(t.size) + bow * (t - 100) ** 2
    np.save(tmp_path / "steep.npy", z)
    spec = {"name": "profile-file", "params": {"path": str(tmp_path / "steep.npy"), "spacing": 1e-4, "detrend": "tilt"}}
    (tmp_path / "p.yaml").write_text(yaml.safe_dump({**preset(tmp_path), "spectrum": spec}))
    code = main(["validate", str(tmp_path / "p.yaml")])
    text = capsys.readouterr().err
    assert code == ExitCode.OK, text
    after_tilt = z - np.polyval(np.polyfit(t, z, 1), t)
    share = 1.0 - np.var(z - np.polyval(np.polyfit(t, z, 2), t)) / np.var(after_tilt)  # brute force
    caveats = ProfileFile(**spec["params"]).input_summary().get("caveats", [])
    assert caveats == ([f"a curvature carries {100 * share:.1f} % of the levelled line's height variance: the contact "
                        "sits where the form puts it; detrend: quadratic removes it, if it is not the surface's own "
                        "shape"] if share > 0.5 else []), (share, caveats)  # fmt: skip


@pytest.mark.parametrize("text", ["x,y,z\n", "# a scan\n# exported empty\n", "  \n\n\t\n"])
def test_a_table_of_no_numbers_is_named_as_such_not_as_a_line(tmp_path, text):
    """A table with a header, comments or blank lines only was 'a map of 1 x 0 pixels (x by
    y), one pixel wide: a line; use profile-file', sending the user to a plugin that refuses
    it too ('0 points'); an empty .npy array likewise, by its shape."""
    (tmp_path / "empty.csv").write_text(text)
    with pytest.raises(ValueError, match=r"a table of no numbers \(a header, comments or blank lines only\): no heights"):
        SurfaceFile(path=str(tmp_path / "empty.csv"), spacing=0.1).rms_height()
    np.save(tmp_path / "empty.npy", np.zeros((1, 0)))
    with pytest.raises(ValueError, match=r"an array of shape \(1, 0\): no heights; expected a map of at least 8 x 8"):
        SurfaceFile(path=str(tmp_path / "empty.npy"), spacing=0.1).rms_height()


def test_a_table_of_one_row_is_a_line_for_profile_file(tmp_path):
    """surface-file sends a map one pixel high to profile-file, which refused a single row of
    heights ('50 columns; expected 1 (z) or 2 (x, z)'): each sent the file away."""
    z = rough(1, 50, 13)[0]
    (tmp_path / "row.csv").write_text(",".join(repr(float(v)) for v in z) + "\n")
    with pytest.raises(ValueError, match="one pixel wide: a line; use profile-file"):
        SurfaceFile(path=str(tmp_path / "row.csv"), spacing=0.1).rms_height()
    line = ProfileFile(path=str(tmp_path / "row.csv"), spacing=0.1).generate(None)
    np.testing.assert_allclose(line.heights, z - z.mean(), rtol=0, atol=1e-12)


def test_a_table_under_a_suffix_of_no_format_is_told_format_table(tmp_path):
    """A .tsv of bare numbers was told to be exported again as a .npy, .csv or .txt; format:
    table reads it as it is."""
    z = rough(10, 9, 14)
    (tmp_path / "map.tsv").write_text(matrix_text(z, "\t"))
    with pytest.raises(ValueError, match="a table of bare numbers .* is read with format: table and spacing"):
        SurfaceFile(path=str(tmp_path / "map.tsv"), spacing=0.1).rms_height()
    read = SurfaceFile(path=str(tmp_path / "map.tsv"), spacing=0.1, format="table", detrend="none").generate(None)
    np.testing.assert_allclose(read.heights, z, rtol=0, atol=1e-9)


# ------------------------------------------------------------ a text export's header units


def write_xyz(path, z, pixel, header: bytes) -> None:
    """An x, y, z text export of the map z[y, x] on square pixels, under ``header``."""
    rows = "".join(f"{i * pixel!r}\t{j * pixel!r}\t{float(z[j, i])!r}\n" for j in range(z.shape[0]) for i in range(z.shape[1]))
    path.write_bytes(header + rows.encode())


@pytest.mark.parametrize("plugin", [ProfileFile, SurfaceFile])
def test_a_line_export_whose_x_is_not_evenly_spaced_is_named_not_an_internal_error(tmp_path, capsys, plugin):
    """An x, z text export whose x steps unevenly (one point 0.01 um off a step of 0.05 um):
    SurfaceTopography reads it as a non-uniform line scan, which has no pixel, and validate
    ended in the catch-all internal error (exit code 70: AttributeError 'pixel_size'). Refused
    by name, by either plugin; the same line evenly spaced is read by profile-file."""
    x = np.arange(200) * 0.05
    z = rough(1, 200, 23)[0] * 0.01
    uneven = x.copy()
    uneven[70] += 0.01
    for name, xs in (("uneven", uneven), ("even", x)):
        (tmp_path / f"{name}.xyz").write_text("".join(f"{float(a)!r}\t{float(b)!r}\n" for a, b in zip(xs, z)))
    params = {"path": str(tmp_path / "uneven.xyz"), "unit": "um"}
    (tmp_path / "p.yaml").write_text(yaml.safe_dump({**preset(tmp_path), "spectrum": {"name": plugin.name, "params": params}}))
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "a line scan whose 200 points are not evenly spaced along x; heights are pressed on a uniform grid" in err, err
    line = ProfileFile(path=str(tmp_path / "even.xyz"), unit="um", detrend="mean").generate(None)
    assert line.spacing == pytest.approx(0.05, rel=1e-9) and line.heights.size == 200


def test_a_line_export_in_metres_whose_x_is_uneven_is_refused_as_a_tables_is(tmp_path):
    """SurfaceTopography takes an x, z export's x as even when its steps differ by under 1e-6
    in the file's unit: in metres, any x. A line of 0.1 um steps with one point 0.03 um off
    (or x at random) was pressed as if even, without a word; a table's x within 0.1 % of a
    step is the rule, and it is now the export's too. The even line is read."""
    x = np.arange(256) * 1e-7
    z = rough(1, 256, 24)[0] * 1e-8
    jittered = x.copy()
    jittered[50] += 3e-8
    for name, xs in (("jittered", jittered), ("even", x)):
        (tmp_path / f"{name}.xyz").write_text("x\tz\n" + "".join(f"{float(a)!r}\t{float(b)!r}\n" for a, b in zip(xs, z)))
    with pytest.raises(ValueError, match=r"x is not uniformly spaced: .* \(0.3 spacings; tolerance 0.001\)"):
        ProfileFile(path=str(tmp_path / "jittered.xyz"), unit="m").rms_height()
    line = ProfileFile(path=str(tmp_path / "even.xyz"), unit="m", detrend="mean").generate(None)
    assert line.spacing == pytest.approx(1e-7, rel=1e-9) and line.heights.size == 256


@pytest.mark.parametrize("header", [
    "# x [µm]\ty [µm]\tz [nm]\n".encode(), b"x (um), y (um), z (nm)\n", b"# x/mm y/mm z/um\n",
])  # fmt: skip
def test_a_text_export_whose_header_names_two_length_units_is_refused(tmp_path, header):
    """SurfaceTopography's XYZ reader skips the header: lateral positions in µm and heights in nm
    were read as bare numbers in one unit, every slope a thousand times off, and the scan said
    'no unit (bare numbers)' only. Refused, naming the units; one unit for all is read."""
    z = rough(8, 9, 16)
    write_xyz(tmp_path / "scan.xyz", z, 0.5, header)
    with pytest.raises(ValueError, match=r"its header names the length units (um, nm|mm, um), .* convert the columns"):
        SurfaceFile(path=str(tmp_path / "scan.xyz")).rms_height()
    write_xyz(tmp_path / "same.xyz", z, 0.5, header.replace(b"nm", b"um").replace(b"z/um", b"z/mm"))
    read = SurfaceFile(path=str(tmp_path / "same.xyz"), detrend="none").generate(None)
    np.testing.assert_allclose(read.heights, z, rtol=0, atol=1e-12)
    assert read.spacing == pytest.approx(0.5, rel=1e-12)


def test_a_text_export_in_latin_1_is_told_to_be_saved_as_utf_8(tmp_path):
    """An export whose header is Latin-1 (its "\\xb5m") failed in the reader and was called a
    damaged file, to be copied again from the instrument, which no copy mends."""
    write_xyz(tmp_path / "scan.xyz", rough(8, 9, 17), 0.5, "# x [\xb5m]\ty [\xb5m]\tz [\xb5m]\n".encode("latin-1"))
    with pytest.raises(ValueError, match="a text export that is not UTF-8 .* save it as UTF-8"):
        SurfaceFile(path=str(tmp_path / "scan.xyz")).rms_height()


@pytest.mark.parametrize("text", ["# x [um]\ty [um]\tz [um]\n", "# x y z\nx y z\n"])
def test_an_xyz_export_of_a_header_alone_is_not_told_it_is_latin_1(tmp_path, text):
    """An x, y, z export of UTF-8 text with no points (a header alone) was told to be 'not UTF-8 (a header
    in Latin-1: its µ?)', the reader's guess at another encoding taken for the file's: it holds no points."""
    (tmp_path / "scan.xyz").write_text(text, encoding="utf-8")
    with pytest.raises(ValueError) as said:
        SurfaceFile(path=str(tmp_path / "scan.xyz")).rms_height()
    assert "holds no points its reader can read (it is UTF-8 text" in str(said.value)
    assert "Latin-1" not in str(said.value)


def test_a_table_with_a_latin_1_header_is_told_to_be_saved_as_utf_8(tmp_path):
    """A matrix of heights under a Latin-1 header ('H\\xf6he (\\xb5m)', as a European spreadsheet
    saves it) was 'not a text file ... read with format: instrument' only; that sends the table
    to the x, y, z reader, which calls it a damaged file to be copied again from the
    instrument. The message names the table's own remedy, and the table saved as UTF-8 is read."""
    z = rough(9, 8, 21)
    header = "H\xf6he (\xb5m)\n"
    (tmp_path / "map.csv").write_bytes(header.encode("latin-1") + matrix_text(z).encode())
    with pytest.raises(ValueError, match=r"not UTF-8 at line 1 .* a table of bare numbers is read as UTF-8: save it so"):
        SurfaceFile(path=str(tmp_path / "map.csv"), spacing=0.1).rms_height()
    (tmp_path / "map.csv").write_bytes(header.encode("utf-8") + matrix_text(z).encode())
    read = SurfaceFile(path=str(tmp_path / "map.csv"), spacing=0.1, detrend="none").generate(None).heights
    np.testing.assert_allclose(read, z, atol=1e-9)


@pytest.mark.parametrize(("text", "line"), [
    ("0.1,0.2,0.3,\n0.4,0.5,0.6,\n0.7,0.8,0.1,\n", 1), ("0.1;0.2;0.3;\n0.4;0.5;0.6;\n0.7;0.8;0.1;\n", 1),
    ("0.1,0.2,0.3\n0.4,0.5,0.6,\n0.7,0.8,0.1\n", 2), ("x,y,z\n0.1,0.2,0.3,\n0.4,0.5,0.6,\n", 2),
])  # fmt: skip
def test_a_table_whose_lines_end_with_a_separator_is_told_so(tmp_path, text, line):
    """A trailing separator (an empty last column) on the first line made it a header, dropped
    without a word, and the table was refused as 'non-numeric content at line 2'."""
    (tmp_path / "map.csv").write_text(text)
    with pytest.raises(ValueError, match=rf"line {line} ends with a separator \((comma|semicolon)\), an empty column"):
        SurfaceFile(path=str(tmp_path / "map.csv"), spacing=0.1).rms_height()


def _npz_as_npy(path, z):
    np.savez(path.with_suffix(".npz"), z=z)
    path.with_suffix(".npz").rename(path)


def _trailing_bytes(path, z):
    np.save(path, z)
    with path.open("ab") as fh:
        fh.write(np.zeros(3).tobytes())


def _cut_short(path, z):
    np.save(path, z)
    with path.open("r+b") as fh:
        fh.truncate(path.stat().st_size - 8)


def _negative_shape(path, z):
    np.save(path, z)
    data = path.read_bytes()
    declared = str(z.shape).encode()
    negative = b"(-" + declared[1:]  # the first side made negative, a space dropped: the header's length kept
    head = data[: 10 + int.from_bytes(data[8:10], "little")]
    forged = head.replace(declared + b", }", negative + b",}")
    assert forged != head and len(forged) == len(head)
    path.write_bytes(forged + data[len(head):])


@pytest.mark.parametrize(("write", "said"), [
    (_negative_shape, "a damaged .npy file: its header declares an array of shape NEGATIVE, a negative number of "
                      "points; save the array again"),  # was '(-BYTES bytes)'
    (_npz_as_npy, "an .npz archive (arrays zipped together), not a .npy array; save the heights alone with numpy.save"),
    (_trailing_bytes, "a damaged .npy file: its header declares an array of shape SHAPE of float64 (BYTES bytes), but the "
                      "file holds BYTES+24 bytes after it"),
    (_cut_short, "a damaged .npy file: its header declares an array of shape SHAPE of float64 (BYTES bytes), but the "
                 "file holds BYTES-8 bytes after it"),
    (lambda path, z: np.save(path, (z * 1000).astype("timedelta64[s]")),
     "non-numeric content (array dtype timedelta64[s]); expected real numbers"),
    (lambda path, z: np.save(path, z.astype(object), allow_pickle=True),  # was 'not a readable .npy array (ValueError)'
     "an array of Python objects (dtype object), which is never unpickled (that could run code); expected real numbers"),
])  # fmt: skip
@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_a_npy_that_is_not_one_array_of_numbers_as_its_header_says_is_named(tmp_path, write, said, plugin):
    """An .npz saved under .npy ended in the catch-all internal error (np.load gives an archive,
    which has no dtype); bytes after the array, which np.load leaves unread, were taken
    without a word; a file cut short was 'not a readable .npy array'; durations were heights."""
    z = rough(12, 10, 18) if plugin is SurfaceFile else rough(1, 40, 18)[0]
    write(tmp_path / "heights.npy", z)
    said = said.replace("SHAPE", str(z.shape)).replace("BYTES+24", f"{z.nbytes + 24:,}")
    said = said.replace("BYTES-8", f"{z.nbytes - 8:,}").replace("BYTES", f"{z.nbytes:,}")
    said = said.replace("NEGATIVE", str((-z.shape[0], *z.shape[1:])))
    with pytest.raises(ValueError) as info:
        plugin(path=str(tmp_path / "heights.npy"), spacing=0.1).rms_height()
    assert said in str(info.value)



@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_an_npz_of_no_two_dimensional_array_is_named_as_such_not_as_damage(tmp_path, plugin):
    """A line saved with numpy.savez (a valid archive, of a 1-D array) was 'not a valid NumPy
    array archive (NPZ) file ...: copy it again from the instrument', as if damaged; an array's
    header too long to read (forged) is named as of unknown shape, its bytes never read whole."""
    import zipfile

    np.savez(tmp_path / "line.npz", z=rough(1, 40, 18)[0], cube=np.zeros((2, 3, 4)))
    with zipfile.ZipFile(tmp_path / "line.npz", "a") as archive:
        archive.writestr("forged.npy", b"\x93NUMPY\x02\x00" + (2**31).to_bytes(4, "little") + bytes(100))
    with pytest.raises(ValueError) as info:
        plugin(path=str(tmp_path / "line.npz"), spacing=0.1).rms_height()
    said = str(info.value)
    assert "file holds no two-dimensional array, the only kind SurfaceTopography reads from one (its arrays: 'z' of " \
           "shape (40,), 'cube' of shape (2, 3, 4), 'forged' of shape unknown; not damage): save a map as a 2D array, a " \
           "line as .npy (np.save) or a column of text for profile-file" in said, said
    assert "copy it again" not in said


def _header_of(text: bytes, version: bytes = b"\x01\x00") -> bytes:
    """A .npy header holding ``text``, padded as numpy pads one (to 64 bytes, a newline last)."""
    body = text + b" " * (-(10 + len(text) + 1) % 64) + b"\n"
    return b"\x93NUMPY" + version + len(body).to_bytes(2, "little") + body


@pytest.mark.parametrize(("content", "said"), [
    (b"hello world" * 20, "not a .npy file (it does not start as numpy.save writes one); save the heights with "
                          "numpy.save, or as a .csv/.txt table of numbers"),
    (_header_of(b"{'descr': '<f8', 'fortran_order': 'yes', 'shape': (12, 10)}") + bytes(960),
     "a damaged .npy file: numpy cannot read its header (fortran_order is not a valid bool); save the array again"),
    (_header_of(b"{'descr': '<f8', 'fo\xfftran_order': False, 'shape': (12, 10)}") + bytes(960),  # the file's text unquoted
     "numpy cannot read its header (its keys are not numpy's descr, fortran_order and shape); save the array again"),
    (b"\x93NUMPY\x09\x00" + bytes(200), "numpy cannot read its header (we only support format version (1,0), (2,0), "
                                        "and (3,0), not (9, 0))"),
    (_header_of(b"{'descr': '<f8', 'fortran_order': False, 'shape': (12, 10)") + bytes(960),  # its } cut
     "numpy cannot read its header (it is not a whole Python dictionary: cut short or edited)"),  # was the tokenizer's tuple
], ids=["no-npy", "header", "keys", "version", "cut-header"])  # fmt: skip
@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_a_npy_numpy_cannot_read_is_told_why(tmp_path, content, said, plugin):
    """A file that is no .npy at all, and one whose header numpy refuses, were both 'not a
    readable .npy array (ValueError)': the exception's name, not what is wrong nor what to do."""
    (tmp_path / "heights.npy").write_bytes(content)
    with pytest.raises(ValueError) as info:
        plugin(path=str(tmp_path / "heights.npy"), spacing=0.1).rms_height()
    assert said in str(info.value)


@pytest.mark.parametrize("xres", [-10, 0])
def test_a_header_declaring_a_side_of_fewer_than_one_point_is_damage(tmp_path, xres):
    """A Gwyddion header of -10 x 12 points over 120 heights was read as 10 x 12 without a word
    (its reader reshapes to -10, which numpy infers); 0 was 'a damaged Gwyddion file (ValueError)'."""
    write_gwy(tmp_path / "scan.gwy", rough(12, 10, 19), 1e-7, 1e-7, xres=xres)
    with pytest.raises(ValueError, match=rf"the file declares {xres} x 12 points \(x by y\), a side of fewer than 1: "
                                         "a damaged header"):
        SurfaceFile(path=str(tmp_path / "scan.gwy"), unit="um").rms_height()


@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_a_tables_nan_is_filled_under_undefined_harmonic(tmp_path, plugin):
    """undefined: harmonic filled only what an instrument file leaves undefined; a table's NaN was
    refused with the very words said without it, as if the preset had not asked to fill them."""
    z = rough(12, 10, 20) if plugin is SurfaceFile else rough(1, 40, 20)[0]
    z.flat[5] = np.nan
    np.save(tmp_path / "heights.npy", z)
    asked = plugin(path=str(tmp_path / "heights.npy"), spacing=0.1, undefined="harmonic", detrend="none")
    assert np.isfinite(asked.generate(None).heights).all()
    assert asked.input_summary()["undefined_points"] == 1 and asked.input_summary()["filled_by"] == "harmonic"
    with pytest.raises(ValueError) as not_asked:
        plugin(path=str(tmp_path / "heights.npy"), spacing=0.1).rms_height()
    assert "1 value(s) in heights not finite" in str(not_asked.value)
    assert "set undefined: harmonic to fill NaN (points not measured)" in str(not_asked.value)
    assert "or leave them out with region" in str(not_asked.value)  # either crops


# ------------------------------------------------------------ a table too large to read


@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_a_table_too_large_to_read_is_refused_by_its_size(tmp_path, monkeypatch, plugin):
    """A table has no header that gives its size, and was read whole: a 1 TB .csv (sparse) under
    ulimit -v ended `frictionlab validate` with 'out of memory; ask for fewer points,
    realizations or workers', the file unnamed and the advice wrong, and without a limit tried
    to read a terabyte. Now refused before it is read when its numbers (counted per byte in its
    first bytes, 8 bytes each, three copies) cannot fit, and named if it runs out while being read."""
    import frictionlab_spectra.text_table as tables
    from frictionlab_spectra.instrument_reader import HEIGHT_COPIES

    z = rough(12, 10, 9) if plugin is SurfaceFile else rough(1, 40, 9)
    (tmp_path / "map.csv").write_text(matrix_text(z))
    copies = HEIGHT_COPIES if plugin is SurfaceFile else tables.TABLE_COPIES  # a map's levelling holds more
    size, need = (tmp_path / "map.csv").stat().st_size, z.size * 8 * copies
    monkeypatch.setattr(tables, "room_to_read", lambda: (need - 1, "the room in this test"))
    with pytest.raises(ValueError, match=rf"a table of {size:,} bytes; reading its numbers takes about .* GiB, more than "
                                         r"the .* GiB this process may use \(the room in this test\): save the heights as "
                                         r"a \.npy array"):
        plugin(path=str(tmp_path / "map.csv"), spacing=0.1).rms_height()
    monkeypatch.setattr(tables, "room_to_read", lambda: (need, "the room in this test"))
    assert plugin(path=str(tmp_path / "map.csv"), spacing=0.1).rms_height() > 0  # room for its copies: read

    def out_of_memory(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(np, "loadtxt", out_of_memory)
    (tmp_path / "again.csv").write_text(matrix_text(z))  # another file: the first one's heights are cached
    with pytest.raises(ValueError, match=rf"a table of {size:,} bytes; reading it ran out of memory: save the heights"):
        plugin(path=str(tmp_path / "again.csv"), spacing=0.1).rms_height()


@pytest.mark.parametrize("columns", [1, 400])
def test_a_table_is_read_in_memory_of_its_numbers_not_of_its_text(tmp_path, columns):
    """A text table was read whole, decoded and split into lines: 3 times its bytes for a matrix
    and 5.5 for a column, 17 times its numbers (a 280 MB column of heights ran out of memory under
    ulimit -v 1048576 for 88 MB of numbers). It is read a line at a time: its numbers' bytes, and
    numpy's spare room while it grows them."""
    import tracemalloc

    from frictionlab_spectra.text_table import read_text_table

    z = np.random.default_rng(3).normal(size=(200_000 // columns, columns))
    np.savetxt(tmp_path / "z.txt", z)
    tracemalloc.start()
    try:
        read = read_text_table(tmp_path / "z.txt", "z.txt")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    np.testing.assert_array_equal(read, z)  # savetxt's 18 digits: the same numbers
    assert peak < 2 * z.nbytes < (tmp_path / "z.txt").stat().st_size, (peak, z.nbytes)
