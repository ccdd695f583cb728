"""The periodic elastic operator the contact CG works on, against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab_solvers.elastic import PeriodicHalfSpace, effective_modulus


@pytest.mark.parametrize("shape", [(64,), (24, 40)])
def test_a_single_wave_is_displaced_by_two_over_q(shape):
    """A pressure cos(q.x) displaces the surface by (2 / |q|) cos(q.x) (E* = 1, pixels)."""
    grids = np.meshgrid(*[np.arange(n) for n in shape], indexing="ij")
    modes = (3, 5)[: len(shape)]
    phase = sum(2 * np.pi * m * g / n for m, g, n in zip(modes, grids, shape))
    q = np.sqrt(sum((2 * np.pi * m / n) ** 2 for m, n in zip(modes, shape)))
    pressure = np.cos(phase)
    operator = PeriodicHalfSpace(shape)
    out = np.empty(shape)
    np.testing.assert_allclose(operator.displacement(pressure, out), 2 / q * pressure, atol=1e-12)
    np.testing.assert_allclose(operator.precondition(pressure, out), q / 2 * pressure, atol=1e-6)
    np.testing.assert_allclose(operator.displacement_estimate(pressure, out), 2 / q * pressure, atol=2e-6 * 2 / q)
    np.testing.assert_allclose(operator.pressure_of(2 / q * pressure), pressure, atol=1e-12)


def test_a_uniform_pressure_moves_nothing_and_the_preconditioner_inverts_the_rest():
    rng = np.random.default_rng(4)
    shape = (32, 48)
    operator = PeriodicHalfSpace(shape)
    assert np.allclose(operator.displacement(np.full(shape, 3.0), np.empty(shape)), 0.0, atol=1e-12)
    field = rng.normal(size=shape)
    field -= field.mean()
    back = operator.precondition(operator.displacement(field, np.empty(shape)), np.empty(shape))
    np.testing.assert_allclose(back, field, atol=1e-5 * np.abs(field).max())


def test_point_stiffness_is_the_inverse_of_the_displacement_under_a_unit_point_pressure():
    shape = (16, 16)
    operator = PeriodicHalfSpace(shape)
    point = np.zeros(shape)
    point[0, 0] = 1.0
    u = operator.displacement(point, np.empty(shape))
    assert operator.point_stiffness == pytest.approx(1.0 / u[0, 0], rel=1e-12)
    # by symmetry the point's own displacement is the largest
    assert u[0, 0] == u.max()


def test_effective_modulus():
    assert effective_modulus(2.0, 0.5) == pytest.approx(2.0 / 0.75)
    with pytest.raises(ValueError, match="poisson_ratio"):
        effective_modulus(1.0, 1.0)


def test_displacement_single_of_a_float32_grid_is_the_displacement_in_single_precision():
    shape = (24, 40)
    grids = np.meshgrid(*[np.arange(n) for n in shape], indexing="ij")
    pressure = np.cos(2 * np.pi * (3 * grids[0] / 24 + 5 * grids[1] / 40))
    q = np.hypot(2 * np.pi * 3 / 24, 2 * np.pi * 5 / 40)
    u = PeriodicHalfSpace(shape).displacement_single(pressure.astype(np.float32))
    assert u.dtype == np.float32
    np.testing.assert_allclose(u, 2 / q * pressure, atol=2e-6 * 2 / q)


@pytest.mark.parametrize("stop", ["certified", "tolerance"])
def test_the_cg_on_float32_grids_of_its_sets_solves_as_on_float64_grids_converted_whole(monkeypatch, stop):
    """The CG spreads its direction and its lift on float32 grids over their sets alone
    (``displacement_single``); an operator without it has the CG convert float64 grids
    whole. The arithmetic is the same, so the sweeps agree: contact sets, iterations,
    pressures."""
    from frictionlab.preset.seeds import realization_rng
    from frictionlab_solvers import bem
    from frictionlab_spectra.surface import PowerLawSurface

    calls = {"single": 0, "whole": 0}

    class Counting(PeriodicHalfSpace):
        def displacement_single(self, pressure32):
            calls["single"] += 1
            return super().displacement_single(pressure32)

    class WholeGrids(PeriodicHalfSpace):
        displacement_single = None

        def displacement_estimate(self, pressure, out):
            calls["whole"] += 1
            return super().displacement_estimate(pressure, out)

    profile = PowerLawSurface(hurst=0.8, points=96, spacing=1.0, short_cutoff=6.0, rms_height=1.0).generate(
        realization_rng(11, 0)
    )
    forces = np.geomspace(1.0, 60.0, 6)
    curves = {}
    for name, operator in (("single", Counting), ("whole", WholeGrids)):
        monkeypatch.setattr(bem, "PeriodicHalfSpace", operator)
        curves[name] = bem.BEMHalfSpace(stop=stop).solve(profile, forces, "force", np.ones_like(profile.heights))
    assert calls["single"] > 0 and calls["whole"] > 0  # each path ran
    single, whole = curves["single"], curves["whole"]
    np.testing.assert_array_equal(single.contact_count, whole.contact_count)
    np.testing.assert_array_equal(single.extras["iterations"], whole.extras["iterations"])
    np.testing.assert_allclose(single.indentation, whole.indentation, rtol=1e-12, atol=0)
