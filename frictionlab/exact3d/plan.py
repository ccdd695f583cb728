"""What the exact 3D study runs, and running it.

For each Hurst exponent the preset ``exact3d-hXX.yaml`` (the main family: a long cut-off
of a quarter of the side, so each surface self-averages; a narrow band, Nayak parameter
4 to 5) is run by the exact solver it names on several grids of the same surfaces (same
side, same cut-off wavelengths: ``SpectrumGenerator.refined``; the finest grid on the
first of them, paired), and, on each grid, MDR presses the surfaces' MDR-equivalent
lines (the same spectrum, the same f = F / (E* h L)), many lines per surface. Three
variants run beside it: the broad-band family (the same long cut-off, a short cut-off
of a few pixels of the finest grid: a band of 32 and more, Nayak parameter 10 to 40) at
some H, the comparison family (long cut-off = the side, the family the page used
before) and the spectral gradient. Every family is pressed at the same loads, so at the
same f. Every ensemble is an ordinary run into its own folder (``runner.run_to_folder``):
resumable, its files those of ``frictionlab run`` but plot.png (the page's figures draw the
ensembles together; one figure per ensemble took two thirds of the quick plan's time).
The jobs run in the plan's order of value, so an interrupted study has the most important
ensembles.
"""

from __future__ import annotations

import json
import math
import os
import re
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..compute import engine
from ..compute.ensemble import RunOutcome
from ..errors import (FrictionlabError, OutputRefused, RunError, RunFolderError, command_word, limit_advice,
                      short_repr, shown_name, warn_user, write_failed)
from ..io.files import atomic_write, output_path_problem
from ..options import RunOptions
from ..preset import Scene, first_unlike, read_preset
from ..plugin.registry import Registry, default_registry
from ..plugin.resolution import MIN_SHORT_CUTOFF_PIXELS
from ..runs.rundir import STATE_FILE, RunDirectory
from ..runs.runfolder import MAX_WALL_SECONDS, output_subfolder, read_json
from ..runs.runner import check_memory, run_to_folder
from ..preset.seeds import realization_rng
from ..compute.signals import WorkInterrupted, interrupted_since, mark
from ..variants import SceneFactory

HURSTS = (0.3, 0.5, 0.7, 0.8, 1.0)
FIRST_HURST = 0.8  # the H whose ensembles run first, and the one with the finest extra grid
APPROXIMATION = "mdr"  # the solver whose prediction is set beside the exact one
MAIN, SIDE, SPECTRAL, BROAD = "main", "side", "spectral", "broad"  # the families of surfaces and gradients
BROAD_HURSTS = (0.5, 0.8, 1.0)  # the H of the broad-band family
MIN_PIXELS_QUOTED = MIN_SHORT_CUTOFF_PIXELS[2]  # pixels on the short cut-off of a grid whose numbers are quoted


def preset_name(hurst: float) -> str:
    return f"exact3d-h{round(hurst * 10):02d}.yaml"


def find_presets(presets_dir: str | Path | None, plan: Plan) -> Path:
    """``presets_dir``, or else ./presets if it holds the family, else the built-in presets."""
    from ..preset.builtin import preset_folder

    names = [preset_name(h) for h in plan.hursts]
    return preset_folder(presets_dir, names, ", ".join(names))


