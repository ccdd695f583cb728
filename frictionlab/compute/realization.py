"""One realization of a scene: generate -> slopes -> solve -> xi.

Kept apart from the driver so every executor (in-process, a process pool, Dask
workers) imports only this and the scene, nothing of the run's bookkeeping.
"""

from __future__ import annotations

import math
import os
import threading
import time
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace

import numpy as np

from ..errors import OUT_OF_MEMORY, PluginError
from ..errors.interrupts import raised_by_signal
from ..plugin.registry import fault_place, plugin_fault
from ..plugin.outputs import (
    LEAVE_INPUTS, RandomWatch, curve_problem, height_of, largest_magnitude, order_problem, profile_problem, read_only,
    refuse, reported_problem, schedule_problem, slopes_problem,
)  # fmt: skip
from ..plugin import SolveCancelled, SolveFailed, defined_rms, force_unit, listening_to_iterations, listening_to_loads
from ..preset import Scene
from ..preset.loads import rng_problem
from ..preset.seeds import realization_rng


@dataclass(frozen=True)
class RealizationResult:
    """What one realization gives. Arrays have one entry per load step; a failed
    realization carries ``error`` and no arrays."""

    index: int
    seconds: float
    xi: np.ndarray | None = None
    contact_count: np.ndarray | None = None
    indentation: np.ndarray | None = None
    force: np.ndarray | None = None  # kept only under indentation control (forces vary)
    real_area_corrected: np.ndarray | None = None  # kept for the solvers that declare corrected_area
    real_gradient_rms: np.ndarray | None = None  # g_r, kept for the solvers that declare real_gradient
    contact_spots: np.ndarray | None = None  # kept for the solvers that declare counts_spots
    slope_rms_line: float = math.nan
    points: int = 0
    force_unit: float = math.nan  # k h X of f = F / (k h X) for this realization's profile
    measured_rms_height: float = math.nan  # the profile's rms height about its own mean
    own_rms_height: float = math.nan  # the h of f when it is the profile's own (profile_rms_height), else NaN
    half_load_points: np.ndarray | None = None  # points carrying half the load, per load (NaN: the solver does not say)
    peak_rms: float = math.nan  # (max z - mean z) / rms height of the profile: a spike stands out
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.error is None


LoadListener = Callable[[int, int, int], None]
"""Hears ``(realization index, loads done, loads)`` as a solver reports each load (``plugin.load_finished``)."""

IterationListener = Callable[[int, int, int, float], None]
"""Hears ``(realization index, load, iteration, residual)`` within a load (``plugin.iteration_done``):
``load`` counts the scene's loads from 1."""



@dataclass(frozen=True)
class SolveListeners:
    """Who hears a realization's solve as it goes: its loads, and its iterations within a load."""

    on_load: LoadListener | None = None
    on_iteration: IterationListener | None = None


UNHEARD = SolveListeners()

ITERATION_EVENT_SECONDS = 0.25  # within a load, progress at most this often (a worker's pipe, a bar's redraws)


class _SolveWatch:
    """The listener of one realization's solve: forwards its loads, forwards its iterations
    at most every ``ITERATION_EVENT_SECONDS``, and raises ``SolveCancelled`` once ``cancel``
    is set (at every iteration, and between the stages of the realization)."""

    def __init__(self, index: int, listeners: SolveListeners, cancel):
        self.index, self.cancel = index, cancel
        self.on_load, self.on_iteration = listeners.on_load, listeners.on_iteration
        self.load = 1
        self.last_event = time.monotonic()

    def check(self) -> None:
        if self.cancel is not None and self.cancel.is_set():
            raise SolveCancelled(f"realization {self.index} cancelled")

    def load_done(self, done: int, total: int) -> None:
        self.load = done + 1
        if self.on_load is not None:
            self.on_load(self.index, done, total)

    def iteration_done(self, iteration: int, residual: float) -> None:
        self.check()
        if self.on_iteration is not None:
            now = time.monotonic()
            if now - self.last_event >= ITERATION_EVENT_SECONDS:
                self.last_event = now
                self.on_iteration(self.index, self.load, iteration, residual)


def compute_realization(scene: Scene, index: int, listeners: SolveListeners = UNHEARD, cancel=None) -> RealizationResult:
    """Realization ``index`` of ``scene``; ``listeners`` hear its solver's progress. A failure is carried on the result; ``SolveCancelled`` is raised once ``cancel``
    (anything with ``is_set()``) is set, within an iteration of the solver."""
    watch = _SolveWatch(index, listeners, cancel)
    with listening_to_loads(watch.load_done), listening_to_iterations(watch.iteration_done):
        return _compute(scene, index, watch)


SAFE_SLOPE = 2.0**400  # slopes up to this in magnitude (and down to its inverse) square and sum without overflow


