"""Pointwise slopes of a rough line or surface.

Every estimator maps heights of shape (N,) on a grid of spacing dx to an array
of the same shape: the slope attributed to each point. The engine forms both the
whole-line rms slope and the rms over the points in contact from it, so the two
always use the same estimator.

On a periodic profile the differences wrap around (the last point's forward
neighbour is the first). On a non-periodic one (a measured scan, whose ends do
not meet) they never do: the jump from the last point to the first is not a
slope. There the end points take the one-sided difference of the segment they
end (``numpy.gradient``'s first-order edges): the forward difference of the last
point is the slope of the last segment, and the central difference of either
end is that of its own segment. Every point keeps a slope, so a contact at an
end of the scan still has one; the last segment counts twice in the whole-line
rms, a bias of order 1/N. With ``line_end: undefined`` an end point that has no
neighbour on the estimator's side (the last point for forward differences, both
ends for central ones) gets no slope instead (NaN): the study's slope read
literally, defined only where z(x_{i+1}) exists. Such a point then counts neither
in the whole-line rms nor in the rms over the contact. The spectral derivative
needs a periodic profile and refuses any other.

On a surface, shape (Ny, Nx) with square pixels, the slope of a pixel is the
gradient magnitude |grad z| = sqrt(dz/dx^2 + dz/dy^2), each component formed
with the estimator's own scheme along its axis; the rms over all pixels is then
the rms gradient of the surface. Lines keep their signed slopes (and their
original, unchanged code path).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar, Literal

import numpy as np
from pydantic import Field

from frictionlab import PluginParams, SlopeEstimator

__all__ = ["CentralDifference", "ForwardDifference", "Spectral"]


def _checked(heights, spacing, minimum: int) -> tuple[np.ndarray, float]:
    heights = np.asarray(heights, dtype=float)
    if heights.ndim not in (1, 2):
        raise ValueError(
            "slope estimators take a line or a surface: heights must have shape (N,) or (Ny, Nx). "
            f"Got shape {heights.shape} instead."
        )
    if min(heights.shape) < minimum:
        what = "line" if heights.ndim == 1 else "surface (along each axis)"
        raise ValueError(
            f"a {what} needs at least {minimum} points for a slope. Got shape {heights.shape} instead."
        )
    spacing = float(spacing)
    if not (np.isfinite(spacing) and spacing > 0.0):
        raise ValueError(f"spacing must be finite and positive. Got {spacing!r} instead.")
    if not np.isfinite(heights).all():
        bad = np.unravel_index(int(np.flatnonzero(~np.isfinite(heights))[0]), heights.shape)
        where = bad[0] if heights.ndim == 1 else tuple(int(i) for i in bad)
        raise ValueError(f"heights must be finite: point {where} is {heights[bad]!r}")
    return heights, spacing


def _gradient_magnitude(z: np.ndarray, dx: float, derivative: Callable[..., np.ndarray], periodic: bool, *extra):
    """|grad z| of a surface from a derivative along one axis (NaN where a component is undefined)."""
    along_x = derivative(z, dx, 1, periodic, *extra)
    along_y = derivative(z, dx, 0, periodic, *extra)
    return np.hypot(along_x, along_y, out=along_x)


def _along(ndim: int, axis: int, index: int) -> tuple:
    """The index of the slice ``index`` along ``axis`` of an ``ndim``-dimensional array."""
    where = [slice(None)] * ndim
    where[axis] = index
    return tuple(where)


def _forward(z: np.ndarray, dx: float, axis: int, periodic: bool = True, undefined_end: bool = False) -> np.ndarray:
    out = (np.roll(z, -1, axis=axis) - z) / dx
    if not periodic:  # the last point: no slope, or the last segment's; never the wrap
        last = _along(z.ndim, axis, -1)
        out[last] = np.nan if undefined_end else out[_along(z.ndim, axis, -2)]
    return out


def _central(z: np.ndarray, dx: float, axis: int, periodic: bool = True, undefined_end: bool = False) -> np.ndarray:
    if not periodic:
        out = np.gradient(z, dx, axis=axis, edge_order=1)
        if undefined_end:  # both ends lack a neighbour on one side
            out[_along(z.ndim, axis, 0)] = np.nan
            out[_along(z.ndim, axis, -1)] = np.nan
        return out
    return (np.roll(z, -1, axis=axis) - np.roll(z, 1, axis=axis)) / (2.0 * dx)


def _spectral(z: np.ndarray, dx: float, axis: int, periodic: bool = True) -> np.ndarray:
    points = z.shape[axis]
    spectrum = np.fft.rfft(z, axis=axis)
    q = (2.0 * np.pi / (points * dx)) * np.arange(spectrum.shape[axis])
    if points % 2 == 0:
        q[-1] = 0.0  # the Nyquist mode's derivative is not real
    spectrum *= 1j * np.expand_dims(q, 1 - axis)
    return np.fft.irfft(spectrum, n=points, axis=axis)


class LineEndParams(PluginParams):
    """The choice at the ends of a non-periodic profile (a periodic one wraps and has no end)."""

    line_end: Literal["last-segment", "undefined"] = Field(
        "last-segment",
        description="an end point of a non-periodic profile without a neighbour on the difference's side: "
        "'last-segment' gives it the one-sided slope of its own segment; 'undefined' gives it no slope (NaN), "
        "so it counts in no rms and a contact made of such points alone has no xi",
    )


class _EndAwareDifference(SlopeEstimator):
    """A finite difference whose ends, on a non-periodic profile, follow ``line_end`` (not registered)."""

    Params = LineEndParams

    def undefined_points(self, periodic: bool) -> bool:
        """True on a non-periodic profile with ``line_end: undefined``."""
        return not periodic and self.params.line_end == "undefined"


class ForwardDifference(_EndAwareDifference):
    name: ClassVar[str] = "forward-difference"
    summary: ClassVar[str] = (
        "forward difference (z[i+1] - z[i]) / dx: the study's definition; |grad z| on a surface"
    )
    dimensions: ClassVar[tuple[int, ...]] = (1, 2)

    def slopes(self, heights: np.ndarray, spacing: float, periodic: bool = True) -> np.ndarray:
        z, dx = _checked(heights, spacing, 2)
        undefined = self.undefined_points(periodic)
        if z.ndim == 2:
            return _gradient_magnitude(z, dx, _forward, periodic, undefined)
        out = np.empty_like(z)
        np.subtract(z[1:], z[:-1], out=out[:-1])
        # periodic: z[N] = z[0]; otherwise the last point has no forward neighbour: no slope, or its segment's
        out[-1] = z[0] - z[-1] if periodic else (np.nan if undefined else out[-2])
        np.divide(out, dx, out=out)
        return out


class CentralDifference(_EndAwareDifference):
    name: ClassVar[str] = "central-difference"
    summary: ClassVar[str] = "central difference (z[i+1] - z[i-1]) / (2 dx); one-sided at the ends of a scan; |grad z| on a surface"
    dimensions: ClassVar[tuple[int, ...]] = (1, 2)

    def slopes(self, heights: np.ndarray, spacing: float, periodic: bool = True) -> np.ndarray:
        z, dx = _checked(heights, spacing, 2)
        undefined = self.undefined_points(periodic)
        if z.ndim == 2:
            return _gradient_magnitude(z, dx, _central, periodic, undefined)
        if not periodic:
            return _central(z, dx, 0, False, undefined)
        out = np.empty_like(z)
        np.subtract(z[2:], z[:-2], out=out[1:-1])
        out[0] = z[1] - z[-1]
        out[-1] = z[0] - z[-2]
        np.divide(out, 2.0 * dx, out=out)
        return out


class Spectral(SlopeEstimator):
    name: ClassVar[str] = "spectral"
    summary: ClassVar[str] = (
        "spectral derivative by FFT (multiply by i q), Nyquist term dropped for even N; |grad z| on a surface"
    )
    dimensions: ClassVar[tuple[int, ...]] = (1, 2)
    periodic_only: ClassVar[bool] = True

    def slopes(self, heights: np.ndarray, spacing: float, periodic: bool = True) -> np.ndarray:
        if not periodic:
            raise ValueError(
                "spectral slopes need a periodic profile: this one's ends do not meet, and the jump between "
                "them would spread over every slope. Use forward-difference or central-difference."
            )
        z, dx = _checked(heights, spacing, 2)
        if z.ndim == 2:
            return _gradient_magnitude(z, dx, _spectral, True)
        points = z.size
        spectrum = np.fft.rfft(z)
        q = (2.0 * np.pi / (points * dx)) * np.arange(spectrum.size)
        spectrum *= 1j * q
        if points % 2 == 0:
            spectrum[-1] = 0.0  # the Nyquist mode's derivative is not real
        return np.fft.irfft(spectrum, n=points)
