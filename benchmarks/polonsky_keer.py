"""The constrained conjugate gradient of Polonsky & Keer (1999) for the contact
of a rigid rough surface on an elastic body: the exact solvers' CG before the
preconditioned projected CG (``frictionlab_solvers.contact_cg``), kept here as the
baseline that bench_bem.py measures the new one against (no preset reaches it)."""

from __future__ import annotations

import numpy as np

from frictionlab import iteration_done

from frictionlab_solvers.contact_cg import REFRESH, NotConverged, _dot
from frictionlab_solvers.elastic import ElasticOperator

__all__ = ["PolonskyKeerCG"]


class PolonskyKeerCG:
    """Polonsky-Keer constrained conjugate gradient on one grid, without a
    preconditioner: the solver before the preconditioned projected CG, kept as
    the baseline of benchmarks/bench_bem.py.

    Works in scaled units (pixels, depths divided by the height range, E* = 1):
    ``depth`` holds ``u_i = (max z - z_i) / s`` in [0, 1]. ``operator`` is
    the elastic body; the grid-sized work buffers are reused by
    every solve, so a step allocates only vectors on the contact set.

    The residual of a state is the largest violation of the contact conditions,
    relative to the rms height: ``max(max_contact |gap|, max_free (-gap)) / h``
    (a point in contact must have zero gap, a free point must not penetrate).
    """

    def __init__(self, operator: ElasticOperator, depth: np.ndarray):
        self.operator = operator
        self.shape = depth.shape
        self.depth = depth
        self.rms = float(np.sqrt(np.mean(np.square(depth - depth.mean()))))
        self.point_stiffness = operator.point_stiffness
        self.gap = np.empty(self.shape)  # displacement + depth, before the rigid level
        self.direction = np.zeros(self.shape)  # the search direction, zero off its contact set
        self.last_gap = np.zeros(self.shape)  # the last step's gap on its contact set, zero elsewhere
        self.response = np.empty(self.shape)
        self.below = np.empty(self.shape, dtype=bool)
        self.scratch = np.empty(self.shape)

    def solve(
        self,
        pressure: np.ndarray,
        *,
        mean_pressure: float | None = None,
        approach: float | None = None,
        tolerance: float,
        max_iterations: int,
    ) -> tuple[np.ndarray, float, int, float]:
        """Iterate from ``pressure`` (modified in place) until the residual is at
        most ``tolerance``. Exactly one of ``mean_pressure`` (force control) and
        ``approach`` (indentation control) is given. Each iteration calls
        ``frictionlab.iteration_done``, which may raise ``SolveCancelled``.

        Returns ``(pressure, approach, iterations, residual)``; raises
        ``NotConverged`` after ``max_iterations`` steps.

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
            iteration_done(iteration, residual)
            if iteration == max_iterations:
                raise NotConverged(iteration, residual)
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
                self.operator.displacement(t_grid, r)
                r_c = r.reshape(-1)[contact]
                curvature = _dot(t_c, r_c)
                if not curvature > 0.0:  # no descent left along t: stuck
                    raise NotConverged(iteration, residual)
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
        self.operator.displacement(pressure, self.gap)
        self.gap += self.depth
