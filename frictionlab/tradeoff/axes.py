"""The five axes of the trade-off study: each runs a few variants of one preset,
measures their cost and compares them with the axis's reference.

=============  ========================================  ==================================
axis           what varies (everything else fixed)       error against
=============  ========================================  ==================================
grid           points N at fixed L and cut-offs          the finest grid (same lines)
realizations   M, the first M of the preset's lines      none: the 95% bootstrap interval
steps          load steps K over the same f range        the densest grid (the preset's K)
solver         contact solver, same surfaces, same f     the reference solver
tolerance      the reference solver's tolerance          the tightest tolerance
=============  ========================================  ==================================

The reference solves the preset solver's own physical problem (``ContactSolver.problem``):
for MDR, an approximation of the elastic half-space, that is ``bem-halfspace`` on the
same isotropic surface whose MDR-equivalent line MDR presses, compared at equal f (the 3D
f of both). Solvers of other problems (the half-plane's ridged surface, a Winkler
foundation) are their own scenes, never an exact MDR.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field, fields

import numpy as np

from ..compute.ensemble import RunOutcome, same_curves_caveat
from ..errors import FrictionlabError, PresetError, RunError
from ..plugin import ContactSolver
from ..preset import Scene
from ..compute.memory import available_memory, estimate, gib
from .metrics import curve_errors, interval_half_width, mean_curve_half_width, relative_difference
from .options import AXES, StudyOptions
from .scenes import Measurement, SceneFactory, measure

Progress = Callable[[str], None]
UNRESOLVED = 3  # fewer mean points in contact than this at the first load: the row says so


@dataclass
class Row:
    """One measured setting. Errors are relative; NaN where a metric does not apply."""

    axis: str
    solver: str
    setting: str
    value: float  # the setting as a number (N, M, K, tolerance; NaN on the solver axis)
    points: int
    realizations: int
    steps: int
    tolerance: float
    seconds: float
    peak_bytes: int
    a: float
    b: float
    a_ci_rel: float
    b_ci_rel: float
    xi_ci_rel: float
    count_first: float  # mean points in contact at the first load (springs, or pixels)
    count_last: float
    real_area_first: float  # real contact fraction (NaN for MDR springs, which are not the real area)
    real_area_last: float
    mdr_springs_first: float  # fraction of MDR springs in contact (NaN for a solver of the real contact)
    mdr_springs_last: float
    approach_first: float  # indentation from the mean plane of the elastic surface, over h
    approach_last: float
    reference: bool = False
    xi_err_f: float = math.nan
    xi_bias_f: float = math.nan
    approach_err_f: float = math.nan
    a_err: float = math.nan
    b_err: float = math.nan
    note: str = ""
    outcome: RunOutcome | None = field(default=None, repr=False, compare=False)


COLUMNS = tuple(f.name for f in fields(Row) if f.name != "outcome")


def approach(scene: Scene, outcome: RunOutcome):
    """Mean indentation over h, measured for every solver from one reference: the first touch of
    the highest point, against the mean plane of the deformed elastic surface. NaN for a solver
    that cannot say where that plane is (``ContactSolver.mean_displacement_known``)."""
    h = outcome.rms_height
    if not scene.solver.mean_displacement_known:
        return np.full(outcome.f.shape, math.nan)
    return (outcome.indentation - scene.solver.mean_displacement(outcome.f, h)) / h


def make_row(axis: str, setting: str, value: float, scene: Scene, measured: Measurement, note: str = "") -> Row:
    outcome, fit = measured.outcome, measured.outcome.fit
    nan = math.nan
    springs = scene.solver.contact_measure == "mdr springs"
    fraction = outcome.contact_fraction
    indentation = approach(scene, outcome) if outcome.done else np.full(2, nan)
    failures = f"{len(outcome.failures)} realization(s) failed, first: {outcome.failures[0][1]}" if outcome.failures else ""
    if outcome.done and outcome.contact_count[0] < UNRESOLVED:
        note = "; ".join(n for n in (note, f"{outcome.contact_count[0]:.2g} points in contact at the first load: "
                                           "the contact is barely resolved") if n)
    return Row(
        axis=axis,
        solver=scene.solver.name,
        setting=setting,
        value=float(value),
        points=grid_side(scene) or 0,
        realizations=outcome.done,
        steps=int(outcome.loads.size),
        tolerance=nan if scene.solver.tolerance() is None else scene.solver.tolerance(),
        seconds=measured.seconds,
        peak_bytes=measured.peak_bytes,
        a=fit.a if fit else nan,
        b=fit.b if fit else nan,
        a_ci_rel=interval_half_width(fit.a_ci, fit.a) if fit else nan,
        b_ci_rel=interval_half_width(fit.b_ci, fit.b) if fit else nan,
        xi_ci_rel=mean_curve_half_width(outcome.xi, outcome.xi_sem, fit.confidence) if fit else nan,
        count_first=float(outcome.contact_count[0]),
        count_last=float(outcome.contact_count[-1]),
        real_area_first=nan if springs else float(fraction[0]),
        real_area_last=nan if springs else float(fraction[-1]),
        mdr_springs_first=float(fraction[0]) if springs else nan,
        mdr_springs_last=float(fraction[-1]) if springs else nan,
        approach_first=float(indentation[0]),
        approach_last=float(indentation[-1]),
        note="; ".join(n for n in (note, failures) if n),
        outcome=outcome,
    )


def compare(rows: list[Row], reference: Row, *, curves: bool = True, approaches: dict | None = None) -> None:
    """Fill the error columns of ``rows`` against ``reference`` (which gets zeros by the same formulas).
    ``approaches``: each row's indentation curve from the common reference (``approach``), by row id."""
    ref = reference.outcome
    for row in rows:
        row.reference = row is reference
        row.a_err = relative_difference(row.a, reference.a)
        row.b_err = relative_difference(row.b, reference.b)
        if row.outcome.done == 0 or ref.done == 0:
            continue
        if curves:
            row.xi_err_f, row.xi_bias_f, _ = curve_errors(row.outcome.f, row.outcome.xi, ref.f, ref.xi)
        if approaches is not None:
            row.approach_err_f, _, _ = curve_errors(row.outcome.f, approaches[id(row)], ref.f, approaches[id(reference)])


