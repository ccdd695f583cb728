"""The contact problem of a rigid rough surface on an elastic body, solved by a
preconditioned projected conjugate gradient on any elastic operator.

At the solution every point either touches (pressure p > 0, gap g = 0) or not
(p = 0, g >= 0), where ``g = u(p) + depth - level``: ``u`` the operator's
displacement, ``depth`` the depths below the top and ``level`` the rigid body's.
That is the minimum, over p >= 0, of the elastic energy ``p.u(p)/2 + p.(depth -
level)``, whose gradient is the gap. Under force control the mean pressure is
prescribed and the level is its Lagrange multiplier; under indentation control
the level is prescribed.
"""

from __future__ import annotations

import numpy as np

from frictionlab import SolveFailed, iteration_done

from .arrays import host, is_cupy, is_numpy, namespace_of, on_device
from .elastic import ElasticOperator

# Steps between exact recomputations of the gap when it is updated
# incrementally: bounds the drift of the update to ~REFRESH rounding errors.
REFRESH = 50
# The certified stop: the contact set has not changed for this many steps, and
# every point's margin (pressure on contact, gap off it) is this many times its
# change in the last step.
STABLE_STEPS = 2
MARGIN_FACTOR = 10.0
# Residual above which the step's response is computed in single precision (a
# float32 FFT pair is off by about 6e-7 relative, half the time of a float64 one);
# below it, and for every gap a stop judges, in double precision.
SINGLE_ABOVE = 1e-5

__all__ = ["REFRESH", "NotConverged", "ProjectedCG", "cold_start"]


class NotConverged(Exception):
    def __init__(self, iterations: int, residual: float):
        super().__init__(iterations, residual)
        self.iterations = iterations
        self.residual = residual


