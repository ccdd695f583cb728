"""Peak memory of a run, estimated from the preset before anything starts.

The estimate is an upper bound for the built-in line pipeline (power-law
synthesis, a slope estimator, the sorted spring sweep), calibrated by measuring
the growth of ``ru_maxrss`` over one realization (benchmarks/bench_scale.py); a
solver that needs more per point declares it (``ContactSolver.bytes_per_point``,
the boundary elements of the half-space: about 1.5x the line pipeline):

* 32 bytes per grid point in the usual case (few candidate points sorted),
  97 when the largest load reaches full contact and every point is sorted;
  ``BYTES_PER_POINT`` takes the worst case with a margin;
* a process with numpy, scipy and frictionlab imported holds about 70 MiB;
* freed arrays of up to 32 MiB are kept for the next realization (``heap``): what is
  kept was in use a moment before, so the peak does not grow;
* the main process keeps every finished realization's per-load arrays;
* a surface pressed as its MDR-equivalent line is pressed on a line of
  2 sqrt(A / pi) / dx points, but the main process first makes that line from the
  whole surface (``SpectrumGenerator.equivalent_line_bytes``), and
  keeps what the surface derived (its synthesis, its map) for the rest of the run;
  worker processes are sent the line alone (``Scene.for_pressing``).

Not counted here: filling a measured map's points not measured (``undefined: harmonic``), whose
cost (kilobytes per point filled) depends on how many there are, known only once the file is
read; the reader estimates it then, before the fill, and refuses one that does not fit.
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from ..errors import RunError, skip_hint, workers_advice
from ..preset import Scene

MiB = 2**20
GiB = 2**30
BYTES_PER_POINT = 112  # measured worst case 97 B (full contact), plus 15% margin
PROFILE_BYTES_PER_POINT = 24  # the heights and slopes a solver is given (16 B), plus 50 %
BYTES_PER_STEP = 96  # per load step in a worker: the sweep's per-load arrays
PROCESS_BASE = 160 * MiB  # main process: interpreter, numpy, scipy, pydantic, matplotlib for the plot
# Of PROCESS_BASE, what matplotlib takes once imported, and once a figure was drawn as PNG (its
# backend imported): a little below the address space each took, measured (34 and 71 MiB).
PLOT_SHARES = {"matplotlib": 32 * MiB, "matplotlib.backends.backend_agg": 64 * MiB}
WORKER_BASE = {"serial": 0, "processes": 96 * MiB, "dask": 256 * MiB}  # per worker process (Dask: with its nanny)
# What a Dask worker's ``memory_limit`` watches: the worker process alone, without
# its nanny (measured 95 MiB with frictionlab and the plugins imported, after a run).
DASK_WORKER_PROCESS = 128 * MiB
KEPT_COPIES = 3  # per-realization rows: the results, the stacked arrays, the file being written
# Making the MDR-equivalent line of a surface whose spectrum does not say what it takes
# (``SpectrumGenerator.equivalent_line_bytes``), per point of the surface: the built-in
# spectra's worst, a non-periodic map read, reflected across its edges and transformed
# (72 B measured), plus a third.
EQUIVALENT_LINE_BYTES_PER_POINT = 96
# numpy's FFT of a line whose length has a prime factor above its square root (Bluestein's algorithm,
# on a padded length of about twice it): 128 B a point more, measured (2,814,498 = 2 x 3^2 x 156,361)
BLUESTEIN_BYTES_PER_POINT = 160


@dataclass(frozen=True)
class MemoryEstimate:
    points: int  # grid points of one realization (of the line, for an MDR-equivalent line)
    workers: int
    executor: str
    per_realization: int  # bytes one realization needs while it runs
    per_worker: int  # a worker process: its base plus one realization
    main: int  # the main process: base plus the kept rows (and the making of an equivalent line)
    total: int  # the peak of the whole run on this machine
    grid: int  # points of the spectrum's grid (the surface's, for an MDR-equivalent line)
    making: int = 0  # bytes the main process takes to make the MDR-equivalent line of the surface

    def describe(self) -> str:
        if self.making:
            return (
                f"{gib(self.total)} (making the MDR-equivalent line of a surface of {points_text(self.grid)} points: "
                f"{gib(self.making)}, then {self.workers} realization(s) at a time of {points_text(self.points)} points: "
                f"{gib(self.per_realization)} each)"
            )
        if self.executor == "serial":
            return (
                f"{gib(self.total)} (one realization of {points_text(self.points)} points: {gib(self.per_realization)}, "
                f"in this process, which keeps {gib(self.main)})"
            )
        return (
            f"{gib(self.total)} ({self.workers} worker(s) x {gib(self.per_worker)} for realizations of "
            f"{points_text(self.points)} points, plus {gib(self.main)} in the main process)"
        )


def gib(n: float) -> str:
    """``n`` bytes in GiB (two decimals; three significant digits from 100,000 GiB on), or MiB below 0.1 GiB."""
    if n >= 1e5 * GiB:  # a preset's absurd grid: its digits would fill the screen
        return f"{n / GiB:.3g} GiB"
    return f"{n / GiB:.2f} GiB" if n >= 0.1 * GiB else f"{n / MiB:.0f} MiB"


def points_text(n: int) -> str:
    """A count of points with thousands separated, or in three significant digits from 1e12 on."""
    return f"{n:,}" if n < 10**12 else f"{float(n):.3g}"


def maps_to_line(scene: Scene) -> bool:
    """Whether the run presses the MDR-equivalent line of its surface: made already, or
    not yet (``line_to_make``)."""
    return scene.equivalent_line is not None or line_to_make(scene)


def line_to_make(scene: Scene) -> bool:
    """Whether this process has yet to make the MDR-equivalent line of the scene's surface:
    ``build_scene`` checks the memory before it makes it (once made, the peak of making it
    is past, and what the surface keeps is in the memory this process already uses)."""
    return scene.equivalent_line is None and scene.spectrum.dimension == 2 and scene.solver.mdr_lines


def line_points(surface_points: int) -> int:
    """Points of the MDR-equivalent line of a surface of ``surface_points`` square pixels:
    ceil(2 sqrt(A / pi) / dx), whatever dx (``equivalent_line.line_grid``; at least 8)."""
    return max(8, math.ceil(2.0 * math.sqrt(surface_points / math.pi) * (1 - 1e-12)))


def grid_points(scene: Scene) -> int:
    """Points of the spectrum's grid: from its ``grid_shape()``, else by generating
    realization 0 once (0 if that fails). For an MDR-equivalent line, the surface's."""
    shape = scene.spectrum.grid_shape()
    if shape is not None:
        return math.prod(shape)
    from ..preset.seeds import realization_rng

    try:
        return scene.spectrum.generate(realization_rng(scene.preset.seed, 0)).points
    except Exception:  # the run itself reports a spectrum that fails, per realization
        return 0


