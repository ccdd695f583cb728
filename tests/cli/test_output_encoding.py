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
def test_a_path_that_is_not_utf8_is_printed_escaped(tmp_path, cli, encoding, argv, made):
    done = cli(*argv, cwd=tmp_path, encoding=encoding)  # strict: what raised before
    assert done.returncode == 0, done.stderr
    assert_escaped(done, tmp_path, argv, made)


def assert_escaped(done, folder, argv, made):
    assert os.path.lexists(folder / os.fsdecode(made))
    printed = done.stdout + done.stderr
    assert b"\xff" not in printed  # the raw byte never reaches the terminal
    if argv[0] != "schema":  # schema --out prints nothing
        assert made.replace(b"\xff", b"\\xff") in printed, printed


def test_the_streams_a_process_is_started_with_escape_it_too(tmp_path):
    """The same in a process of its own, its streams made by PYTHONIOENCODING."""
    argv, made = ["presets", "copy", "quickstart", b"q\xff.yaml"], b"q\xff.yaml"
    env = {**os.environ, "PYTHONIOENCODING": "ascii"}
    done = subprocess.run([sys.executable, "-m", "frictionlab", *argv], capture_output=True, cwd=tmp_path, env=env,
                          timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert_escaped(done, tmp_path, argv, made)


def test_a_folder_named_in_utf8_under_the_c_locale_is_printed_escaped_not_an_internal_error(tmp_path):
    """Under LC_ALL=C without Python's UTF-8 mode (the file system's encoding ASCII), `run
    --out ü` wrote its files, then ended in 'internal error: UnicodeEncodeError' (exit 70): the
    table's 'results in ü/' was made printable once, and os.fsencode refused its 'ü' the second time."""
    env = {**os.environ, "LC_ALL": "C", "LANG": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"}
    env.pop("PYTHONIOENCODING", None)
    argv = ["run", "quickstart", "--set", "realizations=4", "--workers", "1", "--no-plot", "--out", "ü".encode()]
    done = subprocess.run([sys.executable, "-m", "frictionlab", *argv], capture_output=True, cwd=tmp_path, env=env,
                          timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert b"internal error" not in done.stderr
    assert b"results in \\xfc/" in done.stdout, done.stdout  # the ASCII stream's escape of the character
    assert (tmp_path / "ü" / "summary.json").is_file()


def test_a_utf8_value_typed_under_the_c_locale_is_read_and_a_name_it_cannot_give_is_said(tmp_path):
    """Under LC_ALL=C (ASCII file names) `--set description=ü` was refused as 'not UTF-8 text
    ...: type the value in UTF-8', which it was (Python had decoded its bytes as ASCII); a data
    file named 'ü.npy' was 'cannot be read (UnicodeEncodeError)', without why or what to do."""
    import numpy as np

    np.save(tmp_path / "ü.npy", np.random.default_rng(0).standard_normal(64).cumsum())
    env = {**os.environ, "LC_ALL": "C", "LANG": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"}
    env.pop("PYTHONIOENCODING", None)

    def validate(*sets):
        argv = [arg for value in sets for arg in ("--set", value.encode())]
        return subprocess.run([sys.executable, "-m", "frictionlab", "validate", "quickstart", *argv], capture_output=True,
                              cwd=tmp_path, env=env, timeout=300, text=True, errors="replace")  # fmt: skip

    described = validate("description=5 µm, ü")
    assert described.returncode == 0, described.stderr
    named = validate("spectrum.name=profile-file", "spectrum.params={path: ü.npy, spacing: 1.0}")
    assert named.returncode == 2
    assert "spectrum.params.path: cannot be named in this system's encoding of file names (ascii, from the locale): run " \
           "under a UTF-8 locale (LC_ALL=C.UTF-8) or with PYTHONUTF8=1" in named.stderr, named.stderr
    assert "Traceback" not in named.stderr
