"""The exact solvers against a brute-force solution of the same discrete problem.

On a small periodic grid, the contact problem under a total force F is the quadratic
programme: minimise 1/2 p.C p + p.d over pressures p >= 0 with sum(p) dx^D = F, where d
is each point's depth below the highest and C the compliance of the periodic half-space
(or half-plane in plane strain), u_q = 2 p_q / (E* |q|), built here as a dense matrix
from an explicit discrete Fourier transform. Its optimality conditions are those of
contact: a pressure only where the gap closes, a gap nowhere negative. A general
optimiser finds the contact set; the equations of that set are then solved exactly and
checked against every condition. The solvers must find that same set: the count, and
the rms over it of a slope field of random numbers (which tells one set from another).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from frictionlab import Profile
from frictionlab_solvers import BEMHalfPlane, BEMHalfSpace, BEMHalfSpaceFree
from frictionlab_solvers.bem_free import pixel_influence


def dense_compliance(shape: tuple[int, ...], dx: float, modulus: float) -> np.ndarray:
    """C[i, j]: the displacement at point i under a unit pressure on point j, periodic (zero mean)."""
    grids = np.meshgrid(*(np.arange(n) for n in shape), indexing="ij")
    position = np.stack([g.ravel() for g in grids], axis=1)  # (points, dims) in pixels
    modes = np.stack([g.ravel() for g in np.meshgrid(*(np.fft.fftfreq(n, d=dx) for n in shape), indexing="ij")], axis=1)
    q = 2 * np.pi * np.linalg.norm(modes, axis=1)
    response = np.divide(2.0, modulus * q, out=np.zeros_like(q), where=q > 0)
    phase = np.exp(2j * np.pi * position @ (modes * dx).T)  # (points, modes): e^{i q.x}
    return ((phase * response) @ phase.conj().T).real / q.size


def dense_free_compliance(shape: tuple[int, int], dx: float, modulus: float) -> np.ndarray:
    """C[i, j] of the half-space under a non-periodic scan: Love's uniformly loaded pixel
    (tests/test_bem_free.py checks it against the closed forms), u = p dx / E* at unit size."""
    influence = pixel_influence(shape)
    rows, cols = np.unravel_index(np.arange(shape[0] * shape[1]), shape)
    return influence[rows[:, None] - rows[None, :], cols[:, None] - cols[None, :]] * dx / modulus


def exact_contact(compliance: np.ndarray, depth: np.ndarray, force: float, area: float) -> np.ndarray:
    """The points in contact (boolean) of the quadratic programme, checked to rounding."""
    n = depth.size
    total = force / area  # sum of the pressures
    result = minimize(
        lambda p: 0.5 * p @ compliance @ p + p @ depth,
        np.full(n, total / n),
        jac=lambda p: compliance @ p + depth,
        bounds=[(0.0, None)] * n,
        constraints=[{"type": "eq", "fun": lambda p: p.sum() - total, "jac": lambda p: np.ones(n)}],
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 2000},
    )
    contact = result.x > 1e-6 * total / n
    # the set's own equations: C_SS p_S + d_S = c on the set, sum p_S = total
    s = np.flatnonzero(contact)
    system = np.block([[compliance[np.ix_(s, s)], -np.ones((s.size, 1))], [np.ones((1, s.size)), np.zeros((1, 1))]])
    solution = np.linalg.solve(system, np.concatenate([-depth[s], [total]]))
    pressure = np.zeros(n)
    pressure[s] = solution[:-1]
    gap = compliance @ pressure + depth - solution[-1]
    scale = np.abs(depth).max()
    assert pressure.min() >= 0 and pressure[s].min() > 1e-9 * total / n, "a pressure in the set is not positive"
    assert gap.min() > -1e-9 * scale, "a gap outside the set is negative"
    assert np.abs(gap[s]).max() < 1e-9 * scale
    return contact


def rough(shape: tuple[int, ...], seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    modes = np.meshgrid(*(np.fft.fftfreq(n) * n for n in shape), indexing="ij")
    q = np.sqrt(sum(m**2 for m in modes))
    amplitude = np.where(q > 0, q, np.inf) ** -(1.0 + 0.8 + (len(shape) - 1) / 2)
    z = np.fft.ifftn(amplitude * np.exp(2j * np.pi * rng.random(q.shape))).real
    return z / z.std()


@pytest.mark.parametrize(
    ("solver", "shape", "dx", "seed"),
    [(BEMHalfSpace(youngs_modulus=2.0, poisson_ratio=0.3, tolerance=1e-12), (12, 12), 0.5, 1),
     (BEMHalfSpace(youngs_modulus=1.0, poisson_ratio=0.0, tolerance=1e-12), (10, 14), 1.0, 2),
     (BEMHalfPlane(youngs_modulus=3.0, poisson_ratio=0.5, tolerance=1e-12), (96,), 0.25, 1),
     (BEMHalfPlane(youngs_modulus=1.0, poisson_ratio=0.0, tolerance=1e-12), (80,), 1.0, 2),
     (BEMHalfSpaceFree(youngs_modulus=1.5, poisson_ratio=0.2, tolerance=1e-12), (11, 13), 0.5, 1),
     (BEMHalfSpaceFree(youngs_modulus=1.0, poisson_ratio=0.0, tolerance=1e-12), (12, 10), 1.0, 2)],
    ids=["surface-12x12", "surface-10x14", "line-96", "line-80", "free-11x13", "free-12x10"],
)  # fmt: skip
def test_the_contact_set_is_that_of_the_quadratic_programme(solver, shape, dx, seed):
    periodic = solver.name != "bem-halfspace-free"
    z = rough(shape, seed)
    slopes = np.random.default_rng(100 + seed).random(shape) + 0.5
    depth = (z.max() - z).ravel()
    compliance = (dense_compliance if periodic else dense_free_compliance)(shape, dx, solver.stiffness())
    area = dx ** len(shape)
    # the periodic body's full-contact load sets the scale: from a spot or two to about half the points
    periodic_twin = (BEMHalfSpace if len(shape) == 2 else BEMHalfPlane)(youngs_modulus=1.0, poisson_ratio=0.0)
    full = periodic_twin.full_contact_load(Profile(z, dx, periodic=True)) * solver.stiffness()
    forces = full * np.array([1e-4, 0.01, 0.05, 0.2])
    curve = solver.solve(Profile(z, dx, periodic=periodic), forces, "force", slopes)
    counts = []
    for j, force in enumerate(forces):
        contact = exact_contact(compliance, depth, force, area)
        counts.append(int(contact.sum()))
        assert curve.contact_count[j] == contact.sum(), f"load {j}"
        expected = np.sqrt(np.mean(np.square(slopes.ravel()[contact])))
        assert curve.slope_rms_contact[j] == pytest.approx(expected, rel=1e-12), f"load {j}"
    assert counts[0] < counts[-1] < depth.size  # the loads span partial contact
