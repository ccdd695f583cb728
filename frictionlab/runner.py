"""Run one scene into one output folder: the single path every front end uses
(``frictionlab run``, the TUI, each point of a sweep), so they all write the
same files."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from . import engine
from .ensemble import RunOutcome
from .preset import Scene
from .results import write_results


def run_to_folder(
    scene: Scene,
    out_dir: str | Path,
    *,
    workers: int | None = None,
    listeners: Iterable[object] = (),
    cancel=None,
) -> tuple[RunOutcome, dict[str, Path]]:
    """Run ``scene`` and write its result files into ``out_dir``.

    What finished is written even when the run was cancelled or interrupted.
    Returns the outcome and the paths of the files written.
    """
    outcome = engine.run(scene, workers=workers, listeners=listeners, cancel=cancel)
    files = write_results(out_dir, scene, outcome)
    return outcome, files
