"""A path that is not UTF-8 (a byte 0xff in a file name, as Linux allows) is printed
escaped, ``\\xff``, whatever the streams' encoding: never a UnicodeEncodeError and exit 70
after the files were written."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


@pytest.mark.parametrize("encoding", ["utf-8", "latin-1", "ascii"])
@pytest.mark.parametrize(
    "argv, made",
    [
        (["run", "quickstart", "--quiet", "--set", "realizations=4", "--workers", "1", "--out", b"r\xff"], b"r\xff"),
        (["presets", "copy", "quickstart", b"q\xff.yaml"], b"q\xff.yaml"),
        (["schema", "--out", b"s\xff.json"], b"s\xff.json"),
    ],
)
def test_a_path_that_is_not_utf8_is_printed_escaped(tmp_path, encoding, argv, made):
    env = {**os.environ, "PYTHONIOENCODING": encoding}  # strict: what raised before
    done = subprocess.run([sys.executable, "-m", "frictionlab", *argv], capture_output=True, cwd=tmp_path, env=env,
                          timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert os.path.lexists(tmp_path / os.fsdecode(made))
    printed = done.stdout + done.stderr
    assert b"\xff" not in printed  # the raw byte never reaches the terminal
    if argv[0] != "schema":  # schema --out prints nothing
        assert made.replace(b"\xff", b"\\xff") in printed, printed

