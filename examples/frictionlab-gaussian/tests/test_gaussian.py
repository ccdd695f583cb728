"""Tests of the example plugin: frictionlab's conformance checks, then the physics
against closed forms.

The fixtures ``frictionlab_registry`` and ``register_plugin`` come from the
pytest plugin ``frictionlab.testing``, active wherever frictionlab is installed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from frictionlab.testing import check_plugin, check_spectrum

import frictionlab_gaussian
from frictionlab_gaussian import Gaussian

PARAMS = [
    {},
    {"points": 8},
    {"points": 1001, "spacing": 0.25, "correlation_length": 2.0, "rms_height": 3e-6},
    {"points": 64, "correlation_length": 1e4},  # xi >> L: still a valid, finite line
]


@pytest.mark.parametrize("params", PARAMS, ids=str)
def test_conformance(params):
    check_plugin("spectrum", Gaussian, **params)


def test_the_checks_can_fail():
    class Frozen(Gaussian):
        def generate(self, rng):  # ignores the seed
            return super().generate(np.random.default_rng(0))

    with pytest.raises(AssertionError, match="different seeds gave identical heights"):
        check_spectrum(Frozen)


def test_registered_through_the_hook(register_plugin):
    registry = register_plugin(frictionlab_gaussian)
    assert registry.get("spectrum", "Gaussian") is Gaussian
    assert "gaussian" in registry.names("spectrum")


def test_not_registered_without_discovery(frictionlab_registry):
    assert "gaussian" not in frictionlab_registry.names("spectrum")


@pytest.mark.parametrize("xi,h", [(0.5, 1.0), (10.0, 2.5), (300.0, 1e-3)])
def test_psd_normalisation(xi, h):
    """<z^2> = 2 * integral_0^inf C(q) dq = h^2 and <z'^2> = 2 * integral q^2 C = rms_slope^2."""
    gen = Gaussian(correlation_length=xi, rms_height=h)
    upper = 40 / xi  # exp(-400): the rest is nothing
    variance = 2 * integrate.quad(gen.psd, 0, upper, epsabs=0, epsrel=1e-12)[0]
    slope2 = 2 * integrate.quad(lambda q: q**2 * gen.psd(q), 0, upper, epsabs=0, epsrel=1e-12)[0]
    assert variance == pytest.approx(h**2, rel=1e-9)
    assert math.sqrt(slope2) == pytest.approx(gen.rms_slope(), rel=1e-9)
    assert gen.rms_slope() == pytest.approx(math.sqrt(2) * h / xi)


def test_psd_is_vectorised():
    gen = Gaussian()
    q = np.linspace(0, 2, 12).reshape(3, 4)
    assert gen.psd(q).shape == (3, 4)
    assert gen.psd(0.0) == pytest.approx(gen.params.correlation_length / (2 * math.sqrt(math.pi)))


@pytest.mark.parametrize("points", [8, 9, 1024, 1025])
def test_rms_is_exact_and_mean_zero(points):
    gen = Gaussian(points=points, correlation_length=3.0, rms_height=2.5)
    for seed in range(5):
        z = gen.generate(np.random.default_rng(seed)).heights
        assert z.shape == (points,)
        assert abs(z.mean()) < 1e-12
        assert np.sqrt(np.mean(z**2)) == pytest.approx(2.5, rel=1e-12)


def test_line_follows_the_psd():
    """For dx << xi << L each mode carries 4 C(q_k) dq / (1 - sqrt(pi) xi / L)."""
    n, dx, xi, h = 4096, 0.5, 6.0, 1.7
    gen = Gaussian(points=n, spacing=dx, correlation_length=xi, rms_height=h)
    length = n * dx
    z = gen.generate(np.random.default_rng(3)).heights
    spectrum = np.fft.rfft(z)
    k = np.arange(1, n // 2)
    q = 2 * np.pi * k / length
    a2 = (2 * np.abs(spectrum[k]) / n) ** 2
    expected = 4 * gen.psd(q) * (2 * np.pi / length) / (1 - math.sqrt(math.pi) * xi / length)
    strong = expected > 1e-6 * expected.max()
    np.testing.assert_allclose(a2[strong], expected[strong], rtol=1e-9)
    assert spectrum[0] == pytest.approx(0, abs=1e-9)


def test_rms_slope_of_the_line():
    n, dx, xi = 4096, 0.5, 6.0
    gen = Gaussian(points=n, spacing=dx, correlation_length=xi)
    z = gen.generate(np.random.default_rng(11)).heights
    q = 2 * np.pi * np.fft.rfftfreq(n, dx)
    slope = np.fft.irfft(1j * q * np.fft.rfft(z), n=n)
    finite_size = 1 / math.sqrt(1 - math.sqrt(math.pi) * xi / (n * dx))
    assert np.sqrt(np.mean(slope**2)) == pytest.approx(gen.rms_slope() * finite_size, rel=1e-9)


def test_phases_come_from_the_rng():
    gen = Gaussian(points=256)
    a = gen.generate(np.random.default_rng(5)).heights
    b = gen.generate(np.random.default_rng(5)).heights
    c = gen.generate(np.random.default_rng(6)).heights
    assert np.array_equal(a, b)
    assert not np.allclose(a, c)


def test_huge_correlation_length_does_not_underflow():
    z = Gaussian(points=64, correlation_length=1e9).generate(np.random.default_rng(0)).heights
    assert np.all(np.isfinite(z))
    assert np.sqrt(np.mean(z**2)) == pytest.approx(1.0, rel=1e-12)
