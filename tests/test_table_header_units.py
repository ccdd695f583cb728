"""A table's numbers are read bare; what its header says of their units is checked against
the preset: an instrument's text export whose header states its size (Gwyddion's), columns
in different length units (a profilometer's x in mm, z in um), or a unit other than the
preset's. Each was read as bare numbers in the preset's unit, without a word, every slope or
height off by the units' ratio."""

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


def gwyddion_text(path, z_um, pixel_um: float, value_unit: str = "m", scale: float = 1e-6):
    """A map z[y, x] in um as Gwyddion's plain-text export writes it: its size in µm, values in ``value_unit``."""
    ny, nx = z_um.shape
    header = (f"# Channel: Height\n# Width: {nx * pixel_um:.3f} µm\n# Height: {ny * pixel_um:.3f} µm\n"
              f"# Value units: {value_unit}\n")  # fmt: skip
    rows = "".join(" ".join(f"{v * scale:.9e}" for v in row) + "\n" for row in z_um)
    path.write_text(header + rows, encoding="utf-8")
    return path


def test_an_instrument_text_export_read_as_a_table_is_told_to_be_read_as_one(tmp_path, capsys):
    """Gwyddion's .txt export, read by suffix as a table with spacing 0.1 and unit um, had its
    heights in metres taken as micrometres: an rms height of 1e-6 um, validated as 'ok'."""
    z = rough(16, 24)
    path = gwyddion_text(tmp_path / "scan.txt", z, 0.1)
    spectrum = {"name": "surface-file", "params": {"path": str(path), "spacing": 0.1, "unit": "um"}}
    preset = {"name": "gwy", "realizations": 1, "spectrum": spectrum, "solver": {"name": "mdr"},
              "loading": {"start": 0.01, "stop": 0.1, "steps": 3, "unit": "f"}}  # fmt: skip
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset))
    code = main(["validate", str(tmp_path / "p.yaml")])
    text = "".join(capsys.readouterr())
    assert code == ExitCode.USAGE, text
    assert "its header states the scan's units (um, m)" in text and "format: instrument" in text
    assert "Traceback" not in text
    read = SurfaceFile(path=str(path), unit="um", format="instrument", detrend="none").generate(None)
    assert read.spacing == pytest.approx(0.1, rel=1e-9)
    np.testing.assert_allclose(read.heights, z, rtol=1e-8, atol=1e-8)
    bare = SurfaceFile(path=str(path), spacing=0.1, format="table", detrend="none").generate(None)  # asked for
    np.testing.assert_allclose(bare.heights, z * 1e-6, rtol=1e-8, atol=1e-14)


def test_a_profile_with_x_and_z_in_different_units_is_refused(tmp_path):
    """A profilometer's export, x in mm and z in um: the pixel was read as 0.0005 'um', every
    slope a thousand times too steep, and pressures of 20 E* validated as 'ok'."""
    x = np.arange(64) * 0.5
    z = rough(1, 64, 2)[0]
    for name, header, scale in (("mixed.csv", "x [mm],z [um]", 1e-3), ("same.csv", "x [um],z [um]", 1.0),
                                ("road.csv", "x [km],z [mm]", 1e-6)):  # fmt: skip
        (tmp_path / name).write_text(header + "\n" + "".join(f"{float(a * scale)!r},{float(b)!r}\n" for a, b in zip(x, z)))
    with pytest.raises(ValueError, match=r"its header names the length units mm, um, .* convert the columns"):
        ProfileFile(path=str(tmp_path / "mixed.csv"), unit="um").rms_height()
    # a road profile's x in km beside z in mm: km was no unit it knew, so the mm alone read as the table's one unit
    with pytest.raises(ValueError, match=r"its header names the length units km, mm, .* convert the columns"):
        ProfileFile(path=str(tmp_path / "road.csv")).rms_height()
    line = ProfileFile(path=str(tmp_path / "same.csv"), unit="um").generate(None)
    assert line.spacing == pytest.approx(0.5, rel=1e-12) and line.heights.size == 64


