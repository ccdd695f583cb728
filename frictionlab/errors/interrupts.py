"""A KeyboardInterrupt that a signal raised (Ctrl-C, SIGTERM, SIGHUP: the work must stop) told
apart from one that code raised itself (a plugin's ``raise KeyboardInterrupt``: its fault, told
by its name, while the run goes on). frictionlab's own handlers mark what they raise
(``signal_interrupt``); under a handler of someone else's (Python's own, a notebook's) the two
cannot be told apart, and an interrupt is taken as the signal's: stopping is the safe side."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

SIGNAL_ATTRIBUTE = "frictionlab_signal"  # the number of the signal that raised it


def signal_interrupt(signum: int, cls: type[KeyboardInterrupt] = KeyboardInterrupt) -> KeyboardInterrupt:
    """A ``cls`` for signal ``signum``, marked as a signal's (``raised_by_signal``)."""
    exc = cls()
    setattr(exc, SIGNAL_ATTRIBUTE, signum)
    return exc


def raised_by_signal(exc: BaseException) -> bool:
    """Whether ``exc``, a KeyboardInterrupt, is a signal's rather than code's own ``raise``."""
    if not isinstance(exc, KeyboardInterrupt):
        return False
    if getattr(exc, SIGNAL_ATTRIBUTE, None) is not None:
        return True
    if threading.current_thread() is not threading.main_thread():  # signals raise in the main thread only
        return False
    handler = signal.getsignal(signal.SIGINT)
    if handler is signal.SIG_IGN:  # a pool's worker: its parent stops it, no signal raises in it
        return False
    return not str(getattr(handler, "__module__", "")).startswith("frictionlab.")  # ours mark what they raise


@contextlib.contextmanager
def interrupts_marked() -> Iterator[None]:
    """Within (in the main thread): Ctrl-C raises a marked KeyboardInterrupt, so that one raised by
    the code called here is told from it; the previous handler comes back after."""
    if threading.current_thread() is not threading.main_thread() or signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        yield
        return
    previous = signal.signal(signal.SIGINT, _raise_marked)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler if previous is None else previous)


def _raise_marked(signum, frame):
    raise signal_interrupt(signum)
