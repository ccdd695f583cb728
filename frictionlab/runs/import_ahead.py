"""The plotting module imported in a thread while the ensemble computes, so that the
figure drawn after the fit costs only its drawing: matplotlib's import is about 0.25 s,
as long as everything else a Fig. 2 run does around its compute.

The main process mostly waits while the pool's workers compute. A fork must not copy a
half-done import (the child would inherit module locks held by a thread it does not
have), so the import starts only once the workers are running, and any later fork (a
worker replaced after a death) first waits for it to end (``os.register_at_fork``). The
figure takes the module through ``imported``, which waits for it too.
"""

from __future__ import annotations

import importlib
import os
import sys
import threading

from .figures import PLOT_MODULE
from ..plugin.hookspecs import hookimpl

_importing: threading.Thread | None = None


def _wait_for_the_import() -> None:
    if _importing is not None:
        _importing.join()


def imported(name: str):
    """Module ``name``, once any import of it ahead has ended: an import that failed in the
    thread then fails here again with its own error (a thread that asks for a module while
    another's import of it fails gets the half-made module: "cannot import name ...")."""
    _wait_for_the_import()
    return importlib.import_module(name)


def _import_quietly(name: str) -> None:
    try:
        importlib.import_module(name)
    except Exception:  # noqa: BLE001 (the drawing imports it again, and reports the failure where it is read)
        pass


def import_ahead(name: str) -> threading.Thread | None:
    """Import ``name`` in a daemon thread (None: it is imported, or being imported, already).
    A fork of this process waits for that import to end."""
    global _importing
    if name in sys.modules or (_importing is not None and _importing.is_alive()):
        return None
    if _importing is None and hasattr(os, "register_at_fork"):
        os.register_at_fork(before=_wait_for_the_import)
    thread = threading.Thread(target=_import_quietly, args=(name,), name=f"import {name}", daemon=True)
    try:
        thread.start()
    except RuntimeError:  # no thread to be had (a container's pids limit): imported when it is needed
        return None
    _importing = thread
    return thread


class PlotImportAhead:
    """A run listener: at the second realization it hears of, the plotting module is
    imported in a thread. The first realization runs in this process before any pool
    starts; by the second the pool's workers are running (or the run is serial), so no
    fork comes while the import runs. A one-realization run imports it as it draws."""

    def __init__(self) -> None:
        self.heard = 0

    @hookimpl
    def realization_done(self) -> None:
        self.heard += 1
        if self.heard == 2:
            import_ahead(PLOT_MODULE)