@pytest.mark.parametrize("header", ["z [nm]", "# heights (nm)", "Höhe/nm"])
def test_a_table_whose_header_names_another_unit_than_the_presets_is_refused(tmp_path, header):
    z = rough(10, 12, 3)
    (tmp_path / "m.csv").write_text(header + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n" for row in z),
                                    encoding="utf-8")  # fmt: skip
    with pytest.raises(ValueError, match=r"its header names the length unit nm, which a table's reader does not read: .* the preset's unit, um; set unit: nm"):
        SurfaceFile(path=str(tmp_path / "m.csv"), spacing=0.1, unit="um").rms_height()
    for unit in ("nm", None):
        assert SurfaceFile(path=str(tmp_path / "m.csv"), spacing=0.1, unit=unit).generate(None).heights.shape == (10, 12)


@pytest.mark.parametrize("label", ["micron", "\u00b5m", "\u03bcm"])
def test_micrometres_spelled_as_instruments_do_are_micrometres(tmp_path, label):
    x = np.arange(32) * 0.5
    rows = "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(x, rough(1, 32)[0]))
    for name, z_unit in (("nm.csv", "nm"), ("um.csv", "um")):
        (tmp_path / name).write_text(f"x [{label}],z [{z_unit}]\n" + rows, encoding="utf-8")
    with pytest.raises(ValueError, match=r"its header names the length units um, nm"):
        ProfileFile(path=str(tmp_path / "nm.csv"), unit="um").rms_height()
    assert ProfileFile(path=str(tmp_path / "um.csv"), unit="um").generate(None).spacing == pytest.approx(0.5)


def write_points(path, z, dx: float, dy: float, header: str = "# x [um]\ty [um]\tz [um]\n") -> None:
    """A map z[y, x] as an export of x, y, z per point, a row of the map after another."""
    ny, nx = z.shape
    rows = "".join(f"{i * dx:.6f}\t{j * dy:.6f}\t{float(z[j, i])!r}\n" for j in range(ny) for i in range(nx))
    path.write_text(header + rows, encoding="utf-8")


def test_an_export_of_points_named_txt_is_read_as_points_not_as_a_matrix(tmp_path):
    """format: instrument promises an export of x, y, z per line under .csv or .txt; under .txt it
    went to the reader of matrices, which read its three columns as a map 3 pixels wide ('map of 3 x
    120 pixels; at least 8 x 8'), and a line's x, z as damage ('a damaged Plain text file')."""
    z = rough(10, 12, 4)
    write_points(tmp_path / "map.txt", z, 0.1, 0.25)
    read = SurfaceFile(path=str(tmp_path / "map.txt"), format="instrument", unit="um", spacing=0.1, detrend="none")
    np.testing.assert_allclose(read.generate(None).heights, z, rtol=0, atol=1e-12)
    resampled = SurfaceFile(path=str(tmp_path / "map.txt"), format="instrument", unit="um").input_summary()
    assert "0.1 x 0.25 resampled onto square pixels of 0.1" in resampled["pixels"]
    x, line = np.arange(40) * 0.5, rough(1, 40, 5)[0]
    (tmp_path / "line.txt").write_text("x [um]\tz [um]\n" + "".join(f"{a:.3f}\t{float(b)!r}\n" for a, b in zip(x, line)))
    profile = ProfileFile(path=str(tmp_path / "line.txt"), format="instrument", unit="um", detrend="none").generate(None)
    assert profile.spacing == pytest.approx(0.5, rel=1e-9)
    np.testing.assert_allclose(profile.heights, line, rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match=r"map of 3 x 120 pixels .* columns of x, y and z per point .* format: instrument"):
        SurfaceFile(path=str(tmp_path / "map.txt"), spacing=0.1).rms_height()  # a table, by its suffix


def test_a_text_export_in_another_unit_than_the_presets_is_refused(tmp_path):
    """An x, y, z export whose header says um, read with unit: nm, had its numbers taken as nm."""
    z = rough(9, 10, 6)
    write_points(tmp_path / "scan.xyz", z, 0.5, 0.5)
    with pytest.raises(ValueError, match=r"header names the length unit um, which SurfaceTopography's .* reader does not "
                       r"read: .* the preset's unit, nm; set unit: um"):  # fmt: skip
        SurfaceFile(path=str(tmp_path / "scan.xyz"), unit="nm").rms_height()
    assert SurfaceFile(path=str(tmp_path / "scan.xyz"), unit="um").generate(None).spacing == pytest.approx(0.5)