def preset_points(scene: Scene) -> int | None:
    """The preset's points per side (the named spectrum's ``points_param``), if it has one."""
    spectrum = scene.spectrum
    if spectrum.points_param is None:
        return None
    return int(spectrum.params.model_dump()[spectrum.points_param])


def grid_side(scene: Scene) -> int | None:
    """Points per side of the grid pressed: the preset's (``preset_points``), else a
    measured file's (the longer side of a map), from the spectrum's ``grid_shape()``."""
    points = preset_points(scene)
    if points is not None:
        return points
    shape = scene.spectrum.grid_shape()
    return None if shape is None else max(shape)


def _first_problem(exc: PresetError) -> str:
    return exc.problems[0] if exc.problems else str(exc)


PRESET_GRID = ("the preset's grid", "grid (its points)")  # what refuse_beyond names for the preset's own scene


def refuse_beyond(what: str, smaller: str) -> Callable[[Scene], None]:
    """The study's memory check of one scene (a ``build_scene`` ``before_reading``): RunError
    when one realization of it, run here, would need more than is available."""

    def check(scene: Scene) -> None:
        guess = estimate(scene, workers=1, executor="serial")
        available, source = available_memory()
        if guess.total > available:
            raise RunError(
                f"the study would need about {guess.describe()} at its peak for {what}, but "
                f"{gib(available)} is available ({source}): give a smaller {smaller}"
            )

    return check