def bytes_per_point(scene: Scene) -> int:
    """Peak bytes of one realization per grid point: the solver's declaration
    (``ContactSolver.bytes_per_point``) plus the profile and slopes it is given, never
    less than the line pipeline's figure."""
    declared = scene.solver.bytes_per_point
    return BYTES_PER_POINT if declared is None else max(BYTES_PER_POINT, declared + PROFILE_BYTES_PER_POINT)


def kept_arrays(scene: Scene) -> int:
    """Per-load arrays the main process keeps of each realization: xi, contact count,
    indentation, the points carrying half the load, and the forces where they vary."""
    return 5 if scene.forces_vary else 4


def _making_line(scene: Scene, points: int) -> int:
    """Bytes that making the MDR-equivalent line of a surface of ``points`` points takes: what
    the spectrum declares for its own grid; for another, what it declares with its points
    parameter set to the side of a square of ``points`` (the advice's grids), else in proportion."""
    spectrum, grid = scene.spectrum, grid_points(scene)
    declared = spectrum.equivalent_line_bytes()
    if declared is None or grid < 1:
        return points * EQUIVALENT_LINE_BYTES_PER_POINT
    side = math.isqrt(points)
    if points != grid and spectrum.points_param and side * side == points:
        try:
            return type(spectrum)(spectrum.params.model_copy(update={spectrum.points_param: side})).equivalent_line_bytes()
        except ValueError:  # parameters that do not hold at that side: in proportion
            pass
    return declared if points == grid else math.ceil(declared * points / grid)


