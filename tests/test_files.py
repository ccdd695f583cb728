"""Files are written whole or not at all, with the usual permissions."""

import io
import os
import zipfile

import numpy as np
import pytest

from frictionlab.files import atomic_write, write_npz


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


def test_write_npz_reads_back_exactly_deflating_only_what_shrinks(tmp_path):
    rng = np.random.default_rng(5)
    arrays = {
        "rough": rng.normal(size=(300, 400)),  # random floats: deflate saves nothing
        "counts": np.repeat(np.arange(400), 300).reshape(400, 300),  # long runs: deflate pays
        "empty": np.zeros((0,), dtype=np.int64),
        "text": np.array(["a reason", "another"]),
        "scalar": np.float64(2.5),
    }
    path = tmp_path / "arrays.npz"
    atomic_write(path, lambda fh: write_npz(fh, arrays), binary=True)
    with np.load(path) as back:
        assert sorted(back.files) == sorted(arrays)
        for name, array in arrays.items():
            np.testing.assert_array_equal(back[name], array)
            assert back[name].dtype == np.asarray(array).dtype
    with zipfile.ZipFile(path) as archive:
        kinds = {info.filename: info.compress_type for info in archive.infolist()}
    assert kinds["rough.npy"] == zipfile.ZIP_STORED and kinds["counts.npy"] == zipfile.ZIP_DEFLATED
    assert path.stat().st_size < arrays["rough"].nbytes + arrays["counts"].nbytes / 10


def test_write_npz_gives_the_same_bytes_for_the_same_arrays():
    arrays = {"xi": np.linspace(0, 1, 1000), "index": np.arange(10)}
    first, second = io.BytesIO(), io.BytesIO()
    write_npz(first, arrays)
    write_npz(second, arrays)
    assert first.getvalue() == second.getvalue()
