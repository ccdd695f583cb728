"""Progress per load and within a load: a solver's ``load_finished`` and
``iteration_done`` reach the run's listeners as ``load_done`` and ``iteration_done``,
from this process and from a process pool's workers, and the CLI's progress line shows
them; a cancel seen at an iteration abandons the realization being solved."""

import io
import threading
import time
from collections import defaultdict

import numpy as np
import pytest

from frictionlab import SolveCancelled, hookimpl, iteration_done, load_finished
from frictionlab.compute import engine
from frictionlab.progress import ProgressReporter
from frictionlab.options import RunOptions
from frictionlab.plugin import listening_to_iterations, listening_to_loads
from frictionlab.preset import build_scene
from frictionlab.compute.realization import compute_chunk, compute_realization
from frictionlab.preset.seeds import realization_rng

from .conftest import SMALL_PRESET, merge

STEPS = 5
SURFACE = merge(SMALL_PRESET, {
    "realizations": 6,
    "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 32, "short_cutoff": 4.0}},
    "solver": {"name": "bem-halfspace", "params": {}}, "slope": {"name": "forward-difference"},
    "loading": {"control": "force", "start": 1.0, "stop": 20.0, "steps": STEPS, "spacing": "log"},
})  # fmt: skip


class Recorder:
    def __init__(self):
        self.events = []

    @hookimpl
    def load_done(self, index, done, total):
        self.events.append(("load", index, done, total))

    @hookimpl
    def realization_done(self, result):
        self.events.append(("realization", result.index))


def test_outside_a_run_load_finished_does_nothing_and_inside_it_is_heard():
    load_finished(1, 2)  # no listener: nothing happens
    heard = []
    with listening_to_loads(lambda done, total: heard.append((done, total))):
        load_finished(1, 2)
        with listening_to_loads(None):
            load_finished(2, 2)
    load_finished(2, 2)
    assert heard == [(1, 2)]


@pytest.mark.parametrize("options", [RunOptions(workers=1, executor="serial"), RunOptions(workers=2, executor="processes")],
                         ids=["serial", "processes"])  # fmt: skip
def test_every_load_of_every_realization_is_heard_before_its_realization(registry, options):
    scene = build_scene(SURFACE, registry=registry)
    recorder = Recorder()
    outcome = engine.run(scene, options, listeners=[recorder])
    assert outcome.status == "completed"
    loads = defaultdict(list)
    for event in recorder.events:
        if event[0] == "load":
            _, index, done, total = event
            assert total == STEPS
            loads[index].append(done)
        else:
            # a realization is heard after all its loads
            assert loads[event[1]] == list(range(1, STEPS + 1)), event
    assert sorted(loads) == list(range(6))


def test_the_progress_bar_notes_the_load_of_a_long_solve(registry, monkeypatch):
    import frictionlab.progress as progress

    notes = []

    class Bar:  # rich draws the bar; what it is told is under test here
        def __init__(self, stream, description, total, completed=0, started=None, clock=None):
            pass

        def update(self, completed, note=""):
            notes.append(note)

        def print(self, text):
            pass

        def stop(self):
            pass

    monkeypatch.setattr(progress, "_Bar", Bar)
    scene = build_scene(SURFACE, registry=registry)
    engine.run(scene, RunOptions(workers=1, executor="serial"), listeners=[ProgressReporter(io.StringIO(), interactive=True, after=0.0)])
    for index in range(6):
        assert [n for n in notes if n.startswith(f"realization {index}: ") and "iteration" not in n] == [f"realization {index}: load {d}/{STEPS}" for d in range(1, STEPS + 1)]


def test_a_log_gets_a_load_line_only_now_and_then(registry, monkeypatch):
    import frictionlab.progress as progress

    monkeypatch.setattr(progress, "LOAD_LINE_SECONDS", 0.0)
    scene = build_scene(SURFACE, registry=registry)
    stream = io.StringIO()
    engine.run(scene, RunOptions(workers=1, executor="serial"), listeners=[ProgressReporter(stream, interactive=False, after=0.0)])
    assert "realization 0: load 1/5" in stream.getvalue()
    stream = io.StringIO()
    monkeypatch.setattr(progress, "LOAD_LINE_SECONDS", 3600.0)
    engine.run(scene, RunOptions(workers=1, executor="serial"), listeners=[ProgressReporter(stream, interactive=False, after=0.0)])
    assert "load" not in stream.getvalue()


