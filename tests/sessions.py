"""A terminal's session that goes away: what the tests of detached runs and sweeps share."""

import os
import signal
import subprocess
import sys
import textwrap
import time


def wait_for(condition, timeout=120.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.05)
    raise AssertionError("timed out")


def start_then_hang_up(data: dict, out, resolve: bool, plot: bool = True) -> int:
    """Start ``data`` detached into ``out`` (``resolve``: through ``build_scene(...).resolved()``,
    as ``run --detach`` does for one ensemble; else as is, as for a sweep) from a process that
    leads a session of its own, as a shell in a terminal does; then the terminal goes: its whole
    session hears the hangup, then SIGKILL. Returns the pid of the detached process."""
    preset = f"build_scene({data!r}).resolved()" if resolve else repr(data)
    starter = textwrap.dedent(f"""
        import time
        from frictionlab.runs.detached import start_detached, wait_started
        from frictionlab.options import RunOptions
        from frictionlab.preset import build_scene
        process = start_detached({preset}, {str(out)!r}, RunOptions(workers=1), plot={plot!r})
        wait_started(process, {str(out)!r})
        print(process.pid, flush=True)
        time.sleep(600)  # the terminal's session, until it is killed
    """)
    parent = subprocess.Popen([sys.executable, "-c", starter], stdout=subprocess.PIPE, text=True, start_new_session=True)
    pid = int(parent.stdout.readline())
    os.killpg(parent.pid, signal.SIGHUP)
    os.killpg(parent.pid, signal.SIGKILL)
    parent.wait()
    return pid
