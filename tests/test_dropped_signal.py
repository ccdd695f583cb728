"""A Ctrl-C or SIGTERM whose exception Python drops (it landed in a finalizer: "Exception
ignored in ...") still ends a command of several runs: its next run does not start."""

from __future__ import annotations

import signal
import sys

import pytest

from frictionlab.compute import engine
from frictionlab.compute.signals import RaiseOnSignals, Terminated, interrupted_exit_code
from frictionlab.errors import ExitCode
from frictionlab.options import RunOptions
from frictionlab.plugin.hookspecs import hookimpl


class _SignalInFinalizer:
    def __init__(self, signum: int):
        self.signum = signum

    def __del__(self):
        signal.raise_signal(self.signum)  # its handler raises here, where Python drops the exception


def _drop_a_signal(signum: int, monkeypatch) -> list:
    dropped = []
    monkeypatch.setattr(sys, "unraisablehook", lambda unraisable: dropped.append(unraisable.exc_type))
    _SignalInFinalizer(signum)  # collected at once: its __del__ runs, the signal's exception is dropped
    return dropped


@pytest.mark.parametrize("signum, raised, code", [
    (signal.SIGINT, KeyboardInterrupt, ExitCode.INTERRUPTED),
    (signal.SIGTERM, Terminated, ExitCode.TERMINATED),
])  # fmt: skip
def test_a_run_does_not_start_in_a_command_whose_signal_was_dropped(make_scene, monkeypatch, signum, raised, code):
    scene = make_scene({"realizations": 2})
    heard = []

    class Listener:
        @hookimpl
        def run_started(self):
            heard.append("started")

    with RaiseOnSignals():
        dropped = _drop_a_signal(signum, monkeypatch)
        assert dropped and issubclass(dropped[0], raised), "the signal's exception was not dropped as expected"
        with pytest.raises(raised):
            engine.run(scene, RunOptions(workers=1), listeners=[Listener()])
        assert interrupted_exit_code() == code
    assert heard == [], "a run started after the command was interrupted"


def test_outside_a_command_every_run_asked_for_runs(make_scene, monkeypatch):
    """A notebook's Ctrl-C once ends its run; the next run it asks for runs."""
    scene = make_scene({"realizations": 2})
    previous = signal.signal(signal.SIGINT, lambda signum, frame: None)  # a notebook's kernel keeps its own
    try:
        _drop_a_signal(signal.SIGINT, monkeypatch)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert engine.run(scene, RunOptions(workers=1)).status == "completed"


def test_the_command_ends_with_its_handlers_given_back():
    before = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    with RaiseOnSignals():
        assert signal.getsignal(signal.SIGINT) is not before[signal.SIGINT]
    assert {signum: signal.getsignal(signum) for signum in before} == before
