"""The command ends without the interpreter's teardown of every module it imported
(os._exit once its work is done), and loses nothing by it: the atexit functions run, the
output reaches its reader whole, and a thread that is no daemon is waited for."""

from __future__ import annotations

import subprocess
import sys

ENDING = """
import atexit, sys, threading, time
from pathlib import Path
marks = Path(sys.argv[1])

def at_exit():
    (marks / "atexit").write_text("ran")

atexit.register(at_exit)
if sys.argv[2] == "thread":
    def late():
        time.sleep(2.0)  # still running when the command ends
        (marks / "thread").write_text("done")
    threading.Thread(target=late, daemon=False).start()
import frictionlab.cli.main as _  # noqa: F401
main_module = sys.modules["frictionlab.cli.main"]
ended = []
real_exit = main_module.os._exit
main_module.os._exit = lambda code: (ended.append(code), (marks / "os_exit").write_text(str(code)), real_exit(code))
from frictionlab.__main__ import program
sys.argv = ["frictionlab", "presets"]
program()
"""


def ended(tmp_path, thread: str) -> tuple[subprocess.CompletedProcess, set[str]]:
    done = subprocess.run([sys.executable, "-c", ENDING, str(tmp_path), thread], capture_output=True, text=True, timeout=120)
    return done, {p.name for p in tmp_path.iterdir()}


def test_the_process_ends_at_once_with_its_atexit_functions_run_and_its_output_whole(tmp_path):
    done, marks = ended(tmp_path, "none")
    assert done.returncode == 0, done.stderr
    assert marks == {"atexit", "os_exit"}
    listed = subprocess.run([sys.executable, "-m", "frictionlab", "presets"], capture_output=True, text=True, timeout=120)
    assert done.stdout == listed.stdout and "benad2012-fig2" in done.stdout


def test_a_thread_that_is_no_daemon_is_waited_for(tmp_path):
    done, marks = ended(tmp_path, "thread")
    assert done.returncode == 0, done.stderr
    assert marks == {"atexit", "thread"}  # the interpreter's own exit, which waits for the thread
