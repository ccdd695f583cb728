"""An environment variable set to what its reader does not take is said, naming it, before
any work: never an internal error once the work is done."""

import os
import subprocess
import sys

import pytest

from frictionlab.errors import ExitCode

DRAWING_COMMANDS = [  # each draws figures that are its output; matplotlib's import reads MPLBACKEND
    ["study", "quickstart", "--axes", "grid", "--grid-factors", "0.5,1", "--quiet", "--out", "out"],
    ["report", "--quiet", "--out", "out"],
    ["exact3d", "--quick", "--quiet", "--runs", "out"],
    ["plot", "out"],  # said before the folder is looked for
    ["run", "quickstart", "--quiet", "--out", "out"],  # it computed every point of a sweep, then failed each plot.png
    ["run", "quickstart", "--quiet", "--out", "out", "--set", "sweep.parameters.seed.values=[1,2]"],
]


@pytest.mark.parametrize("argv", DRAWING_COMMANDS, ids=lambda argv: " ".join(argv[:1] + argv[5:]))
def test_a_bad_mplbackend_is_refused_before_a_drawing_command_runs(tmp_path, argv):
    env = {**os.environ, "MPLBACKEND": "no-such-backend"}
    done = subprocess.run([sys.executable, "-m", "frictionlab", *argv], capture_output=True, text=True, cwd=tmp_path,
                          env=env, timeout=120)  # fmt: skip
    assert done.returncode == ExitCode.USAGE, done.stderr
    assert "internal error" not in done.stderr and "Traceback" not in done.stderr
    assert "MPLBACKEND='no-such-backend'" in done.stderr and "agg" in done.stderr  # the value and what is allowed
    assert not (tmp_path / "out").exists()  # refused before anything ran
