"""The boundary-element solvers against an independent textbook solver and a known law.

* Polonsky and Keer's (1999) constrained conjugate gradient, written out here in its
  original form (no preconditioner, no single precision, no warm start): the pressure
  that carries the mean pressure, with the gap g = u(p) - z closed to one level on the
  contact and open elsewhere. Driven to a gap spread of 1e-13 of the rms height, it
  gives the contact set, xi and the approach (the level, from the first touch to the
  mean elastic surface, the solvers' reference). frictionlab's solvers, run as a
  warm-started sweep with the tolerance stop, must find the same set and the same
  approach to their own tolerance.
* Small loads on the half-space: the real area grows in proportion to the load,
  A / A0 = kappa p / (E* g), g the rms gradient. kappa lies between Persson's sqrt(8/pi)
  = 1.60 and the vanishing-load limit of Bush, Gibson and Thomas sqrt(2 pi) = 2.51, and
  simulations of broad spectra at 1-5 % contact find about 2 to 2.3 (Hyun et al. 2004;
  Yastrebov, Anciaux and Molinari 2017). Here the surface spans a 64-fold band (4 to 256
  pixels), the area is the perimeter-corrected one, and g the spectral rms gradient: the
  bounds are those of the literature, widened for two finite surfaces.
"""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab import Profile
from frictionlab_slopes import ForwardDifference, Spectral
from frictionlab_solvers import BEMHalfPlane, BEMHalfSpace
from frictionlab_spectra import PowerLaw, PowerLawSurface

BUSH = np.sqrt(2 * np.pi)
PERSSON = np.sqrt(8 / np.pi)


def polonsky_keer(z: np.ndarray, dx: float, e_star: float, mean_pressure: float, spread: float = 1e-13):
    """(contact mask, approach) of the rigid profile ``z`` on the periodic elastic body
    (half-plane for a line, half-space for a surface), u_q = 2 p_q / (E* |q|)."""
    q = np.sqrt(sum(np.square(g) for g in np.meshgrid(
        *(2 * np.pi * np.fft.fftfreq(n, dx) for n in z.shape), indexing="ij")))  # fmt: skip
    compliance = np.divide(2.0, e_star * q, out=np.zeros_like(q), where=q > 0)

    def displacement(p):
        return np.real(np.fft.ifftn(np.fft.fftn(p) * compliance))

    p = np.full(z.shape, mean_pressure)
    t = np.zeros(z.shape)
    delta, g_old = 0.0, 1.0
    for _ in range(2000):
        contact = p > 0
        gap = displacement(p) - z
        gap -= gap[contact].mean()
        if np.ptp(gap[contact]) < spread * z.std() and gap[~contact].min(initial=np.inf) >= 0:
            return contact, z.max() - np.mean((z - displacement(p))[contact])  # in contact z - u = the level
        g_norm = np.sum(gap[contact] ** 2)
        t = np.where(contact, gap + delta * g_norm / g_old * t, 0.0)
        g_old = g_norm
        r = displacement(t)
        r -= r[contact].mean()
        tau = np.sum(gap[contact] * t[contact]) / np.sum(r[contact] * t[contact])
        p = np.maximum(p - tau * t, 0.0)
        overlap = (p == 0) & (gap < 0)
        delta = 0.0 if overlap.any() else 1.0
        p[overlap] -= tau * gap[overlap]
        p *= mean_pressure / p.mean()
    raise AssertionError("the reference solver did not converge")


@pytest.mark.parametrize(
    "solver, spectrum, forces",
    [
        (BEMHalfSpace, PowerLawSurface(hurst=0.8, points=64, spacing=0.5, rms_height=2.0), (0.3, 2.0, 8.0, 30.0)),
        (BEMHalfPlane, PowerLaw(hurst=0.6, points=1024, spacing=0.25, rms_height=0.3), (0.01, 0.05, 0.2, 0.6)),
    ],
)
def test_a_sweep_finds_the_textbook_solvers_contact_set_and_approach(solver, spectrum, forces):
    profile = spectrum.generate(np.random.default_rng(3))
    z, dx = profile.heights, profile.spacing
    slopes = ForwardDifference().slopes(z, dx)
    bem = solver(youngs_modulus=2.0, poisson_ratio=0.3, tolerance=1e-11, stop="tolerance")
    e_star = bem.stiffness()
    curve = bem.solve(profile, np.array(forces), "force", slopes)
    area = z.size * dx**z.ndim
    for j, force in enumerate(forces):
        contact, approach = polonsky_keer(z, dx, e_star, force / area)
        assert 0 < contact.sum() < z.size  # partial contact: the sets say something
        assert curve.contact_count[j] == contact.sum()
        assert curve.slope_rms_contact[j] == pytest.approx(np.sqrt(np.mean(slopes[contact] ** 2)), rel=1e-12)
        # the level's error is at most the largest gap error, tolerance x rms height
        assert curve.indentation[j] == pytest.approx(approach, abs=1e-10 * z.std())


def test_small_load_area_is_proportional_to_load_with_a_kappa_of_the_literature():
    spectrum = PowerLawSurface(hurst=0.8, points=256, spacing=1.0, rms_height=1.0, short_cutoff=4.0)
    ratios = np.array([0.01, 0.02])  # p / (E* g): 2-5 % contact
    kappas = []
    for seed in (0, 1):
        profile = spectrum.generate(np.random.default_rng(seed))
        slopes = Spectral().slopes(profile.heights, 1.0)
        g = np.sqrt(np.mean(slopes**2))
        solver = BEMHalfSpace(youngs_modulus=1.0, poisson_ratio=0.0)
        curve = solver.solve(profile, ratios * g * profile.heights.size, "force", slopes)
        kappas.append(curve.real_area_corrected / ratios)
    kappa = np.mean(kappas, axis=0)
    assert np.all((1.9 < kappa) & (kappa < 2.45)), kappa
    assert np.all((PERSSON < np.ravel(kappas)) & (np.ravel(kappas) < BUSH))
    assert kappa[1] == pytest.approx(kappa[0], rel=0.1)  # linear in the load, to a slow drift
