"""What a run and a sweep tell their front ends as they go: the interfaces the
CLI's progress printers and the TUI's listeners implement, and the wording of
progress they share.

* ``RunListener``: the lifecycle hooks of one ensemble run. ``engine.run``
  calls them on the listeners it is given and on the installed plugins that
  implement them, in the order ``run_started``, then ``realization_done`` or
  ``realization_failed`` once per realization (each maybe preceded by ``load_done``
  per load of its solve and ``iteration_done`` within a load), then ``run_finished``. A
  listener implements any of them, each marked ``@frictionlab.hookimpl``
  (pluggy calls marked methods only, and checks their argument names; a method
  may take fewer of the arguments).
* ``SweepListener``: the events of a sweep (``sweep.run_sweep``); a listener
  subclasses it and overrides what it needs.
"""

from __future__ import annotations

import functools
import os
import traceback
import warnings
from typing import TYPE_CHECKING, Protocol

from ..errors.interrupts import raised_by_signal
from .base import Plugin, PluginParams
from .hookspecs import hookspec

if TYPE_CHECKING:  # annotations only: the engine imports this module
    from ..compute.engine import RunInfo
    from ..compute.ensemble import RunOutcome
    from ..compute.realization import RealizationResult
    from ..runs.sweep import PointResult, Sweep, SweepOutcome, SweepPoint


class RunListener(Protocol):
    """The lifecycle hooks of one run (the pluggy hook specifications themselves)."""

    @hookspec
    def run_started(self, run: RunInfo) -> None:
        """A run begins. ``run`` is the ``RunInfo``: scene, realizations to do,
        realizations already done, seed, workers."""

    @hookspec
    def realization_done(self, run: RunInfo, result: RealizationResult, done: int, total: int) -> None:
        """One realization finished. ``result`` is its ``RealizationResult``;
        ``done`` of ``total`` realizations are now finished (ok or failed)."""

    @hookspec
    def realization_failed(self, run: RunInfo, result: RealizationResult, done: int, total: int) -> None:
        """One realization raised. ``result.error`` holds the message; the run
        goes on with the others."""

    @hookspec
    def load_done(self, run: RunInfo, index: int, done: int, total: int) -> None:
        """Realization ``index`` has solved ``done`` of its ``total`` loads: a solver of
        long loads reports each (``frictionlab.load_finished``). Heard from realizations
        computed in this process and in a process pool's workers, not on Dask (there
        ``realization_done`` is the finest grain)."""

    @hookspec
    def iteration_done(self, run: RunInfo, index: int, load: int, iteration: int, residual: float) -> None:
        """Realization ``index`` is solving its ``load``-th load (counted from 1): ``iteration``
        steps are done and the relative residual is ``residual``. An iterative solver reports
        each iteration (``frictionlab.iteration_done``); listeners hear it at most four times a
        second per realization, so a long load shows movement. Heard as ``load_done`` is."""

    @hookspec
    def run_finished(self, run: RunInfo, outcome: RunOutcome) -> None:
        """The run ended (completed, cancelled or failed). ``outcome`` is the
        ``RunOutcome`` with the statistics and the fit of what finished."""


LIFECYCLE_HOOKS = (
    "run_started", "realization_done", "realization_failed", "load_done", "iteration_done", "run_finished",
)  # fmt: skip


def fault_site(exc: BaseException, package: str):
    """Where ``exc`` was raised in ``package`` (a plugin's top-level module): its innermost frame
    there, ``solve() at module.py:12``, and the class of the plugin (or of its ``Params``) whose
    method is nearest to it on the stack (a helper function has none of its own; a validator is a
    classmethod: its ``cls``); (None, "", None) if no frame is there."""
    frames = [(frame, lineno) for frame, lineno in traceback.walk_tb(exc.__traceback__)
              if str(frame.f_globals.get("__name__", "")).partition(".")[0] == package][::-1]  # fmt: skip
    if not frames:
        return None, "", None
    frame, lineno = frames[0]
    owner = next((kind for f, _ in frames if (kind := _owner(f.f_locals)) is not None), None)
    return frame, f"{frame.f_code.co_name}() at {os.path.basename(frame.f_code.co_filename)}:{lineno}", owner


def _owner(names: dict) -> type | None:
    """The Plugin or PluginParams class a frame's ``self`` or ``cls`` is (or is an instance of), or None."""
    for name in ("self", "cls"):
        value = names.get(name)
        kind = value if isinstance(value, type) else type(value)
        if value is not None and issubclass(kind, (Plugin, PluginParams)):
            return kind
    return None


