"""``frictionlab --help`` lists every exit code, so that a script on a remote server can
tell the endings apart without the documentation at hand."""

from __future__ import annotations

import re

from frictionlab.cli.main import main
from frictionlab.errors import ExitCode


def test_the_help_lists_every_exit_code_once(capsys):
    try:
        code = main(["--help"])
    except SystemExit as ended:
        code = ended.code
    assert code in (0, None)
    text = capsys.readouterr().out
    listed = re.findall(r"^  (\d+) +\S", text.split("exit codes:\n", 1)[-1], re.MULTILINE)
    assert "exit codes:" in text and sorted(map(int, listed)) == sorted(map(int, ExitCode))