@dataclass(frozen=True)
class Plan:
    """Grids and ensembles of one study. ``resolutions``/``realizations``: the main family's
    grids at every H, the last the answer's; ``extra``: finer grids for some H,
    ``(hurst, pixels per side, realizations)``, run on the first surfaces; ``side``: the
    comparison family's grid ``(pixels, realizations)``; ``spectral``: the main family's
    grid and surfaces pressed again with spectral gradients; ``broad``: the broad-band
    family's ``(pixels, realizations, pixels on its short cut-off)`` at ``broad_hursts``
    (its long cut-off the main family's); ``mdr_lines``: MDR-equivalent lines pressed per
    surface; ``loads``: ``(first, last, steps)`` log-spaced forces of every ensemble
    (None: the presets')."""

    name: str
    resolutions: tuple[int, ...]  # pixels per side, coarsest first
    realizations: tuple[int, ...]  # per resolution
    hursts: tuple[float, ...] = HURSTS
    extra: tuple[tuple[float, int, int], ...] = ()
    side: tuple[int, int] | None = None
    spectral: tuple[int, int] | None = None
    broad: tuple[int, int, float] | None = None
    broad_hursts: tuple[float, ...] = BROAD_HURSTS
    mdr_lines: int = 1
    loads: tuple[float, float, int] | None = None
    bootstrap: int = 1000

    def grids(self, hurst: float) -> list[tuple[int, int]]:
        """(pixels per side, realizations) of the main family at ``hurst``, coarsest first."""
        more = [(n, m) for h, n, m in self.extra if math.isclose(h, hurst)]
        return sorted([*zip(self.resolutions, self.realizations), *more])

    def jobs(self) -> list[Job]:
        """Every ensemble, most valuable first, so that an interrupted study holds the most
        of the answer: at FIRST_HURST the main family (each grid exact, then MDR), its
        broad-band family, comparison family and spectral gradients; then the other H, the
        extremes first, each with its broad-band and comparison family; the extra grids; the
        other H's spectral gradients."""
        first = [h for h in self.hursts if math.isclose(h, FIRST_HURST)]
        rest = sorted(h for h in self.hursts if not math.isclose(h, FIRST_HURST))
        rest = [*rest[:1], *rest[-1:], *rest[1:-1]] if len(rest) > 1 else rest
        regular = list(zip(self.resolutions, self.realizations))

        def main(h):
            return [Job(MAIN, h, n, m, exact) for n, m in regular for exact in (True, False)]

        def side(h):
            return [Job(SIDE, h, *self.side, exact) for exact in (True, False)] if self.side else []

        def spectral(h):
            return [Job(SPECTRAL, h, *self.spectral, True)] if self.spectral else []

        def broad(h):
            wanted = self.broad and any(math.isclose(h, b) for b in self.broad_hursts)
            return [Job(BROAD, h, *self.broad[:2], True)] if wanted else []

        jobs = [job for h in first for job in (*main(h), *broad(h), *side(h), *spectral(h))]
        jobs += [job for h in rest for job in (*main(h), *broad(h), *side(h))]
        jobs += [Job(MAIN, h, n, m, exact) for h, n, m in self.extra for exact in (True, False)]
        return jobs + [job for h in rest for job in spectral(h)]


@dataclass(frozen=True)
class Job:
    """One ensemble of the plan: exact, or MDR on ``mdr_lines`` lines per surface."""

    family: str
    hurst: float
    points: int
    surfaces: int
    exact: bool

    def folder(self, solver: str) -> str:
        prefix = "" if self.family == MAIN else f"{self.family}-"
        return f"{prefix}h{self.hurst:.1f}-n{self.points}-{solver}"

    def describe(self) -> str:
        family = {MAIN: "", SIDE: "long cut-off = side, ", SPECTRAL: "spectral gradient, ", BROAD: "broad band, "}[self.family]
        return f"H = {self.hurst:g}, {family}{self.points}² px, {'exact' if self.exact else 'MDR'}, {self.surfaces} surfaces"


# the loads run from a few contact spots per surface to 20 % contact and more: F = 0.15 to 3000 on a
# surface of side 128 and rms height 1 with E* = 1 is f = 0.00104 to 20.8, 4.3 decades
FULL = Plan("full", resolutions=(256, 512, 1024, 2048), realizations=(32, 32, 32, 16), side=(512, 32),
            spectral=(1024, 8), broad=(2048, 16, 16.0), mdr_lines=64, loads=(0.15, 3000.0, 31))  # fmt: skip
QUICK = Plan("quick", resolutions=(64, 96, 128), realizations=(4, 4, 4), side=(64, 4), spectral=(128, 2),
             extra=((FIRST_HURST, 192, 2),), broad=(128, 3, 2.5), mdr_lines=4, loads=(0.15, 3000.0, 10),
             bootstrap=200)  # fmt: skip


@dataclass
class Ensemble:
    """One finished run of the study."""

    job: Job
    solver: str
    scene: Scene
    outcome: RunOutcome
    folder: Path
    spacing: float  # pixel size
    short_cutoff: float  # wavelengths, in the preset's length unit
    long_cutoff: float

    @property
    def hurst(self) -> float:
        return self.job.hurst

    @property
    def points(self) -> int:
        return self.job.points

    @property
    def family(self) -> str:
        return self.job.family

    @property
    def exact(self) -> bool:
        return self.job.exact

    @property
    def pixels_per_short_cutoff(self) -> float:
        return self.short_cutoff / self.spacing

    @property
    def quoted(self) -> bool:
        """Whether the grid resolves the short cut-off well enough for its numbers to be quoted."""
        return self.pixels_per_short_cutoff >= MIN_PIXELS_QUOTED * (1 - 1e-9)


