"""The terminal around the app (``frictionlab.tui.terminal``), driven through a pseudo-terminal:
keys typed while ``frictionlab tui`` loads reach the app as typed, and those it never read are
dropped as it ends instead of reaching the shell."""

import os
import pty
import select
import termios

import pytest

from frictionlab.tui.terminal import hold_keys, release_keys


@pytest.fixture
def terminal():
    """(keyboard, program): what the user types into, and the program's end, in line mode."""
    keyboard, program = pty.openpty()
    attrs = termios.tcgetattr(program)
    attrs[3] |= termios.ICANON | termios.ECHO | termios.IEXTEN
    attrs[0] |= termios.ICRNL
    termios.tcsetattr(program, termios.TCSANOW, attrs)
    yield keyboard, program
    os.close(keyboard)
    os.close(program)


def readable(fd, timeout=0.5) -> bytes:
    got = b""
    while select.select([fd], [], [], timeout)[0]:
        got += os.read(fd, 1024)
        timeout = 0.05
    return got


def test_keys_typed_while_it_loads_reach_the_program_as_typed(terminal):
    keyboard, program = terminal
    before = termios.tcgetattr(program)
    held = hold_keys(program)
    assert held is not None
    os.write(keyboard, b"\x12\tab\r")  # Ctrl+R, Tab, a, b, Enter
    assert readable(program) == b"\x12\tab\r"  # line mode ate Ctrl+R (reprint) and made Enter a line feed
    assert readable(keyboard, timeout=0.1) == b""  # not echoed onto the screen the shell gets back
    release_keys(held)
    assert termios.tcgetattr(program) == before


def test_keys_the_program_never_read_do_not_reach_the_shell(terminal):
    keyboard, program = terminal
    held = hold_keys(program)
    os.write(keyboard, b"rm x")  # typed as it quits: never read
    select.select([program], [], [], 0.5)
    release_keys(held)
    os.write(keyboard, b"ls\n")
    assert readable(program) == b"ls\n"  # what the shell reads next: only what was typed after


def test_nothing_is_held_without_a_terminal(tmp_path):
    with open(tmp_path / "f", "w") as fh:
        assert hold_keys(fh.fileno()) is None
    release_keys(None)  # and nothing to give back


def test_frictionlab_tui_holds_the_keys_first_and_drops_the_unread_ones_as_it_ends(monkeypatch):
    """``frictionlab tui`` holds the keys before anything else loads, and releases them however
    it ends (here refused at once: TERM=dumb)."""
    import sys

    import frictionlab.__main__ as entry
    from frictionlab.tui import terminal

    calls = []
    monkeypatch.setattr(terminal, "hold_keys", lambda: calls.append("hold") or "held")
    monkeypatch.setattr(terminal, "release_keys", lambda held: calls.append(("release", held)))
    monkeypatch.setattr(sys, "argv", ["frictionlab", "tui"])
    monkeypatch.setenv("TERM", "dumb")
    with pytest.raises(SystemExit) as ended:
        entry.program()
    assert ended.value.code == 2
    assert calls == ["hold", ("release", "held")]
