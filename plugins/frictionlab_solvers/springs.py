"""Rows of independent springs under a rigid rough line.

Each grid point is a spring of stiffness ``K = k dx`` (on a surface, each pixel
a spring of stiffness ``k dx^2``: the springs are independent, so a surface is
solved as its flattened pixels). Pressed with a total force
F, the rigid line sinks to the level c with ``F = K * sum_i max(0, z_i - c)``;
the points in contact are those strictly above the level (``z_i > c``).

Everything is computed in *depths below the top*, ``u_i = max(z) - z_i >= 0``,
so that the indentation ``d = max(z) - c`` is formed without cancellation
whatever the offset or scale of the heights. In those variables

    F / K = sum_i max(0, d - u_i),      contact set = {i : u_i < d}.

The contact sets of a sweep are nested (the n shallowest points), so one sort
of the depths solves every load at once (:class:`SpringRow`); the bisection
per load (:class:`BisectionSprings`) is kept as the slow baseline and oracle.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from pydantic import Field

from frictionlab import (
    ContactCurve, ContactSolver, Control, ForceNormalisation, PluginParams, Profile, defined_rms, half_load_points,
    iteration_done,
)  # fmt: skip

from .checks import check_control, check_loads, check_profile
from .elastic import ElasticParams, elastic_stiffness

MDR_BOOK = "10.1007/978-3-642-53876-6"  # Popov & Hess, Method of Dimensionality Reduction

# Relative widening of the candidate bound under force control: a few rounding
# errors of the bound itself. Extra candidates cost nothing but sorting time.
_BOUND_SLACK = 16 * np.finfo(float).eps

__all__ = ["BisectionSprings", "MDRSprings", "SpringRow", "WinklerSprings"]


def _prepare(solver: ContactSolver, profile: Profile, loads, control: str, slopes):
    """Checked (loads, flat heights, flat slopes, spring stiffness K = k dx^ndim) for a sweep."""
    check_control(control)
    loads = check_loads(loads, control)
    heights, slopes, spacing = check_profile(solver, profile, slopes)
    ndim = heights.ndim
    heights, slopes = heights.ravel(), slopes.ravel()  # views when contiguous
    spring = solver.stiffness() * spacing**ndim
    if not (np.isfinite(spring) and spring > 0.0):
        raise ValueError(f"spring stiffness k dx^{ndim} must be finite and positive. Got {float(spring):g} instead.")
    return loads, heights, slopes, spring


def _top(heights: np.ndarray) -> float:
    zmax = float(heights.max())  # NaN propagates through max
    if not np.isfinite(zmax):
        raise ValueError(f"heights must be finite; their maximum is {float(zmax):g}")
    return zmax


def _line_rms(slopes: np.ndarray) -> float:
    """The rms of the defined slopes, formed exactly as the engine forms the whole line's."""
    return defined_rms(slopes)


# ------------------------------------------------------------ the sorted sweep


def _curve(force, indentation, count, points: int, slope_rms, extras: dict, half) -> ContactCurve:
    """The answer over the sweep: ``count`` of the ``points`` springs in contact at each load."""
    count = np.asarray(count).astype(np.int64, copy=False)
    return ContactCurve(force=force, indentation=indentation, contact_count=count, contact_fraction=count / points,
                        slope_rms_contact=slope_rms, extras=extras, half_load_points=half)  # fmt: skip


