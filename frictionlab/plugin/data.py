"""What plugins hand each other: a profile (or surface) to press, and the contact
curve a solver returns for it."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np



def mdr_length(area: float) -> float:
    """L = 2 sqrt(A / pi): the length of the MDR line that stands for a surface of
    apparent area A (the diameter of a disc of that area)."""
    return 2.0 * math.sqrt(area / math.pi)


@dataclass(frozen=True)
class Profile:
    """One rough line, shape (N,), or surface, shape (Ny, Nx), with float64 heights on a
    uniform grid of ``spacing`` (square pixels on a surface).

    ``periodic``: whether the profile repeats (its last point is followed by its
    first), as a synthetic spectrum's lines do; a measured scan's ends do not
    meet, so slopes are never taken across them and periodic solvers refuse it.
    """

    heights: np.ndarray
    spacing: float
    periodic: bool = True

    @property
    def ndim(self) -> int:
        return int(np.ndim(self.heights))

    @property
    def points(self) -> int:
        return int(self.heights.size)

    @property
    def area(self) -> float:
        """The measure of the grid: a line's length N dx, a surface's apparent area A."""
        return self.points * self.spacing**self.ndim


@dataclass(frozen=True)
class ContactCurve:
    """A solver's answer for one profile over a whole load sweep.

    Every array has one entry per load step, in the order of the loads given, float64
    but for the counts (whole numbers).
    ``force`` holds the total loads (their meaning: the solver's ``LoadMeaning``);
    ``indentation`` the rigid-body approach from the first touch, in the frame the
    solver declares (``ContactSolver.indentation_reference``).
    ``contact_fraction`` is ``contact_count / points`` (what it measures: the
    solver's ``contact_measure``).
    ``slope_rms_contact`` is the rms, over the points in contact, of the slopes
    the engine passed in (from the chosen slope estimator).
    ``real_area_corrected``: the real contact area corrected for the pixels the
    contact's perimeter crosses, a fraction of the nominal area; given exactly when
    the solver declares ``corrected_area``, None otherwise.
    ``real_gradient_rms``: g_r, the rms of the slopes over the real contact, each contact
    pixel weighted by its share of the perimeter-corrected area (N - c M pixels, with
    ``c = 0`` it is ``slope_rms_contact``); dimensionless, a slope. Given exactly when the
    solver declares ``real_gradient``, None otherwise.
    ``contact_spots``: the number of contact spots (clusters of contact pixels joined along
    rows and columns), given exactly when the solver declares ``counts_spots``.
    ``half_load_points``: how many points carry half the load (the fewest whose loads,
    largest first, sum to half the total): a spike or a single island carrying the
    load shows as a small number; None when the solver does not say.
    ``extras`` carries solver-specific per-load arrays (iterations, residuals).
    """

    force: np.ndarray
    indentation: np.ndarray
    contact_count: np.ndarray
    contact_fraction: np.ndarray
    slope_rms_contact: np.ndarray
    real_area_corrected: np.ndarray | None = None
    real_gradient_rms: np.ndarray | None = None
    contact_spots: np.ndarray | None = None
    extras: dict[str, np.ndarray] = field(default_factory=dict)
    half_load_points: np.ndarray | None = None


def half_load_points(point_loads: np.ndarray) -> int:
    """How many points carry half the load: the fewest of ``point_loads`` (each point's
    share, >= 0), taken largest first, whose sum reaches half the total; 0 for no load."""
    loads = np.sort(np.ravel(np.asarray(point_loads, dtype=float)))[::-1]
    total = float(loads.sum())
    if not total > 0:
        return 0
    return int(np.searchsorted(np.cumsum(loads), 0.5 * total) + 1)
