"""Instrument formats whose reader SurfaceTopography has but frictionlab did not reach: a
Bruker/Digital Instruments Nanoscope file under .di or a numbered suffix (its reader states no
magic and lists only .spm, .001 to .005), and a Mitutoyo SurfTest workbook (.xlsx, whose reader,
openpyxl, refused the name of an open descriptor for its missing suffix). Each file is written
here as its instrument writes it, and read as SurfaceTopography itself reads it."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab_spectra import ProfileFile, SurfaceFile

NM_PER_VOLT, VOLTS_PER_LSB = 20.0, 3e-4  # the Z scale: one count is 0.006 nm


def write_nanoscope(path, counts: np.ndarray, size_um=(2.0, 1.5)) -> None:
    """A Nanoscope file of one height channel: its text header (sections of backslashed keys),
    then the lines of int16 counts from offset 4096."""
    ny, nx = counts.shape
    offset = 4096
    lines = ["\\*File list", "\\Version: 0x05120000", f"\\Data length: {offset}",
             "\\*Scanner list", f"\\@Sens. Zsens: V {NM_PER_VOLT} nm/V",
             "\\*Ciao scan list", f"\\Samps/line: {nx}", f"\\Lines: {ny}",
             "\\*Ciao image list", f"\\Data offset: {offset}", f"\\Data length: {2 * nx * ny}", "\\Bytes/pixel: 2",
             f"\\Samps/line: {nx}", f"\\Number of lines: {ny}", f"\\Scan Size: {size_um[0]} {size_um[1]} ~m",
             '\\@2:Image Data: S [Height] "Height"',
             f"\\@2:Z scale: V [Sens. Zsens] ({VOLTS_PER_LSB} V/LSB) {VOLTS_PER_LSB * 65536} V",
             "\\*File list end"]  # fmt: skip
    header = ("\r\n".join(lines) + "\r\n").encode("latin-1")
    path.write_bytes(header.ljust(offset, b"\0") + counts.astype("<i2").tobytes())


def preset(path, **params) -> dict:
    return {"name": "scan", "seed": 1, "realizations": 2,
            "spectrum": {"name": "surface-file", "params": {"path": str(path), **params}},
            "solver": {"name": "mdr", "params": {"youngs_modulus": 1.0, "poisson_ratio": 0.0}},
            "loading": {"start": 0.05, "stop": 2.0, "steps": 4, "spacing": "log"}, "fit": {"bootstrap": 10}}  # fmt: skip


@pytest.mark.parametrize("suffix", [".di", ".000"])  # .spm, .001 to .005: by suffix before
def test_a_nanoscope_file_is_read_under_any_of_its_suffixes(tmp_path, suffix, capsys):
    counts = np.random.default_rng(np.random.SeedSequence(3)).integers(-3000, 3000, (12, 16))
    path = tmp_path / f"scan{suffix}"
    write_nanoscope(path, counts)
    surface = SurfaceFile(path=str(path), detrend="none")
    # the first line stored is the top of the image (Gwyddion's): row 0 of z[y, x] is the last
    np.testing.assert_allclose(surface.generate(None).heights, counts[::-1] * VOLTS_PER_LSB * NM_PER_VOLT, rtol=1e-12)
    summary = surface.input_summary()
    assert (summary["unit"], summary["file_spacing"], summary["channel"]) == ("nm", 125.0, "Height")
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset(path)))
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.OK
    assert "16 x 12 pixels (x by y) of 125 nm (from the file)" in capsys.readouterr().out


def test_a_nanoscope_header_with_its_data_as_text_is_named_as_such(tmp_path, capsys):
    """Nanoscope's text variant (``?*File list``), which the reader does not read: its reason."""
    path = tmp_path / "scan.di"
    path.write_bytes(b"?*File list\r\n\\Version: 0x05120000\r\n" + b"0 1 2 3\r\n" * 10)
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset(path)))
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "data stored as text" in err and "Traceback" not in err


def write_surftest(path, x_mm: np.ndarray, z_um: np.ndarray) -> None:
    """A Mitutoyo SurfTest workbook: positions (mm) and heights (um) in columns E and F of
    sheet DATA, a roughness parameter in column A (the heights' unit), the date and the
    cut-off (the positions' unit) on sheet Certificate."""
    import openpyxl  # SurfaceTopography's, for its Mitutoyo reader

    book = openpyxl.Workbook()
    certificate = book.active
    certificate.title = "Certificate"
    certificate["E2"], certificate["E48"] = "10- Oct -2022", "0.08mm"
    data = book.create_sheet("DATA")
    data["A1"] = "Ra     0.018  \u00b5m      "
    for row, (x, z) in enumerate(zip(x_mm, z_um), start=1):
        data.cell(row=row, column=5, value=float(x))
        data.cell(row=row, column=6, value=float(z))
    book.save(path)


def test_a_mitutoyo_workbook_is_read_as_a_line(tmp_path):
    x_mm = 0.0005 * np.arange(1, 65)  # the workbook's x starts at one step
    z_um = np.random.default_rng(np.random.SeedSequence(5)).normal(0.0, 0.1, x_mm.size)
    write_surftest(tmp_path / "line.xlsx", x_mm, z_um)
    line = ProfileFile(path=str(tmp_path / "line.xlsx"), detrend="none")
    np.testing.assert_allclose(line.generate(None).heights, z_um, rtol=1e-12)
    summary = line.input_summary()
    assert summary["unit"] == "\u00b5m" and summary["spacing"] == pytest.approx(0.5, rel=1e-9)  # 0.0005 mm
