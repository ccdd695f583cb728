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
