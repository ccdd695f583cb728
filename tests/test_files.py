"""Files are written whole or not at all, with the usual permissions."""

import errno
import io
import os
import zipfile
from pathlib import Path

import numpy as np
import pytest

from frictionlab.io.files import atomic_write, npz_unpacked_problem, write_npz


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


def test_atomic_write_replaces_a_symlink_and_never_writes_through_it(tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    real = outside / "user.txt"
    real.write_text("the user's file")
    for devices in (False, True):  # a run folder's file, or an output path the user named
        link = tmp_path / f"link-{devices}.txt"
        link.symlink_to(real)
        atomic_write(link, lambda fh: fh.write("new"), devices=devices)
        assert not link.is_symlink() and link.read_text() == "new"
    dangling = tmp_path / "dangling.txt"
    dangling.symlink_to(outside / "created-through-the-link.txt")
    atomic_write(dangling, lambda fh: fh.write("new"))
    assert not dangling.is_symlink() and dangling.read_text() == "new"
    assert real.read_text() == "the user's file" and sorted(p.name for p in outside.iterdir()) == ["user.txt"]


def _fifo_reader(fifo):
    import threading

    got = []
    reader = threading.Thread(target=lambda: got.append(open(fifo).read()), daemon=True)  # never blocks the exit
    reader.start()
    return reader, got


def test_atomic_write_writes_into_a_fifo_the_user_named_and_replaces_one_in_a_run_folder(tmp_path):
    import stat

    fifo = tmp_path / "ff"
    os.mkfifo(fifo)
    reader, got = _fifo_reader(fifo)
    atomic_write(fifo, lambda fh: fh.write("through the pipe"), devices=True)
    reader.join(10)
    assert got == ["through the pipe"]
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    atomic_write(fifo, lambda fh: fh.write("a file now"))  # no reader: opening it to write would block
    assert stat.S_ISREG(os.lstat(fifo).st_mode) and fifo.read_text() == "a file now"


def test_atomic_write_writes_into_a_character_device_the_user_named(tmp_path):
    import stat

    null = tmp_path / "mynull"
    null.symlink_to("/dev/null")  # a link to a device, as /dev/stdout is
    atomic_write(null, lambda fh: fh.write("discarded"), devices=True)
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode) and null.is_symlink()
    atomic_write(null, lambda fh: fh.write("a file now"))  # in a run folder: the link is replaced
    assert not null.is_symlink() and null.read_text() == "a file now" and stat.S_ISCHR(os.stat("/dev/null").st_mode)
    if os.geteuid() == 0:  # a real device node: renaming over it would make it a regular file
        node = tmp_path / "node"
        os.mknod(node, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        atomic_write(node, lambda fh: fh.write("discarded"), binary=False, devices=True)
        assert stat.S_ISCHR(os.lstat(node).st_mode)


def test_atomic_write_refuses_a_folder_or_socket_naming_it(tmp_path):
    import socket

    folder = tmp_path / "sdir"
    folder.mkdir()
    with pytest.raises(IsADirectoryError) as raised:
        atomic_write(folder, lambda fh: fh.write("x"))
    assert raised.value.filename == str(folder) and raised.value.strerror == "is a folder, not a file"
    sock_path = tmp_path / "s"
    with socket.socket(socket.AF_UNIX) as sock:
        sock.bind(str(sock_path))
        with pytest.raises(OSError) as raised:
            atomic_write(sock_path, lambda fh: fh.write("x"))
    assert raised.value.filename == str(sock_path) and raised.value.strerror == "is a socket, not a file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s", "sdir"] and not any(folder.iterdir())


def test_an_open_stream_the_user_named_is_written_into_whatever_it_is_redirected_to(tmp_path):
    """``--out /dev/stdout > file``: the stream is written into; renaming over the link
    (as root, /dev/stdout itself) is what must never happen."""
    from frictionlab.io.files import check_output_file

    target = tmp_path / "redirected.json"
    with open(target, "w") as stream:
        via_proc = Path(f"/proc/self/fd/{stream.fileno()}")
        link = tmp_path / "stdout"
        link.symlink_to(via_proc)  # as /dev/stdout -> /proc/self/fd/1
        assert check_output_file(link, "--out", force=False) == link  # not refused as an existing file
        atomic_write(link, lambda fh: fh.write("through the stream"), devices=True)
        assert link.is_symlink() and os.readlink(link) == str(via_proc)
    assert target.read_text() == "through the stream"


def test_a_fifo_the_user_named_that_nothing_reads_is_refused_not_waited_on(tmp_path, monkeypatch, capsys):
    """`frictionlab schema --out FIFO` with no reader blocked for ever in open(); it is refused
    after a short wait, with the exit code of an output refused, and the FIFO is left as it was."""
    import stat
    import threading

    from frictionlab.cli import main
    from frictionlab.errors import ExitCode
    from frictionlab.io import files

    monkeypatch.setattr(files, "FIFO_READER_WAIT_S", 0.2, raising=False)
    fifo = tmp_path / "ff"
    os.mkfifo(fifo)
    codes = []
    command = threading.Thread(target=lambda: codes.append(main(["schema", "--out", str(fifo)])), daemon=True)
    command.start()
    command.join(20)
    if command.is_alive():  # blocked on the FIFO: a reader opened and closed lets it go
        os.close(os.open(fifo, os.O_RDONLY | os.O_NONBLOCK))
        command.join(5)
    assert codes == [ExitCode.OUTPUT_REFUSED]
    assert "is a FIFO (named pipe) that nothing reads: start its reader first" in capsys.readouterr().err
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def _full_disk(*args):
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))  # as a write or fsync says it: no file named


