"""Ctrl-C (a notebook's interrupt) during ``frictionlab.run``: what finished is written, and
the call raises ``RunInterrupted`` (a KeyboardInterrupt) so that a cell or a loop stops too."""

from __future__ import annotations

import functools
import os
import signal

import pytest

import frictionlab
from frictionlab.progress import ProgressReporter

from .conftest import SMALL_PRESET, merge


@pytest.fixture
def pressed_after_two(monkeypatch):
    """The user presses Ctrl-C once two realizations have finished."""
    seen = ProgressReporter.realization_done

    @functools.wraps(seen)  # keeps its hook marker
    def done(self, done, total):
        seen(self, done, total)
        if done == 2:
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(ProgressReporter, "realization_done", done)


def test_an_interrupted_run_raises_with_what_finished_kept(tmp_path, pressed_after_two):
    preset = merge(SMALL_PRESET, {"realizations": 40})
    started = []
    with pytest.raises(frictionlab.RunInterrupted) as caught:
        for seed in (1, 2):  # a loop of runs stops at the first one interrupted
            started.append(seed)
            frictionlab.run(preset, seed=seed, workers=1, out=tmp_path / f"s{seed}")
    assert started == [1] and isinstance(caught.value, KeyboardInterrupt)
    result = caught.value.result
    assert result.status == "interrupted" and 2 <= result.realizations[0] < 40
    assert str(caught.value).startswith(f"run interrupted: {result.realizations[0]} of 40 realizations finished, kept in")
    assert "resume=True continues it" in str(caught.value)
    kept = frictionlab.load(tmp_path / "s1")
    assert kept.status == "interrupted" and kept.fit == result.fit
    resumed = frictionlab.run(preset, seed=1, workers=1, progress=False, out=tmp_path / "s1", resume=True)
    assert resumed.status == "completed" and resumed.realizations == (40, 40)


def test_an_interrupted_run_in_memory_keeps_its_result_on_the_exception(pressed_after_two):
    with pytest.raises(frictionlab.RunInterrupted, match="kept in memory only") as caught:
        frictionlab.run(merge(SMALL_PRESET, {"realizations": 40}), workers=1)
    assert caught.value.result.folder is None and caught.value.result.realizations[0] >= 2


def test_a_run_pressed_during_its_fit_is_complete_and_still_stops_the_caller(tmp_path, monkeypatch):
    import frictionlab.compute.ensemble as ensemble

    fit = ensemble.fit_log_law

    def fit_while_pressed(*args, **kwargs):  # every realization done; Ctrl-C as the fit starts
        os.kill(os.getpid(), signal.SIGINT)
        return fit(*args, **kwargs)

    monkeypatch.setattr(ensemble, "fit_log_law", fit_while_pressed)
    with pytest.raises(frictionlab.RunInterrupted) as caught:
        frictionlab.run(SMALL_PRESET, workers=1, progress=False, out=tmp_path / "run")
    assert caught.value.result.status == "completed" and caught.value.result.fit is not None
    assert str(caught.value) == (f"run completed: 8 of 8 realizations finished, kept in {tmp_path / 'run'}; "
                                 "the exception's .result holds it")  # fmt: skip
