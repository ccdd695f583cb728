"""Tests of the built-in spectrum generators (random lines from a spectrum).

Expected values come from the definitions, never from a previous run:
psd convention <z^2> = 2 * integral psd dq, mode k of amplitude a_k = 2 sqrt(psd(q_k) dq),
q_k = 2 pi k / L, dq = 2 pi / L. The tests rebuild the mode sums from ``psd`` (not from
the generator's internal amplitude array), measure lines with their own FFTs, and check
the closed-form moments against numerical quadrature.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from pydantic import ValidationError
from scipy.integrate import quad

from frictionlab import Profile
from frictionlab.plugin.registry import validate_plugin_class
from frictionlab_spectra import PowerLaw, ProfileFile, Rolloff

TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------- helpers


def grid(gen):
    """(N, dx, L) from the parameters alone, with the documented defaults."""
    p = gen.params
    n = p.points
    if p.spacing is not None:
        dx = p.spacing
    elif p.length is not None:
        dx = p.length / n
    else:
        dx = 1.0
    return n, dx, n * dx


def modes(gen):
    """q_k and the variance 2 psd(q_k) dq of every grid mode the psd says is in the band."""
    n, dx, length = grid(gen)
    q = TWO_PI / length * np.arange(1, n // 2 + 1)
    w = 2.0 * gen.psd(q) * (TWO_PI / length)
    inside = w > 0
    return q[inside], w[inside]


def rms(z):
    return float(np.sqrt(np.mean(np.square(z))))


def spectral_derivative(z, dx):
    n = z.size
    q = TWO_PI / (n * dx) * np.arange(n // 2 + 1)
    zq = np.fft.rfft(z) * (1j * q)
    if n % 2 == 0:
        zq[-1] = 0.0  # the Nyquist mode has no grid derivative
    return np.fft.irfft(zq, n=n)


def continuum_moment(gen, order):
    """2 * integral q^order psd dq by adaptive quadrature (in ln q, split at the knee)."""
    q, _ = modes(gen)
    b = gen.band
    edges = sorted({b.q_min, b.q_knee, b.q_max})

    def integrand(t):
        qq = math.exp(t)
        return qq ** (order + 1) * float(gen.psd(qq))

    total = 0.0
    for lo, hi in zip(edges[:-1], edges[1:]):
        # stay a hair inside the edges: psd is zero outside the band
        val, _ = quad(integrand, math.log(lo) + 1e-13, math.log(hi) - 1e-13, epsabs=0, epsrel=1e-11, limit=200)
        total += val
    return 2.0 * total


# ---------------------------------------------------------------- contract


@pytest.mark.parametrize("cls", [PowerLaw, Rolloff, ProfileFile])
def test_plugin_contract(cls):
    validate_plugin_class("spectrum", cls)
    for name, info in cls.Params.model_fields.items():
        assert info.description, name
        annotation = str(info.annotation)
        if "float" in annotation or "int" in annotation:
            bounds = [m for m in info.metadata if type(m).__name__ in {"Ge", "Gt", "Le", "Lt"}]
            bounds += re.findall(r"\b(?:Ge|Gt|Le|Lt)\(", annotation)  # a bounded number inside a union (channel)
            assert bounds, f"{cls.__name__}.Params.{name} has no numeric bounds"


def test_constructor_computes_nothing_and_an_edit_recomputes():
    gen = PowerLaw(hurst=0.8, points=1000)
    assert set(vars(gen)) == {"params"}  # the constructor only stores parameters
    first = gen.generate(np.random.default_rng(0)).heights
    assert set(vars(gen)) == {"params", "_cached__synthesis"}
    gen.params.hurst = 0.5  # edited in place, as the TUI does: the synthesis follows
    assert not np.array_equal(gen.generate(np.random.default_rng(0)).heights, first)
    assert np.array_equal(PowerLaw(hurst=0.5, points=1000).generate(np.random.default_rng(0)).heights,
                          gen.generate(np.random.default_rng(0)).heights)  # fmt: skip


# ---------------------------------------------------------------- exact properties of fixed amplitudes

FIXED_CASES = [
    (PowerLaw, dict(hurst=0.8, points=4096)),
    (PowerLaw, dict(hurst=0.3, points=1001, short_cutoff=2.0)),  # odd N, band to the top
    (PowerLaw, dict(hurst=1.0, points=1024, short_cutoff=2.0)),  # Nyquist mode kept
    (PowerLaw, dict(hurst=0.5, points=2000, spacing=0.01, c0=3.0, short_cutoff=0.05, long_cutoff=5.0)),
    (PowerLaw, dict(hurst=0.0, points=777, length=3.5, rms_height=2.5e-6)),
    (Rolloff, dict(hurst=0.7, points=4096, rolloff_wavelength=512.0, rms_height=4.0)),
    (Rolloff, dict(hurst=1.2, points=4096, rolloff_wavelength=30.0, short_cutoff=2.0, c0=1e-3)),
]


@pytest.mark.parametrize(("cls", "kwargs"), FIXED_CASES)
def test_fixed_line_is_exact(cls, kwargs):
    gen = cls(**kwargs)
    n, dx, length = grid(gen)
    q, w = modes(gen)
    h_sum = math.sqrt(w.sum())  # sum_k a_k^2 / 2 with a_k^2 / 2 = 2 psd dq = w
    assert gen.rms_height() == pytest.approx(h_sum, rel=1e-12)
    if kwargs.get("c0") is None:
        assert gen.rms_height() == pytest.approx(kwargs.get("rms_height", 1.0), rel=1e-14)

    profile = gen.generate(np.random.default_rng(7))
    z = profile.heights
    assert z.dtype == np.float64 and z.shape == (n,)
    assert profile.spacing == pytest.approx(dx, rel=1e-15)
    assert rms(z) == pytest.approx(gen.rms_height(), rel=1e-12)
    assert abs(z.mean()) <= 1e-12 * gen.rms_height()

    # every mode has exactly the modulus the psd asks for: |Z_k| = N a_k / 2, Nyquist N a_k / sqrt(2)
    zq = np.abs(np.fft.rfft(z))
    k = np.rint(q * length / TWO_PI).astype(int)
    a = np.sqrt(2.0 * w)
    expected = n * a / 2.0
    if n % 2 == 0 and k[-1] == n // 2:
        expected[-1] = n * a[-1] / math.sqrt(2.0)
    np.testing.assert_allclose(zq[k], expected, rtol=1e-10)
    outside = np.ones(zq.size, bool)
    outside[k] = False
    assert np.all(zq[outside] <= 1e-10 * expected.max())

    again = gen.generate(np.random.default_rng(7)).heights
    other = gen.generate(np.random.default_rng(8)).heights
    assert np.array_equal(z, again)
    assert not np.allclose(z, other)


def test_nyquist_only_band():
    # N = 8, short cut-off 2 dx, long cut-off 2 dx would be empty; L/4 keeps k = 4 = N/2 only
    gen = PowerLaw(hurst=0.5, points=8, long_cutoff=2.0 + 1e-12, short_cutoff=2.0)
    signs = set()
    for seed in range(20):
        z = gen.generate(np.random.default_rng(seed)).heights
        np.testing.assert_allclose(z, z[0] * (-1.0) ** np.arange(8), rtol=1e-14)
        assert abs(z[0]) == pytest.approx(1.0, rel=1e-14)  # variance a^2/2 = h^2 from one real mode
        signs.add(np.sign(z[0]))
    assert signs == {-1.0, 1.0}


# ---------------------------------------------------------------- moments: discrete identities and continuum


@pytest.mark.parametrize("hurst", [0.3, 0.8, 1.0])
def test_moments_of_a_long_line(hurst):
    # N = 1e5, L = 1e5: the band is k = 64 .. 10000, both cut-offs exactly on modes
    n = 100_000
    gen = PowerLaw(hurst=hurst, points=n, long_cutoff=n / 64, c0=1.0)
    q, w = modes(gen)
    dq = TWO_PI / n
    assert q[0] == pytest.approx(64 * dq) and q[-1] == pytest.approx(10_000 * dq)
    z = gen.generate(np.random.default_rng(1)).heights

    # discrete identities: exact up to rounding
    assert np.mean(z**2) == pytest.approx(w.sum(), rel=1e-11)
    slope = spectral_derivative(z, 1.0)
    assert np.mean(slope**2) == pytest.approx(np.sum(q**2 * w), rel=1e-10)
    assert gen.rms_slope_discrete() ** 2 == pytest.approx(np.sum(q**2 * w), rel=1e-12)
    forward = np.roll(z, -1) - z  # periodic forward difference, dx = 1
    modified = (2.0 * np.sin(q / 2.0)) ** 2  # modified wavenumber of the forward difference
    assert np.mean(forward**2) == pytest.approx(np.sum(modified * w), rel=1e-10)

    # continuum: with f = 2 q^order psd, the mode sum is sum_k f(q_k) dq over k = 64 .. 10000,
    # both end points included, so by Euler-Maclaurin
    #   sum = integral + dq (f(q_a) + f(q_b)) / 2 + dq^2 (f'(q_b) - f'(q_a)) / 12 + ...
    # The first-order term is 0.5 % to 1.6 % at order 0 here; after removing it the remainder
    # is about (2H+1)(2H) / (12 * 64^2) <= 1.3e-4 relative, so 5e-4 separates right from wrong.
    for order, closed in ((0, gen.rms_height_continuum() ** 2), (2, gen.rms_slope() ** 2)):
        f = q**order * w / dq  # = 2 q^order psd(q)
        corrected = np.sum(f * dq) - 0.5 * dq * (f[0] + f[-1])
        assert closed == pytest.approx(corrected, rel=5e-4)
        if order == 0:  # the test is sharp enough to see the end-point correction
            assert abs(closed / np.sum(f * dq) - 1) > 4e-3


@pytest.mark.parametrize("hurst", [0.0, 0.3, 0.5, 0.999999, 1.0, 1.3, 1.5])
@pytest.mark.parametrize("cls", [PowerLaw, Rolloff])
def test_closed_forms_match_quadrature(cls, hurst):
    kwargs = dict(hurst=hurst, points=50_000, spacing=0.3, long_cutoff=9000.0, short_cutoff=0.9)
    if cls is Rolloff:
        kwargs["rolloff_wavelength"] = 700.0
    gen = cls(**kwargs)
    assert gen.rms_height_continuum() ** 2 == pytest.approx(continuum_moment(gen, 0), rel=1e-8)
    assert gen.rms_slope() ** 2 == pytest.approx(continuum_moment(gen, 2), rel=1e-8)


def test_log_cases_are_continuous():
    def pair(h):
        return PowerLaw(hurst=h, points=10**6)
    for exact, near in ((1.0, 0.999999), (0.0, 1e-7)):
        a, b = pair(exact), pair(near)
        assert a.rms_slope() == pytest.approx(b.rms_slope(), rel=1e-5)
        assert a.rms_height_continuum() == pytest.approx(b.rms_height_continuum(), rel=1e-5)
        assert a.c0() == pytest.approx(b.c0(), rel=1e-4)


# ---------------------------------------------------------------- spectra of ensembles


def fit_loglog(q, p):
    x, y = np.log(q), np.log(p)
    slope, _ = np.polyfit(x, y, 1)
    return slope, x


@pytest.mark.parametrize("hurst", [0.3, 0.8, 1.0])
@pytest.mark.parametrize("amplitudes", ["fixed", "rayleigh"])
def test_psd_exponent_recovered(hurst, amplitudes):
    n, lines = 4096, 200
    gen = PowerLaw(hurst=hurst, points=n, amplitudes=amplitudes, rms_height=3.0)
    q, _ = modes(gen)
    k = np.rint(q * n / TWO_PI).astype(int)
    rng = np.random.default_rng(11)
    power = np.zeros(k.size)
    for _ in range(lines):
        power += np.abs(np.fft.rfft(gen.generate(rng).heights)[k]) ** 2
    # |Z_k|^2 = N^2 a_k^2 / 4 = N^2 psd dq
    estimate = power / lines / (n**2 * TWO_PI / n)
    slope, x = fit_loglog(q, estimate)
    ratio = estimate / gen.psd(q)
    if amplitudes == "fixed":
        assert slope == pytest.approx(-2 * hurst - 1, abs=1e-9)
        np.testing.assert_allclose(ratio, 1.0, rtol=1e-9)
    else:
        # each mode's power is exponential: the mean of M has relative sd 1/sqrt(M), so the log
        # has sd ~ 1/sqrt(M); least-squares slope sd = that / sqrt(sum (x - xbar)^2). 6 sigma.
        sigma = 1.0 / math.sqrt(lines) / math.sqrt(np.sum((x - x.mean()) ** 2))
        assert slope == pytest.approx(-2 * hurst - 1, abs=6 * sigma)
        assert ratio.mean() == pytest.approx(1.0, abs=6 / math.sqrt(lines * k.size))


@pytest.mark.parametrize("hurst", [0.3, 0.8])
def test_rayleigh_mean_square(hurst):
    n, lines = 1024, 4000
    gen = PowerLaw(hurst=hurst, points=n, amplitudes="rayleigh", rms_height=0.2)
    _, w = modes(gen)
    assert gen.rms_height() ** 2 == pytest.approx(w.sum(), rel=1e-12)
    rng = np.random.default_rng(5)
    ms = np.array([np.mean(gen.generate(rng).heights ** 2) for _ in range(lines)])
    # mode powers are independent exponentials of mean w_k: var(ms) = sum w_k^2. 5 sigma.
    sigma = math.sqrt(np.sum(w**2) / lines)
    assert ms.mean() == pytest.approx(gen.rms_height() ** 2, abs=5 * sigma)
    assert ms.std() > 0.1 * gen.rms_height() ** 2  # really random amplitudes


@pytest.mark.parametrize("amplitudes", ["fixed", "rayleigh"])
def test_phase_and_modulus_distributions(amplitudes):
    # pooled over modes and lines: phases uniform on [0, 2 pi); modulus^2 / expectation is 1
    # (fixed) or a unit exponential (Rayleigh). Kolmogorov-Smirnov at a 1e-4 level: seeded,
    # so a pass is reproducible, and a wrong distribution over 8000 samples fails by far.
    from scipy import stats

    n, lines = 400, 200
    gen = PowerLaw(hurst=0.7, points=n, amplitudes=amplitudes)
    q, w = modes(gen)
    k = np.rint(q * n / TWO_PI).astype(int)
    rng = np.random.default_rng(21)
    zq = np.array([np.fft.rfft(gen.generate(rng).heights)[k] for _ in range(lines)])
    phases = np.mod(np.angle(zq), TWO_PI).ravel()
    assert stats.kstest(phases / TWO_PI, "uniform").pvalue > 1e-4
    power = (np.abs(zq) ** 2 / (n**2 * w / 2)).ravel()  # |Z_k|^2 / (N^2 a_k^2 / 4)
    if amplitudes == "fixed":
        np.testing.assert_allclose(power, 1.0, rtol=1e-10)
    else:
        assert stats.kstest(power, "expon").pvalue > 1e-4


# ---------------------------------------------------------------- rolloff


@pytest.mark.parametrize("hurst", [0.4, 1.0])
def test_rolloff_psd_shape(hurst):
    gen = Rolloff(hurst=hurst, points=8192, rolloff_wavelength=256.0, c0=2.0)
    q_min, q_r, q_max = TWO_PI / 8192, TWO_PI / 256.0, TWO_PI / 10.0
    flat = gen.psd(np.linspace(q_min, q_r * (1 - 1e-9), 50))
    np.testing.assert_allclose(flat, 2.0 * q_r ** (-2 * hurst - 1), rtol=1e-12)
    assert gen.psd(q_r * (1 - 1e-12)) == pytest.approx(gen.psd(q_r), rel=1e-9)
    above = np.geomspace(q_r, q_max, 30)
    np.testing.assert_allclose(gen.psd(above), 2.0 * above ** (-2 * hurst - 1), rtol=1e-12)
    assert np.all(gen.psd(np.array([0.0, q_min * 0.99, q_max * 1.01, 10.0])) == 0.0)

    # discrete and continuum moments, as for the power law
    q, w = modes(gen)
    z = gen.generate(np.random.default_rng(3)).heights
    assert np.mean(z**2) == pytest.approx(w.sum(), rel=1e-11)
    assert gen.rms_slope_discrete() ** 2 == pytest.approx(np.sum(q**2 * w), rel=1e-12)
    assert gen.rms_height_continuum() ** 2 == pytest.approx(continuum_moment(gen, 0), rel=1e-8)


def test_rolloff_at_long_cutoff_is_power_law():
    common = dict(hurst=0.8, points=4096, rms_height=1.5)
    a = PowerLaw(**common).generate(np.random.default_rng(2)).heights
    b = Rolloff(**common, rolloff_wavelength=4096.0).generate(np.random.default_rng(2)).heights
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-13)


# ---------------------------------------------------------------- validation


def _error(cls, **kwargs) -> str:
    with pytest.raises(ValidationError) as info:
        cls(**kwargs)
    return str(info.value)


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        (dict(hurst=-0.1), ["hurst"]),
        (dict(hurst=1.6), ["hurst"]),
        (dict(points=7), ["points"]),
        (dict(spacing=0.0), ["spacing"]),
        (dict(length=-3.0), ["length"]),
        (dict(rms_height=0.0), ["rms_height"]),
        (dict(c0=-1.0), ["c0"]),
        (dict(amplitudes="gaussian"), ["amplitudes"]),
        (dict(long_cutoff=0.0), ["long_cutoff"]),
        (dict(colour="red"), ["colour"]),
        (dict(spacing=1.0, length=500.0), ["spacing", "length"]),
        (dict(long_cutoff=1001.0), ["long_cutoff", "length"]),
        (dict(short_cutoff=1.9), ["short_cutoff", "Nyquist"]),
        (dict(short_cutoff=50.0, long_cutoff=40.0), ["short_cutoff", "long_cutoff"]),
        (dict(rms_height=1.0, c0=1.0), ["rms_height", "c0"]),
        (dict(long_cutoff=300.0, short_cutoff=260.0), ["no mode", "short_cutoff", "long_cutoff"]),
    ],
)
def test_power_law_rejects(kwargs, words):
    message = _error(PowerLaw, **{"hurst": 0.8, "points": 1000, **kwargs})
    for word in words:
        assert word in message


def test_default_cutoffs_named_when_they_clash():
    message = _error(PowerLaw, hurst=0.8, points=8)  # default short cut-off 10 dx > L = 8
    assert "short_cutoff (default" in message and "long_cutoff (default" in message


def test_rolloff_rejects():
    assert "rolloff_wavelength" in _error(Rolloff, hurst=0.8, points=1000)
    assert "rolloff_wavelength" in _error(Rolloff, hurst=0.8, points=1000, rolloff_wavelength=5.0)
    assert "rolloff_wavelength" in _error(Rolloff, hurst=0.8, points=1000, rolloff_wavelength=2000.0)
    with pytest.raises(TypeError):
        Rolloff(PowerLaw.Params(hurst=0.8, points=1000))


def test_consistent_spacing_and_length_accepted():
    gen = PowerLaw(hurst=0.8, points=1000, spacing=0.1, length=100.0)
    assert gen.generate(np.random.default_rng(0)).spacing == pytest.approx(0.1)


def test_params_edited_in_place():
    gen = PowerLaw(hurst=0.8, points=1000)
    before = gen.generate(np.random.default_rng(0)).heights
    gen.params.rms_height = 2.0
    after = gen.generate(np.random.default_rng(0)).heights
    np.testing.assert_allclose(after, 2.0 * before, rtol=1e-13, atol=1e-14)
    with pytest.raises(ValidationError, match="hurst"):
        gen.params.hurst = 3.0


# ---------------------------------------------------------------- scaling (exact scaling laws)


@pytest.mark.parametrize("amplitudes", ["fixed", "rayleigh"])
def test_height_scaling(amplitudes):
    base = dict(hurst=0.6, points=3000, amplitudes=amplitudes)
    z1 = PowerLaw(**base, rms_height=1.3).generate(np.random.default_rng(4)).heights
    for s in (1e-9, 7.0, 1e9):
        zs = PowerLaw(**base, rms_height=1.3 * s).generate(np.random.default_rng(4)).heights
        np.testing.assert_allclose(zs, s * z1, rtol=1e-12, atol=1e-13 * s)
    c1 = PowerLaw(**base, c0=0.5).generate(np.random.default_rng(4)).heights
    c4 = PowerLaw(**base, c0=2.0).generate(np.random.default_rng(4)).heights
    np.testing.assert_allclose(c4, 2.0 * c1, rtol=1e-12, atol=1e-13 * np.abs(c1).max())


def test_line_depends_on_cutoffs_in_units_of_dx_only():
    base = dict(hurst=0.9, points=2048, rms_height=1.0)
    z1 = PowerLaw(**base, spacing=1.0, short_cutoff=4.0).generate(np.random.default_rng(9)).heights
    z2 = PowerLaw(**base, spacing=1e-6, short_cutoff=4e-6).generate(np.random.default_rng(9)).heights
    np.testing.assert_allclose(z2, z1, rtol=1e-10, atol=1e-13)


# ---------------------------------------------------------------- extremes


@pytest.mark.parametrize("points", [8, 9, 10**6])
@pytest.mark.parametrize("hurst", [0.0, 0.01, 0.05, 0.999999, 1.0, 1.5])
def test_extremes(hurst, points):
    kwargs = dict(hurst=hurst, points=points)
    if points < 20:
        kwargs["short_cutoff"] = 2.0
    for h in (1e-12, 1.0, 1e12):
        gen = PowerLaw(**kwargs, rms_height=h)
        z = gen.generate(np.random.default_rng(0)).heights
        assert np.all(np.isfinite(z))
        assert rms(z) == pytest.approx(h, rel=1e-12)
        assert abs(z.mean()) <= 1e-12 * h
        for value in (gen.rms_slope(), gen.rms_height_continuum(), gen.rms_slope_discrete()):
            assert math.isfinite(value) and value > 0
    # tiny q_min (huge L) with C0 given: amplitudes formed relative to q_min, no overflow
    gen = PowerLaw(**{**kwargs, "short_cutoff": kwargs.get("short_cutoff", 10.0) * 1e9}, spacing=1e9, c0=1e-60)
    z = gen.generate(np.random.default_rng(0)).heights
    assert np.all(np.isfinite(z)) and rms(z) == pytest.approx(gen.rms_height(), rel=1e-12)


def test_psd_vectorised_and_quiet():
    gen = PowerLaw(hurst=1.5, points=1000)
    with np.errstate(all="raise"):
        out = gen.psd(np.array([[0.0, 1e-300], [0.1, np.inf]]))
    assert out.shape == (2, 2) and out[0, 0] == 0.0 and out[0, 1] == 0.0 and out[1, 1] == 0.0
    assert out[1, 0] > 0
    assert isinstance(gen.psd(0.1), float)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    hurst=st.floats(0.0, 1.5),
    points=st.integers(8, 3000),
    short=st.floats(2.0, 40.0),
    long_fraction=st.floats(0.01, 1.0),
    amplitudes=st.sampled_from(["fixed", "rayleigh"]),
    seed=st.integers(0, 2**32 - 1),
)
def test_random_bands(hurst, points, short, long_fraction, amplitudes, seed):
    try:
        gen = PowerLaw(
            hurst=hurst, points=points, short_cutoff=short, long_cutoff=long_fraction * points, amplitudes=amplitudes
        )
    except ValidationError:
        assume(False)
    q, w = modes(gen)
    assert q.size >= 1
    z = gen.generate(np.random.default_rng(seed)).heights
    assert np.all(np.isfinite(z)) and abs(z.mean()) <= 1e-12
    if amplitudes == "fixed":
        assert rms(z) == pytest.approx(1.0, rel=1e-12)
    assert math.sqrt(w.sum()) == pytest.approx(1.0, rel=1e-12)


# ---------------------------------------------------------------- profile-file


def _bumpy(n=64):
    i = np.arange(n)
    return 0.3 * np.sin(TWO_PI * 3 * i / n) + 0.1 * np.cos(TWO_PI * 7 * i / n) + 0.05 * (i % 5)


# kind -> (file name, writer(path, x, z), spacing parameter, dtype stored)
PROFILE_FORMATS = {
    "csv1": ("a.csv", lambda p, x, z: np.savetxt(p, z), 0.25, np.float64),
    "csv2": ("a.csv", lambda p, x, z: np.savetxt(p, np.column_stack([x, z]), delimiter=","), None, np.float64),
    "csv-header": (
        "a.csv",
        lambda p, x, z: np.savetxt(p, np.column_stack([x, z]), delimiter=", ", header="x, z", comments=""),
        None,
        np.float64,
    ),
    "txt1": ("a.txt", lambda p, x, z: np.savetxt(p, z, header="profilometer scan"), 0.25, np.float64),
    "txt2": ("a.txt", lambda p, x, z: np.savetxt(p, np.column_stack([x, z]), delimiter="\t"), None, np.float64),
    "npy1": ("a.npy", lambda p, x, z: np.save(p, z), 0.25, np.float64),
    "npy2xN": ("a.npy", lambda p, x, z: np.save(p, np.vstack([x, z])), None, np.float64),
    "npyNx2": ("a.npy", lambda p, x, z: np.save(p, np.column_stack([x, z])), None, np.float64),
    "npy32": ("a.npy", lambda p, x, z: np.save(p, z), 0.25, np.float32),
}


# ------------------------------------------------------------------ the cosine series


@pytest.mark.parametrize("amplitudes", ["fixed", "rayleigh"])
def test_cosine_series_has_the_covariance_of_q_k_pi_over_l(amplitudes):
    """The study's eq. 6 read literally: z = sum_k a_k cos(k pi x / L + phi_k), k = 1 .. N / 10, on
    [0, L). Over random phases its covariance is sum_k a_k^2 / 2 cos(k pi (x - x') / L), with
    a_k = 2 sqrt(psd(q_k) dq), dq = pi / L, scaled to sum a_k^2 / 2 = h^2: measured over 2000 lines."""
    n, dx, h = 200, 0.5, 2.0
    gen = PowerLaw(hurst=0.8, points=n, spacing=dx, rms_height=h, series="cosine", short_cutoff=20 * dx,
                   amplitudes=amplitudes)  # fmt: skip
    assert gen.periodic() is False and (gen.band.k_lo, gen.band.k_hi) == (1, n // 10)
    length = n * dx
    q = np.arange(1, n // 10 + 1) * np.pi / length
    np.testing.assert_allclose(gen.wavevectors(), q, rtol=1e-14)
    power = gen.psd(q) * np.pi / length  # a_k^2 / 4
    power *= h**2 / (2 * power.sum())  # sum a_k^2 / 2 = h^2
    lines = np.array([gen.generate(np.random.default_rng(seed)).heights for seed in range(2000)])
    assert not gen.generate(np.random.default_rng(0)).periodic
    for lag in (0, n // 4, n // 2, 3 * n // 4):
        measured = np.mean(lines[:, : n - lag] * lines[:, lag:])
        expected = np.sum(2 * power * np.cos(q * lag * dx))
        assert measured == pytest.approx(expected, abs=0.05 * h**2), lag
    assert gen.rms_height() == pytest.approx(h, rel=1e-14)


@pytest.mark.parametrize("series,hurst", [("cosine", 1.0), ("cosine", 0.5), ("fft", 0.8)])
def test_measured_height_reference_makes_each_lines_own_rms_h(series, hurst):
    """height_reference: measured: every line, brute force sum((z - mean z)^2) / N, has rms h about its
    own mean and mean zero; it is the nominal line of the same seed shifted and scaled (so the same
    shape, slopes in proportion); profile_rms_height is that rms. The nominal cosine lines scatter."""
    h = 3.0
    common = {"hurst": hurst, "points": 1000, "rms_height": h, "series": series}
    measured, nominal = PowerLaw(**common, height_reference="measured"), PowerLaw(**common)
    assert nominal.profile_rms_height(nominal.generate(np.random.default_rng(0))) is None
    own = []
    for seed in range(20):
        z = measured.generate(np.random.default_rng(seed)).heights
        mean = sum(float(v) for v in z) / z.size
        rms = math.sqrt(sum((float(v) - mean) ** 2 for v in z) / z.size)
        assert rms == pytest.approx(h, rel=1e-12) and abs(mean) < 1e-12 * h
        assert measured.profile_rms_height(Profile(z, 1.0, False)) == pytest.approx(rms, rel=1e-12)
        base = nominal.generate(np.random.default_rng(seed)).heights
        own.append(np.std(base))
        np.testing.assert_allclose(z, (base - base.mean()) * (h / np.std(base)), rtol=0, atol=1e-12 * h)
    if series == "cosine":  # the nominal lines' own rms heights scatter about (and below) h
        assert np.std(own) > 0.05 * h and np.mean(own) < h
    else:  # a periodic fixed-amplitude line has rms h exactly: measured changes nothing but rounding
        np.testing.assert_allclose(own, h, rtol=1e-12)


def test_measured_h_forms_f_and_keeps_the_contact_scaling(tmp_path):
    """Runs of the cosine series with h measured: f = F / (E* h L) with each line's own rms h; the
    springs are linear, so a line scaled by s = h / rms touches at force F as the nominal line
    (rms rms) does at F / s: the contact counts follow from the nominal run's lines by that law."""
    from frictionlab.compute import engine
    from frictionlab.options import RunOptions
    from frictionlab.preset import build_scene
    from frictionlab.preset.seeds import realization_rng
    from frictionlab_solvers import MDRSprings

    h, loads = 2.0, np.geomspace(0.01, 3.0, 7)
    data = {
        "name": "measured", "seed": 5, "realizations": 6, "fit": {"bootstrap": 0}, "output": {"plot": False},
        "spectrum": {"name": "power-law", "params": {"hurst": 1.0, "points": 2048, "rms_height": h,
                                                     "series": "cosine", "height_reference": "measured"}},
        "solver": {"name": "mdr"}, "loading": {"start": 0.01, "stop": 3.0, "steps": 7, "spacing": "log"},
    }  # fmt: skip
    scene = build_scene(data)
    outcome = engine.run(scene, RunOptions(workers=1))
    assert outcome.own_rms_height and outcome.rms_height == pytest.approx(h, rel=1e-12)
    np.testing.assert_allclose(outcome.f, loads / (1.0 * h * 2048), rtol=1e-12)  # E* = 1, L = 2048
    np.testing.assert_allclose(outcome.per_realization["measured_rms_height"], h, rtol=1e-12)
    nominal = PowerLaw(**{**data["spectrum"]["params"], "height_reference": "nominal"})
    for row, index in enumerate(outcome.indices):
        line = nominal.generate(realization_rng(5, int(index)))
        s = h / np.std(line.heights)
        slopes = np.gradient(line.heights)  # any slopes: only the counts are compared
        counts = MDRSprings().solve(line, loads / s, "force", slopes).contact_count
        np.testing.assert_array_equal(outcome.per_realization["contact_count"][row], counts)


@pytest.mark.parametrize("reference", ["nominal", "measured"])
def test_the_summary_says_which_h_and_gives_the_lines_measured_rms(tmp_path, reference):
    """summary.json: which h formed f, and the mean and spread of the lines' own rms heights,
    against the lines regenerated from their seeds and measured by brute force."""
    import json

    from frictionlab.options import RunOptions
    from frictionlab.preset import build_scene
    from frictionlab.runs.runner import run_to_folder
    from frictionlab.preset.seeds import realization_rng

    params = {"hurst": 1.0, "points": 1024, "rms_height": 2.0, "series": "cosine", "height_reference": reference}
    data = {
        "name": "heights", "seed": 9, "realizations": 8, "fit": {"bootstrap": 0}, "output": {"plot": False},
        "spectrum": {"name": "power-law", "params": params}, "solver": {"name": "mdr"},
        "loading": {"start": 0.1, "stop": 3.0, "steps": 4, "spacing": "log"},
    }  # fmt: skip
    run_to_folder(build_scene(data), tmp_path / "run", RunOptions(workers=1))
    heights = json.loads((tmp_path / "run" / "summary.json").read_text())["heights"]
    lines = [PowerLaw(**params).generate(realization_rng(9, i)).heights for i in range(8)]
    rms = [math.sqrt(sum((float(v) - sum(map(float, z)) / z.size) ** 2 for v in z) / z.size) for z in lines]
    assert heights["measured_rms_height"]["lines"] == 8
    assert heights["measured_rms_height"]["mean"] == pytest.approx(np.mean(rms), rel=1e-12)
    assert heights["measured_rms_height"]["std"] == pytest.approx(np.std(rms, ddof=1), rel=1e-6, abs=1e-12)
    assert heights["h"] == pytest.approx(2.0, rel=1e-12)
    if reference == "nominal":
        assert heights["h_in_f"] == "the spectrum's nominal rms height"
        assert heights["measured_rms_height"]["std"] > 0.05
    else:
        assert heights["h_in_f"] == "each line's own rms height about its mean"
        assert heights["measured_rms_height"]["std"] < 1e-12


def test_cosine_series_long_cutoff_is_twice_the_length():
    gen = PowerLaw(hurst=1.0, points=100, series="cosine")
    assert gen.band.long_cutoff == 200.0 and gen.band.k_lo == 1 and gen.band.period == 200.0
    with pytest.raises(ValidationError, match=r"long_cutoff=300.0 must not exceed the period of the cosine "
                                              r"series 2 L = 2 \* points \* spacing = 200.0"):
        PowerLaw(hurst=1.0, points=100, series="cosine", long_cutoff=300.0)
    with pytest.raises(ValidationError, match="series"):
        PowerLaw(hurst=1.0, points=100, series="sine")



@pytest.mark.parametrize("kind", PROFILE_FORMATS)
def test_profile_file_formats(tmp_path, kind):
    file_name, write, spacing, dtype = PROFILE_FORMATS[kind]
    z = (_bumpy() + 5.0).astype(dtype)
    x = 0.25 * np.arange(z.size) + 10.0
    path = tmp_path / file_name
    write(path, x, z)
    gen = ProfileFile(path=str(path), spacing=spacing)
    profile = gen.generate(np.random.default_rng(0))
    expected = z.astype(np.float64) - z.astype(np.float64).mean()
    assert profile.heights.dtype == np.float64
    assert profile.spacing == pytest.approx(0.25, rel=1e-12)
    np.testing.assert_allclose(profile.heights, expected, rtol=0, atol=1e-12)
    assert gen.rms_height() == pytest.approx(rms(expected), rel=1e-12)
    # deterministic: the same line whatever the rng
    assert np.array_equal(gen.generate(np.random.default_rng(99)).heights, profile.heights)


def test_profile_file_detrend(tmp_path):
    n = 64
    i = np.arange(n, dtype=float)
    raw = _bumpy(n) + 2.0 + 0.03 * i
    path = tmp_path / "p.npy"
    np.save(path, raw)
    none = ProfileFile(path=str(path), spacing=1.0, detrend="none").generate(None).heights
    np.testing.assert_array_equal(none, raw)
    mean = ProfileFile(path=str(path), spacing=1.0, detrend="mean").generate(None).heights
    np.testing.assert_allclose(mean, raw - raw.mean(), atol=1e-14)
    gen = ProfileFile(path=str(path), spacing=1.0, detrend="tilt")
    tilt = gen.generate(None).heights
    # least squares: residual has zero mean, is orthogonal to the index, and raw - residual is a line
    assert abs(tilt.mean()) < 1e-14
    assert abs(np.dot(i - i.mean(), tilt)) < 1e-10
    np.testing.assert_allclose(np.diff(raw - tilt, 2), 0.0, atol=1e-13)
    assert gen.rms_height() == pytest.approx(rms(tilt), rel=1e-12)
    assert ProfileFile(path=str(path), spacing=1.0, detrend="none").rms_height() == pytest.approx(np.std(raw))
    # the cache follows in-place edits
    gen.params.detrend = "mean"
    np.testing.assert_allclose(gen.generate(None).heights, mean)


def test_profile_file_returns_a_copy(tmp_path):
    path = tmp_path / "p.npy"
    np.save(path, _bumpy())
    gen = ProfileFile(path=str(path), spacing=1.0)
    first = gen.generate(None).heights
    first[:] = 0.0
    assert np.any(gen.generate(None).heights != 0.0)


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def _profile_error(**kwargs) -> str:
    gen = ProfileFile(**kwargs)  # construction reads nothing
    with pytest.raises(ValueError) as info:
        gen.generate(np.random.default_rng(0))
    message = str(info.value)
    assert kwargs["path"].split("/")[-1] in message
    return message


def test_profile_file_errors(tmp_path):
    heights = "\n".join(str(v) for v in _bumpy(16))
    assert "no such file" in _profile_error(path=str(tmp_path / "missing.csv"), spacing=1.0)

    bad = _bumpy(16).astype(str)
    bad[3], bad[7], bad[9] = "nan", "inf", "NaN"
    message = _profile_error(path=_write(tmp_path, "nan.csv", "\n".join(bad)), spacing=1.0)
    assert "3 value(s) in heights not finite" in message and "line 4, column 1 of the file" in message
    huge = _bumpy(16).astype(str)
    huge[2], huge[5] = "1e308", "-1e200"  # finite, but their squares are not: refused before any arithmetic
    message = _profile_error(path=_write(tmp_path, "huge.csv", "\n".join(huge)), spacing=1.0)
    assert "2 value(s) in heights not finite (NaN or inf) or beyond 1e+100 in magnitude, the first at line 3, column 1 of the file" in message

    x = np.arange(16.0)
    x[5] += 0.3
    text = "\n".join(f"{a},{b}" for a, b in zip(x, _bumpy(16)))
    message = _profile_error(path=_write(tmp_path, "xbad.csv", text))
    assert "not uniformly spaced" in message and "max deviation" in message and "0.3" in message

    message = _profile_error(path=_write(tmp_path, "short.txt", "1\n2\n3\n4\n5\n6\n7\n"), spacing=1.0)
    assert "7 points" in message and "8" in message

    message = _profile_error(path=_write(tmp_path, "text.csv", heights.replace("\n", "\nabc\n", 1)), spacing=1.0)
    assert "non-numeric content at line 2" in message and "abc" not in message  # named, never quoted

    message = _profile_error(path=_write(tmp_path, "flat.txt", "\n".join(["2.5"] * 20)), spacing=1.0)
    assert "constant" in message
    linear = "\n".join(str(0.1 * k + 3) for k in range(20))
    assert "constant" in _profile_error(path=_write(tmp_path, "line.txt", linear), spacing=1.0, detrend="tilt")

    assert "spacing is required" in _profile_error(path=_write(tmp_path, "h.txt", heights))

    text = "\n".join(f"{0.5 * k},{v}" for k, v in enumerate(_bumpy(16)))
    message = _profile_error(path=_write(tmp_path, "xz.csv", text), spacing=0.4)
    assert "spacing=0.4" in message and "0.5" in message


def test_profile_file_x_spacing_beyond_a_presets_range_is_refused(tmp_path):
    """x in range but spaced by 1e-200: the slopes (1e200) would square to inf in every realization."""
    text = "\n".join(f"{1e-200 * k},{v}" for k, v in enumerate(_bumpy(16)))
    message = _profile_error(path=_write(tmp_path, "xtiny.csv", text))
    assert "x spaced by 1e-200" in message and "between 1e-100 and 1e+100" in message
    assert "np.float64" not in _profile_error(path=_write(tmp_path, "xbad.csv", "0,1\n1,2\n2,0\n3,4\n4,1\n5,3\n7,2\n8,5"))

    assert "3 columns" in _profile_error(path=_write(tmp_path, "wide.txt", "1 2 3\n" * 10))
    noise = tmp_path / "p.opd"
    noise.write_bytes(bytes(range(256)) * 4)
    assert "its suffix .opd names Wyko OPD, but its first bytes are not that format's" in \
        _profile_error(path=str(noise), spacing=1.0)
    path = tmp_path / "cube.npy"
    np.save(path, np.zeros((3, 4, 5)))
    assert "shape" in _profile_error(path=str(path), spacing=1.0)
    path = tmp_path / "str.npy"
    np.save(path, np.array(["a"] * 10))
    assert "non-numeric" in _profile_error(path=str(path), spacing=1.0)


def test_profile_file_params():
    assert "detrend" in str(pytest.raises(ValidationError, ProfileFile, path="a.csv", detrend="plane").value)
    assert "spacing" in str(pytest.raises(ValidationError, ProfileFile, path="a.csv", spacing=0.0).value)
    assert "path" in str(pytest.raises(ValidationError, ProfileFile).value)
