"""What the trade-off study measures: its axes and every setting, with the defaults
(``frictionlab study`` shows them in its help). No imports beyond the standard library:
building the CLI's parser reads this module."""

from __future__ import annotations

from dataclasses import dataclass

AXES = ("grid", "realizations", "steps", "solver", "tolerance")


@dataclass(frozen=True)
class StudyOptions:
    reference: str | None = None  # None: the exact solver of the preset solver's problem, for its geometry
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