def test_a_channel_that_is_not_heights_asked_by_name_is_told_why_it_is_not_listed(tmp_path):
    """Gwyddion's export of Height, Phase (deg) and a retrace: asking for 'Phase' listed the two
    height channels as if the file had no Phase."""
    z = rough(12, 16, 7)
    blocks = []
    for name, unit, data in (("Height", "m", z * 1e-6), ("Phase", "deg", z * 40), ("Height retrace", "m", z * 1e-6)):
        rows = "".join(" ".join(f"{v:.9e}" for v in row) + "\n" for row in data)
        blocks.append(f"# Channel: {name}\n# Width: 1.6 µm\n# Height: 1.2 µm\n# Value units: {unit}\n{rows}")
    (tmp_path / "three.txt").write_text("".join(blocks), encoding="utf-8")
    with pytest.raises(ValueError, match=r"no channel named 'Phase'; the file has 0: 'Height', 1: 'Height retrace' "
                       r"\(most readers list channels of heights only: one in degrees, volts or no unit may be left out\)"):  # fmt: skip
        SurfaceFile(path=str(tmp_path / "three.txt"), format="instrument", channel="Phase").rms_height()
    retrace = SurfaceFile(path=str(tmp_path / "three.txt"), format="instrument", channel="Height retrace", unit="um")
    assert retrace.generate(None).spacing == pytest.approx(0.1, rel=1e-9)


@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
def test_a_scan_flat_but_for_rounding_is_not_said_to_have_an_rms_height_of_zero(tmp_path, plugin):
    """5 + 1e-14 noise is refused as flat, as it should be, but was said to have 'rms height zero'."""
    noise = np.random.default_rng(0).normal(size=(16, 16) if plugin is SurfaceFile else 64)
    np.save(tmp_path / "flat.npy", 5.0 + 1e-14 * noise)
    with pytest.raises(ValueError, match=r"is constant \(rms height \d\.\d+e-1[45] after detrend='mean', below 1e-12 of its "
                       r"largest height 5: the rounding of its numbers\)"):  # fmt: skip
        plugin(path=str(tmp_path / "flat.npy"), spacing=1.0).rms_height()
    np.save(tmp_path / "zero.npy", np.zeros_like(noise))
    with pytest.raises(ValueError, match=r"is constant \(rms height zero after detrend='mean'\)"):
        plugin(path=str(tmp_path / "zero.npy"), spacing=1.0).rms_height()


def test_a_text_export_whose_unit_is_spelled_micron_is_not_called_damaged(tmp_path):
    """'# Width: 1.6 micron' (or values in 'microns') is a unit SurfaceTopography's reader does not
    know: the file was 'a damaged Plain text file', to be copied again from the instrument."""
    rows = "".join(" ".join(f"{v:.9e}" for v in row) + "\n" for row in rough(12, 16, 8))
    for name, width, values in (("lateral.txt", "micron", "µm"), ("values.txt", "µm", "microns")):
        header = f"# Channel: Height\n# Width: 1.6 {width}\n# Height: 1.2 {width}\n# Value units: {values}\n"
        (tmp_path / name).write_text(header + rows, encoding="utf-8")
    with pytest.raises(ValueError) as lateral:
        SurfaceFile(path=str(tmp_path / "lateral.txt"), format="instrument").rms_height()
    assert "its header names the lateral unit 'micron', which SurfaceTopography's Plain text reader does not know " \
        "(not damage); write it as one it knows: m, mm, µm (or um)" in str(lateral.value)  # fmt: skip
    with pytest.raises(ValueError) as values:
        SurfaceFile(path=str(tmp_path / "values.txt"), format="instrument").rms_height()
    assert "holds no channel of heights its reader knows" in str(values.value) and "'micron'" in str(values.value)
    assert "damaged" not in str(lateral.value) + str(values.value)


def test_a_header_stating_other_lengths_is_no_instrument_export(tmp_path):
    """'# Cutoff: 0.8 mm' (a filter's wavelength) or '# Probe radius: 2 um' above a profile in um
    is no statement of the numbers' units: read as the table it is."""
    x = np.arange(32) * 0.5
    rows = "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(x, rough(1, 32, 9)[0]))
    (tmp_path / "p.csv").write_text("# Cutoff: 0.8 mm\n# Probe radius: 2 um\nx [um],z [um]\n" + rows, encoding="utf-8")
    assert ProfileFile(path=str(tmp_path / "p.csv"), unit="um").generate(None).spacing == pytest.approx(0.5)