def estimate(scene: Scene, *, workers: int, executor: str, points: int | None = None) -> MemoryEstimate:
    """The peak memory of ``scene``'s run; ``points``: of the spectrum's grid (default
    ``grid_points``), the surface's when its MDR-equivalent line is pressed."""
    grid = grid_points(scene) if points is None else points
    points = line_points(grid) if maps_to_line(scene) else grid
    making = _making_line(scene, grid) if line_to_make(scene) else 0
    steps = int(scene.loads.size)
    kept = scene.preset.realizations * (steps * 8 * kept_arrays(scene) * KEPT_COPIES + 512)
    per_realization = points * bytes_per_point(scene) + steps * BYTES_PER_STEP
    if points == grid and scene.spectrum.dimension == 1:  # a line made by one FFT of its length
        per_realization += fft_extra_bytes(points)
    main = PROCESS_BASE + kept + making  # what the surface keeps of its making stays in this process
    if executor == "serial":
        per_worker, total, workers = 0, main + per_realization, 1
    else:
        per_worker = WORKER_BASE.get(executor, WORKER_BASE["dask"]) + per_realization
        # the main process measures one realization before the workers start
        total = main + max(per_realization, workers * per_worker)
    return MemoryEstimate(points, workers, executor, per_realization, per_worker, main, total, grid, making)


def fft_extra_bytes(points: int) -> int:
    """What numpy's FFT of ``points`` takes beyond the line pipeline's figure: BLUESTEIN_BYTES_PER_POINT
    a point where a prime factor exceeds the square root (it may choose Bluestein's algorithm), else 0."""
    rest, factor = points, 2
    while factor * factor <= rest:  # the prime factors below the root divided out
        while rest % factor == 0:
            rest //= factor
        factor += 1 if factor == 2 else 2
    return BLUESTEIN_BYTES_PER_POINT * points if rest > 1 and rest * rest > points else 0


