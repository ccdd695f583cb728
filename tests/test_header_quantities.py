"""What a scan's header says its numbers are. The angstrom (Å, 1e-10 m, as AFM files state it)
is a length unit of files and of a preset's ``unit``; a bare "A" is the ampere, never guessed.
A column labelled in a unit that is no length (``z [V]``, ``height (nA)``, ``phase [deg]``) holds
no heights: its numbers were read as heights in the preset's unit without a word."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab_spectra import ProfileFile, SurfaceFile

from .test_scan_edge_cases import rough, write_gwy


def write_line(path, header: str, x, z):
    path.write_text(header + "\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(x, z)), encoding="utf-8")
    return path


def validate(tmp_path, capsys, kind: str, params: dict) -> tuple[int, str]:
    preset = {"name": "h", "realizations": 1, "spectrum": {"name": kind, "params": params}, "solver": {"name": "mdr"},
              "loading": {"start": 0.01, "stop": 0.1, "steps": 3, "unit": "f"}}  # fmt: skip
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset, allow_unicode=True), encoding="utf-8")
    code = main(["validate", str(tmp_path / "p.yaml")])
    return code, "".join(capsys.readouterr())


@pytest.mark.parametrize("spelled", ["\u00c5", "\u212b", "angstrom"])
def test_a_table_in_angstroms_is_read_with_unit_angstrom(tmp_path, spelled):
    """A table labelled x [Å], z [Å] could not be read at all: its advice 'set unit: Å' was refused."""
    x, z = np.arange(64) * 5.0, rough(1, 64)[0]
    path = write_line(tmp_path / "afm.csv", f"x [{spelled}],z [{spelled}]", x, z)
    line = ProfileFile(path=str(path), unit=spelled.title() if spelled.isascii() else spelled, detrend="none").generate(None)
    assert line.spacing == pytest.approx(5.0, rel=1e-12)
    np.testing.assert_allclose(line.heights, z, rtol=1e-12)
    with pytest.raises(ValueError, match=r"names the length unit \u00c5, .* set unit: \u00c5, or convert"):
        ProfileFile(path=str(path), unit="nm").rms_height()


def test_an_instrument_file_in_angstroms_converts_to_unit_angstrom(tmp_path):
    z = rough(16, 16, 2)
    path = write_gwy(tmp_path / "afm.gwy", z * 1e-10, 2e-10, 2e-10)  # Gwyddion stores metres
    scan = SurfaceFile(path=str(path), unit="\u00c5", detrend="none").generate(None)
    assert scan.spacing == pytest.approx(2.0, rel=1e-9)
    np.testing.assert_allclose(scan.heights, z, rtol=1e-9)


def test_unit_a_is_refused_as_the_amperes(tmp_path, capsys):
    x, z = np.arange(64) * 5.0, rough(1, 64)[0]
    write_line(tmp_path / "afm.csv", "x,z", x, z)
    code, text = validate(tmp_path, capsys, "profile-file", {"path": str(tmp_path / "afm.csv"), "unit": "A"})
    assert code == ExitCode.USAGE, text
    assert "spectrum.params.unit: must be a length unit (m, mm, um, nm, \u00c5, pm): A is the ampere" in text
    assert "Traceback" not in text


@pytest.mark.parametrize(("header", "label", "unit"), [
    ("x [um],z [V]", "z [V]", "V"), ("x [um],height (nA)", "height (nA)", "nA"),
    ("x [um],phase [deg]", "phase [deg]", "deg"), ("x/um,f/kHz", "f/kHz", "kHz"), ("x [um],z [A]", "z [A]", "A"),
])  # fmt: skip
def test_a_table_column_in_a_unit_that_is_no_length_is_refused(tmp_path, capsys, header, label, unit):
    """Each was validated 'ok', its volts (or degrees) taken for micrometres of height."""
    x, z = np.arange(64) * 0.5, rough(1, 64)[0]
    write_line(tmp_path / "scan.csv", header, x, z)
    code, text = validate(tmp_path, capsys, "profile-file", {"path": str(tmp_path / "scan.csv"), "unit": "um"})
    assert code == ExitCode.USAGE, text
    assert f"'/{tmp_path.name}/scan.csv'" in text or "scan.csv" in text
    assert f"its header's {label!r} says numbers in {unit}" in text
    assert "which is not a length unit (allowed: m, mm, um, nm, \u00c5, pm): they are not heights" in text
    assert ("A is the ampere" in text) == (unit == "A") and "Traceback" not in text


def test_a_map_or_an_xyz_export_in_volts_is_refused_and_labels_that_are_no_unit_are_left(tmp_path):
    z = rough(16, 16, 3)
    rows = "".join(",".join(repr(float(v)) for v in row) + "\n" for row in z)
    (tmp_path / "map.csv").write_text("z [V]\n" + rows, encoding="utf-8")
    with pytest.raises(ValueError, match=r"header's 'z \[V\]' says numbers in V, which is not a length unit"):
        SurfaceFile(path=str(tmp_path / "map.csv"), spacing=0.1, unit="um").rms_height()
    xyz = "".join(f"{0.1 * i:.4f} {0.1 * j:.4f} {z[j, i]:.9g}\n" for j in range(16) for i in range(16))
    (tmp_path / "scan.xyz").write_text("# x [um] y [um] z [mV]\n" + xyz)
    with pytest.raises(ValueError, match=r"header's 'z \[mV\]' says numbers in mV"):
        SurfaceFile(path=str(tmp_path / "scan.xyz"), unit="um").rms_height()
    gwyddion = "# Channel: Amplitude\n# Width: 1.6 \u00b5m\n# Height: 1.6 \u00b5m\n# Value units: V\n"
    (tmp_path / "amplitude.txt").write_text(gwyddion + xyz.replace(" ", "  "), encoding="utf-8")
    for format in ("auto", "table"):  # format: table read its volts as heights
        with pytest.raises(ValueError, match=r"header's 'Value units: V' says numbers in V"):
            SurfaceFile(path=str(tmp_path / "amplitude.txt"), spacing=0.1, unit="um", format=format).rms_height()
    for header in ("height(s) of sample (A2), S/N ratio 3", "z [nm]", "# Setpoint (%): 50\n# Drive [mV]: 3\nz [nm]"):  # no unit's label; a length
        (tmp_path / "ok.csv").write_text(header + "\n" + rows, encoding="utf-8")
        assert SurfaceFile(path=str(tmp_path / "ok.csv"), spacing=0.1, unit="nm").generate(None).heights.shape == (16, 16)


def test_a_gwyddion_channel_in_amperes_is_no_heights_and_another_channel_is_picked(tmp_path):
    """SurfaceTopography's reader took Gwyddion's A (the ampere) for the angstrom: a current
    channel was read as heights of 1e-10 m per ampere."""
    z = rough(16, 16, 4)
    path = write_gwy(tmp_path / "stm.gwy", z * 1e-12, 1e-9, 1e-9, unit_z="A", more=[("Height", z * 1e-9, "m")])
    with pytest.raises(ValueError, match=r"channel 0 \('Height'\) holds values in A, Gwyddion's symbol of the ampere"):
        SurfaceFile(path=str(path), unit="nm").rms_height()
    chosen = SurfaceFile(path=str(path), unit="nm", channel=1, detrend="none")
    np.testing.assert_allclose(chosen.generate(None).heights, z, rtol=1e-9)
    listed = chosen.input_summary()["channels"]  # the current's unit as the file says it, not the reader's m
    assert [c["data_unit"] for c in listed] == ["A", "m"]


def test_a_npy_map_three_wide_is_not_told_to_be_read_as_an_xyz_export(tmp_path):
    """A 3 x 3 .npy was told 'columns of x, y and z per point are read with format: instrument',
    which no .npy is (SurfaceTopography does not read one)."""
    np.save(tmp_path / "tiny.npy", rough(3, 3))
    with pytest.raises(ValueError, match=r"map of 3 x 3 pixels \(x by y\); at least 8 x 8 are needed$"):
        SurfaceFile(path=str(tmp_path / "tiny.npy"), spacing=1.0).rms_height()


def test_a_first_row_of_decimal_commas_is_named_not_taken_for_a_header(tmp_path):
    """'-0,12;1,5' on line 1 was skipped as a header, and line 2 named as the first of decimal commas."""
    z = rough(16, 16, 5)
    (tmp_path / "semi.csv").write_text("".join(";".join(f"{v:.5f}".replace(".", ",") for v in row) + "\n" for row in z))
    with pytest.raises(ValueError, match=r"decimal commas at line 1 \(as 1,5\)"):
        SurfaceFile(path=str(tmp_path / "semi.csv"), spacing=1.0).rms_height()


def test_two_columns_read_as_a_map_are_told_to_be_a_line(tmp_path):
    x, z = np.arange(64) * 0.5, rough(1, 64)[0]
    write_line(tmp_path / "line.csv", "x,z", x, z)
    with pytest.raises(ValueError, match=r"map of 2 x 64 pixels .*; columns of x and z \(a line\) are read by profile-file"):
        SurfaceFile(path=str(tmp_path / "line.csv"), spacing=1.0).rms_height()
