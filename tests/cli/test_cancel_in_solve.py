"""SIGTERM and Ctrl-C stop a run inside a long solve, not after it: real subprocesses,
real signals. The realization in progress is abandoned (neither kept nor failed), what
finished is kept, and ``frictionlab resume`` ends with the numbers of a run never stopped."""

import json
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from frictionlab.errors import ExitCode

from ..conftest import SMALL_PRESET, merge, run_cli
from .conftest import write_preset

# Each realization solves for a second or more at a tight tolerance; the run's first
# realization is solved alone, so a line about a later one means realization 0 is stored.
# Six of them: a log shows progress at most every 1.5 s, so some line is met mid-solve.
REALIZATIONS = 6
LONG_SOLVES = merge(SMALL_PRESET, {
    "realizations": REALIZATIONS,
    "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 512, "short_cutoff": 2.0}},
    "solver": {"name": "bem-halfspace", "params": {"tolerance": 1e-13, "stop": "tolerance"}},  # no early certified stop
    "loading": {"control": "force", "start": 1.0, "stop": 200.0, "steps": 8, "spacing": "log"},
    "fit": {"bootstrap": 50},
    "output": {"plot": False},
})  # fmt: skip
STOP_SECONDS = 1.0  # from the signal to the run's end, all its realizations' solves stopped


@pytest.fixture
def uninterrupted(built_once):
    """``LONG_SOLVES`` run uninterrupted, once a session: its preset, and the numbers it ends with."""

    def build(folder):
        folder.mkdir()
        done = run_cli("run", write_preset(folder, LONG_SOLVES), "--out", folder / "out", "--workers", "2")  # any worker count's numbers
        assert done.returncode == 0, done.stderr

    folder = built_once("long-solves-whole", build)
    return folder / "preset.yaml", folder / "out"


def _mid_solve(line: str) -> bool:
    """A progress line said while a solve goes on: an iteration, or a load before the last
    (in a log, iterations show at most every 1.5 s, and a fast solve may show none)."""
    match = re.search(r"load (\d+)/(\d+)", line)
    return "iteration" in line or (match is not None and int(match[1]) < int(match[2]))


def _wait_for_a_later_solve(proc) -> list[str]:
    """Read the progress until a realization after the first one is solving (after the
    first lines are shown, 2 s in)."""
    lines = []
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        line = proc.stderr.readline()
        if not line:
            break
        lines.append(line)
        if re.match(r"realization [1-9]\d*:", line) and _mid_solve(line):
            return lines
    proc.kill()
    pytest.fail("no progress within a later realization's solve:\n" + "".join(lines))


@pytest.mark.long
@pytest.mark.parametrize(
    ("workers", "signum", "code"),
    [(1, signal.SIGTERM, ExitCode.TERMINATED), (2, signal.SIGINT, ExitCode.INTERRUPTED)],
    ids=["serial-sigterm", "processes-sigint"],
)
def test_a_signal_stops_the_solve_within_a_second_and_resume_gives_the_same_numbers(
    uninterrupted, tmp_path, workers, signum, code
, cli):
    preset, whole = uninterrupted
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "frictionlab", "run", str(preset), "--out", str(out), "--workers", str(workers)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    _wait_for_a_later_solve(proc)
    sent = time.monotonic()
    proc.send_signal(signum)
    stopped = None
    rest = []
    for line in proc.stderr:  # "run interrupted: ..." is written as the run ends, before its files
        rest.append(line)
        if line.startswith("run interrupted") and stopped is None:
            stopped = time.monotonic() - sent
    proc.wait(timeout=60)
    stderr = "".join(rest)
    assert proc.returncode == code, stderr
    assert "Traceback" not in stderr
    assert stopped is not None and stopped < STOP_SECONDS, (stopped, stderr)

    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted"
    assert 1 <= summary["realizations"]["done"] < REALIZATIONS  # realization 0 kept, the one solving abandoned
    assert summary["realizations"]["failed"] == 0

    resumed = cli("resume", out)
    assert resumed.returncode == 0, resumed.stderr
    assert json.loads((out / "summary.json").read_text())["status"] == "completed"
    expected, got = np.load(whole / "realizations.npz"), np.load(out / "realizations.npz")
    assert sorted(got.files) == sorted(expected.files)
    for name in expected.files:
        assert np.array_equal(got[name], expected[name]), name  # bitwise: the same numbers
    assert (out / "curve.csv").read_text() == (whole / "curve.csv").read_text()


# The CLI with every FFT pair of the exact solver preceded by a step of minutes: FFTs of a
# 2048^2 grid on two threads (scipy.fft's pool), as a one-realization run on both cores does.
ENDLESS_STEP = """
import sys
import threading
import numpy as np
import scipy.fft
from frictionlab_solvers import elastic

grid = np.random.default_rng(0).normal(size=(2048, 2048))
apply = elastic.FFTPair.apply

def endless(self, *args, **kwargs):
    if threading.current_thread().name == "frictionlab-solve":  # the run's solve, not the load of full contact before it
        for _ in range(1000):
            scipy.fft.rfftn(grid, workers=2)
    return apply(self, *args, **kwargs)

elastic.FFTPair.apply = endless
from frictionlab.cli.main import program
sys.argv = ["frictionlab", *sys.argv[1:]]
program()
"""
LEAVE_SECONDS = 5.0  # generous: the step left running lasts minutes


@pytest.mark.long
@pytest.mark.parametrize(("signum", "code"), [(signal.SIGTERM, ExitCode.TERMINATED), (signal.SIGINT, ExitCode.INTERRUPTED)])
def test_the_process_ends_without_waiting_for_the_step_in_progress(tmp_path, signum, code):
    """Once a signal cancels a run, the process ends at once even though its solve is inside
    a step that lasts minutes: before, the interpreter's exit waited for the FFT library's
    threads, and with FFTs on two threads it aborted ('terminate called ...', SIGABRT)."""
    preset = write_preset(tmp_path, merge(LONG_SOLVES, {
        "realizations": 1,
        "spectrum": {"params": {"points": 32}},
        "solver": {"params": {"fft_workers": 2}},
    }))  # fmt: skip
    proc = subprocess.Popen(
        [sys.executable, "-c", ENDLESS_STEP, "run", str(preset), "--out", str(tmp_path / "out"), "--workers", "1"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:  # a failed check leaves no process running its endless step
        assert "1 realization of" in proc.stderr.readline()  # the run's first line: its solve is starting
        time.sleep(1.0)  # inside the first step
        assert proc.poll() is None
        sent = time.monotonic()
        proc.send_signal(signum)
        _, stderr = proc.communicate(timeout=60)
    finally:
        proc.kill()
    left = time.monotonic() - sent
    assert proc.returncode == code, stderr
    assert "terminate called" not in stderr and "Traceback" not in stderr, stderr
    assert "run interrupted: 0 of 1 realizations finished" in stderr
    assert left < LEAVE_SECONDS, (left, stderr)
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "interrupted"
