"""What the exact 3D study runs, and running it.

For each Hurst exponent the preset ``exact3d-hXX.yaml`` is run by the exact solver it
names on several grids of the same surface (same side, same cut-off wavelengths:
``SpectrumGenerator.refined``), and, on each grid, MDR presses the surfaces' MDR-equivalent
lines (the same spectrum, the same f = F / (E* h L)). Every ensemble is an ordinary run
into its own folder (``runner.run_to_folder``): resumable, its files those of
``frictionlab run``.
"""

from __future__ import annotations

import json
import math
import re
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..ensemble import RunOutcome
from ..errors import FrictionlabError, OutputRefused, RunFolderError
from ..files import atomic_write, output_path_problem
from ..options import RunOptions
from ..preset import Scene, read_preset
from ..registry import Registry, default_registry
from ..rundir import STATE_FILE
from ..runfolder import read_json
from ..runner import run_to_folder
from ..seeds import realization_rng
from ..signals import WorkInterrupted, interrupted_since, mark
from ..variants import SceneFactory
from .analysis import nayak_parameter

HURSTS = (0.3, 0.5, 0.7, 0.8, 1.0)
APPROXIMATION = "mdr"  # the solver whose prediction is set beside the exact one


def preset_name(hurst: float) -> str:
    return f"exact3d-h{round(hurst * 10):02d}.yaml"


def find_presets(presets_dir: str | Path | None, plan: Plan) -> Path:
    """``presets_dir``, or else ./presets if it holds the family, else the built-in presets."""
    from ..preset.builtin import builtin_folder

    candidates = [Path(presets_dir)] if presets_dir else [Path("presets"), *filter(None, [builtin_folder()])]
    for folder in candidates:
        if all((folder / preset_name(h)).is_file() for h in plan.hursts):
            return folder
    wanted = ", ".join(preset_name(h) for h in plan.hursts)
    raise FrictionlabError(f"--presets: no folder with {wanted}; looked in {', '.join(map(str, candidates))}")


@dataclass(frozen=True)
class Plan:
    """Grids and ensembles of one study. The last resolution is the result's; ``extra``
    adds finer grids for some H, ``(hurst, pixels per side, realizations)``."""

    name: str
    resolutions: tuple[int, ...]  # pixels per side, coarsest first
    realizations: tuple[int, ...]  # per resolution
    hursts: tuple[float, ...] = HURSTS
    extra: tuple[tuple[float, int, int], ...] = ()
    steps: int | None = None  # load steps (None: the preset's)
    bootstrap: int = 1000

    def grids(self, hurst: float) -> list[tuple[int, int]]:
        """(pixels per side, realizations) of ``hurst``, coarsest first."""
        more = [(n, m) for h, n, m in self.extra if math.isclose(h, hurst)]
        return sorted([*zip(self.resolutions, self.realizations), *more])


FULL = Plan("full", resolutions=(128, 256, 512), realizations=(48, 32, 32), extra=((0.8, 1024, 8),))
QUICK = Plan("quick", resolutions=(64, 128, 256), realizations=(4, 4, 4), steps=8, bootstrap=200)


@dataclass
class Ensemble:
    """One finished run of the study."""

    hurst: float
    points: int  # pixels per side
    solver: str
    scene: Scene
    outcome: RunOutcome
    folder: Path
    spacing: float  # pixel size
    short_cutoff: float  # wavelengths, in the preset's length unit
    long_cutoff: float
    nayak: float  # of the surface (realization 0)

    @property
    def exact(self) -> bool:
        return self.solver != APPROXIMATION

    @property
    def pixels_per_short_cutoff(self) -> float:
        return self.short_cutoff / self.spacing


@dataclass
class StudyRuns:
    plan: Plan
    ensembles: list[Ensemble] = field(default_factory=list)
    seconds: float = 0.0

    def find(self, hurst: float, points: int | None = None, exact: bool = True) -> Ensemble | None:
        """The ensemble of ``hurst`` on ``points`` pixels (default: the plan's finest
        resolution), exact or MDR."""
        points = self.plan.resolutions[-1] if points is None else points
        for e in self.ensembles:
            if math.isclose(e.hurst, hurst) and e.points == points and e.exact == exact:
                return e
        return None

    def exact_grids(self, hurst: float) -> list[Ensemble]:
        return sorted((e for e in self.ensembles if e.exact and math.isclose(e.hurst, hurst)), key=lambda e: e.points)


def _cutoffs(scene: Scene) -> tuple[float, float, float]:
    """(pixel size, short and long cut-off wavelengths) of the scene's surface."""
    profile = scene.spectrum.generate(realization_rng(scene.preset.seed, 0))
    params = scene.resolved()["spectrum"]["params"]
    side = min(profile.heights.shape) * profile.spacing
    short = params.get("short_cutoff") or 10 * profile.spacing
    return profile.spacing, float(short), float(params.get("long_cutoff") or side)


