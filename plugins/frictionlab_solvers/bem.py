"""Exact elastic references: a rigid periodic rough line on an elastic
half-plane (plane strain) or surface on an elastic half-space, solved by the
boundary element method.

The elastic surface answers a pressure p with the displacement
``u_q = 2 p_q / (E* |q|)`` in Fourier space (surface stiffness ``E* |q| / 2``,
``|q|`` the wave-vector norm of the line or surface). The mean mode q = 0 of a
periodic half-space has no finite stiffness; it is the rigid-body level, and
displacements are taken with zero mean. The contact problem (gap >= 0,
pressure >= 0, one of them zero at every point) is solved by the constrained
conjugate gradient of Polonsky & Keer (1999): at prescribed mean pressure
(force control) or at prescribed rigid-body approach (indentation control).

Everything is computed in scaled variables: depths below the top
``u_i = (max z - z_i) / s`` with ``s`` the height range, lengths in pixels,
pressures in units of ``E* s / dx``. The answer is therefore the same for
heights of any scale, and the indentation ``d = max(z) - c`` (the level c
where the gap closes) is formed from depths, without cancellation.

Indentation is the approach of the rigid body to the *mean* elastic surface,
measured from the first touch: it grows with load up to ``max z - mean z``,
reached at full contact, and no finite force pushes past it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

import numpy as np
from pydantic import Field

from frictionlab import ContactCurve, ContactSolver, Control, ForceNormalisation, Profile, load_finished

from .contact_area import YASTREBOV_ANCIAUX_MOLINARI, corrected_area_fraction
from .springs import ElasticParams, _check_control, _check_loads, check_profile, elastic_stiffness

POLONSKY_KEER = "10.1016/S0043-1648(99)00113-1"  # Wear 231 (1999) 206

# Steps between exact recomputations of the displacement when it is updated
# incrementally: bounds the drift of the update to ~REFRESH rounding errors.
REFRESH = 50

__all__ = ["BEMHalfPlane", "BEMHalfSpace", "ConstrainedCG", "PeriodicBEM"]


class ConstrainedCG:
    """Polonsky-Keer constrained conjugate gradient on one periodic grid.

    Works in scaled units (pixels, depths divided by the height range, E* = 1):
    ``depth`` holds ``u_i = (max z - z_i) / s`` in [0, 1]. The compliance
    kernel ``2 / |q|`` is built once; the grid-sized work buffers are reused by
    every solve, so a step allocates only vectors on the contact set.

    The residual of a state is the largest violation of the contact conditions,
    relative to the rms height: ``max(max_contact |gap|, max_free (-gap)) / h``
    (a point in contact must have zero gap, a free point must not penetrate).
    """

    def __init__(self, depth: np.ndarray):
        self.shape = depth.shape
        self.depth = depth
        self.rms = float(np.sqrt(np.mean(np.square(depth - depth.mean()))))
        self.compliance = _compliance(self.shape)
        import scipy.fft  # imported on first use: a run that needs no FFT here starts faster

        # pressure on one point per unit of its own displacement
        self.point_stiffness = 1.0 / float(scipy.fft.irfftn(self.compliance, s=self.shape).flat[0])
        self.gap = np.empty(self.shape)  # displacement + depth, before the rigid level
        self.direction = np.zeros(self.shape)  # the search direction, zero off its contact set
        self.last_gap = np.zeros(self.shape)  # the last step's gap on its contact set, zero elsewhere
        self.response = np.empty(self.shape)
        self.below = np.empty(self.shape, dtype=bool)
        self.scratch = np.empty(self.shape)
        self.axes = tuple(range(depth.ndim))
        self.spectrum = np.empty(self.compliance.shape, dtype=complex)

    def displacement(self, pressure: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Zero-mean surface displacement under ``pressure``, written into ``out``.

        numpy's FFTs write into the buffers given (``out``), so a step allocates
        nothing: half the time of ``scipy.fft``, which returns new arrays."""
        spectrum = np.fft.rfftn(pressure, axes=self.axes, out=self.spectrum)
        spectrum *= self.compliance
        np.fft.irfftn(spectrum, s=self.shape, axes=self.axes, out=out)
        return out

    def full_contact_pressure(self, mean_pressure: float) -> np.ndarray:
        """The pressure that closes every gap: ``mean + (stiffness) (z - mean z)``,
        exact in Fourier space (``E* |q| / 2`` applied to the heights)."""
        import scipy.fft  # imported on first use: a run that needs no FFT here starts faster
        spectrum = scipy.fft.rfftn(self.depth)
        stiffness = np.zeros_like(self.compliance)
        np.divide(1.0, self.compliance, out=stiffness, where=self.compliance > 0)
        spectrum *= -stiffness  # heights are minus depths
        fluctuation = scipy.fft.irfftn(spectrum, s=self.shape, overwrite_x=True)
        return fluctuation + mean_pressure

    def solve(
        self,
        pressure: np.ndarray,
        *,
        mean_pressure: float | None = None,
        approach: float | None = None,
        tolerance: float,
        max_iterations: int,
        monitor: Callable[[int, float, np.ndarray], None] | None = None,
    ) -> tuple[np.ndarray, float, int, float]:
        """Iterate from ``pressure`` (modified in place) until the residual is at
        most ``tolerance``. Exactly one of ``mean_pressure`` (force control) and
        ``approach`` (indentation control) is given. ``monitor``, if given, is
        called before each step with the iteration, the residual and the flat
        indices of the contact points (for studies of convergence).

        Returns ``(pressure, approach, iterations, residual)``; raises
        ``_NotConverged`` after ``max_iterations`` steps.

        The CG works on the contact set's points only (gathered vectors); whole
        grids are touched by one FFT pair (the response to the direction), one
        update of the gap and one comparison with the level per step. The gap
        is updated from the step's response while the contact set is unchanged;
        it is recomputed exactly (a second FFT pair) when points are clipped or
        added, every
        ``REFRESH`` steps, and before convergence is accepted. Under force
        control the direction has zero sum, so a step keeps the load; the load
        is restored exactly after points are clipped or added.

        The CG factor is Polak-Ribiere's, clipped at zero (Gilbert & Nocedal
        1992): ``g.(g - g_last) / |g_last|^2`` with the last gap restricted to
        the current contact set. On a fixed set it equals the usual
        ``|g|^2 / |g_last|^2``; across a set change it restarts the CG by itself
        as soon as successive gaps stop being orthogonal. Fletcher-Reeves'
        factor, kept across set changes, froze warm sweeps: after a start whose
        contact gaps were closed to rounding it reached 1e30, and on a fixed set
        the stale direction then made steps of 1e-31 or let the residual grow
        (jamming). Restarting at every set change, as Polonsky & Keer do when
        points are added, also converges but took 1.2-5x more iterations on
        random surfaces of 256-1024 pixels a side.
        """
        force_control = approach is None
        p, g, r, t_grid = pressure.reshape(-1), self.gap.reshape(-1), self.response, self.direction
        t_flat, depth = t_grid.reshape(-1), self.depth.reshape(-1)
        level = approach
        if force_control:  # the load is part of the answer: start from a pressure that carries it
            total = float(p.mean())
            if total > 0.0:
                p *= mean_pressure / total
            else:
                p.fill(mean_pressure)
        gap_flat = self.last_gap.reshape(-1)
        t_flat.fill(0.0)
        gap_flat.fill(0.0)
        kept_on = np.empty(0, dtype=np.intp)  # where t_grid and the last gap are non-zero
        contact = np.flatnonzero(p)
        p_c = p[contact]
        self._exact_gap(pressure)
        exact, since_exact = True, 0
        restart, changed, previous_norm = True, True, 1.0
        iteration = 0
        while True:
            if contact.size == 0:  # only possible under indentation control
                np.subtract(level, depth, out=p)
                np.maximum(p, 0.0, out=p)
                contact = np.flatnonzero(p)
                p_c = p[contact]
                self._exact_gap(pressure)
                exact, since_exact, restart = True, 0, True
                continue
            # gap on contact points: g - level, zero at the solution
            g_c = g[contact]
            if force_control:
                level = float(g_c.mean())
            g_c -= level
            worst_contact = float(np.abs(g_c).max())
            # points below the level: contact points with a negative gap error, and free
            # points that penetrate (p is exactly 0 off the contact set)
            below = np.flatnonzero(np.less(g, level, out=self.below.reshape(-1)))
            penetrating = below[p[below] == 0.0]
            worst_free = level - float(g[penetrating].min()) if penetrating.size else 0.0
            residual = max(worst_contact, worst_free) / self.rms
            if residual <= tolerance:
                if not exact:  # accept only what an exact gap confirms
                    p[contact] = p_c
                    self._exact_gap(pressure)
                    exact, since_exact = True, 0
                    continue
                p[contact] = p_c
                return pressure, float(level), iteration, residual
            if monitor is not None:
                monitor(iteration, residual, contact)
            if iteration == max_iterations:
                raise _NotConverged(iteration, residual)
            iteration += 1

            norm = _dot(g_c, g_c)
            if norm > 0.0:
                # Polak-Ribiere factor, clipped at 0, with the last gap restricted to this set
                beta = 0.0 if restart else (norm - _dot(g_c, gap_flat[contact])) / previous_norm
                if beta > 0.0:  # conjugate to the last direction, restricted to this set
                    t_c = t_flat[contact]
                    t_c *= beta
                    t_c += g_c
                else:
                    t_c = g_c.copy()
                if force_control:  # a zero-sum direction keeps the load
                    t_c -= t_c.mean()
                if not _dot(g_c, t_c) > 0.0:
                    t_c = g_c.copy()
                previous_norm = norm
                if changed:  # the vectors kept on the grid live on the new set
                    t_flat[kept_on] = 0.0
                    gap_flat[kept_on] = 0.0
                    kept_on = contact
                t_flat[contact] = t_c
                gap_flat[contact] = g_c
                self.displacement(t_grid, r)
                r_c = r.reshape(-1)[contact]
                curvature = _dot(t_c, r_c)
                if not curvature > 0.0:  # no descent left along t: stuck
                    raise _NotConverged(iteration, residual)
                step = _dot(g_c, t_c) / curvature
                p_c -= step * t_c
                clipped = float(p_c.min()) < 0.0
                if clipped:
                    np.maximum(p_c, 0.0, out=p_c)
            else:  # contact gaps already closed (a scaled warm start): only add points,
                step = self.point_stiffness  # each with the pressure that lifts it alone
                clipped = False
            # points without pressure after the step whose gap was negative before it
            # get pressure -step * gap (Polonsky & Keer): penetrating free points and
            # clipped contact points
            entering = penetrating
            if clipped:  # disjoint from the free ones
                entering = np.sort(np.concatenate([entering, contact[(p_c == 0.0) & (g_c < 0.0)]]))
            added = entering.size > 0
            changed = clipped or added or norm == 0.0
            restart = norm == 0.0  # no direction was built to carry on
            if changed:
                p[contact] = p_c  # zeros where clipped
                if clipped:
                    contact = contact[p_c > 0.0]
                if added:
                    p[entering] = step * (level - g[entering])
                    contact = np.sort(np.concatenate([contact, entering]))  # disjoint
                p_c = p[contact]
            if changed or since_exact >= REFRESH:
                if force_control:  # restore the load exactly
                    total = float(p_c.sum()) / p.size
                    if not total > 0.0:  # cannot happen in exact arithmetic; start over
                        p.fill(mean_pressure)
                        contact = np.arange(p.size)
                        p_c = p[contact]
                        restart = changed = True
                    else:
                        p_c *= mean_pressure / total
                p[contact] = p_c
                self._exact_gap(pressure)
                exact, since_exact = True, 0
            else:  # linear in p: g(p - step t) = g - step r
                np.multiply(r, step, out=self.scratch)
                self.gap -= self.scratch
                exact, since_exact = False, since_exact + 1

    def _exact_gap(self, pressure: np.ndarray) -> None:
        """``gap = displacement(pressure) + depth``, from the pressure itself."""
        self.displacement(pressure, self.gap)
        self.gap += self.depth


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """The dot product of two vectors without BLAS: a multithreaded BLAS keeps its
    threads spinning after each call, and on a busy machine they took the core the
    next FFT needed (the whole solve ran 3x slower)."""
    return float(np.einsum("i,i->", a, b))