class GuardedListener:
    """An installed plugin's lifecycle hooks (``hookimpls``), called so that one that raises
    is told once, naming the plugin (``label``) and how to be rid of it (``advice``), and
    heard no more in this run, which goes on: a logger's fault never costs the results."""

    def __init__(self, hookimpls, label: str, advice: str):
        self._label, self._advice, self._failed = label, advice, False
        for name, impl in hookimpls:  # (hook name, pluggy HookImpl)
            setattr(self, name, self._guard(name, impl.function))

    def _guard(self, name, function):
        @functools.wraps(function)  # keeps the hookimpl mark and the argument names pluggy reads
        def guarded(*args, **kwargs):
            if self._failed:
                return None
            try:
                return function(*args, **kwargs)
            except (Exception, SystemExit, KeyboardInterrupt) as exc:  # the plugin's fault (its sys.exit() too): told,
                if raised_by_signal(exc):  # not the run's end; Ctrl-C is
                    raise
                self._failed = True
                _, where, _ = fault_site(exc, function.__module__.partition(".")[0])
                said = f": {exc}" if str(exc) else ""  # sys.exit(), a bare raise: no message
                warnings.warn(
                    f"{self._label} raised {type(exc).__name__}{said} in {where or name + '()'}; it hears no more "
                    f"of this run, which goes on: {self._advice}", RuntimeWarning, stacklevel=2,
                )  # fmt: skip
                return None

        return guarded


class SweepListener:
    """The events of a sweep, in order: ``sweep_started``, then per point
    ``point_started`` (whose run then tells ``run_listeners(point)``) and
    ``point_finished``, then ``sweep_finished``. Every method does nothing here."""

    def sweep_started(self, sweep: Sweep) -> None:
        """The sweep begins: every point is planned and valid."""

    def point_started(self, sweep: Sweep, point: SweepPoint) -> None:
        """A point's run begins."""

    def run_listeners(self, point: SweepPoint) -> list[object]:
        """The ``RunListener``s of this point's run."""
        return []

    def point_finished(self, sweep: Sweep, point: SweepPoint, result: PointResult) -> None:
        """A point ended (``result.status`` says how), its files written."""

    def sweep_finished(self, sweep: Sweep, outcome: SweepOutcome) -> None:
        """The sweep ended: sweep.csv, sweep.json (and sweep.png) are written."""


def format_duration(seconds: float) -> str:
    """``12.3 s`` below a minute (``0.04 s`` below a tenth: not "0.0 s" for a run that took
    some), ``4:05`` below an hour, then ``1:02:03``."""
    if 0 < seconds < 0.095:
        return f"{seconds:.1g} s"
    if seconds < 60:
        return f"{seconds:.1f} s"
    minutes, seconds = divmod(int(seconds), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{seconds:02d}" if hours else f"{minutes}:{seconds:02d}"


ESTIMATE_AFTER = 3  # realizations computed before the time left is estimated from their rate


def progress_text(done: int, total: int, failed: int, elapsed: float, restored: int = 0) -> str:
    """``12/40 realizations (8 restored), 1 failed, 3.1/s, elapsed 3.9 s, left 9.0 s``: of this
    invocation, the elapsed time and the rate (not counting the ``restored`` realizations of a
    resume), and the time left at that rate; no rate (``0.0/s, left ?``) before the first
    realization computed here, and ``left ?`` until ``ESTIMATE_AFTER`` are (the first ones
    carry the start: one of 4000 after 0.8 s said 52 minutes left)."""
    computed = done - restored
    rate = computed / elapsed if elapsed > 0 else 0.0
    kept = f" ({restored} restored)" if restored else ""
    failures = f", {failed} failed" if failed else ""
    if rate <= 0:  # none computed here yet (a point a resume restored whole): no rate to tell
        return f"{done}/{total} realizations{kept}{failures}, elapsed {format_duration(elapsed)}"
    left = format_duration((total - done) / rate) if computed >= ESTIMATE_AFTER or done >= total else "?"
    return f"{done}/{total} realizations{kept}{failures}, {rate:.1f}/s, elapsed {format_duration(elapsed)}, left {left}"


def solve_text(index: int, load: int, loads: int, iteration: int | None = None, residual: float | None = None) -> str:
    """``realization 3: load 2/16, iteration 40, residual 3.1e-05``: where a long solve is
    (``load_done`` says the loads done, without the iteration)."""
    text = f"realization {index}: load {load}/{loads}"
    return text if iteration is None else f"{text}, iteration {iteration}, residual {residual:.2g}"
