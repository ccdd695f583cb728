"""Isotropic self-affine surfaces (``power-law-2d``, ``rolloff-2d``) and their MDR-equivalent line.

The surface twin of ``power_law``: same parameters, same band (flat from the long
cut-off q_min up to a knee q_r, power law from q_r to the short cut-off q_max),
same normalisation rules, on a periodic Ny x Nx grid of square pixels.

Conventions
-----------
- Grid: Nx = points, Ny = points_y (default Nx), spacing dx; sides Lx = Nx dx, Ly = Ny dx.
  Wave vectors q = (2 pi kx / Lx, 2 pi ky / Ly), one cell of the q plane is dqx dqy.
- Isotropic PSD C2D(|q|) = C0 q^(-2H-2) in the band, normalised as the 1D one is
  (no 2 pi factors): <z^2> = integral of C2D over the whole q plane
  = 2 pi integral_0^inf q C2D(q) dq, and <|grad z|^2> = 2 pi integral q^3 C2D dq.
  With this convention the MDR rule C1D(q) = pi q C2D(q) keeps both moments:
  2 integral pi q C2D dq = 2 pi integral q C2D dq (and likewise with q^2);
  ``equivalent_line()`` keeps them on the grids too (``equivalent_line.py``).
- Every mode q of the plane with q_min <= |q| <= q_max (edges inclusive to a relative
  1e-9) has variance a_q^2 = C2D(|q|) dqx dqy; the surface is real (modes q and -q are
  conjugate), so <z> = 0 and, for fixed amplitudes, mean(z^2) = sum_q a_q^2 exactly.
- The band is resolved by ``power_law.resolve_band`` on the shorter side: long_cutoff
  defaults to, and may not exceed, min(Lx, Ly), so every direction carries the whole band.
- ``rms_height()`` is the discrete sum sqrt(sum_q a_q^2) (exact for fixed amplitudes, the
  expectation for Rayleigh ones), ``rms_height_continuum()`` the integral; ``rms_slope()``
  is the continuum rms gradient, ``rms_slope_discrete()`` sqrt(sum_q |q|^2 a_q^2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from pydantic import Field

from frictionlab import Profile, SpectrumGenerator

from .equivalent_line import EquivalentLine
from .params_cache import cached_on_params
from .power_law import (
    JACOBS_JUNGE_PASTEWKA_2017,
    PERSSON_2005,
    REL_TOL,
    SQRT_HALF,
    TWO_PI,
    Band,
    BandParams,
    band_caveats,
    band_integral,
    relative_psd,
    resolve_band,
    resolve_spacing,
)


def _surface_band(p) -> tuple[Band, int, int]:
    """(band on the shorter side, Ny, Nx); ValueError naming the fields if inconsistent."""
    nx = p.points
    ny = nx if p.points_y is None else p.points_y
    dx, _ = resolve_spacing(p)
    band = resolve_band(
        p, spacing=dx, points=min(nx, ny), extent="shorter side of the surface min(points, points_y) * spacing"
    )
    return band, ny, nx


def _block_extent(band: Band, ny: int, nx: int) -> tuple[int, int]:
    """(Ky, Kx) of the block of the half spectrum that holds the band: |ky| <= Ky,
    0 <= kx <= Kx, beyond which |q| > q_max."""
    ky_max = min(ny // 2, math.floor(ny * band.spacing / band.short_cutoff * (1 + REL_TOL)))
    kx_max = min(nx // 2, math.floor(nx * band.spacing / band.short_cutoff * (1 + REL_TOL)))
    return ky_max, kx_max


# The peak of ``equivalent_line`` per entry of the block (the synthesis, then the modes given
# to the line), measured with tracemalloc: 66 bytes; plus a fifth.
LINE_BYTES_PER_MODE = 80


# ------------------------------------------------------------------ synthesis state


@dataclass(frozen=True)
class _SurfaceSynthesis:
    """Everything ``generate`` needs, derived once from the parameters.

    The modes live in a block of the half spectrum (rows ``rows`` of the (Ny, Nx//2+1)
    array, columns 0 .. Kx): only |ky| <= Ky and kx <= Kx can lie in the band.
    """

    band: Band
    shape: tuple[int, int]  # (Ny, Nx)
    psd_knee: float  # C2D at the knee (flat level below it)
    rms_height: float  # discrete: sqrt(sum over the plane of a_q^2)
    rows: np.ndarray  # half-spectrum rows of the block
    amplitude: np.ndarray  # a_q per block entry (0 outside the band)
    wavenumber: np.ndarray  # |q| per block entry
    weight: np.ndarray  # 2 for a free column (q and -q both in the plane), 1 for a self-conjugate one
    self_conjugate_columns: tuple[int, ...]  # kx = 0 and kx = Nx/2 (even Nx, in the block)
    pairs: tuple[np.ndarray, np.ndarray]  # block rows (ky, -ky) that are conjugate in those columns
    real_rows: np.ndarray  # block rows ky = 0 and Ny/2: real entries in those columns


class BandLimitedSurface(SpectrumGenerator):
    """Shared synthesis of ``power-law-2d`` and ``rolloff-2d`` (not registered itself)."""

    dimension: ClassVar[int] = 2
    references: ClassVar[tuple[str, ...]] = (PERSSON_2005, JACOBS_JUNGE_PASTEWKA_2017)
    points_param: ClassVar[str | None] = "points"

    class Params(BandParams):
        hurst: float = Field(
            description="Hurst exponent H: C2D ~ q^(-2H-2); 0 <= H <= 1.5 (0 < H <= 1 is usual)", ge=0.0, le=1.5
        )
        points: int = Field(description="grid points per side Nx (and Ny unless points_y is given)", ge=8)
        points_y: int | None = Field(None, description="grid points Ny along y (default: points, a square)", ge=8)
        length: float | None = Field(
            None, description="side Lx = points * spacing; give spacing or length", gt=0.0
        )
        long_cutoff: float | None = Field(
            None,
            description="long cut-off wavelength lambda_L = 2 pi / q_min (default and at most: the shorter side)",
            gt=0.0,
        )
        rms_height: float | None = Field(
            None, description="rms height h of the surface (default 1.0); give rms_height or c0", gt=0.0
        )
        c0: float | None = Field(
            None, description="PSD prefactor C0 in C2D = C0 q^(-2H-2); give rms_height or c0", gt=0.0
        )

        def resolve_band(self) -> Band:  # the band lives on the shorter side
            return _surface_band(self)[0]

    # ------------------------------------------------------------ cache

    @cached_on_params
    def _synthesis(self) -> _SurfaceSynthesis:
        p = self.params
        band, ny, nx = _surface_band(p)
        dx = band.spacing
        dqx, dqy = TWO_PI / (nx * dx), TWO_PI / (ny * dx)
        ky_max, kx_max = _block_extent(band, ny, nx)
        rows = np.unique(np.arange(-ky_max, ky_max + 1) % ny)
        signed = np.where(rows <= ny // 2, rows, rows - ny)
        q = np.hypot((dqy * signed)[:, None], (dqx * np.arange(kx_max + 1))[None, :])
        inside = (q >= band.q_min * (1 - REL_TOL)) & (q <= band.q_max * (1 + REL_TOL))
        if not inside.any():
            raise ValueError("no mode of the grid lies between short_cutoff and long_cutoff: widen the band")
        above = 2.0 * p.hurst + 2.0
        # a_q / a_knee in (0, 1]: no overflow whatever q_min, H and C0
        shape = np.where(inside, relative_psd(q / band.q_knee, 0.5 * above, 0.0), 0.0)

        columns = [0] + ([nx // 2] if nx % 2 == 0 and kx_max == nx // 2 else [])
        weight = np.full(kx_max + 1, 2.0)
        weight[columns] = 1.0
        weight = np.broadcast_to(weight, shape.shape)

        if p.c0 is not None:
            log_psd_knee = math.log(p.c0) - above * math.log(band.q_knee)
            if log_psd_knee > 700.0:
                raise ValueError(f"c0={p.c0!r} is too large for this band: the amplitudes overflow")
            psd_knee = math.exp(log_psd_knee)
            amplitude = math.sqrt(psd_knee * dqx * dqy) * shape
            h = float(math.sqrt(np.sum(weight * amplitude**2)))
        else:
            h = 1.0 if p.rms_height is None else p.rms_height
            scale = h / math.sqrt(np.sum(weight * shape**2))  # discrete normalisation: sum a^2 == h^2
            amplitude = scale * shape
            psd_knee = scale**2 / (dqx * dqy)
        if not (math.isfinite(h) and h > 0 and np.all(np.isfinite(amplitude))):
            raise ValueError(f"c0={p.c0!r} gives amplitudes that are not finite positive numbers")

        positive = np.arange(1, min(ky_max, (ny - 1) // 2) + 1)  # ky whose partner -ky is another row
        pairs = (np.searchsorted(rows, positive), np.searchsorted(rows, ny - positive))
        real = [0] + ([ny // 2] if ny % 2 == 0 and ky_max == ny // 2 else [])
        return _SurfaceSynthesis(
            band, (ny, nx), psd_knee, h, rows, amplitude, q, weight, tuple(columns), pairs,
            np.searchsorted(rows, real),
        )

    # ------------------------------------------------------------ geometry

    @property
    def band(self) -> Band:
        """Resolved spacing and cut-offs (``band.length`` is the shorter side)."""
        return self._synthesis().band

    def grid_shape(self) -> tuple[int, int]:
        """(Ny, Nx) of a generated surface, from the parameters alone: the memory check
        asks for it before a run, and the synthesis allocates in proportion to Ny Nx."""
        _, ny, nx = _surface_band(self.params)
        return (ny, nx)

    def hurst_exponent(self) -> float:
        return float(self.params.hurst)

    def caveats(self) -> tuple[str, ...]:
        return band_caveats(_surface_band(self.params)[0], self.dimension)  # no synthesis: validate asks too

    def refined(self, points: int) -> dict:
        """The same continuous surface on ``points`` pixels per side (``points_y`` in proportion):
        side and cut-off wavelengths kept."""
        band, (ny, nx) = self.band, self.grid_shape()
        changes = {"points": points, "length": nx * band.spacing, "spacing": None,
                   "long_cutoff": band.long_cutoff, "short_cutoff": band.short_cutoff}  # fmt: skip
        if self.params.points_y is not None:
            changes["points_y"] = max(8, round(points * ny / nx))
        return changes

    def c0(self) -> float:
        """The C2D prefactor C0 in use (given, or implied by ``rms_height``)."""
        s = self._synthesis()
        return math.exp(math.log(s.psd_knee) + (2.0 * self.params.hurst + 2.0) * math.log(s.band.q_knee))

    # ------------------------------------------------------------ contract

    def generate(self, rng: np.random.Generator) -> Profile:
        """One surface: random phases (or complex Gaussian modes), conjugate symmetric, one irfft2."""
        s = self._synthesis()
        ny, nx = s.shape
        coeff = (ny * nx) * s.amplitude  # numpy/scipy's irfft2 divides by Ny Nx
        fixed = self.params.amplitudes == "fixed"
        if fixed:
            block = coeff * np.exp(1j * (TWO_PI * rng.random(coeff.shape)))
        else:
            block = coeff * (SQRT_HALF * rng.standard_normal(2 * coeff.size).view(np.complex128).reshape(coeff.shape))
        positive, negative = s.pairs
        for column in s.self_conjugate_columns:
            entries = block[:, column]  # a view: edits land in block
            entries[negative] = np.conj(entries[positive])
            draws = rng.random(s.real_rows.size) if fixed else rng.standard_normal(s.real_rows.size)
            signs = np.where(draws < 0.5, 1.0, -1.0) if fixed else draws
            entries[s.real_rows] = coeff[s.real_rows, column] * signs
        half = np.zeros((ny, block.shape[1]), dtype=np.complex128)
        half[s.rows] = block
        import scipy.fft  # imported on first use: a run that needs no FFT here starts faster
        heights = scipy.fft.irfft2(half, s=(ny, nx))  # zero-pads the columns past Kx
        return Profile(heights=heights, spacing=s.band.spacing)

    def rms_height(self) -> float:
        """Discrete rms height sqrt(sum_q a_q^2): exact for every fixed-amplitude surface."""
        return self._synthesis().rms_height

    def rms_slope_discrete(self) -> float:
        """sqrt(sum_q |q|^2 a_q^2): the rms gradient of the exact (spectral) derivative of a
        fixed-amplitude surface, except that kept Nyquist components have no grid derivative."""
        s = self._synthesis()
        return float(math.sqrt(np.sum(s.weight * (s.wavenumber * s.amplitude) ** 2)))

    def psd(self, q) -> np.ndarray:
        """Isotropic C2D(|q|): C0 q_r^(-2H-2) below the knee, C0 q^(-2H-2) above, zero outside the band."""
        s = self._synthesis()
        b = s.band
        q = np.asarray(q, dtype=np.float64)
        inside = (q >= b.q_min * (1 - REL_TOL)) & (q <= b.q_max * (1 + REL_TOL))
        out = np.where(inside, s.psd_knee * relative_psd(q / b.q_knee, 2.0 * self.params.hurst + 2.0, 0.0), 0.0)
        return out[()] if out.ndim == 0 else out

    def _moment(self, order: int) -> float:
        """2 pi integral q^(order+1) C2D dq over the band: <z^2> (order 0), <|grad z|^2> (order 2)."""
        s = self._synthesis()
        return TWO_PI * s.psd_knee * band_integral(s.band, order + 1, 2.0 * self.params.hurst + 2.0, 0.0)

    def rms_height_continuum(self) -> float:
        """sqrt(2 pi integral q C2D dq). Not the limit of ``rms_height()`` as the pixels shrink:
        the discrete modes near the long cut-off carry the rms height and sum to it otherwise than
        the integral does, at any pixel size."""
        return math.sqrt(self._moment(0))

    def rms_slope(self) -> float:
        """Continuum rms gradient sqrt(2 pi integral q^3 C2D dq) (log case at H = 1)."""
        return math.sqrt(self._moment(2))

    # ------------------------------------------------------------ MDR

    def equivalent_line(self) -> EquivalentLine:
        """The MDR-equivalent line: length 2 sqrt(A / pi), each of its modes carrying the
        power of this surface's modes around it (``equivalent_line.py``), so that it keeps the
        surface's mean square height and mean square gradient; same amplitudes option, scaled
        to ``rms_height()`` (the h of f)."""
        s = self._synthesis()
        ny, nx = s.shape
        return EquivalentLine.of_surface(
            area=nx * ny * s.band.spacing**2, spacing=s.band.spacing, wavenumber=s.wavenumber,
            power=s.weight * s.amplitude**2, rms_height=s.rms_height, amplitudes=self.params.amplitudes,
        )  # fmt: skip

    def equivalent_line_bytes(self) -> int:
        """The peak memory of ``equivalent_line`` (the synthesis included), from the block of
        the spectrum the band fills: known from the parameters alone."""
        band, ny, nx = _surface_band(self.params)
        ky_max, kx_max = _block_extent(band, ny, nx)
        return LINE_BYTES_PER_MODE * min(ny, 2 * ky_max + 1) * (kx_max + 1)


class PowerLawSurface(BandLimitedSurface):
    """Isotropic self-affine surface: C2D = C0 q^(-2H-2) between the long and the short cut-off."""

    name: ClassVar[str] = "power-law-2d"
    summary: ClassVar[str] = (
        "Isotropic self-affine surface: C2D = C0 q^(-2H-2) between two cut-offs, random phases"
    )

    class Params(BandLimitedSurface.Params):
        pass


class RolloffSurface(BandLimitedSurface):
    """Isotropic self-affine surface with a rolloff: C2D flat below q_r = 2 pi / rolloff_wavelength."""

    name: ClassVar[str] = "rolloff-2d"
    summary: ClassVar[str] = (
        "Isotropic self-affine surface with a rolloff: flat C2D below q_r, C0 q^(-2H-2) above"
    )

    class Params(BandLimitedSurface.Params):
        rolloff_wavelength: float = Field(
            description="rolloff wavelength lambda_r = 2 pi / q_r, between short_cutoff and long_cutoff; "
            "C2D is flat for longer waves",
            gt=0.0,
        )