class _NotConverged(Exception):
    def __init__(self, iterations: int, residual: float):
        super().__init__(iterations, residual)
        self.iterations = iterations
        self.residual = residual


def _cold_start(depth: np.ndarray, mean_pressure: float) -> np.ndarray:
    """A first pressure under force control: springs under the points of the
    contact area that the small-load law A/A0 = 2 p / (E* grad h) predicts
    (scaled units), so the CG does not start from full contact."""
    slope_squared = sum(
        float(np.mean(np.square(np.diff(depth, axis=axis, append=np.take(depth, [0], axis=axis)))))
        for axis in range(depth.ndim)
    )
    fraction = min(1.0, 2.0 * mean_pressure / np.sqrt(slope_squared)) if slope_squared > 0 else 1.0
    flat = depth.ravel()
    k = min(flat.size - 1, max(0, int(np.ceil(fraction * flat.size)) - 1))
    level = np.partition(flat, k)[k]
    pressure = np.maximum(level - depth, 0.0)
    total = float(pressure.mean())
    if not total > 0.0:  # ties at the level: fall back to an even start
        return np.full(depth.shape, mean_pressure)
    pressure *= mean_pressure / total
    return pressure


def _compliance(shape: tuple[int, ...]) -> np.ndarray:
    """``2 / |q|`` in pixel units on the rfftn grid, zero for the mean mode."""
    import scipy.fft  # imported on first use: a run that needs no FFT here starts faster
    axes = [2 * np.pi * scipy.fft.fftfreq(n) for n in shape[:-1]]
    axes.append(2 * np.pi * scipy.fft.rfftfreq(shape[-1]))
    grids = np.meshgrid(*axes, indexing="ij", sparse=True)
    q = np.sqrt(sum(np.square(grid) for grid in grids))
    compliance = np.zeros(q.shape)
    np.divide(2.0, q, out=compliance, where=q > 0)
    return compliance


