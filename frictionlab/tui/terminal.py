"""The terminal around the app's run (no Textual here): keys typed while ``frictionlab tui``
starts are kept as typed, and those it never read are dropped as it ends.

Until Textual makes the terminal raw (a second or more after the command, on a loaded
machine), the terminal is in line mode: it echoes what is typed onto the screen the shell
gets back, answers some keys itself (Ctrl+R reprints the line, Ctrl+S stops the output,
Ctrl+U erases it) and turns Enter into a line feed. ``hold_keys`` takes it out of line mode
as soon as the command starts, without echo, so that each key waits unchanged for the app;
``release_keys`` drops what the app did not read (it would reach the shell) and gives the
terminal back as it was.
"""

from __future__ import annotations

import contextlib
import os
import sys

try:
    import termios
except ImportError:  # not a POSIX terminal: nothing to hold
    termios = None


def _stdin_tty() -> int | None:
    """The file descriptor of stdin when it is a terminal, else None."""
    try:
        fd = sys.stdin.fileno()
    except (AttributeError, ValueError, OSError):
        return None
    return fd if os.isatty(fd) else None


def hold_keys(fd: int | None = None):
    """Take the terminal (``fd``, else stdin's) out of line mode and echo (keys reach the app
    as typed: Ctrl+R, Enter, Tab); return what ``release_keys`` restores, or None when it is
    no terminal. Ctrl+C still interrupts a start that takes too long."""
    fd = _stdin_tty() if fd is None else fd
    if fd is None or termios is None or not os.isatty(fd):
        return None
    try:
        before = termios.tcgetattr(fd)
        held = termios.tcgetattr(fd)
        held[3] &= ~(termios.ICANON | termios.ECHO | termios.IEXTEN)  # lflag: no line editing, echo, ^R ^V
        held[0] &= ~(termios.IXON | termios.ICRNL | termios.INLCR | termios.IGNCR)  # iflag: ^S ^Q and Enter as typed
        held[6][termios.VMIN], held[6][termios.VTIME] = 1, 0
        termios.tcsetattr(fd, termios.TCSANOW, held)  # TCSANOW: what was typed before stays to be read
    except termios.error:
        return None
    return fd, before


def release_keys(held) -> None:
    """Drop the keys typed that the app never read, then restore the terminal ``hold_keys``
    found (nothing when it held none)."""
    if held is None:
        return
    fd, before = held
    with contextlib.suppress(termios.error, OSError):
        termios.tcflush(fd, termios.TCIFLUSH)
    with contextlib.suppress(termios.error, OSError):
        termios.tcsetattr(fd, termios.TCSANOW, before)
