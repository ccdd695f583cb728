"""Helpers of the CLI's tests: presets written to files, the CLI in a terminal (the CLI in
this process: ``cli`` in tests/conftest.py)."""

import os
import subprocess
import sys

import pytest
import yaml


def write_preset(tmp_path, data, name="preset.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.fixture
def figure_stubbed(monkeypatch):
    """A study's study.png written as a few bytes, not drawn (a second each): for the tests of
    where a study writes and what it says. The figure itself: test_study.py's
    test_cli_runs_a_study_and_prints_the_recommendation and tests/tradeoff/test_outputs.py."""
    from frictionlab.tradeoff import outputs

    monkeypatch.setattr(outputs, "plot", lambda study, fh: fh.write(b"not drawn"))


RUN_DIRECTORY = {"run.json", "chunks"}  # the run directory's own files (frictionlab.runs.rundir; run.lock is gone once it ends)


class InTerminal:
    """The CLI in a subprocess whose stdout and stderr are a terminal (a pty), as a user
    sees it: ``screen()`` replays what it wrote (text, carriage returns, cursor up, erased
    lines: what a rich bar draws with) into the lines left on the screen."""

    def __init__(self, *args):
        import pty
        import threading

        self.master, slave = pty.openpty()
        env = {**os.environ, "TERM": "xterm", "COLUMNS": "100", "LINES": "40"}
        env.pop("NO_COLOR", None)
        self.process = subprocess.Popen([sys.executable, "-m", "frictionlab", *map(str, args)], stdin=subprocess.DEVNULL,
                                        stdout=slave, stderr=slave, env=env, close_fds=True)  # fmt: skip
        os.close(slave)
        self.raw = bytearray()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        while True:
            try:
                chunk = os.read(self.master, 4096)
            except OSError:  # EIO: the process and its terminal are gone
                return
            if not chunk:
                return
            self.raw += chunk

    def wait(self, timeout=120) -> int:
        code = self.process.wait(timeout=timeout)
        self.reader.join(timeout=10)
        os.close(self.master)
        return code

    def screen(self) -> tuple[list[str], int]:
        """The lines on the screen, and the column the cursor is left at."""
        import re

        lines, row, col = [""], 0, 0
        text = self.raw.decode(errors="replace")
        for token in re.findall(r"\x1b\[[?\d;]*[A-Za-z]|\x1b[()][A-Z0-9]|\r|\n|[^\x1b\r\n]+|\x1b", text):
            if token == "\r":
                col = 0
            elif token == "\n":
                row, col = row + 1, 0
                lines += [""] * (row + 1 - len(lines))
            elif token.startswith("\x1b["):
                code, arg = token[-1], token[2:-1]
                if code == "A":
                    row = max(0, row - int(arg or 1))
                elif code == "K":
                    lines[row] = lines[row][:col] if arg in ("", "0") else ""
            elif not token.startswith("\x1b"):
                line = lines[row].ljust(col)
                lines[row] = line[:col] + token + line[col + len(token):]
                col += len(token)
        return [line.rstrip() for line in lines], col
