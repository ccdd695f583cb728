"""Warm-started sweeps of the boundary-element solvers equal independent cold solves.

A sweep starts each load from the previous load's pressure. That start must never
change the answer: every load of a sweep is compared here with the same load
solved alone from the solver's cold start, under both controls, on lines and
surfaces, including scenes on which warm starts used to freeze (the CG carried
its search direction over a contact-set change with a factor of 1e30).
"""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab import Profile
from frictionlab.preset.seeds import realization_rng
from frictionlab_solvers import BEMHalfPlane, BEMHalfSpace
from frictionlab_spectra.surface import PowerLawSurface


def forward_slopes(z):
    return np.diff(z, append=z[:1])


def assert_sweep_equals_cold_solves(solver, profile, loads, control, slopes):
    sweep = solver.solve(profile, loads, control, slopes)
    for j, load in enumerate(loads):
        cold = solver.solve(profile, np.array([load]), control, slopes)
        assert cold.contact_count[0] == sweep.contact_count[j], f"load {j}"
        assert cold.slope_rms_contact[0] == pytest.approx(sweep.slope_rms_contact[j], rel=1e-12)
        # both within the residual tolerance 1e-8 of the rms height: the outputs agree far closer than 1e-6;
        # the certified stop (force control) leaves the indentation within about 1e-5
        rel = 1e-4 if solver.params.stop == "certified" and control == "force" else 1e-6
        assert cold.force[0] == pytest.approx(sweep.force[j], rel=rel)
        assert cold.indentation[0] == pytest.approx(sweep.indentation[j], rel=rel)
    return sweep


def test_indentation_sweeps_on_equivalent_lines_of_surfaces_converge():
    """Issue scene: MDR-equivalent lines of 128 x 128 power-law-2d surfaces, H = 0.8,
    eight indentations from 0.05 to 1. Ten realizations, six of which used to freeze
    the warm-started sweep at residuals of 1e-4 to 1e-2."""
    line = PowerLawSurface(hurst=0.8, points=128, spacing=1.0).equivalent_line()
    solver = BEMHalfPlane(max_iterations=2000)
    indentations = np.linspace(0.05, 1.0, 8)
    froze = [(0, 4), (0, 15), (0, 17), (1, 16), (1, 36), (1, 37)]
    for seed, index in froze + [(0, 0), (0, 1), (1, 0), (1, 1)]:
        profile = line.generate(realization_rng(seed, index))
        z = profile.heights
        assert z.size == line.params.points and z.max() - z.mean() > 1.0  # all below full contact
        sweep = assert_sweep_equals_cold_solves(solver, profile, indentations, "indentation", forward_slopes(z))
        assert np.all(np.diff(sweep.force) > 0)


@pytest.mark.parametrize("control", ["indentation", "force"])
def test_surface_sweeps_converge_where_they_used_to_freeze(control):
    """A 32 x 32 surface whose warm indentation sweep used to freeze at load 1."""
    spectrum = PowerLawSurface(hurst=0.8, points=32, spacing=1.0, short_cutoff=4.0)
    profile = spectrum.generate(realization_rng(5, 19))
    z = profile.heights
    loads = np.linspace(0.05, 1.0, 8) if control == "indentation" else np.geomspace(0.5, 60, 8)
    loads = loads[loads < z.max() - z.mean()] if control == "indentation" else loads
    assert loads.size >= 5
    assert_sweep_equals_cold_solves(BEMHalfSpace(max_iterations=3000), profile, loads, control, np.ones_like(z))


@pytest.mark.parametrize("control", ["indentation", "force"])
def test_clipped_profile_with_two_plateaus(control):
    """A rough line clipped from above and below: two long flat plateaus at the top
    (hundreds of points touching at once) and a flat valley floor."""
    rng = np.random.default_rng(7)
    k = np.arange(1, 513)
    spectrum = np.zeros(513, complex)
    spectrum[1:] = k**-1.3 * (k <= 100) * np.exp(2j * np.pi * rng.random(512))
    z = np.fft.irfft(spectrum, n=1024)
    z /= z.std()
    top = np.sort(z)[-300]
    z = np.clip(z, np.quantile(z, 0.1), top)
    plateau = z == top
    runs = np.diff(np.flatnonzero(np.diff(np.concatenate([[0], plateau.astype(int), [0]]))))[::2]
    assert np.sort(runs)[-2:].min() >= 40  # at least two long plateaus on top
    profile = Profile(z, 1.0)
    if control == "indentation":
        loads = np.linspace(0.02, 0.8, 7) * (z.max() - z.mean())
    else:
        loads = np.geomspace(1.0, 300.0, 7)
    sweep = assert_sweep_equals_cold_solves(BEMHalfPlane(), profile, loads, control, forward_slopes(z))
    assert sweep.contact_count[0] >= plateau.sum()  # the plateaus touch first, all at once
