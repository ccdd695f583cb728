"""The run listener's snapshots: coalesced, and the interim fit is the final point estimate."""


import numpy as np
import pytest

from frictionlab.compute.engine import run as engine_run
from frictionlab.compute.fit import least_squares
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.tui.live import LiveListener

from ..conftest import merge
from .conftest import TINY


def test_live_snapshots_coalesce_and_the_interim_fit_is_the_final_point_estimate(registry):
    scene = build_scene(merge(TINY, {"realizations": 12}), registry=registry)
    posted = []
    outcome = engine_run(scene, RunOptions(workers=1), listeners=[LiveListener(posted.append, interval=3600.0)])
    # started, the first and the last realization, finished: nothing for the ten in between
    assert [s.done for s in posted] == [0, 1, 12, 12]
    last = posted[-1]
    assert last.finished and last.failed == 0
    np.testing.assert_allclose(last.xi, outcome.xi, rtol=1e-12)
    np.testing.assert_allclose(last.f, outcome.f, rtol=1e-12)
    coef, *_ = least_squares(outcome.f, outcome.xi)
    assert last.fit.a == pytest.approx(outcome.fit.a, rel=1e-10) == pytest.approx(coef[0], rel=1e-10)
    assert last.fit.b == pytest.approx(outcome.fit.b, rel=1e-10)

    every = []
    engine_run(scene, RunOptions(workers=1), listeners=[LiveListener(every.append, interval=0.0)])
    assert [s.done for s in every] == [0, *range(1, 13), 12]


def twelve_stopped_after_five(registry, folder):
    """A scene of 12 realizations, and the outcome of its run into ``folder`` cancelled once 5 were done."""
    import threading

    from frictionlab.plugin.hookspecs import hookimpl
    from frictionlab.runs.runner import run_to_folder

    scene = build_scene(merge(TINY, {"realizations": 12, "output": {"plot": False}}), registry=registry)  # numbers only
    cancel = threading.Event()

    class StopAfterFive:
        @hookimpl
        def realization_done(self, done):
            if done >= 5:
                cancel.set()

    stopped, _ = run_to_folder(scene, folder, RunOptions(workers=1), listeners=[StopAfterFive()], cancel=cancel)
    return scene, stopped


def test_after_a_resume_the_interim_fit_covers_the_restored_realizations_too(registry, tmp_path):
    from frictionlab.runs.runner import run_to_folder

    scene, stopped = twelve_stopped_after_five(registry, tmp_path)
    posted = []
    resumed, _ = run_to_folder(scene, tmp_path, RunOptions(workers=1, resume=True),
                               listeners=[LiveListener(posted.append, interval=0.0)])  # fmt: skip
    assert posted[0].done == posted[0].restored == stopped.done  # the restored ones, shown at once
    np.testing.assert_allclose(posted[0].xi, stopped.xi, rtol=1e-12)
    last = posted[-1]
    assert last.done == 12 and resumed.done == 12
    np.testing.assert_allclose(last.xi, resumed.xi, rtol=1e-12)  # the mean over all 12, not the 7 new
    assert last.fit.b == pytest.approx(resumed.fit.b, rel=1e-10)


def test_a_followed_resume_counts_its_restored_realizations_once_and_as_restored(registry, tmp_path):
    """The TUI follows a resume through its progress.jsonl: the restored realizations are the
    first snapshot's (never counted down from 1 as if computed now, which made the rate negative)."""
    from frictionlab.runs.progresslog import Follower, ProgressLog
    from frictionlab.runs.runner import run_to_folder

    scene, stopped = twelve_stopped_after_five(registry, tmp_path)
    resumed, _ = run_to_folder(scene, tmp_path, RunOptions(workers=1, resume=True), listeners=[ProgressLog(tmp_path)])
    posted = []
    Follower(tmp_path, scene, [LiveListener(posted.append, interval=0.0)]).poll()
    assert [s.restored for s in posted] == [stopped.done] * len(posted)
    assert [s.done for s in posted] == [stopped.done, *range(stopped.done + 1, 13), 12]  # the last: the run's end
    np.testing.assert_allclose(posted[0].xi, stopped.xi, rtol=1e-12)
    np.testing.assert_allclose(posted[-1].xi, resumed.xi, rtol=1e-12)  # each realization once
    assert posted[-1].finished