@dataclass
class StudyRuns:
    plan: Plan
    ensembles: list[Ensemble] = field(default_factory=list)
    missing: list[Job] = field(default_factory=list)  # jobs of the plan that have not finished
    seconds: float = 0.0

    def find(self, hurst: float, points: int | None = None, exact: bool = True, family: str = MAIN) -> Ensemble | None:
        """The finished ensemble of ``hurst`` on ``points`` pixels (default: the finest
        finished regular grid of the main family), exact or MDR; None if it did not run."""
        if points is None:
            grids = [e.points for e in self.exact_grids(hurst) if e.points in self.plan.resolutions]
            if not grids:
                return None
            points = grids[-1]
        for e in self.ensembles:
            if math.isclose(e.hurst, hurst) and e.points == points and e.exact == exact and e.family == family:
                return e
        return None

    def exact_grids(self, hurst: float, family: str = MAIN) -> list[Ensemble]:
        return sorted((e for e in self.ensembles if e.exact and e.family == family and math.isclose(e.hurst, hurst)),
                      key=lambda e: e.points)  # fmt: skip

    def hursts(self) -> list[float]:
        """The H whose main family has a finished exact grid and MDR beside it."""
        return [h for h in self.plan.hursts if self.find(h) is not None and self.find(h, exact=False) is not None]


def _cutoffs(scene: Scene) -> tuple[float, float, float]:
    """(pixel size, short and long cut-off wavelengths) of the scene's surface."""
    profile = scene.spectrum.generate(realization_rng(scene.preset.seed, 0))
    params = scene.resolved()["spectrum"]["params"]
    side = min(profile.heights.shape) * profile.spacing
    short = params.get("short_cutoff") or 10 * profile.spacing
    return profile.spacing, float(short), float(params.get("long_cutoff") or side)


def _scene(factory: SceneFactory, job: Job, plan: Plan, before_reading: Callable[[Scene], None] | None = None) -> Scene:
    """The scene of ``job``: the preset refined to the job's grid, with its family's changes
    (``before_reading``: as ``build_scene``'s, a memory check)."""
    base = factory.base
    changes = {f"spectrum.params.{k}": v for k, v in base.spectrum.refined(job.points).items()}
    if job.family == SIDE:
        changes["spectrum.params.long_cutoff"] = changes["spectrum.params.length"]
    if job.family == SPECTRAL:
        changes["slope.name"] = "spectral"
    if job.family == BROAD:  # a short cut-off of plan.broad[2] pixels of the job's grid
        changes["spectrum.params.short_cutoff"] = plan.broad[2] * changes["spectrum.params.length"] / job.points
    changes.update({"realizations": job.surfaces, "fit.bootstrap": plan.bootstrap})
    if plan.loads is not None:
        first, last, steps = plan.loads
        changes.update({"loading.start": first, "loading.stop": last, "loading.steps": steps, "loading.spacing": "log"})
    if not job.exact:  # the equivalent line depends on the surface only through its spectrum
        changes.update({"solver": factory.solver_choice(APPROXIMATION), "realizations": job.surfaces * plan.mdr_lines})
    return factory.make(changes, before_reading=before_reading)


class _Fits(Exception):
    """Raised once an ensemble's memory check passed: its MDR-equivalent line need not be made."""


def check_memory_ahead(factories: dict[float, SceneFactory], runs_dir: Path, plan: Plan, options: RunOptions) -> None:
    """Refuse (RunError), before any ensemble runs, a study one of whose ensembles left to run
    does not fit in memory (each run's own check, ``runner.check_memory``): not hours in, at
    its finest grid. The check is arithmetic: no surface is made for it."""
    if not options.memory_check:
        return

    def check(scene: Scene) -> None:
        check_memory(scene, replace(options, resume=False))
        raise _Fits

    for job in plan.jobs():
        factory = factories[job.hurst]
        if finished(Path(runs_dir) / job.folder(_solver_name(factory, job))):
            continue
        try:
            _scene(factory, job, plan, before_reading=check)
        except _Fits:
            continue
        except RunError as exc:
            raise RunError(
                f"the exact 3D study starts nothing: its ensemble {job.describe()} does not fit: {exc} The study's "
                "grids are its plan's, whatever its presets say: of that advice a preset's setting does not apply; "
                "--workers and a higher limit do, or more memory free, or --quick (grids of 64² to 192² px, "
                "not converged)."
            ) from None