def test_a_full_disk_names_the_file_it_was_writing_and_leaves_no_part_of_it(tmp_path, monkeypatch):
    """A write's ENOSPC named no file: `report` and `exact3d` said 'cannot write the output',
    naming neither the file nor its folder."""
    target = tmp_path / "summary.json"
    monkeypatch.setattr(os, "fsync", _full_disk)
    with pytest.raises(OSError) as raised:
        atomic_write(target, lambda fh: fh.write("{}"))
    assert (raised.value.errno, raised.value.filename) == (errno.ENOSPC, str(target))
    assert list(tmp_path.iterdir()) == []  # nothing that looks whole, no temporary


def test_a_rename_refused_names_the_file_not_its_temporary(tmp_path, monkeypatch):
    """A rename over a file that cannot be replaced (chattr +i: EPERM) said 'Operation not
    permitted: .../.exist.json.3rpqgi_w.tmp', a temporary the user never heard of."""
    target = tmp_path / "exist.json"
    target.write_text("keep")

    def refused(src, dst):  # as os.replace says it: both names
        raise PermissionError(errno.EPERM, os.strerror(errno.EPERM), str(src), str(dst))

    monkeypatch.setattr(os, "replace", refused)
    with pytest.raises(OSError) as raised:
        atomic_write(target, lambda fh: fh.write("{}"))
    assert (raised.value.errno, raised.value.filename, raised.value.filename2) == (errno.EPERM, str(target), None)
    assert [p.name for p in tmp_path.iterdir()] == ["exist.json"] and target.read_text() == "keep"


def test_a_full_device_the_user_named_is_named_too(tmp_path):
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full on this system")
    with pytest.raises(OSError) as raised:
        atomic_write(Path("/dev/full"), lambda fh: fh.write("x" * 65536), devices=True)
    assert (raised.value.errno, raised.value.filename) == (errno.ENOSPC, "/dev/full")


def test_an_output_folder_under_a_device_says_what_the_device_is(tmp_path):
    from frictionlab.io.files import output_path_problem

    assert output_path_problem(Path(os.devnull) / "run") == f"{os.devnull}/run cannot be made a folder: {os.devnull} is a character device"


def test_a_socket_given_as_an_input_file_is_named_a_socket(tmp_path, cli):
    """Opening a socket fails with ENXIO, which read "cannot be read: no such device or address"
    (a preset file; a run folder's run.json in frictionlab runs): it is said as what it is."""
    import socket

    from frictionlab.io.inputs import InputFileProblem, open_regular_file
    from frictionlab.runs.runfolder import open_member

    (tmp_path / "run").mkdir()
    with socket.socket(socket.AF_UNIX) as sock, socket.socket(socket.AF_UNIX) as inner:
        sock.bind(str(tmp_path / "p.yaml"))
        inner.bind(str(tmp_path / "run" / "run.json"))
        with pytest.raises(InputFileProblem, match="^preset file is a socket, not a regular file$"):
            open_regular_file(tmp_path / "p.yaml", "preset file")
        with pytest.raises(InputFileProblem, match="^run.json is a socket, not a regular file$"):
            open_member(tmp_path / "run", "run.json")
        done = cli("validate", str(tmp_path / "p.yaml"))
    assert done.returncode == 3 and "preset file is a socket, not a regular file" in done.stdout + done.stderr


def test_an_npy_header_claiming_more_than_its_deflated_entry_can_unpack_to_is_refused_unread():
    """The sizes a zip's directory declares are the forger's too: an entry of 2 GiB declared
    over a few hundred deflated bytes passed a bound of what the run can write, and numpy
    allocated the 2 GiB its header claimed before reading them (EOF)."""
    claimed = 2**28  # float64s: 2 GiB
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (claimed,)})
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("xi.npy", header.getvalue() + bytes(64))
    data = bytearray(buffer.getvalue())
    declared = (len(header.getvalue()) + 8 * claimed).to_bytes(4, "little")  # both headers' uncompressed size
    local, central = data.index(b"PK\x03\x04"), data.index(b"PK\x01\x02")
    data[local + 22 : local + 26], data[central + 24 : central + 28] = declared, declared
    with zipfile.ZipFile(io.BytesIO(bytes(data))) as archive:
        assert archive.getinfo("xi.npy").file_size > 8 * claimed  # as declared: no smaller than the claim
        problem = npz_unpacked_problem(archive, most=2**40)
    assert problem is not None and f"array 'xi': its header claims shape ({claimed},) of float64" in problem
