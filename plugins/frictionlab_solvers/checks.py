"""Checks of a solver's inputs shared by every built-in solver: the control, the
loads, and the profile's shape and spacing."""

from __future__ import annotations

import numpy as np

from frictionlab import ContactSolver, Profile, SolveFailed


def check_control(control: str) -> None:
    if control not in ("force", "indentation"):
        raise ValueError(f"control must be 'force' or 'indentation'. Got {control!r} instead.")


def check_loads(loads, control: str) -> np.ndarray:
    loads = np.asarray(loads, dtype=float)
    what = "force" if control == "force" else "indentation"
    if loads.ndim != 1:
        raise ValueError(f"loads must be a 1D array of {what}s. Got shape {loads.shape} instead.")
    if loads.size == 0:
        raise ValueError(f"loads is empty: give at least one {what}")
    good = np.isfinite(loads) & (loads > 0.0)
    if not good.all():
        j = int(np.argmin(good))
        value = loads[j]
        problem = "not finite" if not np.isfinite(value) else "not positive"
        raise ValueError(
            f"every load must be a finite positive {what}: load {j} is {float(value):g} ({problem})"
        )
    return loads


def check_profile(solver: ContactSolver, profile: Profile, slopes) -> tuple[np.ndarray, np.ndarray, float]:
    """Heights and slopes as float arrays of the profile's shape, and the spacing;
    a shape the solver cannot press is an error naming what it presses."""
    heights = np.asarray(profile.heights, dtype=float)
    if heights.ndim not in solver.dimensions or heights.size == 0:
        shapes = " or ".join({1: "(N,)", 2: "(Ny, Nx)"}[d] for d in solver.dimensions)
        what = " or ".join({1: "a line", 2: "a surface"}[d] for d in solver.dimensions)
        raise SolveFailed(
            f"{solver.name} presses {what}: heights must have shape {shapes} with at least one point. "
            f"Got shape {heights.shape} instead."
        )
    slopes = np.asarray(slopes, dtype=float)
    if slopes.shape != heights.shape:
        raise ValueError(
            f"slopes must have the shape of the heights {heights.shape}. Got {slopes.shape} instead."
        )
    spacing = float(profile.spacing)
    if not (np.isfinite(spacing) and spacing > 0.0):
        raise ValueError(f"profile spacing must be finite and positive. Got {float(spacing):g} instead.")
    return heights, slopes, spacing
