"""A size cap costs nothing: a file is read into a buffer the size of what it holds.

``fh.read(n)`` allocates its n bytes before it reads one: with a cap as n (16 GiB for a
chunk of a few kB) every read failed where the kernel does not overcommit (``ulimit -v``,
``vm.overcommit_memory=2``), and with it every run, resume and ``load()``.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

from frictionlab.io.inputs import InputFileProblem, read_regular_file

ROOT = Path(__file__).resolve().parents[1]
SOURCES = sorted([*(ROOT / "frictionlab").rglob("*.py"), *(ROOT / "plugins").rglob("*.py")])
READS = {"read", "pread", "recv", "readinto"}


def _size_argument(call: ast.Call) -> ast.expr | None:
    """The buffer-size argument of a read call: ``fh.read(n)``, ``os.read(fd, n)``, ``os.pread(fd, n, at)``."""
    name = call.func.attr
    on_os = isinstance(call.func.value, ast.Name) and call.func.value.id == "os"
    position = 1 if on_os or name == "pread" else 0
    return call.args[position] if len(call.args) > position else None


SMALL_BLOCK = 1 << 20  # a named constant up to this many bytes is a block, not a cap


def _small_constants(tree: ast.Module) -> set[str]:
    """The module-level names bound to a literal number of at most ``SMALL_BLOCK`` bytes."""
    return {
        target.id
        for node in tree.body
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant)
        and isinstance(node.value.value, int) and 0 < node.value.value <= SMALL_BLOCK
        for target in node.targets
        if isinstance(target, ast.Name)
    }  # fmt: skip


def _bounded(size: ast.expr, small: set[str] = frozenset()) -> bool:
    """A size that cannot be a cap: a constant block (a literal, or a module constant of at
    most 1 MiB), ``len(...)`` of what is held, or a ``min(...)`` (with the file's size, its
    remaining bytes or a block)."""
    if isinstance(size, ast.Constant) or (isinstance(size, ast.BinOp) and all(
            isinstance(side, ast.Constant) for side in (size.left, size.right))):  # fmt: skip
        return True
    if isinstance(size, ast.Name) and size.id in small:
        return True
    return isinstance(size, ast.Call) and isinstance(size.func, ast.Name) and size.func.id in {"min", "len"}


def test_no_read_in_the_package_or_the_plugins_takes_a_cap_as_its_buffer_size():
    unbounded = []
    for path in SOURCES:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        small = _small_constants(tree)
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in READS:
                size = _size_argument(node)
                if size is not None and not _bounded(size, small):
                    unbounded.append(f"{path.relative_to(ROOT)}:{node.lineno}: {ast.unparse(node)}")
    assert not unbounded, "reads sized by something other than the data:\n" + "\n".join(unbounded)


def test_the_check_finds_a_read_sized_by_a_cap():
    calls = [ast.parse(code).body[0].value for code in ("fh.read(limit + 1)", "os.pread(fd, MAX_BYTES, 0)", "fh.read(cap)")]
    assert not any(_bounded(_size_argument(call)) for call in calls)
    fine = [ast.parse(code).body[0].value for code in ("fh.read(min(size + 1, cap))", "fh.read(1 << 20)", "fh.read()")]
    assert all(_size_argument(call) is None or _bounded(_size_argument(call)) for call in fine)
    module = ast.parse("MAGIC = 512\nMAX_BYTES = 16 << 30\nCAP = 1 << 40\nfh.read(MAGIC)\nfh.read(CAP)")
    small = _small_constants(module)
    reads = [node.value for node in module.body[3:]]
    assert _bounded(_size_argument(reads[0]), small) and not _bounded(_size_argument(reads[1]), small)


def test_a_small_file_under_a_huge_cap_is_read_under_a_virtual_memory_limit(tmp_path):
    """Under RLIMIT_AS of 1 GiB, a 5 kB file read with the chunks' cap of 16 GiB: the old
    reader asked for a 16 GiB buffer (MemoryError)."""
    (tmp_path / "small").write_bytes(bytes(range(256)) * 20)
    code = (
        "import resource, sys\n"
        "resource.setrlimit(resource.RLIMIT_AS, (2**30, 2**30))\n"
        "from frictionlab.io.inputs import read_regular_file\n"
        "data = read_regular_file(sys.argv[1], 16 * 1024**3)\n"
        "assert data == bytes(range(256)) * 20, len(data)\n"
        "print('read', len(data))\n"
    )
    done = subprocess.run([sys.executable, "-c", code, str(tmp_path / "small")], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout == "read 5120\n", done.stderr[-2000:]


@pytest.mark.parametrize("size", [0, 1, 4095, 4096, 100_000])
def test_the_reader_returns_the_whole_file_at_or_under_the_cap(tmp_path, size):
    data = bytes(i % 251 for i in range(size))
    (tmp_path / "f").write_bytes(data)
    assert read_regular_file(tmp_path / "f", size) == data
    assert read_regular_file(tmp_path / "f") == data
    if size:
        with pytest.raises(InputFileProblem, match=f"of {size:,} bytes, more than the limit of {size - 1:,} bytes"):
            read_regular_file(tmp_path / "f", size - 1)


class _Growing:
    """A file object that holds ``extra`` bytes more than its fstat said (written while read)."""

    def __init__(self, data: bytes):
        self.data, self.at, self.asked = data, 0, []

    def read(self, n):
        self.asked.append(n)
        block = self.data[self.at: self.at + n]
        self.at += len(block)
        return block


@pytest.mark.parametrize("limit", [None, 150, 10_000_000])
def test_a_file_that_grew_while_read_is_read_to_one_byte_past_the_cap_in_small_buffers(limit):
    from frictionlab.io.inputs import GROWTH_BLOCK, read_bounded

    data = bytes(range(200)) * 10_000  # 2 MB, where the fstat said 100 bytes
    fh = _Growing(data)
    got = read_bounded(fh, 100, limit)
    assert got == (data if limit is None or limit >= len(data) else data[: limit + 1])
    assert max(fh.asked) <= max(101, GROWTH_BLOCK)