def slope_scale(slopes: np.ndarray) -> float:
    """1, or the power of two that brings the largest magnitude among ``slopes`` to about 1
    when their squares would overflow or underflow (heights over spacing past 1e154, say: both
    numbers a preset allows); a power of two scales every slope exactly."""
    largest = largest_magnitude(slopes)  # NaN ones (undefined slopes) passed by
    if not math.isfinite(largest) or largest == 0.0 or 1 / SAFE_SLOPE <= largest <= SAFE_SLOPE:
        return 1.0
    return math.ldexp(1.0, -math.frexp(largest)[1])


def _solve(scene: Scene, profile, slopes: np.ndarray, watch: _SolveWatch, unit: float, randomness: RandomWatch):
    """The solver's curve over the scene's loads; contact fractions first turned into this
    profile's forces by solving (``loads.forces_for_fractions``, from f = the fraction: ``unit``
    is the profile's k h X). ``randomness``: numpy's global random state, looked at last before the solver."""
    if scene.solver_loads is not None:
        loads, control = scene.solver_loads, scene.control
    else:
        from ..preset.loads import forces_for_fractions

        def seeking(j: int) -> None:  # iterations of the search are said as the load's
            watch.load = j + 1

        loads = forces_for_fractions(scene.solver, profile, scene.loads, slopes, first_guess=unit, on_load=seeking)
        control = "force"
    if problem := schedule_problem(loads):  # contact fractions: forces found by solving, in order
        raise ValueError(problem)
    curve = scene.solver.solve(profile, read_only(loads), control, slopes)
    refuse(scene.solver, randomness.problem("solve()")
           or curve_problem(scene.solver, curve, loads.size)
           or reported_problem(curve, loads, control, profile.points, largest_magnitude(slopes))
           or order_problem(scene.solver, curve, control))  # fmt: skip
    return curve


def _compute(scene: Scene, index: int, watch: _SolveWatch) -> RealizationResult:
    check_cancel = watch.check
    start = time.perf_counter()
    try:
        rng = realization_rng(scene.preset.seed, index)
        randomness = RandomWatch()  # looked at between plugin calls: one look per call
        profile = scene.generator.generate(rng)
        refuse(scene.generator, randomness.problem("generate()") or profile_problem(scene.generator, profile))
        if index == 0 and not scene.probed:  # a generator ignoring its rng: checked once a run, here if not before it
            refuse(scene.generator, rng_problem(scene, profile) or randomness.problem("generate()"))
        profile = replace(profile, heights=read_only(profile.heights))  # what the estimator and solver are lent
        check_cancel()  # a large surface takes a second to generate
        slopes = scene.slope.slopes(profile.heights, profile.spacing, profile.periodic)
        refuse(scene.slope, randomness.problem("slopes()") or slopes_problem(scene.slope, slopes, profile))
        check_cancel()
        scale = slope_scale(slopes)  # xi is a ratio of two rms slopes: an exact scale cancels
        slopes = read_only(slopes * scale if scale != 1.0 else slopes)
        if scene.slope.undefined_points(profile.periodic):
            slope_rms_line = defined_rms(slopes)  # over the points that have a slope
        else:  # every slope defined: a NaN makes the rms NaN, refused below
            slope_rms_line = float(np.sqrt(np.mean(np.square(slopes))))
        if not (math.isfinite(slope_rms_line) and slope_rms_line > 0):
            raise ValueError(
                f"the rms slope of the whole line is {slope_rms_line}: xi is undefined (is the line constant?)"
            )
        h, own_h = height_of(scene.generator, profile)
        refuse(scene.generator, randomness.problem("profile_rms_height()"))
        unit = force_unit(scene.solver, h, profile)
        curve = _solve(scene, profile, slopes, watch, unit, randomness)
        half = curve.half_load_points
        heights = np.asarray(profile.heights, dtype=float)
        mean = float(heights.mean())
        rms = float(np.sqrt(np.mean(np.square(heights - mean))))  # np.std, its mean kept for the peak
        return RealizationResult(
            index=index,
            seconds=time.perf_counter() - start,
            xi=curve.slope_rms_contact / slope_rms_line,
            contact_count=np.asarray(curve.contact_count),
            indentation=np.asarray(curve.indentation),
            force=np.asarray(curve.force) if scene.forces_vary else None,
            real_area_corrected=np.asarray(curve.real_area_corrected, float) if scene.solver.corrected_area else None,
            real_gradient_rms=np.asarray(curve.real_gradient_rms, float) / scale if scene.solver.real_gradient else None,
            contact_spots=np.asarray(curve.contact_spots, float) if scene.solver.counts_spots else None,
            slope_rms_line=slope_rms_line / scale,
            points=profile.points,
            force_unit=unit,
            measured_rms_height=rms,
            own_rms_height=math.nan if own_h is None else float(own_h),
            half_load_points=np.full(scene.loads.size, math.nan) if half is None else np.asarray(half, float),
            peak_rms=(float(heights.max()) - mean) / rms if rms > 0 else math.nan,
        )
    except SolveCancelled:  # neither a result nor a failure: the realization runs again on resume
        raise
    except (Exception, SystemExit, KeyboardInterrupt) as exc:  # carried, not raised: one bad line (a plugin's
        if raised_by_signal(exc):  # sys.exit(), its own KeyboardInterrupt) must not end the run; Ctrl-C must
            raise
        return RealizationResult(index=index, seconds=time.perf_counter() - start, error=_capped(_failure(scene, exc)))