def _half_load_points(u: np.ndarray, n: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Per load, the fewest springs carrying half its force: the k shallowest of the ``n`` in
    contact at indentation ``d`` (sorted depths ``u``), the smallest k whose share
    k d - sum(u[:k]) reaches half of n d - sum(u[:n]) (a share that grows with k: a
    bisection over k for every load at once, log2(max n) steps)."""
    most = int(n.max())
    prefix = np.concatenate([[0.0], np.cumsum(u[:most])])
    half = 0.5 * (n * d - prefix[n])
    if n.size * most <= 1 << 16:  # small: every share at once (the bisection's steps cost more)
        k = np.arange(1, most + 1)
        short = (k * d[:, None] - prefix[1:] < half[:, None]) & (k <= n[:, None])  # the k short of half, in contact
        return np.count_nonzero(short, axis=1) + 1
    low, high = np.ones_like(n), n.copy()  # the answer lies in [low, high]
    for _ in range(int(n.max()).bit_length()):
        middle = (low + high) >> 1
        enough = middle * d - prefix[middle] >= half
        high = np.where(enough, middle, high)
        low = np.where(enough, low, middle + 1)
    return low


class SpringRow(ContactSolver):
    """Independent springs of stiffness ``stiffness() * dx``: exact sweep from one
    (partial) sort. Not registered itself; subclasses define ``stiffness`` and
    their declarations.

    The indentation is the rigid body's travel since the first touch against the
    springs' base, which does not move. The springs' mean compression is
    F / (k N dx^ndim) = f h (their f is F / (k h L) on a line, F / (k h A) on a
    surface): ``mean_displacement``.

    ``extras["candidates"]`` (one entry per load, the same for the whole sweep):
    how many points were sorted. Only points shallower than the largest load can
    reach (``u < F_max / (k dx)`` or ``u < d_max``) are candidates: a single
    point in contact already carries ``k dx * d``, so ``d <= F / (k dx)``.
    """

    indentation_reference: ClassVar[str] = "undeformed body"
    undefined_slopes: ClassVar[bool] = True

    def mean_displacement(self, f: np.ndarray, rms_height: float) -> np.ndarray:
        """The springs' mean compression f h."""
        return np.asarray(f, dtype=float) * rms_height

    def solve(
        self, profile: Profile, loads: np.ndarray, control: Control, slopes: np.ndarray
    ) -> ContactCurve:
        loads, heights, slopes, spring = _prepare(self, profile, loads, control, slopes)
        points = heights.size

        zmax = _top(heights)
        if control == "force":
            reach = loads / spring  # F / K: an upper bound of the indentation
            bound = float(reach.max()) * (1.0 + _BOUND_SLACK)
        else:
            reach = loads
            bound = float(reach.max())

        # Candidates: z >= fl(zmax - bound) keeps every float with u < bound
        # (round-to-nearest cannot put a float strictly between the two).
        candidates = np.flatnonzero(heights >= zmax - bound)
        count = candidates.size
        if count == points:  # everything may touch: one full sort
            depth = zmax - heights
            order = np.argsort(depth, kind="stable")
            u = depth[order]
        else:
            depth = zmax - heights[candidates]
            perm = np.argsort(depth, kind="stable")
            order = candidates[perm]
            u = depth[perm]  # sorted depths, u[0] == 0 (the top)
        if not np.isfinite(u[-1]):
            raise ValueError("heights must be finite")

        # G[m] = (force at which point m+1 starts touching) / K
        #      = sum_{j=1..m} j (u[j] - u[j-1]): a cumsum of non-negative terms.
        onset = np.empty(count)
        onset[0] = 0.0
        if count > 1:
            np.cumsum(np.arange(1, count) * np.diff(u), out=onset[1:])

        if control == "force":
            n = np.searchsorted(onset, reach, side="left")  # #{m : G[m] < F/K} >= 1
            prefix = np.cumsum(u)
            indentation = (reach + prefix[n - 1]) / n  # d = (F/K + sum of n depths) / n
            # Keep the exact invariant u[n-1] < d <= u[n] against the last rounding
            # (past the last candidate the next depth is >= the bound >= d: no cap).
            np.maximum(indentation, np.nextafter(u[n - 1], np.inf), out=indentation)
            np.minimum(indentation, np.append(u, np.inf)[n], out=indentation)
            force = loads.copy()
        else:
            indentation = loads.copy()
            n = np.searchsorted(u, indentation, side="left")  # #{i : u_i < d} >= 1
            # F/K = G[n-1] + n (d - u[n-1]): both terms non-negative, no cancellation.
            force = spring * (onset[n - 1] + n * (indentation - u[n - 1]))

        squares = np.square(slopes[order])
        cumulative = np.cumsum(squares)
        undefined = None
        if np.isnan(cumulative[-1]):  # points without a slope (undefined_slopes): counted in no rms
            undefined = np.isnan(squares)
            squares[undefined] = 0.0
            cumulative = np.cumsum(squares)
        if not np.isfinite(cumulative[-1]):
            raise ValueError("slopes must be finite or NaN (and their squares must not overflow)")
        if undefined is None:
            slope_rms = np.sqrt(cumulative[n - 1] / n)
        else:
            defined = np.cumsum(~undefined)[n - 1]
            with np.errstate(invalid="ignore", divide="ignore"):  # no defined slope in contact: NaN
                slope_rms = np.sqrt(cumulative[n - 1] / defined)
        if count == points:
            full = n == points
            if full.any():  # xi = 1 to the last bit at full contact
                slope_rms[full] = _line_rms(slopes)

        candidates = np.full(loads.size, count, dtype=np.int64)
        half = _half_load_points(u, n, indentation)
        return _curve(force, indentation, n, points, slope_rms, {"candidates": candidates}, half)

    def full_contact_load(self, profile: Profile) -> float | None:
        """K sum(z - min z): past it the deepest spring too is compressed."""
        heights = np.asarray(profile.heights, dtype=float)
        return float(self.stiffness() * profile.spacing**heights.ndim * np.sum(heights - heights.min()))


# -------------------------------------------------------------------- plugins


class MDRSprings(SpringRow):
    name: ClassVar[str] = "mdr"
    summary: ClassVar[str] = (
        "MDR springs of stiffness E* dx: exact load sweep from one partial sort of the heights"
    )
    references: ClassVar[tuple[str, ...]] = (MDR_BOOK,)
    # MDR is defined on a line: a surface runs as its MDR-equivalent line (preset.build_scene),
    # whose length is 2 sqrt(A / pi): F / (E* h L) is then the surface's own 3D f
    dimensions: ClassVar[tuple[int, ...]] = (1,)
    mdr_lines: ClassVar[bool] = True
    normalisations = {1: ForceNormalisation(load="force", modulus="E*", extent="length", pressure_area="mdr disc")}
    problem: ClassVar[str] = "elastic half-space"
    approximation: ClassVar[bool] = True  # the 3D contact of an isotropic surface, reduced to a line
    contact_measure: ClassVar[str] = "mdr springs"
    body_params: ClassVar[tuple[str, ...]] = ("youngs_modulus", "poisson_ratio")

    Params = ElasticParams

    def stiffness(self) -> float:
        """E* = E / (1 - nu^2)."""
        return elastic_stiffness(self.params)


class WinklerSprings(SpringRow):
    name: ClassVar[str] = "winkler"
    summary: ClassVar[str] = (
        "Winkler foundation: independent springs of a given modulus per unit length (area), exact sweep"
    )
    references: ClassVar[tuple[str, ...]] = ()
    dimensions: ClassVar[tuple[int, ...]] = (1, 2)  # one spring per point, or per pixel of a surface
    # k per unit length of a line is a stress (N/m^2); per unit area of a surface a stress per length (N/m^3)
    normalisations = {
        1: ForceNormalisation(load="force", modulus="k", extent="length"),
        2: ForceNormalisation(load="force", modulus="k", extent="area"),
    }
    problem: ClassVar[str] = "Winkler foundation"
    body_params: ClassVar[tuple[str, ...]] = ("modulus",)

    class Params(PluginParams):
        modulus: float = Field(
            1.0,
            gt=0.0,
            allow_inf_nan=False,
            description="foundation modulus k: stiffness per unit length of a line (a stress, N/m^2), or per unit "
            "area of a surface (a stress per length, N/m^3; E/t for a thin layer of thickness t)",
        )

    def stiffness(self) -> float:
        return float(self.params.modulus)


# ------------------------------------------------------------- naive baseline


class BisectionSprings(MDRSprings):
    """The naive method: for each force separately, bisect the indentation over
    the full array until the force matches to ``tolerance`` (relative).

    Contact counts are exact, not tolerance-limited: at the end the true
    indentation d* lies in the final bracket (lo, hi]; points with u <= lo are
    in contact, points with u >= hi are not, and a point whose depth lies inside
    the bracket (a tie with the level, e.g. a plateau reached exactly at this
    force) is in contact iff the force at d = u is below the load, i.e. iff
    u < d*. The reported indentation is the last midpoint (within tolerance).

    ``extras``: ``iterations`` (bisection steps per load, 0 under indentation
    control) and ``residual`` (|F(d) - F| / F at the reported indentation).
    """

    name: ClassVar[str] = "mdr-bisection"
    summary: ClassVar[str] = (
        "MDR springs solved by bisection per load: the slow baseline for benchmarks and checks"
    )
    references: ClassVar[tuple[str, ...]] = (MDR_BOOK,)
    tolerance_param: ClassVar[str | None] = "tolerance"

    class Params(MDRSprings.Params):
        tolerance: float = Field(
            1e-10, gt=0.0, le=0.1, allow_inf_nan=False, description="relative tolerance on the force of each load step"
        )
        max_iterations: int = Field(
            200, ge=1, le=10_000, description="maximum bisection steps per load"
        )

    def solve(
        self, profile: Profile, loads: np.ndarray, control: Control, slopes: np.ndarray
    ) -> ContactCurve:
        loads, heights, slopes, spring = _prepare(self, profile, loads, control, slopes)
        points = heights.size
        depth = _top(heights) - heights  # u_i >= 0
        if not np.isfinite(depth).all():
            raise ValueError("heights must be finite")

        def reduced_force(d: float) -> float:  # F(d) / K
            return float(np.maximum(d - depth, 0.0).sum())

        steps = loads.size
        indentation = np.empty(steps)
        force = np.empty(steps)
        count = np.empty(steps, dtype=np.int64)
        slope_rms = np.empty(steps)
        iterations = np.zeros(steps, dtype=np.int64)
        residual = np.zeros(steps)
        half = np.empty(steps, dtype=np.int64)
        tolerance = self.params.tolerance

        for j, load in enumerate(loads):
            if control == "indentation":
                d = float(load)
                force[j] = spring * reduced_force(d)
                contact = depth < d
            else:
                target = load / spring
                lo, hi = 0.0, target  # F(0) = 0 < F; F(F/K) >= F (the top point alone)
                d, value = hi, reduced_force(hi)
                for step in range(1, self.params.max_iterations + 1):
                    mid = 0.5 * (lo + hi)
                    if mid <= lo or mid >= hi:  # bracket down to one ulp
                        break
                    d, value = mid, reduced_force(mid)
                    iterations[j] = step
                    if value < target:
                        lo = mid
                    else:
                        hi = mid
                    if abs(value - target) <= tolerance * target:
                        break
                    iteration_done(step, abs(value - target) / target)  # a long bisection stops on cancel
                residual[j] = abs(value - target) / target
                force[j] = load
                contact = depth <= lo
                for level in np.unique(depth[(depth > lo) & (depth < hi)]):
                    if reduced_force(level) < target:  # level < d*: strictly inside
                        contact |= depth == level
            indentation[j] = d
            count[j] = int(contact.sum())
            slope_rms[j] = _line_rms(slopes[contact])
            half[j] = half_load_points(np.where(contact, np.maximum(d - depth, 0.0), 0.0))

        extras = {"iterations": iterations, "residual": residual}
        return _curve(force, indentation, count, points, slope_rms, extras, half)
