"""Progress per load: a solver's ``load_finished`` reaches the run's listeners as
``load_done``, from this process and from a process pool's workers, and the CLI's
progress line shows it."""

import io
from collections import defaultdict

import pytest

from frictionlab import engine, hookimpl, load_finished
from frictionlab.progress import ProgressReporter
from frictionlab.options import RunOptions
from frictionlab.plugin import listening_to_loads
from frictionlab.preset import build_scene

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
        def __init__(self, stream, description, total, completed=0, started=None):
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