def test_keys_in_any_case_units_as_written(tmp_path):
    """Keys are matched in any case ('Value Units'); units only as written: 'MM' is no unit (it was
    looked up as one, a KeyError: an internal error)."""
    from frictionlab_spectra.header_units import named_units

    assert named_units("# WIDTH: 25.6 MM\n# value units: M\n1 2\n") == ([], False)
    assert named_units("# Width: 2 µm\n# Value Units: m\n1\n") == (["um", "m"], True)


@pytest.mark.parametrize("header, named", [("x [in],z [uin]", "in"), ("x [mm],z [\u00b5in]", "\u00b5in"),
                                           ("x (inch), z (mil)", "inch"), ("z/in", "in"),
                                           ("x [ft],z [um]", "ft"), ("x (feet), z (mm)", "feet")])  # fmt: skip
def test_a_header_in_inches_is_refused_not_read_bare(tmp_path, header, named):
    """A US profilometer's export in inches and microinches: the units were not known, so not
    counted, and the numbers were read bare in the preset's unit ('x [mm],z [µin]' with unit: mm
    took every height in µin for mm) without a word."""
    columns = 1 if "," not in header else 2
    rows = "".join(",".join([f"{i * 0.5!r}", repr(float(v))][-columns:]) + "\n" for i, v in enumerate(rough(1, 32)[0]))
    (tmp_path / "in.csv").write_text(header + "\n" + rows, encoding="utf-8")
    for unit in ("mm", None):
        with pytest.raises(ValueError, match=rf"its header names the length unit '{named}', .* convert the columns to one of m, mm"):
            ProfileFile(path=str(tmp_path / "in.csv"), unit=unit, spacing=0.5).rms_height()
    heights = "".join(f"{float(v)!r}\n" for v in rough(1, 32)[0])
    (tmp_path / "word.csv").write_text("z (in um)\n" + heights)  # "in" as a word, not a unit
    assert ProfileFile(path=str(tmp_path / "word.csv"), unit="um", spacing=0.5).generate(None).heights.size == 32


def test_a_table_takes_the_length_unit_its_header_names_when_the_preset_gives_none(tmp_path, capsys):
    """'x [um],z [um]' or 'z [nm]' over a table with no unit in the preset: the numbers were
    taken as bare numbers ('no unit') without a word; the header's unit is theirs, and said so."""
    x, z = np.arange(32) * 0.5, rough(1, 32, 10)[0]
    (tmp_path / "line.csv").write_text("x [um],z [um]\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(x, z)))
    (tmp_path / "map.csv").write_text("z [nm]\n" + "".join(",".join(map(repr, row.tolist())) + "\n" for row in rough(9, 10)))
    (tmp_path / "bare.csv").write_text("x,z\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(x, z)))
    line = ProfileFile(path=str(tmp_path / "line.csv")).input_summary()
    assert (line["unit"], line["unit_from"], line["spacing"]) == ("um", "header", pytest.approx(0.5))
    surface = SurfaceFile(path=str(tmp_path / "map.csv"), spacing=0.1).input_summary()
    assert (surface["unit"], surface["unit_from"]) == ("nm", "header")
    bare = ProfileFile(path=str(tmp_path / "bare.csv")).input_summary()  # no unit named: as before
    assert (bare["unit"], bare["unit_from"]) == (None, "none")
    given = ProfileFile(path=str(tmp_path / "line.csv"), unit="\u00b5m").input_summary()
    assert (given["unit"], given["unit_from"]) == ("um", "preset")
    spectrum = {"name": "profile-file", "params": {"path": str(tmp_path / "line.csv")}}
    preset = {"name": "line", "realizations": 1, "spectrum": spectrum, "solver": {"name": "mdr"},
              "loading": {"start": 0.01, "stop": 0.1, "steps": 3, "unit": "f"}}  # fmt: skip
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset))
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.OK
    assert "32 points of 0.5 um (from the file), rms height" in (out := capsys.readouterr().out)
    assert "unit um from the file's header" in out and "no unit" not in out


