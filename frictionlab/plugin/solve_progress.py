"""A solve's progress, told from inside a solver's loop: loads finished, iterations
done, the cancel that stops a long solve, and the failure a plugin explains itself."""

from __future__ import annotations

import threading
from collections.abc import Callable
from contextlib import contextmanager



_listening = threading.local()  # per thread: ``load`` and ``iteration``, the listeners of the solve it runs


def load_finished(done: int, total: int) -> None:
    """A solver whose loads take long calls this after each load of ``solve``: ``done``
    of its ``total`` loads are solved. The run forwards it to its listeners
    (``RunListener.load_done``); outside a run that listens it does nothing."""
    listener = getattr(_listening, "load", None)
    if listener is not None:
        listener(done, total)


class SolveCancelled(Exception):
    """Raised by ``iteration_done`` inside a solver's loop when the run it belongs to
    is cancelled (the TUI's cancel, Ctrl-C, SIGTERM). A solver lets it propagate: the
    realization is then neither stored nor counted as failed, and runs again on resume."""


class SolveFailed(ValueError):
    """Raised by a plugin for a failure it explains itself (a solver that did not converge,
    a profile it cannot press): the message says what happened and what to change. The
    realization fails with that message alone, told neither as a bug (no source line) nor
    as the plugin's fault. A ValueError, so code that catches a plugin's refusals catches it."""


def iteration_done(iteration: int, residual: float) -> None:
    """An iterative solver calls this once per iteration of its inner loop: ``iteration``
    steps of the current load are done and its relative residual is ``residual``. The run
    forwards it, coalesced, to its listeners as progress within a load, and raises
    ``SolveCancelled`` here once the run is cancelled, so a long solve stops within a
    fraction of a second. Outside a run that listens it does nothing (and costs a call)."""
    listener = getattr(_listening, "iteration", None)
    if listener is not None:
        listener(iteration, residual)


@contextmanager
def _listening_to(kind: str, listener):
    previous = getattr(_listening, kind, None)
    setattr(_listening, kind, listener)
    try:
        yield
    finally:
        setattr(_listening, kind, previous)


def listening_to_loads(listener: Callable[[int, int], None] | None):
    """Within the block, ``load_finished(done, total)`` calls ``listener`` (this thread only)."""
    return _listening_to("load", listener)


def listening_to_iterations(listener: Callable[[int, float], None] | None):
    """Within the block, ``iteration_done(iteration, residual)`` calls ``listener``, which
    may raise ``SolveCancelled`` (this thread only: a solve abandoned in another thread
    never hears the next run's listeners)."""
    return _listening_to("iteration", listener)