@pytest.mark.parametrize("unit, start, stop", [("f", 1e-4, 1e-2), ("pressure", 1e-7, 1e-5)])
def test_live_f_of_loads_given_as_f_or_a_pressure_is_the_run_s(registry, unit, start, stop):
    """The snapshot's f is formed from the solver's forces, not from the numbers the preset gives."""
    loading = {"unit": unit, "start": start, "stop": stop, "spacing": "log"}
    scene = build_scene(merge(TINY, {"realizations": 3, "loading": loading}), registry=registry)
    posted = []
    outcome = engine_run(scene, RunOptions(workers=1), listeners=[LiveListener(posted.append, interval=3600.0)])
    np.testing.assert_allclose(posted[-1].f, outcome.f, rtol=1e-12)
    if unit == "f":
        np.testing.assert_allclose(outcome.f, np.geomspace(start, stop, scene.loads.size), rtol=1e-12)


def test_once_every_realization_is_done_the_elapsed_time_and_the_rate_stop(registry):
    """While a finished run writes its results (seconds on a loaded machine), the progress line's
    elapsed time went on and its rate fell (50 in 0.3 s read "9.8/s, elapsed 5.1 s") under a final
    line of "in 0.3 s": the line stops with the last realization, and says what the run does."""
    from types import SimpleNamespace

    from frictionlab.plugin.hookspecs import hookimpl
    from frictionlab.plugin.listeners import progress_text

    scene = build_scene(merge(TINY, {"realizations": 4}), registry=registry)
    now = [100.0]
    posted = []
    live = LiveListener(posted.append, interval=0.0, clock=lambda: now[0])
    live.run_started(run=SimpleNamespace(scene=scene, resumed=0, total=4, restored=[]))
    results = []

    class Keep:
        @hookimpl
        def realization_done(self, result):
            results.append(result)

    engine_run(scene, RunOptions(workers=1), listeners=[Keep()])
    for done, result in enumerate(results, start=1):
        now[0] += 0.25
        live.realization_done(result=result, done=done, total=4)
    now[0] += 0.3  # the last chunk stored, the pool ended
    live.tick()
    live.run_finished()  # the engine's end, the elapsed time of summary.json and of the final line
    now[0] += 5.0  # the results written, the process ending
    live.tick()
    writing, finished, after = posted[-3], posted[-2], posted[-1]
    assert writing.elapsed == pytest.approx(1.0) and finished.elapsed == pytest.approx(1.3)
    assert after.elapsed == pytest.approx(1.3)
    assert writing.solving == "writing the results" and finished.solving == ""
    line = progress_text(writing.done, writing.total, writing.failed, writing.elapsed)
    assert "4.0/s" in line and "elapsed 1.0 s" in line


def test_the_time_left_waits_for_a_rate_of_a_few_realizations():
    """One of 4000 after 0.8 s (the pool's start in it) said 52 minutes left; two computed
    after a resume of 3097 said 33 minutes: no estimate until ESTIMATE_AFTER are computed here."""
    from frictionlab.plugin.listeners import ESTIMATE_AFTER, progress_text

    assert progress_text(1, 4000, 0, 0.8).endswith("left ?")
    assert progress_text(3099, 20000, 0, 0.24, restored=3097).endswith("left ?")
    done = ESTIMATE_AFTER
    line = progress_text(done, 4000, 0, 1.0)  # a rate of ESTIMATE_AFTER per second
    assert line.endswith(f"left {(4000 - done) // ESTIMATE_AFTER // 60}:{(4000 - done) // ESTIMATE_AFTER % 60:02d}"), line
    assert progress_text(2, 2, 0, 0.5).endswith("left 0.0 s")  # all done: nothing is left


@pytest.mark.parametrize("seconds, said", [(0.0, "0.0 s"), (0.004, "0.004 s"), (0.0123, "0.01 s"), (0.04, "0.04 s"),
                                           (0.1, "0.1 s"), (12.34, "12.3 s"), (245.0, "4:05"), (3723.0, "1:02:03")])
def test_a_duration_is_said_with_a_digit_that_is_not_zero_unless_it_is_none(seconds, said):
    """Found by a newcomer: 'completed: 8/8 realizations in 0.0 s' of a run that took 0.04 s."""
    from frictionlab.plugin.listeners import format_duration

    assert format_duration(seconds) == said
