"""How a run is carried out, as opposed to what it computes (that is the preset):
one ``RunOptions``, built once by a front end (the CLI from its flags, the TUI,
a script) and handed to ``runner.run_to_folder``, ``sweep.run_sweep`` or
``engine.run``. Every default lives here.

None of these options changes a number: the same preset and seed give the same
results whatever the workers, the executor or a resume.
"""

from __future__ import annotations

import numbers
import os
from dataclasses import dataclass

from .errors import FrictionlabError, require, short_repr

EXECUTORS = ("serial", "processes", "dask")


def default_workers() -> int:
    """Every core this process may use."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


@dataclass(frozen=True)
class RunOptions:
    """Where and how realizations run, and what may happen to the output folder.

    Each message of a refused value starts with the field's name (the CLI spells
    it as its flag, ``--workers``)."""

    workers: int | None = None  # processes (or Dask workers); None: every core
    executor: str | None = None  # serial | processes | dask; None: see ``executor_for``
    scheduler: str | None = None  # address of an existing Dask scheduler
    retries: int = 2  # reruns of a chunk whose worker died
    dashboard: bool = False  # serve the Dask dashboard of the local cluster
    resume: bool = False  # continue the run left in the output folder
    memory_check: bool = True  # refuse a run whose estimated peak memory does not fit
    force: bool = False  # write into a folder that is not a run of this preset

    def __post_init__(self):
        for name in ("workers", "retries"):  # numpy's integers (np.int64 of an arange) are whole numbers too
            value = getattr(self, name)
            if isinstance(value, numbers.Integral) and not isinstance(value, bool | int):
                object.__setattr__(self, name, int(value))
        if self.workers is not None and (isinstance(self.workers, bool) or not isinstance(self.workers, int)):
            raise FrictionlabError(f"workers must be a whole number >= 1. Got {short_repr(self.workers)} instead.")
        if self.workers is not None and self.workers < 1:
            raise FrictionlabError(f"workers must be >= 1. Got {self.workers} instead.")
        if self.executor is not None and self.executor not in EXECUTORS:
            raise FrictionlabError(f"executor must be one of {', '.join(EXECUTORS)}. Got {short_repr(self.executor)} instead.")
        if self.scheduler and self.executor not in (None, "dask"):
            raise FrictionlabError(
                f"scheduler {short_repr(self.scheduler)} needs the dask executor. Got executor {self.executor!r} instead."
            )
        if isinstance(self.retries, bool) or not isinstance(self.retries, int) or self.retries < 0:
            raise FrictionlabError(f"retries must be a whole number >= 0. Got {short_repr(self.retries)} instead.")
        for name in ("dashboard", "resume", "memory_check", "force"):  # force="no" is a truthy str: it forced
            if not isinstance(value := getattr(self, name), bool):
                raise FrictionlabError(f"{name} must be True or False. Got {short_repr(value)} ({type(value).__name__}) instead.")
        if self.dashboard:  # before anything starts: without bokeh the dashboard's address serves only 404s
            require("bokeh", "dashboard")

    def workers_for(self, realizations: int) -> int:
        """Workers of a run of ``realizations``: as asked (every core by default), never more than realizations."""
        return min(realizations, default_workers() if self.workers is None else self.workers)

    def executor_for(self, workers: int) -> str:
        """The executor asked for; by default Dask with a scheduler, a process pool for
        more than one worker, else this process."""
        if self.executor is not None:
            return self.executor
        return "dask" if self.scheduler else "processes" if workers > 1 else "serial"
