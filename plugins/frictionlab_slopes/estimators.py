"""Pointwise slopes of a periodic rough line (SPEC section 4).

Every estimator maps heights of shape (N,) on a periodic grid of spacing dx to
an array of the same shape: the slope attributed to each point. The engine
forms both the whole-line rms slope and the rms over the points in contact from
it, so the two always use the same estimator.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from frictionlab import SlopeEstimator

__all__ = ["CentralDifference", "ForwardDifference", "Spectral"]


def _checked(heights, spacing, minimum: int) -> tuple[np.ndarray, float]:
    heights = np.asarray(heights, dtype=float)
    if heights.ndim != 1:
        raise ValueError(
            f"slope estimators take a line: heights must have shape (N,). Got shape {heights.shape} instead."
        )
    if heights.size < minimum:
        raise ValueError(
            f"a periodic line needs at least {minimum} points for a slope. Got {heights.size} instead."
        )
    spacing = float(spacing)
    if not (np.isfinite(spacing) and spacing > 0.0):
        raise ValueError(f"spacing must be finite and positive. Got {spacing!r} instead.")
    if not np.isfinite(heights).all():
        bad = int(np.flatnonzero(~np.isfinite(heights))[0])
        raise ValueError(f"heights must be finite: point {bad} is {heights[bad]!r}")
    return heights, spacing


class ForwardDifference(SlopeEstimator):
    name: ClassVar[str] = "forward-difference"
    summary: ClassVar[str] = "forward difference (z[i+1] - z[i]) / dx, periodic: the study's definition"

    def slopes(self, heights: np.ndarray, spacing: float) -> np.ndarray:
        z, dx = _checked(heights, spacing, 2)
        out = np.empty_like(z)
        np.subtract(z[1:], z[:-1], out=out[:-1])
        out[-1] = z[0] - z[-1]  # periodic wrap: z[N] = z[0]
        np.divide(out, dx, out=out)
        return out


class CentralDifference(SlopeEstimator):
    name: ClassVar[str] = "central-difference"
    summary: ClassVar[str] = "central difference (z[i+1] - z[i-1]) / (2 dx), periodic"

    def slopes(self, heights: np.ndarray, spacing: float) -> np.ndarray:
        z, dx = _checked(heights, spacing, 2)
        out = np.empty_like(z)
        np.subtract(z[2:], z[:-2], out=out[1:-1])
        out[0] = z[1] - z[-1]
        out[-1] = z[0] - z[-2]
        np.divide(out, 2.0 * dx, out=out)
        return out


class Spectral(SlopeEstimator):
    name: ClassVar[str] = "spectral"
    summary: ClassVar[str] = "spectral derivative by FFT (multiply by i q), Nyquist term dropped for even N"

    def slopes(self, heights: np.ndarray, spacing: float) -> np.ndarray:
        z, dx = _checked(heights, spacing, 2)
        points = z.size
        spectrum = np.fft.rfft(z)
        q = (2.0 * np.pi / (points * dx)) * np.arange(spectrum.size)
        spectrum *= 1j * q
        if points % 2 == 0:
            spectrum[-1] = 0.0  # the Nyquist mode's derivative is not real
        return np.fft.irfft(spectrum, n=points)
