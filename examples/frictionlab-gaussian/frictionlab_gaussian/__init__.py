"""frictionlab-gaussian: Gaussian-correlated random rough lines.

An example third-party frictionlab plugin (copy it to start your own). It adds
one spectrum generator, ``gaussian``, found by frictionlab through the entry
point ``gaussian`` in the group ``frictionlab`` (see ``pyproject.toml``).

The physics
-----------
A line with the Gaussian height autocorrelation

    <z(x) z(x + r)> = h^2 exp(-(r / xi)^2)

(h the rms height, xi the correlation length) has, in frictionlab's convention
for the one-sided 1D power spectral density, <z^2> = 2 * integral_0^inf C(q) dq,
i.e. C(q) = (1 / 2 pi) * integral of the autocorrelation times exp(-i q r) dr,

    C(q) = h^2 xi / (2 sqrt(pi)) * exp(-(q xi / 2)^2).

Check: 2 * integral_0^inf C dq = h^2 xi / sqrt(pi) * sqrt(pi) / xi = h^2.
Its rms slope is <z'^2>^(1/2) = (2 * integral_0^inf q^2 C dq)^(1/2) = sqrt(2) h / xi.

The line
--------
N points of spacing dx, periodic, wave vectors q_k = 2 pi k / L (L = N dx) for
k = 1 .. ceil(N/2) - 1 (the mean and the Nyquist mode are left out, so <z> = 0
and every mode is an exact sine on the grid):

    z(x) = sum_k a_k cos(q_k x + phi_k),   a_k proportional to sqrt(C(q_k)),

with phases phi_k uniform in [0, 2 pi) from the ``numpy.random.Generator`` the
engine passes in, and fixed amplitudes scaled so that sum_k a_k^2 / 2 = h^2:
the modes are orthogonal on the grid, so the rms of every generated line is
exactly ``rms_height`` (up to rounding). For dx << xi << L the sum over the
modes is spectrally accurate except for the missing q = 0 term, which held
C(0) 2 pi / L = h^2 sqrt(pi) xi / L of the variance; so

    a_k^2 = 4 C(q_k) (2 pi / L) / (1 - sqrt(pi) xi / L)

to high accuracy: the discrete line follows psd() up to that finite-size factor
(and so does its rms slope, sqrt(2) h / xi times the square root of the factor).
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

import frictionlab
from frictionlab import PluginParams, Profile, SpectrumGenerator

__version__ = "0.1.0"


class Gaussian(SpectrumGenerator):
    """Random line with a Gaussian autocorrelation, random phases, fixed amplitudes."""

    name = "gaussian"
    summary = "Gaussian-correlated random line: random phases, fixed amplitudes, exact rms height"
    references = ("10.1088/0953-8984/17/1/R01",)  # Persson et al. 2005, rough-surface spectra
    # What frictionlab may use besides generate() and rms_height() (see frictionlab.plugin):
    points_param = "points"  # named in memory advice ("spectrum.params.points <= ...")

    class Params(PluginParams):
        points: int = Field(1024, ge=8, le=2**24, description="Number of grid points N of the periodic line.")
        spacing: float = Field(1.0, gt=0, le=1e12, description="Grid spacing dx (length units).")
        correlation_length: float = Field(
            10.0, gt=0, le=1e12, description="Correlation length xi of <z(x)z(x+r)> = h^2 exp(-(r/xi)^2) (length units)."
        )
        rms_height: float = Field(1.0, gt=0, le=1e12, description="Rms height h of every generated line (length units).")

    # ------------------------------------------------------------ closed forms

    def psd(self, q):
        """One-sided 1D PSD C(q) = h^2 xi / (2 sqrt(pi)) exp(-(q xi / 2)^2), vectorised."""
        p = self.params
        q = np.asarray(q, dtype=float)
        return p.rms_height**2 * p.correlation_length / (2 * math.sqrt(math.pi)) * np.exp(
            -((q * p.correlation_length / 2) ** 2)
        )

    def rms_height(self) -> float:
        return float(self.params.rms_height)

    def rms_slope(self) -> float:
        """sqrt(2) h / xi, of the continuous spectrum (the discrete line approaches
        it for dx << xi << L)."""
        return math.sqrt(2.0) * self.params.rms_height / self.params.correlation_length

    # ------------------------------------------------------------ declarations

    def grid_shape(self) -> tuple[int, ...]:
        """The shape of every line, known without generating one (memory estimates)."""
        return (self.params.points,)

    def refined(self, points: int) -> dict:
        """The same line (length, correlation length) sampled on ``points`` points."""
        length = self.params.points * self.params.spacing
        return {"points": points, "spacing": length / points}

    # ------------------------------------------------------------ the line

    def amplitudes(self) -> tuple[np.ndarray, np.ndarray]:
        """Wave vectors q_k (k = 1 .. ceil(N/2) - 1) and fixed amplitudes a_k with
        sum a_k^2 / 2 = h^2."""
        p = self.params
        length = p.points * p.spacing
        k = np.arange(1, (p.points - 1) // 2 + 1)
        q = 2 * math.pi * k / length
        # C(q_k) relative to C(q_1), in log space: no underflow when xi >> L
        weight = np.exp(-((q**2 - q[0] ** 2) * p.correlation_length**2) / 4)
        amplitude = np.sqrt(weight)
        amplitude *= p.rms_height / math.sqrt(np.sum(amplitude**2) / 2)
        return q, amplitude

    def generate(self, rng: np.random.Generator) -> Profile:
        n = self.params.points
        _, amplitude = self.amplitudes()
        phases = rng.uniform(0.0, 2 * math.pi, size=amplitude.size)
        spectrum = np.zeros(n // 2 + 1, dtype=complex)
        spectrum[1 : amplitude.size + 1] = (n / 2) * amplitude * np.exp(1j * phases)
        heights = np.fft.irfft(spectrum, n=n)  # = sum_k a_k cos(q_k x + phi_k)
        return Profile(heights=heights, spacing=float(self.params.spacing))


@frictionlab.hookimpl
def register_spectra(register):
    register(Gaussian)