class ProjectedCG:
    """Preconditioned projected conjugate gradient on one grid.

    Works in scaled units (pixels, depths divided by the height range, E* = 1):
    ``depth`` holds ``u_i = (max z - z_i) / s`` in [0, 1]; ``operator`` is the
    elastic body (:class:`~frictionlab_solvers.elastic.ElasticOperator`). The
    grid-sized work buffers are reused by every solve.

    The residual of a state is the largest violation of the contact conditions,
    relative to the rms height: ``max(max_contact |gap|, max_free (-gap)) / h``
    (a point in contact must have zero gap, a free point must not penetrate).
    """

    def __init__(self, operator: ElasticOperator, depth):
        if tuple(depth.shape) != tuple(operator.shape):
            raise ValueError(f"depth of shape {depth.shape} on an operator of shape {operator.shape}")
        self.operator = operator
        self.xp = xp = getattr(operator, "xp", None) or namespace_of(depth)
        self.shape = tuple(depth.shape)
        self.depth = depth = on_device(xp, depth)
        self.rms = float(xp.sqrt(xp.mean(xp.square(depth - xp.mean(depth)))))
        self.int_scatter = is_numpy(xp) or is_cupy(xp)  # x[indices] = values: not in the array API

        def grid(dtype=xp.float64):
            return xp.zeros(self.shape, dtype=dtype)

        self.gap = grid()  # displacement + depth, before the rigid level
        self.direction = grid()  # the search direction, zero off its working set
        self.last_residual = grid()  # the last step's residual on its working set, zero elsewhere
        self.response = grid()  # the displacement under the direction
        self.preconditioned = grid()
        self.scratch = grid()
        # an operator whose preconditioner is a float32 transform takes the residual spread on a
        # float32 grid, and the CG reads its answer on the working set only: no float64 grid
        # cleared, converted and written back whole at every step
        self.precondition_single = getattr(operator, "precondition_single", None)
        self.spread32 = grid(xp.float32) if self.precondition_single is not None else None
        # likewise the rough responses and the lift's correction: the direction and the lift
        # spread on float32 grids over their sets alone, the float32 answer used as it is
        self.displacement_single = getattr(operator, "displacement_single", None) if self.spread32 is not None else None
        self.direction32 = grid(xp.float32) if self.displacement_single is not None else None

    def solve(
        self,
        pressure,
        *,
        mean_pressure: float | None = None,
        approach: float | None = None,
        tolerance: float,
        max_iterations: int,
        certified: bool = False,
    ) -> tuple:
        """Iterate from ``pressure`` (modified in place) until the residual is at
        most ``tolerance`` or, with ``certified``, until the contact set is
        certified. Exactly one of ``mean_pressure`` (force control) and
        ``approach`` (indentation control) is given. Each iteration calls
        ``frictionlab.iteration_done``, which may raise ``SolveCancelled``: the
        solve then stops where it is.

        Returns ``(pressure, level, iterations, residual)``; raises
        ``NotConverged`` after ``max_iterations`` steps.

        A step works on the *working set*: the contact points and the free
        points that penetrate. Its gradient there is the gap minus the level;
        the preconditioner (the operator's approximate stiffness, applied to the
        gradient spread on the grid and read back on the set) makes the CG
        converge in a few steps per decade once the set is found. Under force
        control the direction has zero sum on the set, so a step keeps the
        load. Points the step would push below zero pressure are set to zero
        (clipped) and leave the set, and the load is restored by scaling. The
        gap is updated from the step's response (and, after clipping, from the
        operator's single-precision displacement under the lift of the clipped
        points), and recomputed exactly every ``REFRESH`` steps and before a
        stop is accepted: the stop always judges an exact gap. While the
        residual is above ``SINGLE_ABOVE`` the response too is computed in single
        precision; from the first step below it on, in double precision, and the
        gap is then recomputed exactly.

        The CG factor is Polak-Ribiere's, clipped at zero (Gilbert & Nocedal
        1992), with the last residual restricted to the current set, and is kept
        across set changes: on a fixed set it is the usual factor, and across a
        change it restarts the CG by itself as soon as successive residuals stop
        being orthogonal in the preconditioner's metric.

        The certified stop: the set has not changed for ``STABLE_STEPS`` steps
        (no point clipped, none penetrating), and every point's margin exceeds
        ``MARGIN_FACTOR`` times its change in the last step: the pressure of a
        contact point, the gap of a free one. The contact set is then final
        (checked against tolerance-1e-12 solves, tests/test_certified_stop.py),
        while the pressures and the level are only as converged as the
        residual returned.

        The arrays are the operator's namespace's (``xp``): the sets are index
        vectors (``nonzero``) and masks of the grid, gathered with ``take`` and
        scattered through the mask where the namespace has no integer scatter.
        The contact set is always the support of the pressure (``p > 0``), which
        is zero off it.
        """
        xp = self.xp
        force_control = approach is None
        # Python floats: a strict namespace takes no numpy scalar (np.float64) in arithmetic
        mean_pressure = None if mean_pressure is None else float(mean_pressure)
        approach = None if approach is None else float(approach)
        operator = self.operator
        flat = (-1,)
        p, g, depth = xp.reshape(pressure, flat), xp.reshape(self.gap, flat), xp.reshape(self.depth, flat)
        d_grid, r_grid = xp.reshape(self.direction, flat), xp.reshape(self.last_residual, flat)
        z_grid = xp.reshape(self.preconditioned, flat)
        size = p.shape[0]
        level = approach
        if force_control:  # the load is part of the answer: start from a pressure that carries it
            total = float(xp.mean(p))
            if total > 0.0:
                p *= mean_pressure / total
            else:
                p[...] = mean_pressure
        d_grid[...] = 0.0
        r_grid[...] = 0.0
        spread = None  # the last working set, off which the direction and the residual grids are zero
        spread32 = None  # the same for the float32 grid of the preconditioner (None: anywhere)
        s_grid = None if self.spread32 is None else xp.reshape(self.spread32, flat)
        spread_d32 = None  # the same for the float32 direction grid
        d32_grid = None if self.direction32 is None else xp.reshape(self.direction32, flat)
        contact = xp.nonzero(p)[0]
        self._exact_gap(pressure)
        exact, since_exact = True, 0
        previous_rz = 1.0  # r.z of the last step
        stable = 0  # steps since the contact set last changed
        last_step = 0.0  # the last step's length, for the margins of the certified stop
        last_level = level
        rough = True  # responses in single precision while the residual is above SINGLE_ABOVE
        response = self.response  # the displacement under the last step's direction (float32 while rough)
        iteration = 0
        while True:
            if contact.shape[0] == 0:  # only possible under indentation control
                p[...] = xp.maximum(level - depth, 0.0)
                contact = xp.nonzero(p)[0]
                self._exact_gap(pressure)
                exact, since_exact, stable = True, 0, 0
                continue
            g_c = xp.take(g, contact)
            if force_control:
                level = float(xp.mean(g_c))
            g_c -= level
            worst_contact = float(xp.max(xp.abs(g_c)))
            # points below the level: contact points with a negative gap error, and free
            # points that penetrate (p is exactly 0 off the contact set)
            below = xp.nonzero(g < level)[0]
            penetrating = below[xp.take(p, below) == 0.0]
            worst_free = level - float(xp.min(xp.take(g, penetrating))) if penetrating.shape[0] else 0.0
            residual = max(worst_contact, worst_free) / self.rms
            done = residual <= tolerance or (
                certified and stable >= STABLE_STEPS and self._certain(p, g, contact, level, last_level, last_step, response)
            )
            if done:
                if not exact:  # accept only what an exact gap confirms
                    self._exact_gap(pressure)
                    exact, since_exact = True, 0
                    continue
                return pressure, float(level), iteration, residual
            iteration_done(iteration, residual)
            if iteration == max_iterations:
                raise NotConverged(iteration, residual)
            iteration += 1

            # the working set (sorted indices; its mask for a namespace without integer scatter)
            # and the gradient on it
            in_working = None if self.int_scatter else (p != 0.0) | (g < level)
            if penetrating.shape[0]:
                working = xp.sort(xp.concat([contact, penetrating]))  # disjoint
                r = xp.take(g, working)
                r -= level
                if force_control:  # the gradient within zero-sum steps
                    r -= xp.mean(r)
            else:
                working, r = contact, g_c
            # the preconditioned gradient, zero-sum under force control
            if self.precondition_single is not None:
                spread32 = self._respread(s_grid, spread32, working, in_working, r)
                z = xp.astype(xp.take(xp.reshape(self.precondition_single(self.spread32), flat), working), xp.float64)
            else:
                z_grid[...] = 0.0
                self._scatter(z_grid, working, in_working, r)
                operator.precondition(self.preconditioned, self.preconditioned)
                z = xp.take(z_grid, working)
            if force_control:
                z -= xp.mean(z)
            rz = _dot(r, z, xp)
            if not rz > 0.0:  # no descent left: stuck (rounding at a converged state)
                raise NotConverged(iteration, residual)
            # Polak-Ribiere factor, clipped at 0, with the last residual restricted to this set
            beta = (rz - _dot(z, xp.take(r_grid, working), xp)) / previous_rz
            if beta > 0.0:
                d = xp.take(d_grid, working)
                d *= beta
                d += z
                if force_control:
                    d -= xp.mean(d)
                if not _dot(r, d, xp) > 0.0:
                    d = z
            else:
                d = z
            previous_rz = rz
            for spread_on_grid, values in ((d_grid, d), (r_grid, r)):
                self._respread(spread_on_grid, spread, working, in_working, values)
            spread = working
            if rough and residual <= SINGLE_ABOVE:  # from here on every response is exact
                rough = False
                since_exact = REFRESH  # and the gap is recomputed exactly after this step
            if not rough:
                response = operator.displacement(self.direction, self.response)
            elif self.displacement_single is not None:
                spread_d32 = self._respread(d32_grid, spread_d32, working, in_working, d)
                response = self.displacement_single(self.direction32)
            else:
                response = operator.displacement_estimate(self.direction, self.response)
            curvature = _dot(d, xp.astype(xp.take(xp.reshape(response, flat), working), xp.float64, copy=False), xp)
            if not curvature > 0.0:  # no descent left along d: stuck
                raise NotConverged(iteration, residual)
            step = _dot(r, d, xp) / curvature
            p_w = xp.take(p, working)
            p_w -= step * d
            clipped = float(xp.min(p_w)) <= 0.0
            if clipped:
                # gap(p - step d + lift) = gap - step w + u(lift), the lift raising clipped points to 0
                lift = xp.maximum(p_w, 0.0)
                lift -= p_w
                p_w += lift
                self._scatter(p, working, in_working, p_w)
                contact = working[p_w > 0.0]
                if self.displacement_single is not None:
                    spread32 = self._respread(s_grid, spread32, working, in_working, lift)
                    correction = self.displacement_single(self.spread32)
                else:
                    z_grid[...] = 0.0
                    self._scatter(z_grid, working, in_working, lift)
                    correction = operator.displacement_estimate(self.preconditioned, self.scratch)
                self.gap -= self.depth  # the displacement, to be scaled with the pressure
                self.gap += correction  # float32 or float64: added in float64
                self.gap -= self._times(response, step)
                if force_control:  # restore the load exactly
                    total = float(xp.sum(xp.take(p, contact))) / size
                    if not total > 0.0:  # cannot happen in exact arithmetic; start over
                        p[...] = mean_pressure
                        contact = xp.arange(size)
                        d_grid[...] = 0.0
                        r_grid[...] = 0.0
                        spread = None
                        since_exact = REFRESH  # the gap is recomputed below
                    else:
                        p *= mean_pressure / total  # zero off the contact set
                        self.gap *= mean_pressure / total
                self.gap += self.depth
                stable = 0
                if since_exact >= REFRESH:
                    self._exact_gap(pressure)
                    exact, since_exact = True, 0
                else:
                    exact, since_exact = False, since_exact + 1
            elif not force_control and working.shape[0] == size and float(xp.mean(r)) > 0.0:
                # full contact under indentation control, the level above the rigid body's
                # full-contact level: a uniform pressure has no stiffness (the energy is linear
                # along it), so the pressure drops evenly until its lowest point lifts off
                self._scatter(p, working, in_working, p_w)
                p -= xp.min(p_w)
                contact = xp.nonzero(p)[0]
                self._exact_gap(pressure)
                exact, since_exact, stable = True, 0, 0
            else:
                self._scatter(p, working, in_working, p_w)
                stable = stable + 1 if working is contact else 0
                contact = working
                if since_exact >= REFRESH:
                    self._exact_gap(pressure)
                    exact, since_exact = True, 0
                else:  # linear in p: g(p - step d) = g - step w
                    self.gap -= self._times(response, step)
                    exact, since_exact = False, since_exact + 1
            last_step, last_level = step, level

    def _scatter(self, grid, indices, mask, values) -> None:
        """``grid[indices] = values`` (``indices`` the sorted positions of ``mask``)."""
        if self.int_scatter:
            grid[indices] = values
        else:  # the array API's boolean scatter, in the same (ascending) order
            grid[mask] = values

    def _respread(self, grid, spread, working, mask, values):
        """Zero ``grid`` (zero off ``spread``) and write ``values`` (cast to its dtype) at the
        sorted indices ``working`` (``mask`` their positions); returns ``working``, the grid's
        new spread."""
        self._clear(grid, spread)
        self._scatter(grid, working, mask, self.xp.astype(values, grid.dtype, copy=False))
        return working

    def _clear(self, grid, spread) -> None:
        """Zero ``grid``, which is zero off the indices ``spread`` (None: anywhere): on
        numpy only those points (a working set is a few percent of the grid)."""
        if spread is not None and self.int_scatter:
            grid[spread] = 0.0
        else:
            grid[...] = 0.0

    def _times(self, field, factor: float):
        """``field * factor`` in float64 (``field`` float32 or float64), on numpy into the
        scratch grid (no allocation)."""
        if is_numpy(self.xp):
            return np.multiply(field, factor, out=self.scratch, dtype=np.float64)
        return self.xp.astype(field, self.xp.float64, copy=False) * factor

    def _certain(self, p, g, contact, level: float, last_level: float, last_step: float, response) -> bool:
        """Every point's margin exceeds MARGIN_FACTOR times its change in the last
        step (which moved p by ``-last_step * direction`` and the gap by
        ``-last_step * response``, on an unchanged contact set)."""
        xp = self.xp
        d_c = xp.take(xp.reshape(self.direction, (-1,)), contact)
        if not bool(xp.all(xp.take(p, contact) > MARGIN_FACTOR * last_step * xp.abs(d_c))):
            return False
        # free points: gap - level against its change, -step w - (level - last_level)
        change = self._times(response, -last_step)
        change -= level - last_level
        change = xp.abs(change)
        change *= MARGIN_FACTOR
        change += level
        # a free point (zero pressure: the contact set is the pressure's support) within it
        return not bool(xp.any((g <= xp.reshape(change, (-1,))) & (p == 0.0)))

    def _exact_gap(self, pressure) -> None:
        """``gap = displacement(pressure) + depth``, from the pressure itself."""
        self.operator.displacement(pressure, self.gap)
        self.gap += self.depth


