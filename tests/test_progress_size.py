"""A run's progress.jsonl is sized to what a follower needs: counts, outcomes and the mean
curve, never each realization's curve (about 10 KB a realization at 400 load steps, before)."""

import json

import numpy as np

from frictionlab.compute.engine import RunInfo
from frictionlab.compute.realization import RealizationResult
from frictionlab.plugin.hookspecs import hookimpl
from frictionlab.preset import build_scene
from frictionlab.runs.detached import _last_count
from frictionlab.runs.progresslog import PROGRESS_FILE, Follower, ProgressLog

from .conftest import SMALL_PRESET, merge

STEPS = 400


class Clock:
    def __init__(self):
        self.now = 1.0e9

    def __call__(self) -> float:
        return self.now


class Heard:
    def __init__(self):
        self.results, self.failed, self.times = [], [], []
        self.clock = None

    @hookimpl
    def realization_done(self, result, done, total):
        self.results.append((result, done))
        self.times.append(self.clock())

    @hookimpl
    def realization_failed(self, result, done, total):
        self.failed.append((result, done))


def result(index: int, rng) -> RealizationResult:
    if index % 97 == 5:
        return RealizationResult(index=index, seconds=0.1, error=f"no contact in realization {index}")
    return RealizationResult(index=index, seconds=0.1 + index * 1e-7, xi=rng.random(STEPS),
                             contact_count=rng.integers(0, 9000, STEPS) * 1.0, points=100_000,
                             force_unit=2.0, slope_rms_line=0.5)  # fmt: skip


def log_run(folder, total: int, seconds_each: float):
    """Play a run of ``total`` realizations to a ProgressLog, ``seconds_each`` apart; its results."""
    scene = build_scene(merge(SMALL_PRESET, {"realizations": total, "loading": {"steps": STEPS}}))
    clock, rng, results = Clock(), np.random.default_rng(1), []
    log = ProgressLog(folder, clock=clock)
    log.run_started(RunInfo(scene=scene, total=total, workers=4))
    for done in range(1, total + 1):
        clock.now += seconds_each
        results.append(result(done - 1, rng))
        (log.realization_done if results[-1].ok else log.realization_failed)(results[-1], done, total)
        if done == 1:  # the first is told at once: a follower's plot appears
            assert len((folder / PROGRESS_FILE).read_bytes().splitlines()) == 2  # started, then it
    log.close()
    return scene, results


def test_a_long_run_writes_tens_of_bytes_a_realization_and_its_follower_hears_each(tmp_path):
    total = 20_000
    scene, results = log_run(tmp_path, total, seconds_each=0.05)  # 1000 s of 400 load steps
    size = (tmp_path / PROGRESS_FILE).stat().st_size
    assert size / total < 250  # 193 now; 10566 before (211 MB for these 20000): each realization its curves
    heard = Heard()
    follower = Follower(tmp_path, scene, [heard])
    heard.clock = follower.now
    while follower.poll():
        pass
    assert np.all(np.diff(heard.times) > 0)  # each told at its share of its line's time: a rate as the run's
    assert [done for _, done in sorted(heard.results + heard.failed, key=lambda item: item[1])] == list(range(1, total + 1))
    assert [r.index for r, _ in heard.failed] == [r.index for r in results if not r.ok]
    assert heard.failed[0][0].error == "no contact in realization 5"
    ok = [r for r in results if r.ok]
    np.testing.assert_allclose(sum(r.xi for r, _ in heard.results) / len(ok), np.mean([r.xi for r in ok], axis=0), rtol=1e-9)
    np.testing.assert_allclose(sum(r.contact_count for r, _ in heard.results), sum(r.contact_count for r in ok), rtol=1e-9)
    assert _last_count(tmp_path) == total


def test_a_slow_run_writes_each_realization_as_it_finishes(tmp_path):
    scene, _ = log_run(tmp_path, 6, seconds_each=30.0)
    heard = Heard()
    follower = Follower(tmp_path, scene, [heard])
    heard.clock = follower.now
    follower.poll()
    assert [done for _, done in heard.results] == [1, 2, 3, 4, 5] and [done for _, done in heard.failed] == [6]
    assert len((tmp_path / PROGRESS_FILE).read_bytes().splitlines()) == 1 + 6  # started, then each at once


def test_a_run_of_days_writes_its_realizations_at_least_every_minute(tmp_path):
    scene, _ = log_run(tmp_path, 3000, seconds_each=20.0)  # 60000 s: 1% of it would be 10 minutes
    times = [json.loads(line)["time"] for line in (tmp_path / PROGRESS_FILE).read_bytes().splitlines()[1:]]
    assert max(np.diff(times)) <= 60.0 + 20.0  # a minute, and the realization that found it due
