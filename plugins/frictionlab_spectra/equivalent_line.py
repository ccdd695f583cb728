"""The MDR-equivalent line of a surface: one implementation for every surface spectrum.

MDR (Popov and Hess; Geike and Popov for random surfaces) replaces the contact of an
isotropic rough surface of apparent area A with an elastic half-space by a line of
length L = 2 sqrt(A / pi) pressed into independent springs, whose 1D spectrum is
C1D(q) = pi q C2D(q). With frictionlab's normalisations (<z^2> = 2 integral C1D dq on a
line, = 2 pi integral q C2D dq on a surface) each line mode, q_k = 2 pi k / L with
width dq = 2 pi / L, then carries the power of the annulus of the surface's spectrum
around q_k, and the line keeps the surface's mean square height and mean square
gradient.

On the grids both spectra are discrete. ``line_mode_powers`` gives each mode of the
surface (power P at wave number |q|) to the two line modes that bracket it,
q_k <= |q| < q_(k+1), in shares linear in q^2 ((q_(k+1)^2 - |q|^2) / (q_(k+1)^2 - q_k^2)
to k, the rest to k + 1). The shares keep both sums exactly: sum P (the mean square
height) and sum |q|^2 P (the mean square gradient), whatever the surface's grid. Two
kinds of modes cannot be split so: one below the first line mode (|q| < 2 pi / L,
possible only on a map more elongated than 4 : pi) goes whole to k = 1, and one past
the line's Nyquist mode (the corners of a measured map's q plane, |q| up to
sqrt(2) pi / dx) is left out; the line is scaled to the surface's rms height either way.

The line has N = ceil(L / dx) points of spacing L / N <= dx (``line_grid``), so its
length is exactly 2 sqrt(A / pi) and it carries every wave the surface's grid does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
from pydantic import Field, model_validator

from frictionlab import PluginParams, Profile, SpectrumGenerator, mdr_length

from .params_cache import cached_on_params
from .power_law import TWO_PI, line_coefficients, random_phase_line

MDR_BOOK = "10.1007/978-3-642-53876-6"  # Popov & Hess, Method of Dimensionality Reduction
GEIKE_POPOV_2007 = "10.1103/PhysRevE.76.036710"  # MDR mapping of a random rough surface
MIN_POINTS = 8


def line_grid(area: float, spacing: float) -> tuple[int, float]:
    """(N, spacing) of the MDR line of a surface of apparent area ``area`` and pixel side
    ``spacing``: N = ceil(L / dx) points of spacing L / N, L = 2 sqrt(A / pi)."""
    length = mdr_length(area)
    points = max(MIN_POINTS, math.ceil(length / spacing * (1 - 1e-12)))
    return points, length / points


def line_mode_powers(wavenumber: np.ndarray, power: np.ndarray, points: int, spacing: float) -> np.ndarray:
    """The power of each mode k = 1 .. N // 2 of the MDR line (N = ``points`` of ``spacing``)
    from the surface's modes (``power`` at ``wavenumber`` |q|, any shape): shares linear in
    q^2 between the two line modes that bracket each surface mode (see the module docstring)."""
    top = points // 2
    dq = TWO_PI / (points * spacing)
    x = np.asarray(wavenumber, dtype=np.float64).ravel() / dq  # in line modes
    p = np.asarray(power, dtype=np.float64).ravel()
    keep = (p > 0) & (x <= top * (1 + 1e-12))
    x, p = np.minimum(x[keep], top), p[keep]
    low = np.floor(x).astype(np.int64)
    share = (x * x - low * low) / (2.0 * low + 1.0)  # to mode low + 1
    below = low < 1  # below the first line mode: all of it to k = 1
    low[below], share[below] = 1, 0.0
    share[low >= top] = 0.0
    powers = np.bincount(low, weights=(1.0 - share) * p, minlength=top + 2)
    powers += np.bincount(low + 1, weights=share * p, minlength=top + 2)
    return powers[1 : top + 1]


@dataclass(frozen=True)
class _Synthesis:
    wavenumber: np.ndarray  # q_k, k = 1 .. N // 2
    amplitude: np.ndarray  # a_k of z = sum a_k cos(q_k x + phi_k), sum a_k^2 / 2 == h^2
    coeff: np.ndarray  # irfft coefficients of the regular modes (``line_coefficients``)
    nyquist: float  # and of the Nyquist mode (0.0 for odd N)


class EquivalentLine(SpectrumGenerator):
    """The MDR-equivalent line of a surface (made by a surface spectrum's ``equivalent_line()``,
    not named in presets): random phases, mode powers from the surface's spectrum."""

    name: ClassVar[str] = "mdr-equivalent-line"
    summary: ClassVar[str] = "MDR-equivalent line of a surface: C1D(q) = pi q C2D(q), length 2 sqrt(A / pi)"
    references: ClassVar[tuple[str, ...]] = (MDR_BOOK, GEIKE_POPOV_2007)

    class Params(PluginParams):
        points: int = Field(description="points N of the line, ceil(2 sqrt(A / pi) / dx)", ge=MIN_POINTS)
        spacing: float = Field(description="grid spacing of the line, 2 sqrt(A / pi) / N", gt=0.0)
        rms_height: float = Field(description="rms height h of the line: the surface's", gt=0.0)
        mode_power: tuple[float, ...] = Field(
            description="power of each line mode k = 1 .. points // 2 (q_k = 2 pi k / (N dx)) from the "
            "surface's spectrum, >= 0; scaled so that the line's mean square height is rms_height^2",
        )
        amplitudes: Literal["fixed", "rayleigh"] = Field(
            "fixed", description="'fixed': amplitudes from the powers, random phases; 'rayleigh': complex Gaussian modes"
        )

        @model_validator(mode="after")
        def _check_spectrum(self):
            power = np.asarray(self.mode_power, dtype=np.float64)
            if power.size != self.points // 2:
                raise ValueError(
                    f"mode_power must have points // 2 = {self.points // 2} values. Got {power.size} instead."
                )
            if not (np.all(np.isfinite(power)) and np.all(power >= 0) and np.any(power > 0)):
                raise ValueError("mode_power must be finite, >= 0 and not all zero")
            return self

    @classmethod
    def of_surface(cls, area: float, spacing: float, wavenumber=None, power=None, *, rms_height: float,
                   amplitudes: str = "fixed", modes=None) -> EquivalentLine:  # fmt: skip
        """The line of a surface of apparent ``area`` and pixel ``spacing`` whose modes have
        ``power`` at ``wavenumber`` |q| (or ``modes``: (wavenumber, power) blocks, summed one at
        a time: the shares are linear in the power), scaled to ``rms_height``."""
        points, line_spacing = line_grid(area, spacing)
        blocks = [(wavenumber, power)] if modes is None else modes
        powers = sum(line_mode_powers(q, p, points, line_spacing) for q, p in blocks)
        return cls(points=points, spacing=line_spacing, rms_height=rms_height,
                   mode_power=tuple(powers.tolist()), amplitudes=amplitudes)  # fmt: skip

    @cached_on_params
    def _synthesis(self) -> _Synthesis:
        p = self.params
        q = (TWO_PI / (p.points * p.spacing)) * np.arange(1, p.points // 2 + 1)
        power = np.asarray(p.mode_power, dtype=np.float64)
        amplitude = np.sqrt(2.0 * power) * (p.rms_height / math.sqrt(float(power.sum())))  # a_k^2 / 2 = P_k
        coeff, nyquist = line_coefficients(amplitude, p.points, p.points // 2)
        return _Synthesis(q, amplitude, coeff, nyquist)

    def generate(self, rng: np.random.Generator) -> Profile:
        """One line z_j = sum_k a_k cos(q_k x_j + phi_k), phi_k uniform (or complex Gaussian modes)."""
        s = self._synthesis()
        heights = random_phase_line(s.coeff, s.nyquist, 1, self.params.points, rng,
                                    rayleigh=self.params.amplitudes != "fixed")  # fmt: skip
        return Profile(heights=heights, spacing=self.params.spacing)

    def rms_height(self) -> float:
        """The surface's rms height: exact for every fixed-amplitude line."""
        return self.params.rms_height

    def grid_shape(self) -> tuple[int, ...]:
        return (self.params.points,)

    def psd(self, q) -> np.ndarray:
        """The line's one-sided C1D = pi q C2D: P_k / (2 dq) at q_k, linear between, zero outside."""
        s = self._synthesis()
        q = np.abs(np.asarray(q, dtype=np.float64))
        dq = s.wavenumber[0]
        out = np.interp(q, s.wavenumber, 0.25 * s.amplitude**2 / dq, left=0.0, right=0.0)
        return out[()] if out.ndim == 0 else out

    def rms_slope_discrete(self) -> float:
        """sqrt(sum_k q_k^2 a_k^2 / 2): the rms spectral derivative of every fixed-amplitude line
        (a kept Nyquist mode has zero grid slope, so a finite difference sees a little more)."""
        s = self._synthesis()
        qa = s.wavenumber * s.amplitude
        return float(math.sqrt(0.5 * np.dot(qa, qa)))