class Study:
    """Runs the axes of one preset; ``rows`` collects what is measured."""

    def __init__(
        self, factory: SceneFactory, options: StudyOptions, progress: Progress = lambda _: None, run_listeners=list
    ):
        """``progress`` hears a line per measured setting; ``run_listeners()`` gives the
        listeners of each run (a progress bar per run)."""
        self.factory = factory
        self.run_listeners = run_listeners
        self.options = options
        self.progress = progress
        self.rows: list[Row] = []
        self.notes: list[str] = []
        self.one_surface = False  # every realization the same curve (the realizations axis says so)
        self.base = factory.base
        preset = self.base.preset
        self.grid_m = min(preset.realizations, options.grid_realizations)
        generator = self.base.spectrum
        compare_points = options.compare_points if generator.dimension == 1 else options.compare_points_surface
        points = preset_points(self.base)
        # The comparison scene: the preset on a smaller grid, fewer lines and loads, same f range.
        self.compare_changes = {
            "realizations": min(preset.realizations, options.compare_realizations),
            "loading.steps": min(preset.loading.steps, options.compare_steps),
        }
        if points is not None:  # a smaller system at the same resolution (spacing and cut-offs in dx)
            self.compare_changes[f"spectrum.params.{generator.points_param}"] = min(points, compare_points)
        self.reference_choice = self._reference_choice()
        self._reference_row: Row | None = None
        self._reference_scene: Scene | None = None

    def _reference_choice(self) -> dict | None:
        """The reference solver: the one named by ``--reference``, which must solve the preset solver's
        problem and press its geometry; by default the exact solver of that problem for the preset's
        geometry, one for non-periodic profiles when the preset's is a scan (none: the solver and
        tolerance axes are skipped, with a note)."""
        base = self.base.solver
        tolerance = min(self.options.tolerances)
        if self.options.reference is not None:
            choice = self.factory.solver_choice(self.options.reference, tolerance=tolerance)
            reference = self.factory.registry.get("solver", choice["name"])
            if reference.name == base.name and "solver" in self.options.axes:
                raise FrictionlabError(
                    f"--reference {self.options.reference}: {base.name} is the preset's own solver, and the solver axis "
                    f"would compare it with itself (every error 0); give another solver of the {base.problem} "
                    "(frictionlab plugins lists them), or leave --reference out for the exact one, or leave solver out "
                    "of --axes (the tolerance axis measures a solver against its own tightest tolerance)"
                )
            if reference.problem != base.problem:
                raise FrictionlabError(
                    f"--reference: {reference.name} solves the {reference.problem}, but the preset's solver "
                    f"{base.name} the {base.problem}: a different physical problem, not an exact {base.name}. "
                    f"Compare with a solver of the {base.problem}."
                )
            try:
                self.factory.make({**self.compare_changes, "solver": choice})
            except PresetError as exc:
                raise FrictionlabError(f"--reference: {reference.name} cannot run the preset: {_first_problem(exc)}") from None
            return choice
        dimension, periodic = self.base.spectrum.dimension, self.base.spectrum.periodic()
        exact = [info.cls for info in self.factory.registry.infos("solver")
                 if _exact_for(info.cls, base, dimension) and (periodic or not info.cls.periodic_only)]  # fmt: skip
        if not exact:
            shape = {1: "lines", 2: "surfaces"}[dimension]
            self.notes.append(
                f"solver, tolerance: skipped: no installed solver solves the {base.problem} exactly on {shape}"
                + (" (MDR's exact counterpart, bem-halfspace, presses an isotropic surface: run the study on a "
                   "surface preset such as power-law-2d)" if base.approximation and dimension == 1 else "")
            )  # fmt: skip
            return None
        return self.factory.solver_choice(exact[0].name, tolerance=tolerance)

    # ------------------------------------------------------------ running

    def _run(self, axis: str, setting: str, value: float, scene: Scene, note: str = "") -> Row:
        return self._measured_row(axis, setting, value, scene, note)[0]

    def _measured_row(self, axis: str, setting: str, value: float, scene: Scene, note: str = "") -> tuple[Row, RunOutcome]:
        measured = measure(scene, repeats=self.options.repeats, listeners=self.run_listeners())
        row = make_row(axis, setting, value, scene, measured, note)
        self.progress(
            f"{axis:<12} {setting:<16} {row.solver:<14} {row.seconds:9.3f} s {row.peak_bytes / 2**20:9.1f} MiB"
            f"  b = {row.b:.4f}" + (f"  ({row.note})" if row.note else "")
        )
        return row, measured.outcome

    def run(self) -> list[Row]:
        for axis in self.options.axes:
            if axis not in AXES:
                raise FrictionlabError(f"--axes: unknown axis {axis!r}; the axes are {', '.join(AXES)}")
        self.check_memory()
        runs = {"grid": self.grid_axis, "realizations": self.realizations_axis, "steps": self.steps_axis,
                "solver": self.solver_axis, "tolerance": self.tolerance_axis}  # fmt: skip
        for axis in self.options.axes:
            self.rows += runs[axis]()
        if self.options.reference_grid and self.reference_choice is not None:
            choice = self.reference_choice
            self.rows += self.grid_axis(
                {**self.compare_changes, "solver": choice},
                self.options.reference_grid,
                label="grid (reference)",
            )
        return self.rows

    def check_memory(self) -> None:
        """Refuse (RunError), before anything runs, a study whose largest setting would need more
        memory than is available: the largest grid factor (and reference grid), else the preset's N;
        each checked before its measured map is read or its MDR-equivalent line made."""
        axes = set(self.options.axes)
        if axes & {"realizations", "steps"}:
            refuse_beyond(*PRESET_GRID)(self.base)
        grids = []  # (axis, option, changes, factors), as grid_axis runs them
        if "grid" in axes:
            grids.append(("grid", "--grid-factors", {"realizations": self.grid_m}, self.options.grid_factors))
        if self.options.reference_grid and self.reference_choice is not None:
            grids.append(("grid (reference)", "--reference-grid", {**self.compare_changes, "solver": self.reference_choice},
                          self.options.reference_grid))  # fmt: skip
        for axis, option, changes, factors in grids:
            start = self.factory.make(changes, keep_f_range=False)
            points, generator = preset_points(start), start.spectrum
            if points is None or not factors:
                continue
            n = int(round(points * max(factors)))
            refined = generator.refined(n) or {generator.points_param: n}
            check = refuse_beyond(f"the {axis} axis at N = {n:,} ({option} {max(factors):g})", option)
            try:  # the f range needs a surface generated: not yet
                self.factory.make({**changes, **{f"spectrum.params.{k}": v for k, v in refined.items()}},
                                  keep_f_range=False, before_reading=check)  # fmt: skip
            except PresetError:
                continue  # the axis skips it with a note

    # ------------------------------------------------------------ axes

    def grid_axis(self, changes: dict | None = None, factors=None, label: str = "grid") -> list[Row]:
        changes = {"realizations": self.grid_m} if changes is None else changes
        factors = sorted(self.options.grid_factors if factors is None else factors)
        start = self.factory.make(changes)
        generator, points = start.spectrum, preset_points(start)
        if points is None:
            self.notes.append(f"{label}: skipped, spectrum {generator.name!r} declares no points parameter")
            return []
        if generator.refined(points) is None:
            self.notes.append(f"{label}: spectrum {generator.name!r} cannot be refined at fixed length: only N varies")
        else:
            fixed = ", ".join(f"{k} = {v:g}" for k, v in generator.refined(points).items()
                              if k != generator.points_param and isinstance(v, float))  # fmt: skip
            self.notes.append(
                f"{label}: {fixed} held fixed (lengths in the preset's units); the spacing varies with N, so the "
                f"same seed gives the same continuous {'line' if generator.dimension == 1 else 'surface'} sampled "
                f"more finely; M = {start.preset.realizations}"
            )
        rows, grids = [], set()
        for factor in factors:
            n = int(round(points * factor))
            if n in grids:  # a factor given twice (or 1 and 1.0001): its copy, the reference, had no error
                self.notes.append(f"{label}: factor {factor:g} gives N = {n} again; each grid is run once")
                continue
            grids.add(n)
            refined = generator.refined(n) or {generator.points_param: n}
            try:
                scene = self.factory.make({**changes, **{f"spectrum.params.{k}": v for k, v in refined.items()}})
            except PresetError as exc:
                self.notes.append(f"{label}: N = {n} skipped: {_first_problem(exc)}")
                continue
            rows.append(self._run(label, f"N={n}", n, scene))
        if rows:
            compare(rows, rows[-1])
        return rows

    def realizations_axis(self) -> list[Row]:
        total = self.base.preset.realizations
        levels, m = [], total
        while m >= min(self.options.realizations_min, total):
            levels.append(m)
            if m == 1:
                break
            m //= 2
        measured = [self._measured_row("realizations", f"M={m}", m, self.factory.make({"realizations": m}))
                    for m in sorted(levels)]  # fmt: skip
        self.notes.append(
            "realizations: the first M lines of the preset (same seed), N and loads as in the preset; "
            "the error is the half-width of the bootstrap interval, no reference"
        )
        if (caveat := same_curves_caveat(measured[-1][1].per_realization["xi"])) is not None:
            self.one_surface = True
            self.notes.append(f"realizations: {caveat}")  # the run's own caveat, of the largest M
        return [row for row, _ in measured]

    def steps_axis(self) -> list[Row]:
        densest = self.base.preset.loading.steps
        levels = sorted({k for k in self.options.step_levels if 2 <= k < densest} | {densest})
        rows = [
            self._run("steps", f"K={k}", k, self.factory.make({"realizations": self.grid_m, "loading.steps": k}))
            for k in levels
        ]
        compare(rows, rows[-1], curves=False)
        self.notes.append(
            f"steps: the same {self.grid_m} lines, K loads from {self.base.preset.loading.start:g} to "
            f"{self.base.preset.loading.stop:g} ({self.base.preset.loading.spacing}); error of the fit against the densest"
        )
        return rows

    def _reference(self) -> Row:
        if self._reference_row is None:
            scene = self.factory.make({**self.compare_changes, "solver": self.reference_choice})
            tolerance = scene.solver.tolerance()
            setting = f"tol={tolerance:g}" if tolerance is not None else "reference"
            self._reference_row = self._run("solver", setting, math.nan, scene, note="reference")
            self._reference_scene = scene
        return self._reference_row

    def _describe_compare(self, scene: Scene) -> str:
        loading = scene.preset.loading
        points = grid_side(scene)
        return (
            (f"N = {points}, " if points is not None else "")
            + f"M = {scene.preset.realizations}, K = {loading.steps} loads from {loading.start:g} to "
            f"{loading.stop:g} (the preset's f range)"
        )

    def solver_axis(self) -> list[Row]:
        if self.reference_choice is None:
            return []
        base = self.factory.make(self.compare_changes)
        reference = self._reference()
        measured = [(reference, self._reference_scene)]
        if base.solver.name != reference.solver:
            measured.insert(0, (self._run("solver", base.solver.name, math.nan, base), base))
        rows = [row for row, _ in measured]
        unplaced = [scene.solver.name for _, scene in measured if not scene.solver.mean_displacement_known]
        if all(row.outcome.done for row in rows) and not unplaced:
            compare(rows, reference, approaches={id(row): approach(scene, row.outcome) for row, scene in measured})
        else:
            compare(rows, reference)
        what = "surfaces" if base.spectrum.dimension == 2 else "lines"
        mapped = f" ({base.solver.name} presses their MDR-equivalent lines)" if base.equivalent_line is not None else ""
        definitions = "; ".join(dict.fromkeys(scene.normalisation.definition for _, scene in measured))
        self.notes.append(
            f"solver: {self._describe_compare(base)}; every solver sees the same {what}{mapped}; errors against "
            f"{reference.solver} ({reference.setting}) at equal f ({definitions}); "
            + (f"indentations not compared: {' and '.join(unplaced)} measures its indentation from the undeformed "
               "body and cannot say where the mean plane of the deformed surface is (it differs from surface to "
               "surface), so approach columns are empty" if unplaced else
               "the indentation of every solver is measured from the first touch of the highest point, against "
               "the mean plane of the deformed elastic surface")
        )  # fmt: skip
        return rows

    def tolerance_axis(self) -> list[Row]:
        if self.reference_choice is None:
            return []
        name = self.reference_choice["name"]
        if self.factory.registry.get("solver", name).tolerance_param is None:
            self.notes.append(f"tolerance: skipped, {name} declares no tolerance (a direct solver)")
            return []
        tightest = min(self.options.tolerances)
        rows = []
        for tolerance in sorted(set(self.options.tolerances), reverse=True):
            if tolerance == tightest:
                reference = self._reference()
                row = dataclasses.replace(reference, axis="tolerance", value=tolerance, setting=f"tol={tolerance:g}",
                                          note="the solver axis's reference run")  # fmt: skip
            else:
                choice = self.factory.solver_choice(name, tolerance=tolerance)
                scene = self.factory.make({**self.compare_changes, "solver": choice})
                row = self._run("tolerance", f"tol={tolerance:g}", tolerance, scene)
            rows.append(row)
        compare(rows, rows[-1])
        self.notes.append(f"tolerance: {name} on the solver axis's scene; errors against tolerance {tightest:g}")
        return rows


def _exact_for(cls: type[ContactSolver], base: ContactSolver, dimension: int) -> bool:
    """Whether ``cls`` solves ``base``'s problem exactly on profiles of ``dimension``."""
    return cls.problem == base.problem and not cls.approximation and dimension in cls.dimensions

