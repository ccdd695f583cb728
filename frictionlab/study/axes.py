"""The five axes of the trade-off study: each runs a few variants of one preset,
measures their cost and compares them with the axis's reference.

=============  ========================================  ==================================
axis           what varies (everything else fixed)       error against
=============  ========================================  ==================================
grid           points N at fixed L and cut-offs          the finest grid (same lines)
realizations   M, the first M of the preset's lines      none: the 95% bootstrap interval
steps          load steps K over the same f range        the densest grid (the preset's K)
solver         contact solver, same lines, same loads    the reference solver
tolerance      the reference solver's tolerance          the tightest tolerance
=============  ========================================  ==================================
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, fields

from ..ensemble import RunOutcome
from ..errors import FrictionlabError, PresetError
from ..preset import Scene
from .metrics import curve_errors, interval_half_width, mean_curve_half_width, relative_difference
from .scenes import Measurement, SceneFactory, measure

AXES = ("grid", "realizations", "steps", "solver", "tolerance")

Progress = Callable[[str], None]
UNRESOLVED = 3  # fewer mean points in contact than this at the first load: the row says so


@dataclass
class StudyOptions:
    reference: str = "bem-halfplane"
    axes: tuple[str, ...] = AXES
    grid_factors: tuple[float, ...] = (0.25, 0.5, 1.0, 2.0, 4.0)  # times the preset's N; the largest is the reference
    grid_realizations: int = 50  # M on the grid and steps axes (the same lines at every setting)
    realizations_min: int = 5  # smallest M on the realizations axis (levels halve from the preset's M)
    step_levels: tuple[int, ...] = (5, 10, 20, 50, 100, 200)  # plus the preset's K, the reference
    # N of the solver and tolerance axes, where the reference runs: the preset's N up to this cap
    # (the cost of the reference is cut through M and K first: a coarser grid at the same f range
    # leaves fewer points in contact, and a contact of one or two points compares nothing).
    compare_points: int = 131072
    compare_points_surface: int = 128  # the same, points per side, for a preset of surfaces
    compare_realizations: int = 10
    compare_steps: int = 40
    tolerances: tuple[float, ...] = (1e-2, 1e-4, 1e-6, 1e-8)  # the tightest is the reference
    reference_grid: tuple[float, ...] = ()  # grid factors for the reference solver on the compare scene
    target: float = 0.02  # relative error in b the recommendation aims at
    repeats: int = 1  # best-of repeats of every timing


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
    phi_first: float
    phi_last: float
    count_first: float  # mean points in contact at the first load
    count_last: float
    reference: bool = False
    xi_err_f: float = math.nan
    xi_bias_f: float = math.nan
    xi_err_phi: float = math.nan
    a_err: float = math.nan
    b_err: float = math.nan
    note: str = ""
    outcome: RunOutcome | None = field(default=None, repr=False, compare=False)


COLUMNS = tuple(f.name for f in fields(Row) if f.name != "outcome")


def make_row(axis: str, setting: str, value: float, scene: Scene, measured: Measurement, note: str = "") -> Row:
    outcome, fit = measured.outcome, measured.outcome.fit
    nan = math.nan
    failures = f"{len(outcome.failures)} realization(s) failed, first: {outcome.failures[0][1]}" if outcome.failures else ""
    if outcome.done and outcome.contact_count[0] < UNRESOLVED:
        note = "; ".join(n for n in (note, f"{outcome.contact_count[0]:.2g} points in contact at the first load: "
                                           "the contact is barely resolved") if n)
    return Row(
        axis=axis,
        solver=scene.solver.name,
        setting=setting,
        value=float(value),
        points=int(getattr(preset_generator(scene).params, "points", 0) or 0),
        realizations=outcome.done,
        steps=int(outcome.loads.size),
        tolerance=float(getattr(scene.solver.params, "tolerance", nan)),
        seconds=measured.seconds,
        peak_bytes=measured.peak_bytes,
        a=fit.a if fit else nan,
        b=fit.b if fit else nan,
        a_ci_rel=interval_half_width(fit.a_ci, fit.a) if fit else nan,
        b_ci_rel=interval_half_width(fit.b_ci, fit.b) if fit else nan,
        xi_ci_rel=mean_curve_half_width(outcome.xi, outcome.xi_sem, fit.confidence) if fit else nan,
        phi_first=float(outcome.contact_fraction[0]),
        phi_last=float(outcome.contact_fraction[-1]),
        count_first=float(outcome.contact_count[0]),
        count_last=float(outcome.contact_count[-1]),
        note="; ".join(n for n in (note, failures) if n),
        outcome=outcome,
    )


def compare(rows: list[Row], reference: Row, *, curves: bool = True, contact_fraction: bool = False) -> None:
    """Fill the error columns of ``rows`` against ``reference`` (which gets zeros by the same formulas)."""
    ref = reference.outcome
    for row in rows:
        row.reference = row is reference
        row.a_err = relative_difference(row.a, reference.a)
        row.b_err = relative_difference(row.b, reference.b)
        if row.outcome.done == 0 or ref.done == 0:
            continue
        if curves:
            row.xi_err_f, row.xi_bias_f, _ = curve_errors(row.outcome.f, row.outcome.xi, ref.f, ref.xi)
        if contact_fraction:
            row.xi_err_phi, _, overlap = curve_errors(
                row.outcome.contact_fraction, row.outcome.xi, ref.contact_fraction, ref.xi
            )
            if overlap < 2 and row is not reference:
                row.note = "; ".join(
                    n for n in (row.note, f"contact fractions overlap the reference's at {overlap} load(s)") if n
                )


def preset_generator(scene: Scene):
    """The spectrum generator the preset names: for a surface pressed by a line solver the scene
    runs its MDR-equivalent line, but the grid and the geometry are the surface's."""
    surface = getattr(scene, "surface", None)
    return surface if surface is not None else scene.spectrum


