"""Freed memory kept for the next realization instead of handed back to the system at once;
OpenBLAS on one thread (``one_blas_thread_unless_chosen``); and, under a process limit on
memory, address space reserved and never used held back (``spare_address_space_under_a_limit``).

glibc hands a freed block of more than 128 kB straight back to the system (and trims the
heap's top past a threshold it sets from the blocks seen), and the next realization's
arrays of the same size then fault in every page afresh: a 1e5-point line's realization
frees and allocates some 1.5 MB each time, 365 page faults, a quarter of its time (2.2 ms
against 1.6 ms). Blocks up to ``KEEP_BYTES`` are served from the heap instead, and up to
``KEEP_BYTES`` of its free top is kept for reuse. The peak a run needs does not grow: what
is kept was in use a moment before, and the next arrays reuse it. Larger arrays (a 2048 x
2048 surface's) are mapped and unmapped as before.

Set in the processes frictionlab owns: the ``frictionlab`` command's, a detached run's and
the pool's workers (``pool._serve``); a notebook's own process keeps its allocator as it is.
"""

from __future__ import annotations

import os

from ..errors import process_limit

M_TRIM_THRESHOLD = -1  # mallopt's parameters (malloc.h)
M_MMAP_THRESHOLD = -3
M_ARENA_MAX = -8
ARENAS = 2  # malloc arenas under a process limit (``spare_address_space_under_a_limit``)
KEEP_BYTES = 32 * 2**20  # glibc's own ceiling for the thresholds it raises by itself


def keep_freed_memory() -> bool:
    """Have glibc keep freed blocks up to ``KEEP_BYTES`` for reuse; False where the C
    library is not glibc (musl, macOS, Windows: their allocators decide)."""
    # both or neither: a fixed mmap threshold with glibc's default trim (128 kB) would trim the same pages
    return _mallopt(M_TRIM_THRESHOLD, KEEP_BYTES) and _mallopt(M_MMAP_THRESHOLD, KEEP_BYTES)


def hand_back_freed_memory() -> None:
    """glibc's ``malloc_trim(0)``: the heap's free blocks handed back to the system. Before a run,
    what the checks freed (realization 0 made up to three times to probe it) was kept beside the
    first realization's arrays: a 2e6-point line's peak went from 236 to 348 MiB, now and then."""
    import ctypes

    try:
        ctypes.CDLL(None).malloc_trim(0)
    except (OSError, AttributeError, TypeError):  # not glibc: its allocator decides
        pass


def _mallopt(parameter: int, value: int) -> bool:
    """glibc's ``mallopt``; False where the C library is not glibc."""
    import ctypes  # here: --help and a usage error need not load it

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError, TypeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return mallopt(parameter, value) == 1