# -------------------------------------------------------------------- plugins


class PeriodicBEM(ContactSolver):
    """Shared solver of the half-plane and half-space plugins: they differ only
    in the dimension of the wave vectors (and so of the profile)."""

    references: ClassVar[tuple[str, ...]] = (POLONSKY_KEER,)
    indentation_reference: ClassVar[str] = "mean surface"
    periodic_only: ClassVar[bool] = True
    body_params: ClassVar[tuple[str, ...]] = ("youngs_modulus", "poisson_ratio")
    tolerance_param: ClassVar[str | None] = "tolerance"
    # measured 147 B per point (tracemalloc, 128^2 to 512^2 surfaces pressed to full contact:
    # the CG's grids, two FFT buffers, the full-contact pressure, index arrays), plus 20 %
    bytes_per_point: ClassVar[int | None] = 176

    class Params(ElasticParams):
        tolerance: float = Field(
            1e-8,
            ge=1e-14,
            le=0.1,
            allow_inf_nan=False,
            description="relative residual: largest gap error on contact points or penetration elsewhere, over the rms height",
        )
        max_iterations: int = Field(
            10_000, ge=1, le=10_000_000, description="conjugate-gradient steps allowed per load before giving up"
        )

    def stiffness(self) -> float:
        """E* = E / (1 - nu^2)."""
        return elastic_stiffness(self.params)

    def solve(
        self, profile: Profile, loads: np.ndarray, control: Control, slopes: np.ndarray
    ) -> ContactCurve:
        _check_control(control)
        loads = _check_loads(loads, control)
        heights, slopes, spacing = check_profile(self, profile, slopes)
        if not profile.periodic:
            raise ValueError(
                f"{self.name} presses periodic profiles only, and this one is not (a scan whose ends do not "
                "meet). Make it periodic (remove its tilt, check that its ends meet, then set the spectrum's "
                "periodic: true) or press it with a solver of independent springs (mdr, winkler)."
            )
        if not np.isfinite(heights).all():
            raise ValueError("heights must be finite")
        points = heights.size
        depth = heights.max() - heights
        scale = float(depth.max())  # the height range s
        # F = (scaled mean pressure) * force_unit: pressure unit E* s / dx times the area
        force_unit = self.stiffness() * scale * spacing ** (heights.ndim - 1) * points
        line_rms = float(np.sqrt(np.mean(np.square(slopes))))  # as the engine forms it

        steps = loads.size
        force = np.empty(steps)
        indentation = np.empty(steps)
        count = np.empty(steps, dtype=np.int64)
        corrected = np.ones(steps) if self.corrected_area else None  # full contact: no edge to correct
        slope_rms = np.empty(steps)
        iterations = np.zeros(steps, dtype=np.int64)
        residual = np.zeros(steps)

        if scale == 0.0:  # a flat profile: every load presses every point evenly
            if control == "indentation":
                raise ValueError(
                    "the profile is flat: it touches everywhere at once, so any indentation past "
                    "the first touch needs an infinite force. Use control 'force'."
                )
            return ContactCurve(
                force=loads.copy(),
                indentation=np.zeros(steps),
                contact_count=np.full(steps, points, dtype=np.int64),
                contact_fraction=np.ones(steps),
                slope_rms_contact=np.full(steps, line_rms),
                real_area_corrected=corrected,
                extras={"iterations": iterations, "residual": residual},
            )

        depth /= scale
        cg = ConstrainedCG(depth)
        full_approach = float(depth.mean())  # scaled max z - mean z
        tolerance, max_iterations = self.params.tolerance, self.params.max_iterations
        if control == "indentation":
            too_deep = np.flatnonzero(loads / scale >= full_approach)
            if too_deep.size:
                j = int(too_deep[0])
                raise ValueError(
                    f"indentation {loads[j]!r} (load {j}) is at or past the full-contact approach "
                    f"max(z) - mean(z) = {full_approach * scale:.6g}: on a periodic elastic body the "
                    "approach to the mean surface saturates at full contact, and no finite force "
                    "reaches it. Use control 'force' or smaller indentations."
                )
        else:
            full_fluctuation = cg.full_contact_pressure(0.0)
            full_threshold = -float(full_fluctuation.min())  # mean pressure of full contact

        pressure = None  # the solution at the previous load, `previous`
        previous = 1.0
        for j, load in enumerate(loads):
            target = load / force_unit if control == "force" else load / scale
            if control == "force" and target > full_threshold:
                pressure = full_fluctuation + target  # exact; the CG only checks it
            elif pressure is not None:
                # warm start: the previous solution scaled to the new load (a linear
                # extrapolation from two loads measured slower: more points clipped)
                pressure *= target / previous
            elif control == "force":
                pressure = _cold_start(depth, target)
            else:
                pressure = np.maximum(target - depth, 0.0)
            previous = target
            try:
                pressure, approach, iterations[j], residual[j] = cg.solve(
                    pressure,
                    mean_pressure=target if control == "force" else None,
                    approach=target if control == "indentation" else None,
                    tolerance=tolerance,
                    max_iterations=max_iterations,
                )
            except _NotConverged as failure:
                what = "force" if control == "force" else "indentation"
                raise ValueError(
                    f"{self.name} did not converge at load {j} ({what} {float(load):g}): residual "
                    f"{failure.residual:.3g} > tolerance {tolerance:g} after {failure.iterations} "
                    "iterations. Raise max_iterations or loosen the tolerance."
                ) from None
            contact = pressure > 0.0
            n = int(np.count_nonzero(contact))
            count[j] = n
            if corrected is not None and n < points:
                corrected[j] = corrected_area_fraction(contact)
            if control == "force":
                force[j] = load
                indentation[j] = approach * scale
            else:
                force[j] = float(pressure.mean()) * force_unit
                indentation[j] = load
            if n == points:  # xi = 1 to the last bit at full contact
                slope_rms[j] = line_rms
            else:
                slope_rms[j] = float(np.sqrt(np.mean(np.square(slopes[contact]))))
            load_finished(j + 1, steps)  # a load of a large surface takes seconds: progress per load

        return ContactCurve(
            force=force,
            indentation=indentation,
            contact_count=count,
            contact_fraction=count / points,
            slope_rms_contact=slope_rms,
            real_area_corrected=corrected,
            extras={"iterations": iterations, "residual": residual},
        )