def _solver_name(factory: SceneFactory, job) -> str:
    """The solver ``job``'s ensemble runs, as its folder is named, without making its scene."""
    return factory.base.solver.name if job.exact else factory.solver_choice(APPROXIMATION)["name"]


def finished(folder: Path) -> bool:
    """Whether ``folder`` holds a run that completed (its manifest says so)."""
    try:
        state = RunDirectory(folder).state() if (folder / STATE_FILE).is_file() else None
    except FrictionlabError:
        return False
    return bool(state) and state.get("status") == "completed"


def run_plan(
    presets_dir: Path,
    runs_dir: Path,
    plan: Plan,
    options: RunOptions = RunOptions(),
    *,
    compute: bool = True,
    registry: Registry | None = None,
    log: Callable[[str], None] = lambda text: None,
) -> StudyRuns:
    """Run every ensemble of ``plan`` into ``runs_dir/<family->H-<pixels>-<solver>/``, in
    the plan's order; a folder left by an earlier run of the same plan is resumed (nothing
    finished runs again). Without ``compute`` only the finished ensembles are read back,
    and the others are listed in ``StudyRuns.missing``."""
    registry = registry or default_registry()
    runs = StudyRuns(plan)
    counted = time.perf_counter()

    def count_time() -> None:
        # after every ensemble, not only at the end: a study killed outright (SIGKILL, a
        # session closed) keeps its time up to its last finished ensemble
        nonlocal counted
        now = time.perf_counter()
        if Path(runs_dir).is_dir():  # a --finished-only page reads the time, and writes nothing there
            runs.seconds = _add_time(Path(runs_dir), plan, now - counted) if compute else _time(Path(runs_dir), plan)
        counted = now

    factories: dict[float, SceneFactory] = {}
    for job in plan.jobs():  # every H's preset read and checked before any ensemble runs
        if job.hurst not in factories:
            path = Path(presets_dir) / preset_name(job.hurst)
            if not path.is_file():
                raise FrictionlabError(f"the exact 3D study needs the preset {shown_name(path)}: it is missing")
            data = read_preset(path, registry=registry)
            if data.get("sweep") is not None:  # it was dropped without a word: the study makes its own ensembles
                raise FrictionlabError(
                    f"{shown_name(path)}: sweep: the preset sweeps {', '.join(data['sweep'].get('parameters') or {})}, "
                    "but the study runs its own ensembles of it (grids, families), none of them swept; remove the sweep"
                )
            try:  # its loads are scaled on a surface of the preset's grid, made before any memory check
                factories[job.hurst] = factory = SceneFactory(data, registry, source=str(path))
            except MemoryError as exc:  # the plan's grids are fixed: fewer points is no advice here
                raise RunError(f"the exact 3D study starts nothing: out of memory making a surface of {shown_name(path)} "
                               f"({exc}); run it where more memory is free{limit_advice()}") from None  # fmt: skip
            # the page names it by its file's H
            if (unlike := first_unlike(factory.base.resolved(), {"spectrum.params.hurst": job.hurst})) is not None:
                raise FrictionlabError(
                    f"{shown_name(path)}: spectrum.params.hurst is {unlike[1]!r}, but the study takes this file for H = {job.hurst:g} "
                    f"and reports its ensembles so; give a preset of H = {job.hurst:g} (frictionlab presets copy "
                    f"{preset_name(job.hurst).removesuffix('.yaml')})"
                )
    for job in plan.jobs():  # a link at an ensemble's folder, or files of the user's there: refused before any runs
        name = job.folder(_solver_name(factories[job.hurst], job))
        folder = output_subfolder(runs_dir, name, "run the command again", make=False)
        if compute and folder.is_dir() and not (folder / STATE_FILE).exists():  # what its run refuses, not hours in
            RunDirectory(folder, force=options.force).check_fresh(_scene(factories[job.hurst], job, plan))
    if compute:
        check_memory_ahead(factories, runs_dir, plan, options)
    kept = (f"the ensembles that finished are kept in {shown_name(runs_dir)}; run the command again with "
            f"--runs {command_word(runs_dir)} to resume")  # fmt: skip
    try:
        for job in plan.jobs():
            scene = _scene(factories[job.hurst], job, plan)
            folder = output_subfolder(runs_dir, job.folder(scene.solver.name), "run the command again", make=compute)
            if not compute and not finished(folder):
                runs.missing.append(job)
                continue
            # a completed ensemble is read, not resumed: no lock taken, nothing written (a
            # --finished-only page may be reading it while a study walks past it)
            done = RunDirectory(folder).completed_results(scene) if finished(folder) else None
            if done is None and not compute:  # marked completed, its numbers not whole: read, never repaired here
                warn_user(f"{shown_name(folder)} says it finished, but its results do not check out (a chunk changed "
                          "or missing, another preset): left out of the page; the same command without "
                          "--finished-only recomputes what is damaged")  # fmt: skip
                runs.missing.append(job)
                continue
            seen = mark()
            if done is not None:
                log(f"exact3d: {job.describe()} (finished: read back)")
                outcome = engine.run(scene, RunOptions(workers=1), restored=done)
            else:
                resume = (folder / STATE_FILE).is_file()
                log(f"exact3d: {job.describe()}" + (" (resumed)" if resume else ""))
                outcome, _ = run_to_folder(scene, folder, replace(options, resume=resume), plot=False)
            if outcome.status in ("interrupted", "cancelled") or interrupted_since(seen):
                raise KeyboardInterrupt
            if outcome.status != "completed":
                raise FrictionlabError(
                    f"the run in {shown_name(folder)} ended {outcome.status}" + (f": {outcome.error}" if outcome.error else "")
                    + "; run the command again with the same --runs to resume it"
                )  # fmt: skip
            spacing, short, long = _cutoffs(scene)
            runs.ensembles.append(Ensemble(job, scene.solver.name, scene, outcome, folder, spacing, short, long))
            if done is None:
                count_time()
    except KeyboardInterrupt:  # in a run (which ended interrupted, its work kept) or between two
        raise WorkInterrupted(kept) from None
    except (OSError, RunError) as exc:  # a full disk: what finished stays
        raise (write_failed(exc, kept) if isinstance(exc, OSError) else RunError(f"{exc}; {kept}")) from None
    finally:  # the time of an invocation that computed counts in the study's, however it ended
        count_time()
    return runs