def smooth_at_most(n: int) -> int:
    """The largest 2^a 3^b 5^c 7^d <= ``n`` (>= 1): a length numpy's FFT takes in place, fast."""
    best, power7 = 1, 1
    while power7 <= n:
        power5 = power7
        while power5 <= n:
            power3 = power5
            while power3 <= n:
                best = max(best, power3 << (n // power3).bit_length() - 1)  # the largest 2^a after it
                power3 *= 3
            power5 *= 5
        power7 *= 7
    return best


def available_memory() -> tuple[int, str]:
    """Bytes this process may still use, and where the figure comes from: the
    smallest of MemAvailable, the room left under a cgroup limit, and under the
    process limits RLIMIT_AS and RLIMIT_DATA."""
    found = _machine_rooms() + _process_limits()
    if not found:
        return 2**62, "unknown: the platform does not say"
    return min(found)


def _counted_twice() -> int:
    """What the room left to this process is credited once it has imported matplotlib or drawn
    a figure (a report's later figures): that share of ``PROCESS_BASE``, which the estimate
    counts, is then also in the memory this process uses, which the room is measured after."""
    return max((share for name, share in PLOT_SHARES.items() if name in sys.modules), default=0)


def _machine_rooms() -> list[tuple[int, str]]:
    """The room the machine leaves to all the run's processes together: MemAvailable, and
    what a cgroup limit leaves."""
    found: list[tuple[int, str]] = []
    try:
        found.append((_system_available() + _counted_twice(), "the memory the system says is available: MemAvailable on Linux"))
    except (OSError, RuntimeError):
        pass
    for limit_file, usage_file in (
        ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),  # cgroup v2
        ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes"),  # v1
    ):
        try:
            limit = Path(limit_file).read_text().strip()
            usage = int(Path(usage_file).read_text().strip())
        except (OSError, ValueError):
            continue
        if limit.isdigit() and int(limit) < 2**60:
            found.append((int(limit) - usage + _counted_twice(), f"the cgroup limit {limit_file} less current usage"))
    return found


PROC_MEMINFO, PROC_STATM = "/proc/meminfo", "/proc/self/statm"  # Linux


def _system_available() -> int:
    """MemAvailable of /proc/meminfo on Linux, read directly (psutil's import would be most
    of a short run's memory check); psutil's figure elsewhere."""
    try:
        with open(PROC_MEMINFO, "rb") as fh:
            for line in fh:
                if line.startswith(b"MemAvailable:"):
                    return int(line.split()[1]) * 1024  # kB
    except (OSError, ValueError, IndexError):
        pass
    import psutil  # every platform's available memory

    return int(psutil.virtual_memory().available)


def _address_space() -> tuple[int, int]:
    """(virtual size, data segment) of this process in bytes: /proc/self/statm on Linux,
    psutil elsewhere (where the data segment is not told, the virtual size stands for it)."""
    try:
        with open(PROC_STATM, "rb") as fh:
            fields = fh.read().split()
        page = os.sysconf("SC_PAGE_SIZE")
        return int(fields[0]) * page, int(fields[5]) * page
    except (OSError, ValueError, IndexError):
        import psutil

        used = psutil.Process().memory_info()
        return used.vms, getattr(used, "data", used.vms)  # data: psutil has it on Linux only


def _process_limits() -> list[tuple[int, str]]:
    """Room left under this process's limits on address space and data (``ulimit -v``,
    ``ulimit -d``), which each worker process inherits: a limit of each process, not of the
    run (``check_fits``). The room is the limit less the address space this process holds,
    which a worker, importing the same modules, holds too."""
    try:
        import resource
    except ImportError:  # not on Windows
        return []
    vms, data = _address_space()
    found = []
    for name, current in (("RLIMIT_AS", vms), ("RLIMIT_DATA", data)):
        soft, _ = resource.getrlimit(getattr(resource, name))
        if soft != resource.RLIM_INFINITY:
            found.append((soft - current + _counted_twice(), f"the process limit {name} (ulimit -{'v' if name == 'RLIMIT_AS' else 'd'}) less what this process uses"))
    return found


def _largest_process(guess: MemoryEstimate) -> int:
    """The peak of the run's largest process: the main one (its rows, and the realization it
    measures before the workers start, or runs itself), or a worker."""
    return max(guess.main + guess.per_realization, guess.per_worker)


def _check_each_process(scene: Scene, guess: MemoryEstimate, executor: str) -> None:
    """Refuse (RunError) a run one of whose processes would pass a process limit (``ulimit
    -v``, ``ulimit -d``), naming it and a grid that would fit: fewer workers never help,
    since each worker has the whole limit to itself."""
    need = _largest_process(guess)
    for room, source in _process_limits():
        if need <= room:
            continue
        points_param = _points_path(scene)
        fits = _largest_process(estimate(scene, workers=1, executor=executor, points=1)) <= room
        if not fits:  # frictionlab itself does not fit: no setting of the preset helps
            advice = _higher_limit(source, room, need)
        elif points_param:
            advice = f"{points_param} <= {_most_points(scene, executor, room, _largest_process):,}, or with {_higher_limit(source, room, need)}"
        else:  # only a smaller map helps when its line alone does not fit: no count of realizations does
            advice = _smaller_map(guess) if guess.making + PROCESS_BASE > room else "fewer realizations"
        main_largest = need == guess.main + guess.per_realization
        making = (f"making the MDR-equivalent line of a surface of {points_text(guess.grid)} points in the main process: "
                  f"{gib(guess.making)}, " if guess.making and main_largest else "")  # fmt: skip
        own = need - guess.per_realization - (guess.making if main_largest else 0)  # what a 0 MiB realization leaves
        raise RunError(
            f"one process of this run would need about {gib(need)} at its peak ({making}a realization of "
            f"{points_text(guess.points)} points: {gib(guess.per_realization)}, the process itself with Python, its "
            f"libraries and what it keeps: {gib(own)}), but {gib(room)} is available ({source}; each worker process has the "
            f"limit to itself). It would fit with {advice}.{skip_hint()}"
        )


def _higher_limit(source: str, room: int, need: int) -> str:
    """The process limit (``source``, which leaves ``room``) under which ``need`` fits, as
    the ``ulimit`` command that sets it: whole MiB in KiB (as ulimit counts), 2 % above, since
    what a process holds once loaded differs from one start to the next by some kB."""
    import resource

    name, flag = ("RLIMIT_AS", "-v") if "RLIMIT_AS" in source else ("RLIMIT_DATA", "-d")
    soft, _ = resource.getrlimit(getattr(resource, name))
    return f"a higher limit: ulimit {flag} {math.ceil((soft - room + need) * 1.02 / MiB) * 1024} or more"


def _smaller_map(guess: MemoryEstimate) -> str:
    """The advice when making a surface's MDR-equivalent line alone does not fit."""
    return (f"fewer points: making the MDR-equivalent line of a surface of {points_text(guess.grid)} points alone "
            f"needs {gib(guess.making)} (a measured map: crop it or make its pixels coarser)")


def _points_path(scene: Scene) -> str | None:
    """The preset path of the spectrum's points parameter, if it has one."""
    name = scene.spectrum.points_param
    return f"spectrum.params.{name}" if name else None


def _total(guess: MemoryEstimate) -> int:
    return guess.total


def _in_dask_worker(guess: MemoryEstimate) -> int:
    return DASK_WORKER_PROCESS + guess.per_realization


def _most_points(scene: Scene, executor: str, available: int, need=_total) -> int:
    """The largest points per side (``SpectrumGenerator.points_param``) whose one-worker
    estimate fits: ``need(estimate) <= available`` (by default the run's whole peak), 2 % to
    spare, as ``_higher_limit`` leaves (a count offered at the edge was refused when run, the
    process holding a MiB more at its check). A line's is a length its FFT takes without more
    memory (``smooth_at_most``: 2,814,498, with a prime factor of 156,361, was offered and ran out)."""
    available, dimension = int(0.98 * available), scene.spectrum.dimension
    side = smooth_at_most if dimension == 1 else (lambda n: n)  # monotone: the search below holds

    def fits(n: int) -> bool:
        return need(estimate(scene, workers=1, executor=executor, points=side(n) ** dimension)) <= available

    low, high = 1, 2
    while fits(high):
        low, high = high, 2 * high
    while high - low > 1:
        middle = (low + high) // 2
        low, high = (middle, high) if fits(middle) else (low, middle)
    return side(low)


def check_fits(scene: Scene, *, workers: int, executor: str, remote_workers: bool = False) -> MemoryEstimate:
    """Refuse (RunError) a run whose estimated peak exceeds the available memory,
    naming the estimate, the limit and a setting that would fit."""
    if remote_workers:  # workers on other machines: only the main process is here
        executor, workers = "serial", 1
    guess = estimate(scene, workers=workers, executor=executor)
    available, source = available_memory()
    if executor != "serial" and source.startswith("the process limit"):
        # a process limit bounds each of the run's processes, not their sum: the sum is the machine's to bound
        _check_each_process(scene, guess, executor)
        available, source = min(_machine_rooms(), default=(2**62, "unknown: the platform does not say"))
    if guess.total <= available:
        return guess
    advice = []
    for fewer in range(workers - 1, 0, -1):
        if estimate(scene, workers=fewer, executor=executor, points=guess.grid).total <= available:
            advice.append(workers_advice(fewer))
            break
    least = estimate(scene, workers=1, executor=executor, points=1).total  # frictionlab itself, with the smallest grid
    if not advice and least > available:  # no setting of the preset helps
        advice.append(_higher_limit(source, available, guess.total) if source.startswith("the process limit") else
                      f"more memory free: frictionlab itself (Python, numpy, scipy) needs about {gib(least)}")  # fmt: skip
    if not advice:
        one = estimate(scene, workers=1, executor=executor, points=guess.grid)
        points_param = _points_path(scene)
        one_worker = f"{workers_advice(1)} and " if workers > 1 else ""  # not advised to a run that has one already
        if points_param:
            advice.append(f"{one_worker}{points_param} <= {_most_points(scene, executor, available):,}")
        else:
            rows = scene.loads.size * 8 * kept_arrays(scene) * KEPT_COPIES + 512
            most = math.floor((available - PROCESS_BASE - one.making - one.per_realization) / rows)
            if most >= 1:
                advice.append(f"{one_worker}realizations <= {most:,}")
            elif one.making:  # no count of realizations fits: only a smaller surface does
                advice.append(_smaller_map(one))
            else:  # no count of realizations fits (it offered 'realizations <= 0'): only a smaller grid does
                advice.append(f"fewer points: one realization of {points_text(one.points)} points alone needs "
                              f"{gib(one.per_realization)} (a measured scan: crop it or make its pixels coarser)")  # fmt: skip
    if source.startswith("the process limit") and not advice[0].startswith("a higher limit"):
        advice[0] += f", or with {_higher_limit(source, available, guess.total)}"
    raise RunError(
        f"this run would need about {guess.describe()} at its peak, but {gib(available)} is available "
        f"({source}). It would fit with {advice[0]}.{skip_hint()}"
    )


def check_worker_limits(scene: Scene, limits: Mapping[str, int | None], *, usable: float = 1.0) -> MemoryEstimate:
    """Refuse (RunError) a run whose realization cannot fit in the smallest
    memory limit of the Dask workers, naming that worker, its limit, the
    per-task estimate and a grid that would fit. ``limits``: bytes by worker
    address, 0 or None for a worker without a limit (skipped). ``usable``: the
    fraction of its limit at which a worker is killed (Dask's
    ``distributed.worker.memory.terminate``)."""
    guess = estimate(scene, workers=1, executor="dask")
    bounded = {address: limit for address, limit in limits.items() if limit}
    if not bounded:
        return guess
    address, limit = min(bounded.items(), key=lambda item: item[1])
    need, room = _in_dask_worker(guess), int(limit * usable)
    if need <= room:
        return guess
    smallest = f"the smallest of {len(bounded)} workers with a limit; " if len(bounded) > 1 else ""
    advice = f"workers with a memory limit of at least {gib(math.ceil(need / usable))}"
    one_point = estimate(scene, workers=1, executor="dask", points=1)
    if _points_path(scene) and _in_dask_worker(one_point) <= room:
        advice = f"{_points_path(scene)} <= {_most_points(scene, 'dask', room, _in_dask_worker):,}, or on " + advice
    raise RunError(
        f"one realization of {points_text(guess.points)} points would need about {gib(need)} in a Dask worker "
        f"({gib(guess.per_realization)} plus {gib(DASK_WORKER_PROCESS)} for the worker process), but Dask worker "
        f"{address} has a memory limit of {gib(limit)} ({smallest}Dask kills a worker at {usable:.0%} of its limit). "
        f"It would fit with {advice}.{skip_hint()}"
    )
