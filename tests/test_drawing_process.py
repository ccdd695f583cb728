"""plot.png drawn by a process forked as ``frictionlab run`` starts: the same file as drawn
here, its failures said as here, and the figure never lost when it dies. Each case runs in
a fresh process: a fork is refused where a thread already runs (a test worker's may)."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest

from .conftest import PRESETS

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the drawing process is forked on Linux only")

SMALL_RUN = f"""
import os, signal, sys, threading
from pathlib import Path
from frictionlab.runs.figures import CurveFigure, DrawingProcess
from frictionlab.runs.results import write_curve_figure
from frictionlab.compute import engine
from frictionlab.errors import RunError
from frictionlab.options import RunOptions
from frictionlab.preset import load_scene
scene = load_scene({str(PRESETS / "benad2012-fig2.yaml")!r}, ["realizations=3", "spectrum.params.points=1024",
                   "spectrum.params.length=1024", "loading.steps=8", "fit.bootstrap=10"])
outcome = engine.run(scene, RunOptions(workers=1))

def reaped(pid):
    try:
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return True
    return False
"""


def _run(code: str, tmp_path) -> list[str]:
    done = subprocess.run(
        [sys.executable, "-c", SMALL_RUN + textwrap.dedent(code)], capture_output=True, text=True, cwd=tmp_path
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.split()


def test_the_drawing_process_writes_the_same_plot_png_as_this_process(tmp_path):
    out = _run(
        """
        drawer = DrawingProcess.start()
        pid = drawer.pid
        print(drawer.send(Path("there.png"), scene, outcome), drawer.wait(), reaped(pid), drawer.pid)
        write_curve_figure(Path("here.png"), CurveFigure.of(scene, outcome))
        """,
        tmp_path,
    )
    assert out == ["True", "True", "True", "None"]  # drawn there, and the process collected
    assert (tmp_path / "there.png").read_bytes() == (tmp_path / "here.png").read_bytes()


def test_a_plot_that_cannot_be_written_is_refused_as_here(tmp_path):
    (tmp_path / "a-file").write_text("not a folder")
    out = _run(
        """
        messages = []
        drawer = DrawingProcess.start()
        drawer.send(Path("a-file/plot.png"), scene, outcome)
        for draw in (drawer.wait, lambda: write_curve_figure(Path("a-file/plot.png"), CurveFigure.of(scene, outcome))):
            try:
                draw()
            except RunError as exc:
                messages.append(str(exc))
        print(len(messages), messages[0] == messages[1], "a-file/plot.png" in messages[0])
        """,
        tmp_path,
    )
    assert out == ["2", "True", "True"]


def test_a_drawing_process_that_died_leaves_the_figure_to_the_run(tmp_path):
    """Killed before it drew: the run draws plot.png itself, and lists it in summary.json."""
    out = _run(
        """
        from frictionlab.runs.runner import run_to_folder
        drawer = DrawingProcess.start()
        os.kill(drawer.pid, signal.SIGKILL)
        outcome, files = run_to_folder(scene, "run", RunOptions(workers=1), drawer=drawer)
        print(drawer.pid, files["plot"])
        """,
        tmp_path,
    )
    assert out == ["None", "run/plot.png"]
    assert (tmp_path / "run" / "plot.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["files"]["plot"] == "plot.png"


def test_a_drawing_process_that_dies_while_drawing_leaves_the_figure_to_the_run(tmp_path):
    out = _run(
        """
        import time
        from frictionlab.runs import figures
        from frictionlab.runs.results import add_plot
        drawn_here = figures.write_figure
        figures.write_figure = lambda path, draw: time.sleep(60)  # the child's drawing never ends
        drawer = DrawingProcess.start()
        figures.write_figure = drawn_here
        print(drawer.send(Path("plot.png"), scene, outcome))
        os.kill(drawer.pid, signal.SIGKILL)
        files = add_plot(".", scene, outcome, {}, drawer)
        print(drawer.pid, files["plot"])
        """,
        tmp_path,
    )
    assert out == ["True", "None", "plot.png"]
    assert (tmp_path / "plot.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_closing_ends_the_process_at_once_and_twice_is_harmless(tmp_path):
    out = _run(
        """
        drawer = DrawingProcess.start()
        pid = drawer.pid
        drawer.close()  # while it imports matplotlib: killed, and collected
        drawer.close()
        print(reaped(pid), drawer.send(Path("plot.png"), scene, outcome), os.path.exists("plot.png"))
        """,
        tmp_path,
    )
    assert out == ["True", "False", "False"]


def test_a_process_forked_later_closes_its_copy_of_the_connection(tmp_path):
    """A pool's worker must not keep the drawing process waiting once the command has ended."""
    out = _run(
        """
        drawer = DrawingProcess.start()
        connection = drawer._connection
        child = os.fork()
        if child == 0:
            os._exit(0 if drawer.pid is None and connection.closed else 3)
        _, status = os.waitpid(child, 0)
        print(os.waitstatus_to_exitcode(status), drawer.pid is not None, connection.closed)
        drawer.close()
        """,
        tmp_path,
    )
    assert out == ["0", "True", "False"]


def test_no_drawing_process_where_a_thread_runs_or_the_fork_fails(tmp_path):
    out = _run(
        """
        waiting = threading.Event()
        thread = threading.Thread(target=waiting.wait)
        thread.start()
        with_thread = DrawingProcess.start()
        waiting.set()
        thread.join()
        def refused():
            raise BlockingIOError(11, "Resource temporarily unavailable")
        os.fork = refused
        print(with_thread, DrawingProcess.start())
        """,
        tmp_path,
    )
    assert out == ["None", "None"]


def test_frictionlab_run_draws_plot_png_in_its_drawing_process(tmp_path):
    """The command's own path, from its start to the figure listed in summary.json."""
    done = subprocess.run(
        [sys.executable, "-m", "frictionlab", "run", str(PRESETS / "benad2012-fig2.yaml"), "--quiet", "--out", "run",
         "--set", "realizations=3", "--set", "spectrum.params.points=1024", "--set", "spectrum.params.length=1024",
         "--set", "loading.steps=8", "--workers", "1"],
        capture_output=True, text=True, cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["files"]["plot"] == "plot.png"
    assert (tmp_path / "run" / "plot.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_drawing_process_killed_while_it_writes_leaves_no_temporary_file(tmp_path):
    """The run ended by an error (a disk full as its chunks merged) while plot.png was
    being written there: the process is killed, and its half-written file removed."""
    out = _run(
        """
        drawer = DrawingProcess.start()
        drawer.send(Path("plot.png"), scene, outcome)
        Path(".plot.png.k1ll3d_x.tmp").write_bytes(b"half a png")  # where the kill caught atomic_write
        Path(".other.png.k1ll3d_x.tmp").write_bytes(b"not the figure's")
        drawer.close()
        print(sorted(path.name for path in Path(".").glob("*.tmp")))
        """,
        tmp_path,
    )
    assert out == ["['.other.png.k1ll3d_x.tmp']"]