class BEMHalfPlane(PeriodicBEM):
    name: ClassVar[str] = "bem-halfplane"
    summary: ClassVar[str] = (
        "exact elastic half-plane (plane strain) under a periodic line: FFT boundary elements, Polonsky-Keer CG"
    )
    dimensions: ClassVar[tuple[int, ...]] = (1,)
    # plane strain: the line is a ridged surface, straight in depth; its load is a force per unit depth
    normalisations = {1: ForceNormalisation(load="force per unit depth", modulus="E*", extent="one")}
    problem: ClassVar[str] = "elastic half-plane (plane strain)"


class BEMHalfSpace(PeriodicBEM):
    name: ClassVar[str] = "bem-halfspace"
    summary: ClassVar[str] = (
        "exact elastic half-space under a periodic surface: FFT boundary elements, Polonsky-Keer CG"
    )
    dimensions: ClassVar[tuple[int, ...]] = (2,)
    normalisations = {2: ForceNormalisation(load="force", modulus="E*", extent="mdr length")}
    problem: ClassVar[str] = "elastic half-space"
    references: ClassVar[tuple[str, ...]] = (POLONSKY_KEER, YASTREBOV_ANCIAUX_MOLINARI)
    # the pixel count's perimeter correction (contact_area.py) is derived for a surface's pixel edges
    corrected_area: ClassVar[bool] = True