def test_an_export_read_as_a_table_takes_the_unit_its_header_states_for_its_values(tmp_path):
    """Gwyddion's export read with format: table: its values in nm were bare numbers without a
    word, and with unit: um taken as micrometres; its sizes' unit (Width: µm) is no height's."""
    path = gwyddion_text(tmp_path / "scan.txt", rough(12, 16, 11), 0.1, value_unit="nm", scale=1e3)
    read = SurfaceFile(path=str(path), spacing=100.0, format="table").input_summary()
    assert (read["unit"], read["unit_from"]) == ("nm", "header")
    with pytest.raises(ValueError, match=r"its header names the length unit nm, .* the preset's unit, um; set unit: nm"):
        SurfaceFile(path=str(path), spacing=0.1, unit="um", format="table").rms_height()
    assert SurfaceFile(path=str(path), spacing=100.0, unit="nm", format="table").input_summary()["unit_from"] == "preset"


def test_a_text_export_takes_the_unit_its_header_names_when_its_reader_gives_none(tmp_path):
    """An x, y, z export under '# x [um] y [um] z [um]' read with no unit: SurfaceTopography's
    reader skips the header, and the scan was 'no unit (bare numbers)'."""
    z = rough(9, 10, 12)
    write_points(tmp_path / "scan.xyz", z, 0.5, 0.5)
    read = SurfaceFile(path=str(tmp_path / "scan.xyz"), detrend="none")
    summary = read.input_summary()
    assert (summary["unit"], summary["unit_from"]) == ("um", "header")
    np.testing.assert_allclose(read.generate(None).heights, z, rtol=0, atol=1e-12)  # as read: not converted


@pytest.mark.parametrize("last, said", [("# Value units: nm", "its header states the scan's units \\(nm\\)"),
                                        ("z [nm]", "its header names the length unit nm")])  # fmt: skip
def test_a_unit_named_past_the_first_4_kb_of_a_long_header_is_still_read(tmp_path, last, said):
    """100 comment lines (6.5 kB) before the line naming the unit: only the first 4 kB were looked
    at, and the numbers, in nm, were taken in the preset's um without a word."""
    comments = "".join(f"# instrument setting {i}: {'x' * 50}\n" for i in range(100))
    rows = "".join(",".join(repr(float(v)) for v in row) + "\n" for row in rough(10, 12, 4))
    (tmp_path / "m.csv").write_text(comments + last + "\n" + rows, encoding="utf-8")
    with pytest.raises(ValueError, match=said):
        SurfaceFile(path=str(tmp_path / "m.csv"), spacing=0.1, unit="um").rms_height()


@pytest.mark.parametrize("label, named", [("z [Nanometers]", "nm"), ("height (micrometre)", "um"),
                                          ("Height [Microns]", "um"), ("z/Millimeter", "mm")])  # fmt: skip
def test_a_unit_spelled_out_in_any_case_is_that_unit(tmp_path, label, named):
    """'z [nanometer]' was no unit: the numbers, in nm, were taken in the preset's um without a word."""
    rows = "".join(f"{0.5 * i!r},{float(v)!r}\n" for i, v in enumerate(rough(1, 32, 5)[0]))
    (tmp_path / "line.csv").write_text(f"x,{label}\n" + rows, encoding="utf-8")
    other = "pm" if named != "pm" else "nm"
    with pytest.raises(ValueError, match=rf"its header names the length unit {named}, .* the preset's unit, {other}"):
        ProfileFile(path=str(tmp_path / "line.csv"), unit=other).rms_height()
    assert ProfileFile(path=str(tmp_path / "line.csv")).input_summary()["unit"] == named


@pytest.mark.parametrize("header, label, unit", [("x [furlong],z [um]", "x [furlong]", "furlong"),
                                                 ("t [s],z [nm]", "t [s]", "s"), ("z [NM]", "z [NM]", "NM")])  # fmt: skip
def test_a_column_labelled_in_a_unit_frictionlab_does_not_know_is_refused(tmp_path, header, label, unit):
    """'x [furlong],z [um]' was read as x in um (the one unit known), every slope off by the units'
    ratio, validated as 'ok': a bracketed unit that is no known unit is refused, naming the label."""
    columns = header.count(",") + 1
    rows = "".join(",".join([f"{i * 0.5!r}", repr(float(v))][-columns:]) + "\n" for i, v in enumerate(rough(1, 32)[0]))
    (tmp_path / "odd.csv").write_text(header + "\n" + rows, encoding="utf-8")
    for given in ("um", None):
        with pytest.raises(ValueError, match=rf"its header's '{re.escape(label)}' names the unit '{unit}', which is no unit"):
            ProfileFile(path=str(tmp_path / "odd.csv"), unit=given, spacing=0.5).rms_height()