def one_blas_thread_unless_chosen() -> None:
    """OpenBLAS starts no threads of its own (``OPENBLAS_NUM_THREADS=1``) unless the user set
    its thread count in the environment. Its threads, started as numpy is imported (in the
    command's process and again in each worker it forks), spin for a while after each wake:
    a Fig. 2 run took 1.03 s of CPU with them and 0.87 s without, time taken from the workers
    on a machine with as many cores as workers. frictionlab's own BLAS work runs on one thread
    anyway (the fit; the solvers use FFTs, the pool's workers one core each). Under a process
    limit on memory it matters more: at import OpenBLAS reserves a buffer of 32 to 64 MiB per
    thread, one per core, and when that does not fit it spins for ever inside the import, deaf
    to SIGTERM, or exits printing 'OpenBLAS error: Memory allocation still failed'.

    Before numpy is imported; the process's children inherit the environment."""
    if not any(os.environ.get(name) for name in ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")):
        os.environ["OPENBLAS_NUM_THREADS"] = "1"  # the variables OpenBLAS reads, in order


def spare_address_space_under_a_limit() -> None:
    """Under a process limit on memory (``ulimit -v``, ``ulimit -d``), glibc keeps ``ARENAS``
    malloc arenas, not 8 per core of 64 MiB each, unless the user chose otherwise in the
    environment: a Dask cluster's threads took 1 GiB of address space in the main process
    (0.4 GiB with 2 arenas), and a sweep on Dask ran out of it under ulimit -v 700000
    ("can't start new thread"), then hung.

    Before threads start; the process's children inherit the environment."""
    if process_limit() is None:
        return
    if not os.environ.get("MALLOC_ARENA_MAX"):
        os.environ["MALLOC_ARENA_MAX"] = str(ARENAS)  # children: glibc reads it as they start
        _mallopt(M_ARENA_MAX, ARENAS)  # this process, started already


BLAS_BUFFER = 32 * 2**20  # the work buffer OpenBLAS allocates as it loads (33,558,528 bytes asked, seen under gdb)
BLAS_SLACK = 8 * 2**20  # what else the load maps (a thread's stack, the loader's own tables)


def refuse_blas_without_room() -> None:
    """Under ``ulimit -v``, numpy's and scipy's OpenBLAS each load only where the address space
    left holds it, its libraries and its work buffer; else the import raises ``BlasNoRoom``.
    Where the buffer does not fit, OpenBLAS does not fail as an import does: scipy's spun for
    ever inside the import (`run` of an instrument file under ulimit -v 163840 hung), numpy's
    exited printing only 'OpenBLAS error: Memory allocation still failed'. Not on a system
    without /proc (the room is read from /proc/self/statm)."""
    limit = process_limit()
    if limit is None or limit[1] != "-v" or not os.path.exists("/proc/self/statm"):
        return
    import sys

    if not any(isinstance(finder, _BlasRoom) for finder in sys.meta_path):
        sys.meta_path.insert(0, _BlasRoom(limit[0]))


class BlasNoRoom(ImportError):
    """numpy's or scipy's OpenBLAS has no room to load under the process limit.
    An ImportError, as a library that cannot be mapped is ('failed to map segment'); the CLI
    says it as ``errors.out_of_memory_loading`` does, naming the library."""

    def __init__(self, library: str, need: int, room: int):
        self.library = library
        super().__init__(f"{library}: failed to map segment from shared object (it needs about {need >> 20} MiB of "
                         f"address space with its work buffer; {max(room, 0) >> 20} MiB is left)")  # fmt: skip


class _BlasRoom:
    """A finder on ``sys.meta_path`` that finds nothing itself: before each compiled module of
    numpy or scipy loads, until that package's OpenBLAS is mapped, it checks the room."""

    def __init__(self, limit: int):
        self.limit = limit
        self.waiting = {"numpy", "scipy"}  # packages whose OpenBLAS is not mapped yet

    def find_spec(self, name, path=None, target=None):
        package = name.partition(".")[0]
        if package not in self.waiting or name == package:  # a package's __init__ is no compiled module
            return None
        from importlib.machinery import EXTENSION_SUFFIXES, PathFinder

        spec = PathFinder.find_spec(name, path, target)
        if spec is None or not spec.origin or not spec.origin.endswith(tuple(EXTENSION_SUFFIXES)):
            return None  # left to the other finders
        libs = _blas_libraries(spec.origin, package)
        if not libs or _mapped(libs[0]):
            self.waiting.discard(package)  # loaded (or none of its own): no more checks
            return None
        need = sum(os.path.getsize(lib) for lib in libs) + os.path.getsize(spec.origin) + BLAS_BUFFER + BLAS_SLACK
        room = self.limit - _address_space()
        if room < need:
            raise BlasNoRoom(os.path.basename(libs[0]), need, room)
        return None


def _blas_libraries(origin: str, package: str) -> list[str]:
    """The OpenBLAS a wheel of ``package`` brings (``numpy.libs/libscipy_openblas64_*.so``) first,
    then the other libraries beside it; [] where it brings none (a system's BLAS)."""
    origin = os.path.realpath(origin)  # as /proc/self/maps names what is mapped
    at = origin.rfind(os.sep + package + os.sep)
    folder = os.path.join(origin[:at], f"{package}.libs")
    try:
        names = sorted(os.listdir(folder), key=lambda name: "openblas" not in name) if at >= 0 else []
    except OSError:  # no wheel's libraries beside it
        return []
    return [os.path.join(folder, name) for name in names] if names and "openblas" in names[0] else []


def _mapped(library: str) -> bool:
    with open("/proc/self/maps") as fh:
        return any(line.endswith(library + "\n") for line in fh)


def _address_space() -> int:
    """This process's address space in bytes (what ``ulimit -v`` limits)."""
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
