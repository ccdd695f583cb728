"""A table of heights is read as UTF-8 text; one in UTF-16 without its byte-order mark (or
bytes that are no text) is valid UTF-8 to a decoder, NUL bytes and all, and was refused by
what came after: 'non-numeric content at line 2', or '0 points, at least 8 are needed'."""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab_spectra import ProfileFile, SurfaceFile


@pytest.mark.parametrize("content", [
    pytest.param("".join(f"{v!r}\n" for v in np.sin(np.arange(64) / 5.0)).encode("utf-16-le"), id="utf-16-no-mark"),
    pytest.param(b"\x00\x01\x02" * 100, id="control-bytes"),
])  # fmt: skip
def test_a_table_with_nul_bytes_is_named_not_utf8(tmp_path, content):
    (tmp_path / "t.csv").write_bytes(content)
    for kind in (ProfileFile, SurfaceFile):
        with pytest.raises(ValueError, match=r"not UTF-8 at line 1 \(.*UTF-16's NUL bytes.*save it so"):
            kind(path=str(tmp_path / "t.csv"), spacing=1.0).rms_height()
