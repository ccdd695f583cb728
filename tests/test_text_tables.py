"""Tables of heights as programs save them, refused by what is wrong with them, not by what
came after: a table is read as UTF-8 text (one in UTF-16 without its byte-order mark, or bytes
that are no text, is valid UTF-8 to a decoder, NUL bytes and all), with decimal points."""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab_spectra import ProfileFile, SurfaceFile


@pytest.mark.parametrize("content", [
    pytest.param("".join(f"{float(v)!r}\n" for v in np.sin(np.arange(64) / 5.0)).encode("utf-16-le"), id="utf-16-no-mark"),
    pytest.param(b"\x00\x01\x02" * 100, id="control-bytes"),
])  # fmt: skip
def test_a_table_with_nul_bytes_is_named_not_utf8(tmp_path, content):
    (tmp_path / "t.csv").write_bytes(content)
    for kind in (ProfileFile, SurfaceFile):
        with pytest.raises(ValueError, match=r"not UTF-8 at line 1 \(.*UTF-16's NUL bytes.*save it so"):
            kind(path=str(tmp_path / "t.csv"), spacing=1.0).rms_height()


def test_a_column_of_decimal_commas_is_named(tmp_path):
    """A spreadsheet's single column with decimal commas (0,0677 a line: no separator to say so)
    was read as x = 0, z = 677 and refused as 'x is not uniformly spaced' (or 'x must increase');
    x and z in whole numbers (1,0 / 2,5) are still read as a line's x and z."""
    z = np.sin(np.arange(64) / 5.0) * 1e-3
    (tmp_path / "d.csv").write_text("".join(f"{float(v)!r}\n".replace(".", ",") for v in z))
    for kind in (ProfileFile, SurfaceFile):
        with pytest.raises(ValueError, match=r"decimal commas at line \d+ \(as 1,5\); .* export the table with decimal points"):
            kind(path=str(tmp_path / "d.csv"), spacing=1.0).rms_height()
    (tmp_path / "xz.csv").write_text("".join(f"{i},{v}\n" for i, v in enumerate([0, 5, 7, 1, 0, 3, 2, 9, 4, 6])))
    line = ProfileFile(path=str(tmp_path / "xz.csv")).generate(None)
    assert line.spacing == 1.0 and line.heights.size == 10


def test_fortran_exponents_are_read_as_the_numbers_they_are(tmp_path):
    """1.0D-06 and 2.5d+03, as a Fortran program writes a double, made 'a second line of text before
    the numbers' (numpy reads no D): read as 1.0e-06 and 2.5e+03, in a line's column (x and z too)
    and in a map of whitespace, commas or semicolons; a NaN among them is still named by its line
    and column, and a cell that is no number still refused by its line."""
    rng = np.random.default_rng(4)
    z = np.cumsum(rng.normal(size=64)) * 1e-6
    (tmp_path / "z.txt").write_text("z [m]\n" + "".join(f"{v:.6E}\n".replace("E", "D") for v in z))
    (tmp_path / "xz.csv").write_text("".join(f"{i * 0.5:.3e},{v:.6e}\n".replace("e", "d") for i, v in enumerate(z)))
    for name in ("z.txt", "xz.csv"):
        line = ProfileFile(path=str(tmp_path / name), **({} if name == "xz.csv" else {"spacing": 0.5})).generate(None)
        np.testing.assert_allclose(line.heights + z.mean(), z, rtol=1e-6, atol=1e-12)  # detrend mean by default
        assert line.spacing == pytest.approx(0.5, rel=1e-12)
    m = rng.normal(size=(16, 16)) * 1e3
    for separator in (" ", ",", ";"):
        (tmp_path / "m.txt").write_text("".join(separator.join(f"{v:.8E}".replace("E", "d") for v in row) + "\n" for row in m))
        read = SurfaceFile(path=str(tmp_path / "m.txt"), spacing=1.0, detrend="none")._measured().heights
        np.testing.assert_allclose(read, m, rtol=1e-8)
    holed = [f"{v:.6E}".replace("E", "D") for v in z]
    holed[9] = "NaN"
    (tmp_path / "nan.txt").write_text("\n".join(holed) + "\n")
    with pytest.raises(ValueError, match=r"at line 10, column 1"):
        ProfileFile(path=str(tmp_path / "nan.txt"), spacing=1.0).rms_height()
    holed[9] = "1.0Q-06"  # no exponent Fortran writes: still no number
    (tmp_path / "bad.txt").write_text("\n".join(holed) + "\n")
    with pytest.raises(ValueError, match=r"non-numeric content at line 10 .*: column 1 is not a number"):
        ProfileFile(path=str(tmp_path / "bad.txt"), spacing=1.0).rms_height()


@pytest.mark.parametrize("quoted", ['"{v!r}"\n', '"{i}","{v!r}"\n', "{i},'{v!r}'\n"])
def test_numbers_in_quotes_are_named_as_such(tmp_path, quoted):
    """A spreadsheet's export that quotes every field: each line was taken for 'a second line of
    text before the numbers'."""
    z = np.random.default_rng(np.random.SeedSequence(5)).normal(size=32).tolist()
    (tmp_path / "q.csv").write_text("".join(quoted.format(i=i, v=v) for i, v in enumerate(z)))
    with pytest.raises(ValueError, match=r"numbers in quotes at line 2 \(as \"1.5\"\); a table's numbers are bare"):
        ProfileFile(path=str(tmp_path / "q.csv"), spacing=1.0).generate(None)
    (tmp_path / "header.csv").write_text('"x","z"\n' + "".join(f"{i},{v!r}\n" for i, v in enumerate(z)))  # a quoted header
    assert ProfileFile(path=str(tmp_path / "header.csv")).generate(None).heights.size == 32