# ------------------------------------------------------------ within a load: iterations and cancel

LONG_LOADS = merge(SURFACE, {
    "realizations": 3,
    "spectrum": {"params": {"points": 128, "short_cutoff": 2.0}},
    "solver": {"params": {"tolerance": 1e-13, "stop": "tolerance"}},  # no early certified stop: solves that last
    "loading": {"start": 1.0, "stop": 200.0, "steps": 8},
})  # fmt: skip


class CountdownCancel:
    """A cancel token that becomes set once it has been looked at ``checks`` times."""

    def __init__(self, checks: int):
        self.checks = checks

    def is_set(self) -> bool:
        self.checks -= 1
        return self.checks < 0


@pytest.fixture(scope="module")
def long_loads(registry):
    """The scene of ``LONG_LOADS`` and its realization 0, computed once for the module (seconds)."""
    scene = build_scene(LONG_LOADS, registry=registry)
    return scene, compute_realization(scene, 0)


def test_bem_reports_every_iteration_of_every_load_to_the_listener(long_loads):
    scene, realization = long_loads
    heard = []
    profile = scene.generator.generate(realization_rng(scene.preset.seed, 0))
    slopes = scene.slope.slopes(profile.heights, profile.spacing, profile.periodic)
    with listening_to_loads(lambda done, total: heard.append(("load", done))):
        with listening_to_iterations(lambda iteration, residual: heard.append((iteration, residual))):
            curve = scene.solver.solve(profile, scene.loads, scene.control, slopes)
    iteration_done(1, 0.5)  # outside the block: nobody hears it
    per_load, current = [], []
    for event in heard:
        if event[0] == "load":
            per_load.append(current)
            current = []
        else:
            current.append(event)
    assert len(per_load) == scene.loads.size
    for j, events in enumerate(per_load):
        # one event per step, before the step: 0, 1, ..., iterations - 1, each with the residual then
        assert [i for i, _ in events] == list(range(curve.extras["iterations"][j]))
        assert all(r > scene.solver.params.tolerance for _, r in events)
    np.testing.assert_array_equal(curve.contact_count, realization.contact_count)


def test_a_cancel_seen_within_a_solve_abandons_the_realization(long_loads):
    scene, whole = long_loads
    with pytest.raises(SolveCancelled):
        compute_realization(scene, 0, cancel=CountdownCancel(checks=20))  # 2 between stages, then per iteration
    assert compute_chunk(scene, [0, 1], cancel=CountdownCancel(checks=20)) == []
    # a cancel never set changes nothing: the numbers of the realization computed without one
    assert compute_chunk(scene, [0], cancel=CountdownCancel(checks=10**9))[0].xi.tolist() == whole.xi.tolist()


def test_iterations_are_heard_at_most_four_times_a_second(registry, monkeypatch):
    import frictionlab.compute.realization as realization

    clock = iter(np.arange(0.0, 1000.0, 0.1))  # each look at the clock: 0.1 s later
    monkeypatch.setattr(realization.time, "monotonic", lambda: next(clock))
    heard = []
    watch = realization._SolveWatch(4, realization.SolveListeners(on_iteration=lambda *event: heard.append(event)), None)  # at 0 s
    for iteration in range(10):
        watch.iteration_done(iteration, 1.0 / (iteration + 1))
    # clock at 0.1, 0.2, ... 1.0 s: heard at 0.3 (0.25 s after the start), 0.6 and 0.9 s
    assert heard == [(4, 1, 2, 1 / 3), (4, 1, 5, 1 / 6), (4, 1, 8, 1 / 9)]


class CancelMidSolve:
    """Sets the run's cancel at the first iteration or load heard from a realization after
    the first (which the engine runs alone, before the executor's). Iterations are heard at
    most four times a second, so a fast solve may report none: its first load's end, which
    is always heard and leaves loads to solve, sets the cancel then."""

    def __init__(self, cancel):
        self.cancel, self.solving = cancel, None

    def _heard(self, index):
        if index > 0 and self.solving is None:
            self.solving = index
            self.cancel.set()

    @hookimpl
    def iteration_done(self, index, load, iteration, residual):
        self._heard(index)

    @hookimpl
    def load_done(self, index, done, total):
        if done < total:  # loads are left: the cancel comes within the solve
            self._heard(index)


@pytest.fixture(scope="module")
def long_loads_whole(registry):
    """LONG_LOADS run uninterrupted, once for every test that compares with it."""
    return engine.run(build_scene(LONG_LOADS, registry=registry), RunOptions(workers=1, executor="serial"))


