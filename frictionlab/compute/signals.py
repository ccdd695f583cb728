"""Ctrl-C (SIGINT), SIGTERM and SIGHUP (the terminal closed: an SSH session that
dropped) end a run the same way: the first one sets the run's
cancel, which the solves running see at their next iteration (they are abandoned,
what finished is kept), the run ends "interrupted" and its folder can be resumed;
a second one interrupts at once. The exit code says which
signal it was (130, 143 or 129). A SIGHUP ignored when the command started
(``nohup``, a detached run) stays ignored.

Signal handlers live in the main thread only; the TUI, which runs the engine
in a worker thread, cancels through its own event instead.
"""

from __future__ import annotations

import signal
import threading

from ..errors import ExitCode, shown
from ..errors.interrupts import signal_interrupt

HANDLED = (signal.SIGINT, signal.SIGTERM, *([signal.SIGHUP] if hasattr(signal, "SIGHUP") else []))  # no SIGHUP on Windows
ENDINGS = {signal.SIGINT: (ExitCode.INTERRUPTED, "interrupted"), signal.SIGTERM: (ExitCode.TERMINATED, "terminated")}
if hasattr(signal, "SIGHUP"):
    ENDINGS[signal.SIGHUP] = (ExitCode.HUNG_UP, "hung up (the terminal closed)")
received: list[int] = []  # the signals that ended work in this process, in order


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised where Ctrl-C raises KeyboardInterrupt (so every path that
    keeps finished work on Ctrl-C keeps it on SIGTERM too)."""


def _raise_for(signum: int):
    received.append(signum)
    raise _interrupt(signum)


def _interrupt(signum: int) -> KeyboardInterrupt:
    """What signal ``signum`` raises, marked as a signal's (a plugin's own raise is its fault)."""
    return signal_interrupt(signum, KeyboardInterrupt if signum == signal.SIGINT else Terminated)


def _ending() -> tuple[ExitCode, str]:
    """The exit code and word of the signal that ended the work: the first other than
    Ctrl-C (a SIGTERM or hangup after a Ctrl-C is what ended it), else Ctrl-C's."""
    others = [signum for signum in received if signum != signal.SIGINT]
    return ENDINGS[others[0]] if others else ENDINGS[signal.SIGINT]


def interrupted_exit_code() -> ExitCode:
    """TERMINATED if a SIGTERM ended the work, HUNG_UP for a SIGHUP, else INTERRUPTED."""
    return _ending()[0]


def interrupted_word() -> str:
    """What ended the work, as the command's last line says it: "interrupted", "terminated"..."""
    return _ending()[1]


def install(handler) -> dict:
    """``handler`` for each signal of HANDLED but one ignored (``nohup``'s SIGHUP); the previous handlers."""
    return {signum: signal.signal(signum, handler) for signum in HANDLED
            if not (signum != signal.SIGINT and signal.getsignal(signum) == signal.SIG_IGN)}  # fmt: skip


def mark() -> int:
    """A mark for ``interrupted_since``: the signals received so far."""
    return len(received)


def interrupted_since(seen: int) -> bool:
    """Whether SIGINT or SIGTERM came since ``mark()`` gave ``seen``: a run whose last chunk
    was running when it came ends completed, yet the command of several runs must stop."""
    return len(received) > seen


class WorkInterrupted(KeyboardInterrupt):
    """A command of several runs (report, exact3d) stops after a run that ended
    interrupted: the finished runs are kept; ``str()`` says where, and how to go on."""


class RunInterrupted(KeyboardInterrupt):
    """``frictionlab.run`` stopped by Ctrl-C, a notebook's interrupt or SIGTERM: raised once
    what finished is written, so that a cell or a loop of runs stops there too. ``result``
    holds the ``Result`` (or ``SweepResult``) as it ended (in a notebook, after the cell:
    ``sys.last_value.result``); ``resume=True`` into its folder continues it."""

    def __init__(self, result):
        super().__init__(result)
        self.result = result

    def __str__(self) -> str:
        r = self.result
        if hasattr(r, "rows"):  # a sweep's
            done = f"{sum(row.get('status') == 'completed' for row in r.rows)} of {len(r.rows)} points"
        else:
            done = f"{r.realizations[0]} of {r.realizations[1]} realizations"
        kept = f"kept in {shown(r.folder)}" if r.folder else "kept in memory only"
        kept += " (resume=True continues it)" if r.folder and r.status != "completed" else ""
        return f"run {r.status}: {done} finished, {kept}; the exception's .result holds it"


_in_command = False  # within RaiseOnSignals: a signal received ends the command, not only its run


class SignalsNoted:
    """Within the block, Ctrl-C, SIGTERM and SIGHUP are noted (``signal``, the last one; each
    in ``received``) instead of raised: the caller acts on them where it chooses (between two
    polls, once a set of files is all written). Outside the main thread it notes nothing."""

    def __init__(self):
        self.signal: int | None = None
        self._noted = threading.Event()
        self._previous: dict[int, object] = {}

    def _note(self, signum, frame) -> None:
        received.append(signum)
        self.signal = signum
        self._noted.set()

    def wait(self, seconds: float) -> None:
        """Sleep ``seconds``, or less if a signal comes."""
        self._noted.wait(seconds)

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self._previous = install(self._note)
        return self

    def __exit__(self, *exc) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, signal.SIG_DFL if handler is None else handler)


class RaiseOnSignals:
    """While a command runs: SIGTERM raises Terminated and Ctrl-C KeyboardInterrupt (as
    Python's own handler does), each recorded in ``received``; earlier signals are
    forgotten, and the previous handlers come back at the end. Recorded, because Python
    drops an exception raised in a finalizer ("Exception ignored in ..."): a signal that
    lands there is lost, and a command of several runs would go on to its next
    (``stop_if_interrupted``)."""

    def __enter__(self):
        global _in_command
        received.clear()
        self.previous = {}
        if threading.current_thread() is threading.main_thread():
            self.previous = install(lambda signum, frame: _raise_for(signum))
            _in_command = True
        return self

    def __exit__(self, *exc):
        global _in_command
        if self.previous:  # entered in the main thread
            _in_command = False
        for signum, handler in self.previous.items():
            signal.signal(signum, signal.SIG_DFL if handler is None else handler)
        return False


def stop_if_interrupted() -> None:
    """Before a run starts: within a command that was interrupted already (its exception
    dropped, say), raise again instead of starting it. A notebook's own process, outside
    any command, starts every run it asks for."""
    if _in_command and received:
        raise _interrupt(received[-1])


class CancelOnSignals:
    """While a run goes on: the first SIGINT, SIGTERM or SIGHUP sets ``cancel`` (running
    solves stop at their next iteration; what finished is kept); a second one raises KeyboardInterrupt or
    Terminated. Only in the main thread, where signals land."""

    def __init__(self, cancel):
        self.cancel = cancel
        self.signal: int | None = None  # the first one received
        self.previous: dict[int, object] = {}

    @property
    def pressed(self) -> bool:
        return self.signal is not None

    def _handle(self, signum, frame):
        if self.signal is not None:
            _raise_for(signum)
        received.append(signum)
        self.signal = signum
        self.cancel.set()

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self.previous = install(self._handle)
        return self

    def __exit__(self, *exc):
        for signum, handler in self.previous.items():
            signal.signal(signum, signal.SIG_DFL if handler is None else handler)
        return False