MAX_ERROR_CHARACTERS = 4000  # of a realization's recorded error: a chunk holds it (runs.chunks bounds its size)


def _capped(error: str) -> str:
    """``error`` cut to MAX_ERROR_CHARACTERS, saying how much was left out: a plugin's message of a
    megabyte made its chunk larger than any chunk can be, refused and computed again on each resume."""
    if len(error) <= MAX_ERROR_CHARACTERS:
        return error
    cut = MAX_ERROR_CHARACTERS - 40
    return f"{error[:cut]}... ({len(error) - cut} more characters)"


def _failure(scene: Scene, exc: BaseException) -> str:
    """A realization's error as recorded, ``Type: message``: a failure the plugin explains
    (``SolveFailed``) as its message; one raised in a third party's plugin as that plugin's
    fault; a broken answer named with its plugin; anything else with the line that raised it."""
    if isinstance(exc, SolveFailed):  # deliberate and told for the user: no source line, no blame
        return f"SolveFailed: {exc}"
    classes = [type(scene.spectrum), type(scene.solver), type(scene.slope)]
    if isinstance(exc, MemoryError) and (place := fault_place(exc, classes)) is not None:
        return f"{OUT_OF_MEMORY}: {exc} (in {place[0]}, {place[1]})"  # the machine's limit, met in a plugin: no blame
    fault = plugin_fault(exc, classes)
    if fault is not None:
        return f"PluginError: {fault}" + (f" ({LEAVE_INPUTS})" if "read-only" in str(exc) else "")
    error = f"{type(exc).__name__}: {exc}"
    if isinstance(exc, PluginError):  # no line of ours to show
        return error
    where = traceback.extract_tb(exc.__traceback__)[-1]
    return error + f" ({os.path.basename(where.filename)}:{where.lineno})"


def compute_chunk(
    scene: Scene, indices: Iterable[int], listeners: SolveListeners = UNHEARD, cancel=None
) -> list[RealizationResult]:
    """The task every executor runs: a chunk of realizations, in order. Once ``cancel`` is
    set it returns those finished (a prefix of ``indices``, maybe none): the realization
    in progress is abandoned."""
    results = []
    for i in indices:
        try:
            results.append(compute_realization(scene, int(i), listeners, cancel))
        except SolveCancelled:
            break
        if cancel is not None and cancel.is_set():
            break
    return results


CANCEL_POLL_SECONDS = 0.05  # how often ``compute_chunk_here`` looks at the cancel while it waits
_abandoned: list[threading.Thread] = []  # solves a cancelled run left to stop by themselves


def solve_abandoned() -> bool:
    """Whether a solve that a cancelled run left behind (``compute_chunk_here``) is still
    inside its step in this process."""
    return any(thread.is_alive() for thread in _abandoned)


def compute_chunk_here(
    scene: Scene, indices: Iterable[int], listeners: SolveListeners = UNHEARD, cancel=None
) -> list[RealizationResult]:
    """``compute_chunk`` for this process: in a helper thread, this one waiting (and
    handling signals). Once ``cancel`` is set it returns at once with the realizations
    finished; the one being solved is left to stop at its next iteration by itself: a
    step of a large solve (FFTs of millions of points) takes seconds and cannot be
    interrupted. An error of a listener is raised here."""
    finished: list[RealizationResult] = []
    errors: list[BaseException] = []

    def work() -> None:
        try:
            for index in indices:
                finished.extend(compute_chunk(scene, [index], listeners, cancel))
                if cancel is not None and cancel.is_set():
                    return
        except BaseException as exc:  # handed to the waiting thread
            errors.append(exc)

    solver = threading.Thread(target=work, name="frictionlab-solve", daemon=True)
    try:
        solver.start()
    except RuntimeError:  # no thread to be had (a container's pids limit): solved here, a cancel heard between realizations
        work()
    while solver.is_alive():
        solver.join(CANCEL_POLL_SECONDS)
        if cancel is not None and cancel.is_set():
            _abandoned.append(solver)
            return list(finished)
    if errors:
        raise errors[0]
    return finished