def test_brackets_that_hold_no_unit_above_the_labels_are_no_unit(tmp_path):
    rows = "".join(f"{i * 0.5!r},{float(v)!r}\n" for i, v in enumerate(rough(1, 32)[0]))
    (tmp_path / "dated.csv").write_text("# scanned [2024-01-01]\nx [um],z [um]\n" + rows)
    assert ProfileFile(path=str(tmp_path / "dated.csv"), spacing=0.5).generate(None).heights.size == 32


def test_a_headers_size_with_a_decimal_comma_gives_its_pixel_under_format_table(tmp_path):
    """'# Width: 2,400 µm' (Gwyddion's export in a locale whose decimal mark is a comma), read with
    format: table, stated no pixel: its pixel was not named beside the preset's, nor its oblong
    shape; with format: auto such a header was not even taken for an export's. Read as 2.400 µm."""
    z = rough(16, 24)
    point = gwyddion_text(tmp_path / "point.txt", z, 0.1, value_unit="um", scale=1.0)
    comma = tmp_path / "comma.txt"
    comma.write_text(point.read_text(encoding="utf-8").replace("2.400 µm", "2,400 µm").replace("1.600 µm", "1,600 µm"),
                     encoding="utf-8")  # fmt: skip
    assert "# Width: 2,400 µm\n# Height: 1,600 µm" in comma.read_text(encoding="utf-8")
    for path in (point, comma):
        summary = SurfaceFile(path=str(path), spacing=0.2, unit="um", format="table").input_summary()
        assert summary["file_spacing"] == pytest.approx(0.1, rel=1e-9), path.name
        with pytest.raises(ValueError, match="its header states the scan's units"):  # an export's: format: instrument
            SurfaceFile(path=str(path), spacing=0.2, unit="um").rms_height()
    comma.write_text(comma.read_text(encoding="utf-8").replace("1,600 µm", "3,200 µm"), encoding="utf-8")
    caveats = SurfaceFile(path=str(comma), spacing=0.2, unit="um", format="table").input_summary()["caveats"]
    assert any("which is not square" in caveat and "0.1 x 0.2 um" in caveat for caveat in caveats)


@pytest.mark.parametrize("header", ["x_um,z_nm", '"X, um","Z, nm"', "x in um,z in nm", "x {um},z {nm}", "x:um,z:nm",
                                    "# x: um, z: nm\nx,z", "x_um z_nm"])  # fmt: skip
def test_units_labelled_as_spreadsheets_write_them_are_read(tmp_path, header):
    """x in um beside heights in nm, labelled without brackets: the labels were read as no unit, the
    numbers bare, and the force unit, every F and p / E* off by 1000 without a word."""
    x = np.arange(32) * 0.5
    rows = "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(x, rough(1, 32, 4)[0]))
    (tmp_path / "mixed.csv").write_text(header + "\n" + rows, encoding="utf-8")
    with pytest.raises(ValueError, match=r"its header names the length units um, nm, .* convert the columns"):
        ProfileFile(path=str(tmp_path / "mixed.csv")).rms_height()
    (tmp_path / "same.csv").write_text(header.replace("nm", "um") + "\n" + rows, encoding="utf-8")
    line = ProfileFile(path=str(tmp_path / "same.csv"))
    assert line.generate(None).spacing == pytest.approx(0.5) and line.input_summary()["unit"] == "um"


@pytest.mark.parametrize("header", ["time_ms,z", "# Cutoff: 0.8 mm\nx,z", "# operator: Smith\nx,z"])
def test_words_that_only_look_like_units_are_no_unit(tmp_path, header):
    rows = "".join(f"{i * 0.5!r},{float(v)!r}\n" for i, v in enumerate(rough(1, 32)[0]))
    (tmp_path / "p.csv").write_text(header + "\n" + rows)
    assert ProfileFile(path=str(tmp_path / "p.csv"), unit="um").generate(None).spacing == pytest.approx(0.5)