TIME_FILE = "exact3d-time.json"
TIME_FILE_BYTES = 4096  # {"plan": ..., "seconds": ...}
ENSEMBLE_FOLDER = re.compile(rf"(?:(?:{SIDE}|{SPECTRAL}|{BROAD})-)?h\d\.\d-n\d+-[A-Za-z0-9_.-]+")  # one ensemble's, as Job.folder names it


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
    total = _time(runs_dir, plan) + seconds
    atomic_write(runs_dir / TIME_FILE, lambda fh: json.dump({"plan": plan.name, "seconds": total}, fh))
    return total


def _time(runs_dir: Path, plan: Plan) -> float:
    """The study's wall time so far in ``runs_dir``'s TIME_FILE (0 if it has none of this plan)."""
    if not os.path.lexists(runs_dir / TIME_FILE):  # none yet
        return 0.0
    try:
        earlier = read_json(runs_dir, TIME_FILE, TIME_FILE_BYTES)
    except RunFolderError as exc:  # not one this study wrote: started afresh, said so
        return _time_not_counted(str(exc))
    if earlier.get("plan") != plan.name:  # another plan's (a --quick study before): its time is not this one's
        return 0.0
    seconds_before = earlier.get("seconds")
    usable = isinstance(seconds_before, int | float) and not isinstance(seconds_before, bool)
    # an edited file's -5 or 1e308 was printed on the page as the study's wall time (1e308: 300 digits)
    if usable and 0 <= seconds_before <= MAX_WALL_SECONDS:
        return float(seconds_before)
    return _time_not_counted(f"{shown_name(runs_dir / TIME_FILE)}: seconds is {short_repr(seconds_before, 40)}, "
                             f"not a time from 0 to {MAX_WALL_SECONDS:g}")  # fmt: skip


def _time_not_counted(why: str) -> float:
    warn_user(f"{why}: the study's earlier invocations' time is not counted in the wall time its page gives")
    return 0.0