def _first_problem(exc: PresetError) -> str:
    return exc.problems[0] if exc.problems else str(exc)


class Study:
    """Runs the axes of one preset; ``rows`` collects what is measured."""

    def __init__(self, factory: SceneFactory, options: StudyOptions, progress: Progress = lambda _: None):
        self.factory = factory
        self.options = options
        self.progress = progress
        self.rows: list[Row] = []
        self.notes: list[str] = []
        self.base = factory.base
        preset = self.base.preset
        self.grid_m = min(preset.realizations, options.grid_realizations)
        generator = preset_generator(self.base)
        compare_points = options.compare_points if generator.dimension == 1 else options.compare_points_surface
        points = int(getattr(generator.params, "points", compare_points))
        # The comparison scene: the preset on a smaller grid, fewer lines and loads, same f range.
        self.compare_changes = {
            "spectrum.params.points": min(points, compare_points),
            "realizations": min(preset.realizations, options.compare_realizations),
            "loading.steps": min(preset.loading.steps, options.compare_steps),
        }
        self.reference_choice = factory.solver_choice(options.reference, tolerance=min(options.tolerances))
        self._check_dimensions(self.reference_choice["name"])
        self._reference_row: Row | None = None

    def _check_dimensions(self, solver: str) -> None:
        accepts = self.factory.registry.get("solver", solver).dimensions
        generator = preset_generator(self.base)
        if generator.dimension not in accepts:
            raise FrictionlabError(
                f"--reference: solver {solver!r} accepts {' or '.join(f'{d}D' for d in accepts)} profiles; "
                f"the preset's spectrum {generator.name!r} makes {generator.dimension}D ones. "
                f"Choose a reference solver that presses the preset's own geometry."
            )

    # ------------------------------------------------------------ running

    def _run(self, axis: str, setting: str, value: float, scene: Scene, note: str = "") -> Row:
        measured = measure(scene, repeats=self.options.repeats)
        row = make_row(axis, setting, value, scene, measured, note)
        self.progress(
            f"{axis:<12} {setting:<16} {row.solver:<14} {row.seconds:9.3f} s {row.peak_bytes / 2**20:9.1f} MiB"
            f"  b = {row.b:.4f}" + (f"  ({row.note})" if row.note else "")
        )
        return row

    def run(self) -> list[Row]:
        for axis in self.options.axes:
            if axis not in AXES:
                raise FrictionlabError(f"--axes: unknown axis {axis!r}; the axes are {', '.join(AXES)}")
        for axis in self.options.axes:
            new = getattr(self, f"{axis}_axis")()
            self.rows += new
        if self.options.reference_grid:
            choice = self.reference_choice
            self.rows += self.grid_axis(
                {**self.compare_changes, "solver": choice},
                self.options.reference_grid,
                label="grid (reference)",
            )
        return self.rows

    # ------------------------------------------------------------ axes

    def grid_axis(self, changes: dict | None = None, factors=None, label: str = "grid") -> list[Row]:
        changes = {"realizations": self.grid_m} if changes is None else changes
        factors = sorted(self.options.grid_factors if factors is None else factors)
        start = self.factory.make(changes)
        generator = preset_generator(start)
        points = getattr(generator.params, "points", None)
        if points is None:
            self.notes.append(f"{label}: skipped, spectrum {generator.name!r} has no 'points' parameter")
            return []
        band = getattr(generator, "band", None)
        fixed = {}
        if band is not None:  # refine the same continuous line: L and the cut-off wavelengths stay put
            fixed = {
                "spectrum.params.length": band.length,
                "spectrum.params.spacing": None,
                "spectrum.params.long_cutoff": band.long_cutoff,
                "spectrum.params.short_cutoff": band.short_cutoff,
            }
            self.notes.append(
                f"{label}: L = {band.length:g}, long cut-off {band.long_cutoff:g}, short cut-off "
                f"{band.short_cutoff:g} held fixed (lengths in the preset's units); dx = L / N varies, "
                f"so the same seed gives the same continuous line sampled more finely; M = {start.preset.realizations}"
            )
        else:
            self.notes.append(
                f"{label}: spectrum {generator.name!r} exposes no band: only N varies, its cut-offs follow its defaults"
            )
        rows = []
        for factor in factors:
            n = int(round(points * factor))
            try:
                scene = self.factory.make({**changes, **fixed, "spectrum.params.points": n})
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
        rows = [self._run("realizations", f"M={m}", m, self.factory.make({"realizations": m})) for m in sorted(levels)]
        self.notes.append(
            "realizations: the first M lines of the preset (same seed), N and loads as in the preset; "
            "the error is the half-width of the bootstrap interval, no reference"
        )
        return rows

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
            tolerance = self.reference_choice["params"].get("tolerance")
            setting = f"tol={tolerance:g}" if tolerance is not None else "reference"
            self._reference_row = self._run("solver", setting, math.nan, scene, note="reference")
        return self._reference_row

    def _describe_compare(self, scene: Scene) -> str:
        loading = scene.preset.loading
        return (
            f"N = {self.compare_changes['spectrum.params.points']}, M = {scene.preset.realizations}, "
            f"K = {loading.steps} loads from {loading.start:g} to {loading.stop:g} "
            "(the preset's f range)"
        )

    def solver_axis(self) -> list[Row]:
        registry = self.factory.registry
        names = [self.base.solver.name]
        if "winkler" in registry.names("solver") and self.base.spectrum.dimension in registry.get("solver", "winkler").dimensions:
            names.append("winkler")
        reference = self._reference()
        rows = []
        for name in dict.fromkeys(names):
            if name == reference.solver:
                continue
            scene = self.factory.make({**self.compare_changes, "solver": self.factory.solver_choice(name)})
            rows.append(self._run("solver", name, math.nan, scene))
        rows.append(reference)
        compare(rows, reference, contact_fraction=True)
        self.notes.append(
            f"solver: {self._describe_compare(self.factory.make(self.compare_changes))}; every solver sees the same "
            f"lines; errors against {reference.solver} ({reference.setting}); xi_err_f compares at equal f, "
            "xi_err_phi at equal mean contact fraction"
        )
        return rows

    def tolerance_axis(self) -> list[Row]:
        name = self.reference_choice["name"]
        if "tolerance" not in self.factory.registry.get("solver", name).Params.model_fields:
            self.notes.append(f"tolerance: skipped, {name} has no 'tolerance' parameter")
            return []
        tightest = min(self.options.tolerances)
        rows = []
        for tolerance in sorted(set(self.options.tolerances), reverse=True):
            if tolerance == tightest:
                reference = self._reference()
                row = Row(**{**{c: getattr(reference, c) for c in COLUMNS}, "outcome": reference.outcome})
                row.axis, row.value, row.setting = "tolerance", tolerance, f"tol={tolerance:g}"
                row.note = "the solver axis's reference run"
            else:
                choice = self.factory.solver_choice(name, tolerance=tolerance)
                scene = self.factory.make({**self.compare_changes, "solver": choice})
                row = self._run("tolerance", f"tol={tolerance:g}", tolerance, scene)
            rows.append(row)
        compare(rows, rows[-1])
        self.notes.append(f"tolerance: {name} on the solver axis's scene; errors against tolerance {tightest:g}")
        return rows
