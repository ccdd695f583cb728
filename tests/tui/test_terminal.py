"""The terminal around the app (``frictionlab.tui.terminal``), driven through a pseudo-terminal:
keys typed while ``frictionlab tui`` loads reach the app as typed, and those it never read are
dropped as it ends instead of reaching the shell."""

import contextlib
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


def test_a_sigterm_while_the_keys_are_held_ends_as_terminated_not_a_traceback(monkeypatch, capsys):
    """`timeout 5 frictionlab tui` runs it as a background job: taking the terminal stops it
    (SIGTTOU) until timeout's SIGTERM, which raised inside ``hold_keys``, outside the handling
    that says 'terminated': a traceback."""
    import signal
    import sys

    import frictionlab.__main__ as entry
    from frictionlab.tui import terminal

    def stopped_until_terminated():
        signal.getsignal(signal.SIGTERM)(signal.SIGTERM, None)

    monkeypatch.setattr(terminal, "hold_keys", stopped_until_terminated)
    monkeypatch.setattr(sys, "argv", ["frictionlab", "tui"])
    previous = signal.getsignal(signal.SIGTERM)
    try:
        with pytest.raises(SystemExit) as ended:
            entry.program()
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert ended.value.code == 143 and capsys.readouterr().err == "terminated\n"


def _spawned_tui(tmp_path, python_args=("-m", "frictionlab", "tui")):
    """``frictionlab tui`` (or Python with ``python_args``) in a pseudo-terminal in line mode with
    echo, as a login shell leaves it: (process, keyboard end, program end, the program end's
    attributes before it started)."""
    import subprocess
    import sys

    keyboard, program = pty.openpty()
    os.set_blocking(keyboard, False)
    before = termios.tcgetattr(program)
    env = {**os.environ, "TERM": "xterm-256color"}
    process = subprocess.Popen([sys.executable, *python_args], stdin=program, stdout=program,
                               stderr=program, cwd=tmp_path, env=env, start_new_session=True)  # fmt: skip
    return process, keyboard, program, before


def _ended(process, keyboard, program) -> None:
    """The spawned process ended (killed if it still runs) and its pseudo-terminal closed."""
    if process.poll() is None:
        process.kill()
    process.wait()
    os.close(keyboard)
    os.close(program)


def _wait_reading(process, keyboard, until, timeout=60.0) -> bytes:
    """What the program wrote until ``until(written)`` (its output is read as it comes: a full
    pseudo-terminal would block it)."""
    import time

    written = b""
    deadline = time.monotonic() + timeout
    while not until(written):
        assert time.monotonic() < deadline, "timed out"
        if select.select([keyboard], [], [], 0.001)[0]:
            with contextlib.suppress(OSError):
                written += os.read(keyboard, 65536)
    return written


# the drawn screen's case is long (a process that imports and draws the whole app: seconds)
@pytest.mark.parametrize("when, signum, code", [
    ("while it loads", "SIGTERM", 143),
    pytest.param("as its screen is drawn", "SIGTERM", 143, marks=pytest.mark.long),
    pytest.param("as its screen is drawn", "SIGHUP", 129, marks=pytest.mark.long),  # a hangup was raised mid-draw
])  # fmt: skip
def test_sigterm_to_frictionlab_tui_gives_the_terminal_back(tmp_path, when, signum, code):
    """A SIGTERM while it loads (after it took the terminal out of line mode, before its commands
    handle signals) killed it there, its terminal left without echo nor line mode; once the app
    draws, one raised in the app's mount ended it with a traceback. It ends with 143 and the
    terminal as it found it: line mode, echo, the main screen."""
    import signal

    process, keyboard, program, before = _spawned_tui(tmp_path)
    try:
        if when == "while it loads":  # as soon as the keys are held
            written = _wait_reading(process, keyboard, lambda _: not termios.tcgetattr(program)[3] & termios.ECHO)
        else:
            written = _wait_reading(process, keyboard, lambda written: b"\x1b[?1049h" in written)  # alternate screen
        process.send_signal(getattr(signal, signum))
        written += _wait_reading(process, keyboard, lambda _: process.poll() is not None)
        written += _wait_reading(process, keyboard, lambda _: not select.select([keyboard], [], [], 0.2)[0])
        after = termios.tcgetattr(program)
    finally:
        _ended(process, keyboard, program)
    assert process.returncode == code
    assert after == before
    assert b"Traceback" not in written and b"Error" not in written
    assert written.count(b"\x1b[?1049h") == written.count(b"\x1b[?1049l")  # back on the main screen


@pytest.mark.long
def test_a_hangup_ends_the_tui_even_when_its_exit_would_wait_for_ever(tmp_path):
    """Once seen after an SSH session closed: the app's exit waited on Textual's writer thread,
    whose writes to the closed terminal never ended, and the process stayed behind. The app's
    exit is made to hang here; the hangup ends the process all the same, with 129, within
    HANGUP_GRACE_SECONDS."""
    import signal
    import time

    from frictionlab.tui import HANGUP_GRACE_SECONDS

    script = (
        "import sys\n"
        "from frictionlab.tui.app import FrictionlabApp\n"
        "FrictionlabApp.terminate = lambda self, code=None: None  # an exit that never comes\n"
        "sys.argv = ['frictionlab', 'tui']\n"
        "from frictionlab.__main__ import program\n"
        "program()\n"
    )
    process, keyboard, program, _ = _spawned_tui(tmp_path, ("-c", script))
    try:
        _wait_reading(process, keyboard, lambda written: b"\x1b[?1049h" in written)  # the app has drawn
        sent = time.monotonic()
        process.send_signal(signal.SIGHUP)
        _wait_reading(process, keyboard, lambda _: process.poll() is not None, timeout=HANGUP_GRACE_SECONDS + 20)
        took = time.monotonic() - sent
    finally:
        _ended(process, keyboard, program)
    assert process.returncode == 129
    assert took >= HANGUP_GRACE_SECONDS * 0.9  # its own exit was given its time first