def _dot(a, b, xp=None) -> float:
    """The dot product of two vectors, on numpy without BLAS: a multithreaded BLAS keeps
    its threads spinning after each call, and on a busy machine they took the core the
    next FFT needed (the whole solve ran 3x slower)."""
    if xp is None or is_numpy(xp):
        return float(np.einsum("i,i->", a, b))
    return float(xp.sum(a * b))


def cold_start(depth: np.ndarray, mean_pressure: float) -> np.ndarray:
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


def next_pressure(pressure: np.ndarray | None, previous: float, target: float, control: str, depth: np.ndarray):
    """The pressure a load's CG starts from: the last load's solution scaled to this one (a
    warm start; a linear extrapolation from two loads measured slower: more points clipped),
    else a cold start under force control, or the overlap under indentation control."""
    if pressure is not None:
        pressure *= target / previous
        return pressure
    if control == "force":
        return cold_start(depth, target)
    return np.maximum(target - depth, 0.0)


def solve_load(cg: ProjectedCG, solver: str, j: int, load: float, pressure: np.ndarray, target: float,
               control: str, tolerance: float, max_iterations: int, certified: bool):  # fmt: skip
    """Load ``j`` of a sweep solved from ``pressure``: ``(pressure, approach, iterations,
    residual)``; a SolveFailed naming ``solver``, the load and what to change if it does not converge."""
    try:
        pressure, approach, iterations, residual = cg.solve(
            on_device(getattr(cg, "xp", None), pressure),  # the baseline CG has no namespace
            mean_pressure=target if control == "force" else None,
            approach=target if control == "indentation" else None,
            tolerance=tolerance,
            max_iterations=max_iterations,
            # under indentation control only the tolerance converges the force (the baseline CG has no such stop)
            **({"certified": True} if certified and control == "force" else {}),
        )
        return host(pressure), approach, iterations, residual  # on the GPU: back to the host
    except NotConverged as failure:
        what = "force" if control == "force" else "indentation"
        raise SolveFailed(
            f"{solver} did not converge at load {j} ({what} {float(load):g}): residual "
            f"{failure.residual:.3g} > tolerance {tolerance:g} after {failure.iterations} "
            "iterations. Raise max_iterations or loosen the tolerance."
        ) from None
