"""A measured surface as a spectrum generator: ``surface-file``, and its MDR-equivalent line.

The file holds a height map z[row, column] of shape (Ny, Nx) on square pixels of side
``spacing`` (an AFM or profilometer topography):

- ``.npy``: a 2D array of real numbers;
- ``.csv`` / ``.txt``: a matrix of numbers, one row of the map per line, separated by
  commas or whitespace; ``#`` starts a comment and one non-numeric header line is skipped.

Like a synthetic surface the map is treated as periodic. ``detrend="plane"`` removes the
least-squares plane a + b x + c y (a scan that was not levelled); any remaining step at the
wrap is part of the surface the solver sees.

Solvers of lines (``mdr``, ``mdr-bisection``) get ``equivalent_line()``: a
``measured-equivalent-line`` whose spectrum is the MDR rule C1D(q) = pi q C2D(q) applied to
the map's own radially averaged PSD (one FFT of the detrended map, binned in |q|), with the
normalisation of ``surface.py`` (<z^2> = integral of C2D over the q plane, no 2 pi factors).
Its lines are random-phase syntheses (phases from the rng: realizations differ, seeds
reproduce) of N = round(2 sqrt(Nx Ny / pi)) points of the map's spacing, normalised to the
map's rms height (the h of f). Only |q| up to the line's Nyquist pi / spacing can be carried:
the map's corner modes beyond it are left out of the line's slopes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar, Literal

import numpy as np
import scipy.fft
from pydantic import Field, model_validator

from frictionlab import InputFile, PluginParams, Profile, SpectrumGenerator

from .power_law import TWO_PI, line_coefficients, random_phase_line
from .profile_file import check_finite, file_suffix, load_npy, read_text_table, remove_mean
from .surface import GEIKE_POPOV_2007, MDR_BOOK

MIN_SIDE = 8


@dataclass(frozen=True)
class _Map:
    key: tuple
    heights: np.ndarray  # detrended, read-only
    spacing: float
    rms_height: float


@dataclass(frozen=True)
class RadialPSD:
    """Radially averaged C2D of a map in annuli |q| / width in [k - 1/2, k + 1/2), k = 1, 2, ...
    (the modes below width / 2 join k = 1): psd[k-1] = (sum of |z_q|^2 over the annulus) /
    (2 pi q_k width), the annulus' power per unit area of the q plane, so that
    sum_k 2 pi q_k width psd_k = mean(z^2) exactly (the MDR line's modes carry that power)."""

    wavenumber: np.ndarray  # q_k = k * width
    psd: np.ndarray  # C2D_k
    count: np.ndarray  # modes of the map in annulus k


def radial_psd(heights: np.ndarray, spacing: float, width: float | None = None) -> RadialPSD:
    """The radial average of a periodic map's C2D (one FFT). The default ``width`` is
    min(dqx, dqy), the finer of the map's own wavenumber steps."""
    ny, nx = heights.shape
    dqx, dqy = TWO_PI / (nx * spacing), TWO_PI / (ny * spacing)
    width = min(dqx, dqy) if width is None else width
    power = np.abs(scipy.fft.fft2(heights)) ** 2 / float(nx * ny) ** 2  # sums to mean(z^2)
    power[0, 0] = 0.0  # the mean is no roughness
    q = np.hypot((dqy * np.fft.fftfreq(ny, 1.0 / ny))[:, None], (dqx * np.fft.fftfreq(nx, 1.0 / nx))[None, :])
    index = np.maximum(np.floor(q / width + 0.5).astype(np.int64), 1).ravel()
    count = np.bincount(index)[1:]
    wavenumber = width * np.arange(1, count.size + 1)
    annulus_power = np.bincount(index, weights=power.ravel())[1:]
    count[0] -= 1  # the q = 0 mode was put in k = 1 with zero power
    return RadialPSD(wavenumber, annulus_power / (TWO_PI * wavenumber * width), count)


class SurfaceFile(SpectrumGenerator):
    """A measured height map read from a file; every ``generate`` returns the same surface."""

    name: ClassVar[str] = "surface-file"
    summary: ClassVar[str] = "Measured surface read from a .npy/.csv/.txt height map (Ny, Nx) on square pixels"
    references: ClassVar[tuple[str, ...]] = ()
    dimension: ClassVar[int] = 2

    class Params(PluginParams):
        path: InputFile = Field(description="file of heights (.npy 2D array, or .csv/.txt matrix: one map row per "
                                "line); a relative path is taken from the preset file's folder", min_length=1)
        spacing: float = Field(description="pixel side dx (square pixels), in the units of the heights' x", gt=0.0)
        detrend: Literal["none", "mean", "plane"] = Field(
            "mean",
            description="remove nothing, the mean, or the least-squares plane before use; "
            "the map is treated as periodic",
        )

    # ------------------------------------------------------------ contract

    def generate(self, rng: np.random.Generator) -> Profile:
        """The measured map (a fresh copy each call); ``rng`` is not used."""
        surface = self._map()
        return Profile(heights=surface.heights.copy(), spacing=surface.spacing)

    def rms_height(self) -> float:
        """rms of the detrended map about its mean (a constant offset does not count)."""
        return self._map().rms_height

    def radial_psd(self) -> RadialPSD:
        """The detrended map's radially averaged C2D in annuli of the map's own finest dq."""
        surface = self._map()
        return radial_psd(surface.heights, surface.spacing)

    def equivalent_line(self) -> "MeasuredEquivalentLine":
        """The MDR-equivalent line (SPEC section 7) of this map: same spacing, N = round(2 sqrt(Nx Ny
        / pi)) points, C1D = pi q C2D with C2D the map's radial average in annuli centred on the
        line's own wavenumbers q_k = 2 pi k / (N dx) (so each line mode carries the power of its
        annulus), normalised to rms height ``rms_height()``."""
        surface = self._map()
        n = int(round(2.0 * math.sqrt(surface.heights.size / math.pi)))
        psd = radial_psd(surface.heights, surface.spacing, width=TWO_PI / (n * surface.spacing))
        c2d = np.zeros(n // 2)
        kept = min(c2d.size, psd.psd.size)  # annuli past the line's Nyquist (the map's corners) are left out
        c2d[:kept] = psd.psd[:kept]
        return MeasuredEquivalentLine(
            points=n, spacing=surface.spacing, rms_height=surface.rms_height, surface_psd=tuple(c2d.tolist())
        )

    # ------------------------------------------------------------ reading

    def _map(self) -> _Map:
        key = tuple(self.params.__dict__.items())
        cached = getattr(self, "_cache", None)
        if cached is not None and cached.key == key:
            return cached
        p = self.params
        path = Path(p.path)
        where = f"surface-file {str(path)!r}"
        z = _read_map(path, where)
        check_finite(where, "heights", z)
        heights = _detrend(z, p.detrend)
        rms = float(np.std(heights))
        if not rms > 1e-12 * float(np.max(np.abs(z))):  # also true for an all-zero map
            raise ValueError(
                f"{where}: the map is constant (rms height zero after detrend={p.detrend!r}); "
                "a flat surface has no roughness"
            )
        heights.flags.writeable = False
        self._cache = _Map(key, heights, float(p.spacing), rms)
        return self._cache


def _read_map(path: Path, where: str) -> np.ndarray:
    """The (Ny, Nx) float64 map of a .npy or text file, at least MIN_SIDE points each way."""
    if file_suffix(path, where) == ".npy":
        data = load_npy(path, where)
    else:
        data = read_text_table(path, where)
    if data.ndim != 2 or 1 in data.shape:
        raise ValueError(
            f"{where}: array of shape {data.shape}; expected a 2D height map (Ny, Nx) "
            "(for a single line use profile-file)"
        )
    if min(data.shape) < MIN_SIDE:
        ny, nx = data.shape
        raise ValueError(f"{where}: map of {ny} x {nx} points; at least {MIN_SIDE} x {MIN_SIDE} are needed")
    return data.astype(np.float64)


def _detrend(z: np.ndarray, mode: str) -> np.ndarray:
    if mode == "none":
        return z.copy()
    out = remove_mean(z)
    if mode == "plane":
        # centred row and column indices are orthogonal on the grid (and to the constant):
        # projecting on each in turn is the least-squares plane
        ny, nx = z.shape
        x = np.arange(nx, dtype=np.float64) - 0.5 * (nx - 1)
        y = np.arange(ny, dtype=np.float64) - 0.5 * (ny - 1)
        out -= (np.sum(out * x[None, :]) / (ny * np.dot(x, x))) * x[None, :]
        out -= (np.sum(out * y[:, None]) / (nx * np.dot(y, y))) * y[:, None]
    return out


# ------------------------------------------------------------------ the equivalent line


@dataclass(frozen=True)
class _LineSynthesis:
    key: tuple
    wavenumber: np.ndarray  # q_k, k = 1 .. N // 2
    amplitude: np.ndarray  # a_k of z = sum a_k cos(q_k x + phi_k), sum a_k^2 / 2 == h^2
    scale: float  # the normalisation to h: line C1D / (pi q C2D)
    coeff: np.ndarray  # irfft coefficients of the regular modes (``line_coefficients``)
    nyquist: float  # and of the Nyquist mode (0.0 for odd N)


class MeasuredEquivalentLine(SpectrumGenerator):
    """The MDR-equivalent line of a measured map (made by ``SurfaceFile.equivalent_line()``,
    not named in presets): random phases, amplitudes from C1D = pi q C2D_measured."""

    name: ClassVar[str] = "measured-equivalent-line"
    summary: ClassVar[str] = (
        "MDR-equivalent line of a measured map: C1D = pi q C2D (radially averaged), random phases"
    )
    references: ClassVar[tuple[str, ...]] = (MDR_BOOK, GEIKE_POPOV_2007)

    class Params(PluginParams):
        points: int = Field(description="points N of the line, round(2 sqrt(Nx Ny / pi))", ge=MIN_SIDE)
        spacing: float = Field(description="grid spacing dx (the map's pixel side)", gt=0.0)
        rms_height: float = Field(description="rms height h of every line (the map's)", gt=0.0)
        surface_psd: tuple[float, ...] = Field(
            description="the map's radially averaged C2D at the line's wavenumbers q_k = 2 pi k / (N dx), "
            "k = 1 .. N // 2 (>= 0)",
        )

        @model_validator(mode="after")
        def _check_spectrum(self):
            c = np.asarray(self.surface_psd, dtype=np.float64)
            if c.size != self.points // 2:
                raise ValueError(
                    f"surface_psd must have points // 2 = {self.points // 2} values. Got {c.size} instead."
                )
            if not (np.all(np.isfinite(c)) and np.all(c >= 0) and np.any(c > 0)):
                raise ValueError("surface_psd must be finite, >= 0 and not all zero")
            return self

    def _synthesis(self) -> _LineSynthesis:
        key = tuple(self.params.__dict__.items())
        cached = getattr(self, "_cache", None)
        if cached is not None and cached.key == key:
            return cached
        p = self.params
        dq = TWO_PI / (p.points * p.spacing)
        q = dq * np.arange(1, p.points // 2 + 1)
        shape = 2.0 * np.sqrt(math.pi * q * np.asarray(p.surface_psd) * dq)  # a_k^2 / 2 = 2 C1D dq
        factor = p.rms_height / math.sqrt(0.5 * float(np.dot(shape, shape)))
        amplitude = factor * shape
        coeff, nyquist = line_coefficients(amplitude, p.points, p.points // 2)
        self._cache = _LineSynthesis(key, q, amplitude, factor**2, coeff, nyquist)
        return self._cache

    def generate(self, rng: np.random.Generator) -> Profile:
        """One line z_j = sum_k a_k cos(q_k x_j + phi_k), phi_k uniform from ``rng``."""
        s = self._synthesis()
        return Profile(heights=random_phase_line(s.coeff, s.nyquist, 1, self.params.points, rng),
                       spacing=self.params.spacing)  # fmt: skip

    def rms_height(self) -> float:
        """The map's rms height: exact for every line (fixed amplitudes)."""
        return self.params.rms_height

    def psd(self, q) -> np.ndarray:
        """The line's one-sided C1D = pi q C2D_measured (times the normalisation to h), linear
        between its wavenumbers q_k and zero outside [q_1, q_(N/2)]."""
        s = self._synthesis()
        q = np.abs(np.asarray(q, dtype=np.float64))
        c1d = s.scale * math.pi * s.wavenumber * np.asarray(self.params.surface_psd)
        out = np.interp(q, s.wavenumber, c1d, left=0.0, right=0.0)
        return out[()] if out.ndim == 0 else out

    def rms_slope_discrete(self) -> float:
        """sqrt(sum_k q_k^2 a_k^2 / 2): the rms spectral derivative of every line (a kept
        Nyquist mode has zero grid slope, so finite differences see a little less)."""
        s = self._synthesis()
        qa = s.wavenumber * s.amplitude
        return float(math.sqrt(0.5 * np.dot(qa, qa)))
