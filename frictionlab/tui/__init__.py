"""The terminal UI (``frictionlab tui``): the only package that imports Textual.

Importing this package is cheap; Textual loads when the app is built.
"""

from __future__ import annotations

import gc
import os
import signal
import sys
import threading
from pathlib import Path

from ..errors import FrictionlabError

HANGUP_GRACE_SECONDS = 3.0  # after a hangup, the app's own exit has this long; then the process ends regardless


def run_app(
    preset: str | Path | None = None,
    *,
    presets_dir: str | Path | None = None,
    runs_dir: str | Path | None = None,
    options=None,
) -> int:
    """Run the app until it quits; ``options`` (``RunOptions``): how its runs are carried out."""
    from ..preset.builtin import user_presets_dir

    user_presets_dir()  # FRICTIONLAB_PRESETS_DIR=~nouser: said now, not as a traceback in the app
    if not (sys.stdin.isatty() and sys.stdout.isatty()):  # keys come from, and the screen goes to, a terminal
        raise FrictionlabError(
            "frictionlab tui needs a terminal for its keys and its screen (stdin and stdout are not one here); "
            "without one, run presets headless: frictionlab run PRESET"
        )
    from .app import FrictionlabApp
    from .keyorder import keep_escape_before_control_keys, paste_keeps_escapes

    keep_escape_before_control_keys()
    paste_keeps_escapes()
    start_process_helpers()
    app = FrictionlabApp(preset, presets_dir=presets_dir, runs_dir=runs_dir, options=options)
    from ..compute.signals import HANDLED

    ends = [signum for signum in HANDLED  # Ctrl-C is a key of the app's; a hangup nohup ignores stays ignored
            if signum != signal.SIGINT and signal.getsignal(signum) != signal.SIG_IGN]  # fmt: skip
    previous = {signum: signal.signal(signum, lambda signum, frame: _exit_on_sigterm(app, signum)) for signum in ends}
    # what is imported by now lives as long as the app: kept out of the cycle collector's
    # walks, its longest pause while presets open and the form is walked through falls from
    # 0.17-0.20 s to 0.12-0.13 s
    gc.freeze()
    try:
        app.run()
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    if app.farewell:
        print(app.farewell, file=sys.stderr)
    return app.return_code or 0


def _exit_on_sigterm(app, signum: int = signal.SIGTERM) -> None:
    """SIGTERM (or SIGHUP: its terminal closed) while the app runs: it quits
    (``FrictionlabApp.terminate``), so its terminal is given back whole. Raised where the
    handler lands, it could stop the app's own cleanup between two escape codes and leave the
    terminal on the alternate screen. Before the app's loop runs, or once it has closed, it is
    raised as at any other time (``signals.RaiseOnSignals``): nothing of the screen is to give back."""
    from ..compute.signals import ENDINGS, _raise_for

    loop = app._loop  # set while the app's loop runs, its cleanup included
    if loop is None:
        _raise_for(signum)
    code = int(ENDINGS[signum][0])
    loop.call_soon_threadsafe(app.terminate, code)
    if signum == getattr(signal, "SIGHUP", None):
        _end_after(HANGUP_GRACE_SECONDS, code)


def _end_after(seconds: float, code: int) -> None:
    """End the process ``seconds`` from now if it has not ended by then. After a hangup its
    terminal is gone, with nothing of it to give back, and the app's exit once waited for ever
    on Textual's writer thread, whose writes to the closed terminal never ended: the process
    stayed behind, an orphan of the SSH session. Its runs are processes of their own."""
    timer = threading.Timer(seconds, os._exit, args=(code,))
    timer.daemon = True
    timer.start()


def start_process_helpers() -> None:
    """Start multiprocessing's forkserver and resource tracker now.

    While a Textual app runs, ``sys.stderr`` is Textual's capture object, whose
    ``fileno()`` is -1; the resource tracker hands ``sys.stderr.fileno()`` to
    the helper process it starts, and that fails (``bad value(s) in
    fds_to_keep``). Started before the app, with the real stderr, both are
    found running when a run's process pool needs them.
    """
    import multiprocessing

    if "forkserver" in multiprocessing.get_all_start_methods():
        from multiprocessing import forkserver, resource_tracker

        resource_tracker.ensure_running()
        forkserver.ensure_running()