@pytest.mark.parametrize("options", [RunOptions(workers=1, executor="serial"), RunOptions(workers=2, executor="processes")],
                         ids=["serial", "processes"])  # fmt: skip
@pytest.mark.long
def test_a_run_cancelled_within_a_solve_keeps_what_finished_and_resumes_to_the_same_numbers(registry, options,
                                                                                             long_loads_whole):
    scene = build_scene(LONG_LOADS, registry=registry)
    cancel = threading.Event()
    listener = CancelMidSolve(cancel)
    outcome = engine.run(scene, options, listeners=[listener], cancel=cancel)
    whole = long_loads_whole
    finished = outcome.indices.tolist()
    assert outcome.status == "cancelled" and listener.solving is not None
    assert 0 in finished and len(finished) < scene.preset.realizations and outcome.failures == []
    if options.executor == "serial":  # in this process the cancel is seen within the solve that set it
        assert listener.solving not in finished
    # in a pool the cancel travels to the worker, whose solve may end first: then it is kept whole.
    # Every kept row is the uninterrupted run's, never a solve cut short
    for name, values in whole.per_realization.items():
        np.testing.assert_array_equal(outcome.per_realization[name], values[finished], err_msg=name)
    kept = [compute_realization(scene, int(i)) for i in outcome.indices]
    resumed = engine.run(scene, options, restored=kept)
    assert resumed.status == whole.status == "completed"
    for name, values in whole.per_realization.items():
        np.testing.assert_array_equal(resumed.per_realization[name], values, err_msg=name)


def test_in_this_process_a_cancel_returns_at_once_while_a_long_step_still_runs(registry, monkeypatch):
    import frictionlab.compute.realization as realization

    monkeypatch.setattr(realization, "ITERATION_EVENT_SECONDS", 0.0)
    scene = build_scene(LONG_LOADS, registry=registry)
    cancel, release, heard = threading.Event(), threading.Event(), []

    def a_long_step(index, load, iteration, residual):  # a step no check can interrupt (an FFT of 4096^2)
        heard.append(iteration)
        if len(heard) == 1:
            cancel.set()
            release.wait(120)

    results = realization.compute_chunk_here(scene, [0, 1], realization.SolveListeners(on_iteration=a_long_step), cancel)
    returned_during_the_step = not release.is_set()
    release.set()
    assert results == [] and returned_during_the_step


def _sleep_through(seconds: float) -> float:
    time.sleep(seconds)  # a job that never looks at stop_event()
    return seconds


@pytest.mark.long  # a process of its own, seconds end to end: pytest -m long
def test_a_pool_kills_a_worker_whose_job_does_not_stop_after_a_cancel():
    from frictionlab.compute.executors import pool_context
    from frictionlab.compute.pool import WorkerPool

    cancel = threading.Event()
    pool = WorkerPool(1, pool_context(), _sleep_through)
    timer = threading.Timer(0.5, cancel.set)
    timer.start()
    finished = list(pool.run({"long": 120.0}, cancel))  # without the kill: two minutes, then [("long", 120.0)]
    timer.cancel()
    assert finished == []


def test_a_log_shows_the_iterations_of_a_long_load(registry, monkeypatch):
    import re

    import frictionlab.progress as progress
    import frictionlab.compute.realization as realization

    monkeypatch.setattr(progress, "LOAD_LINE_SECONDS", 0.0)
    monkeypatch.setattr(realization, "ITERATION_EVENT_SECONDS", 0.0)
    scene = build_scene(merge(LONG_LOADS, {"realizations": 1}), registry=registry)
    stream = io.StringIO()
    outcome = engine.run(scene, RunOptions(workers=1), listeners=[ProgressReporter(stream, interactive=False, after=0.0)])
    lines = re.findall(r"^realization 0: load (\d+)/8, iteration (\d+), residual (\S+)$", stream.getvalue(), re.M)
    # every step of each load in order, from the first (0), each with a residual above the tolerance
    per_load = defaultdict(list)
    for load, iteration, _ in lines:
        per_load[int(load)].append(int(iteration))
    assert outcome.status == "completed" and list(per_load) == sorted(per_load) and 1 in per_load
    assert all(heard == list(range(len(heard))) for heard in per_load.values())
    assert all(float(residual) > 1e-13 for *_, residual in lines)