def run_plan(
    presets_dir: Path,
    runs_dir: Path,
    plan: Plan,
    options: RunOptions = RunOptions(),
    *,
    registry: Registry | None = None,
    log: Callable[[str], None] = lambda text: None,
) -> StudyRuns:
    """Run every ensemble of ``plan`` into ``runs_dir/<H>-<pixels>-<solver>/``; a folder
    left by an earlier run of the same plan is resumed (nothing finished runs again)."""
    registry = registry or default_registry()
    runs = StudyRuns(plan)
    started = time.perf_counter()
    try:
        for hurst in plan.hursts:
            path = Path(presets_dir) / preset_name(hurst)
            if not path.is_file():
                raise FrictionlabError(f"the exact 3D study needs the preset {path}: it is missing")
            factory = SceneFactory(read_preset(path, registry=registry), registry, source=str(path))
            base = factory.base
            approximation = factory.solver_choice(APPROXIMATION)
            for points, realizations in plan.grids(hurst):
                changes = {f"spectrum.params.{k}": v for k, v in base.spectrum.refined(points).items()}
                changes.update({"realizations": realizations, "fit.bootstrap": plan.bootstrap})
                if plan.steps is not None:
                    changes["loading.steps"] = plan.steps
                exact = factory.make(changes)
                spacing, short, long = _cutoffs(exact)
                alpha = nayak_parameter(exact.spectrum.generate(realization_rng(exact.preset.seed, 0)).heights, spacing)
                for solver_choice in (None, approximation):
                    scene = exact if solver_choice is None else factory.make({**changes, "solver": solver_choice})
                    folder = Path(runs_dir) / f"h{hurst:.1f}-n{points}-{scene.solver.name}"
                    resume = (folder / STATE_FILE).is_file()
                    log(f"exact3d: H = {hurst}, {points}^2 pixels, {scene.solver.name}, {realizations} realizations"
                        + (" (resumed)" if resume else ""))  # fmt: skip
                    seen = mark()
                    outcome, _ = run_to_folder(scene, folder, replace(options, resume=resume))
                    if outcome.status in ("interrupted", "cancelled") or interrupted_since(seen):
                        raise KeyboardInterrupt
                    if outcome.status != "completed":
                        raise FrictionlabError(
                            f"the run in {folder} ended {outcome.status}" + (f": {outcome.error}" if outcome.error else "")
                            + "; run the command again with the same --runs to resume it"
                        )  # fmt: skip
                    runs.ensembles.append(
                        Ensemble(hurst, points, scene.solver.name, scene, outcome, folder, spacing, short, long, alpha)
                    )
    except KeyboardInterrupt:  # in a run (which ended interrupted, its work kept) or between two
        raise WorkInterrupted(
            f"the ensembles that finished are kept in {runs_dir}; run the command again with --runs {runs_dir} to resume"
        ) from None
    runs.seconds = _add_time(Path(runs_dir), plan, time.perf_counter() - started)
    return runs


TIME_FILE = "exact3d-time.json"
TIME_FILE_BYTES = 4096  # {"plan": ..., "seconds": ...}
ENSEMBLE_FOLDER = re.compile(r"h\d\.\d-n\d+-[A-Za-z0-9_.-]+")  # the folder of one ensemble, as run_plan names it


def check_runs_folder(runs_dir: Path, *, force: bool, own: tuple[str, ...] = ()) -> None:
    """Refuse (OutputRefused) a ``--runs`` folder that is a file, or that holds anything but this
    study's: its ensembles' folders, its TIME_FILE, and the names in ``own`` (its page), unless
    ``force``. An earlier study's folder is resumed; a user's folder is not filled with runs."""
    problem = output_path_problem(runs_dir)
    if problem:
        raise OutputRefused(f"--runs: {problem}; give a folder")
    if force or not runs_dir.is_dir():
        return
    foreign = sorted(
        p.name for p in runs_dir.iterdir()
        if not ((ENSEMBLE_FOLDER.fullmatch(p.name) and p.is_dir() and not p.is_symlink())
                or (p.name == TIME_FILE and _is_time_file(p)) or p.name in own)
    )  # fmt: skip
    if foreign:
        shown = ", ".join(repr(name) for name in foreign[:3]) + (", ..." if len(foreign) > 3 else "")
        raise OutputRefused(
            f"--runs {runs_dir} is not empty and is not the runs folder of an exact 3D study (it holds {shown}): "
            "give another folder, or --force to write the study's runs into it (its own files are then replaced)"
        )


def _is_time_file(path: Path) -> bool:
    """Whether ``path`` is a TIME_FILE this study wrote: {"plan": ..., "seconds": ...}."""
    try:
        data = read_json(path.parent, path.name, TIME_FILE_BYTES)
    except RunFolderError:  # a link, a FIFO, too large, not a JSON object
        return False
    return set(data) == {"plan", "seconds"}


def _add_time(runs_dir: Path, plan: Plan, seconds: float) -> float:
    """The study's wall time summed over the invocations that ran into ``runs_dir`` (a
    resumed or regenerated study adds its own), kept in ``TIME_FILE``."""
    path = runs_dir / TIME_FILE
    try:
        earlier = read_json(runs_dir, TIME_FILE, TIME_FILE_BYTES)
    except RunFolderError:  # none yet, or not one this study wrote: started afresh
        earlier = {}
    seconds_before = earlier.get("seconds")
    usable = isinstance(seconds_before, int | float) and not isinstance(seconds_before, bool)
    total = float(seconds_before) if usable and math.isfinite(seconds_before) and earlier.get("plan") == plan.name else 0.0
    total += seconds
    atomic_write(path, lambda fh: json.dump({"plan": plan.name, "seconds": total}, fh))
    return total
