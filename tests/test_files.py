"""Files are written whole or not at all, with the usual permissions."""

import os

import pytest

from frictionlab.files import atomic_write


def test_atomic_write_gives_the_usual_permissions_not_mkstemps(tmp_path):
    target = tmp_path / "out.txt"
    atomic_write(target, lambda fh: fh.write("x"))
    mask = os.umask(0)
    os.umask(mask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~mask


def test_atomic_write_leaves_the_old_file_when_writing_fails(tmp_path):
    target = tmp_path / "summary.json"
    target.write_text("old")

    def explode(fh):
        fh.write("half a fi")
        raise RuntimeError("disk on fire")

    with pytest.raises(RuntimeError):
        atomic_write(target, explode)
    assert target.read_text() == "old"
    assert list(tmp_path.iterdir()) == [target]  # no temporary left behind
