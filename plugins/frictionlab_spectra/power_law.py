"""Band-limited self-affine rough lines: ``power-law`` and ``rolloff``.

Both are one generator, a PSD that is flat from the long cut-off q_min up to a
knee q_r and a power law C0 q^(-2H-1) from q_r up to the short cut-off q_max
(``power-law`` is the case q_r = q_min), synthesised as a sum of cosines with
random phases by one inverse real FFT.

Conventions
-----------
- Grid: N points, spacing dx, length L = N dx, periodic; q_k = 2 pi k / L, dq = 2 pi / L.
- ``series: cosine`` instead: the non-periodic sum of cosines with q_k = k pi / L
  (dq = pi / L, twice as dense) on [0, L), the source study's eq. 6 read literally
  (pi / L <= q <= pi / (10 dx): short_cutoff = 20 dx). Its modes are those of a
  periodic line of length 2L, of which the line is the first half; the
  long cut-off then defaults to, and may not exceed, 2L. The ends do not meet
  (``periodic()`` is False), and the modes are not orthogonal on [0, L), so a
  line's rms height scatters about the nominal one.
- One-sided 1D PSD with <z^2> = 2 * integral_0^inf psd(q) dq.
- Mode k (kept when q_min <= q_k <= q_max, both inclusive up to a relative 1e-9)
  is a_k cos(q_k x + phi_k) with a_k = 2 sqrt(psd(q_k) dq), i.e. variance
  a_k^2 / 2 = 2 psd(q_k) dq. There is no k = 0 mode, so <z> = 0 exactly.
- Two rms heights: ``rms_height()`` is the discrete sum sqrt(sum_k a_k^2 / 2),
  which every fixed-amplitude line has exactly (and the expectation for Rayleigh
  amplitudes); ``rms_height_continuum()`` is sqrt(2 * integral psd dq). Likewise
  ``rms_slope_discrete()`` = sqrt(sum_k q_k^2 a_k^2 / 2) and ``rms_slope()``, the
  continuum integral. They differ by the Riemann-sum error of the band.
- ``height_reference: measured``: each generated line is shifted to zero mean and
  scaled so that its own rms height about its mean is h (``rms_height()``), and f
  is formed with that measured rms (``profile_rms_height``): the study's h, the rms
  of the line's height distribution (eq. 8). With the default ``nominal`` h is the
  expected rms of the ensemble; a cosine-series line then scatters about it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np

from pydantic import Field, model_validator

from frictionlab import PluginParams, Profile, SpectrumGenerator, short_cutoff_caveat

from .params_cache import cached_on_params

TWO_PI = 2.0 * math.pi
REL_TOL = 1e-9  # band edges and length/spacing consistency are checked to this relative tolerance
SQRT_HALF = math.sqrt(0.5)

PERSSON_2005 = "10.1088/0953-8984/17/1/R01"
JACOBS_JUNGE_PASTEWKA_2017 = "10.1088/2051-672X/aa51f8"


# ------------------------------------------------------------------ geometry


def band_caveats(band: Band, dimension: int) -> tuple[str, ...]:
    """A generator's ``caveats()``: the short cut-off on too few pixels, or nothing."""
    caveat = short_cutoff_caveat(band.short_cutoff / band.spacing, dimension)
    return () if caveat is None else (caveat,)


@dataclass(frozen=True)
class Band:
    """The resolved grid and cut-offs of a spectrum's parameters (defaults filled in)."""

    points: int
    spacing: float
    length: float
    long_cutoff: float
    short_cutoff: float
    knee: float  # wavelength where the power law starts (= long_cutoff for power-law)
    k_lo: int  # first kept mode
    k_hi: int  # last kept mode (inclusive)
    period: float  # the period of the modes q_k = 2 pi k / period: L, or 2 L for the cosine series

    @property
    def dq(self) -> float:
        return TWO_PI / self.period

    @property
    def period_points(self) -> int:
        """Grid points of one period of the modes (N, or 2 N for the cosine series)."""
        return int(round(self.period / self.spacing))

    @property
    def q_min(self) -> float:
        return TWO_PI / self.long_cutoff

    @property
    def q_max(self) -> float:
        return TWO_PI / self.short_cutoff

    @property
    def q_knee(self) -> float:
        return TWO_PI / self.knee


def resolve_spacing(p, points: int | None = None) -> tuple[float, float]:
    """(spacing dx, length N dx) from ``spacing`` or ``length`` (default dx = 1); ValueError if both
    are given and disagree. ``points`` defaults to ``p.points`` (the side along which ``length`` is given)."""
    n = p.points if points is None else points
    if p.spacing is not None and p.length is not None:
        if not math.isclose(p.length, n * p.spacing, rel_tol=REL_TOL):
            raise ValueError(
                f"spacing={p.spacing!r} and length={p.length!r} disagree: length must equal "
                f"points * spacing = {n * p.spacing!r}; give only one of spacing and length"
            )
    if p.spacing is not None:
        return p.spacing, n * p.spacing
    if p.length is not None:
        return p.length / n, p.length
    return 1.0, float(n)


def resolve_band(p: "PowerLaw.Params", *, spacing: float | None = None, points: int | None = None,
                 extent: str = "line length L = points * spacing", series: str = "fft") -> Band:  # fmt: skip
    """Fill in defaults and check the geometry; ValueError (naming the fields) if inconsistent.

    A surface passes its resolved ``spacing`` and the ``points`` of its shorter side (the band's
    longest wave must fit every direction); ``extent`` names that length in messages. ``series``
    "cosine": the modes q_k = k pi / L of the non-periodic cosine series (period 2 L)."""
    if spacing is None:
        dx, length = resolve_spacing(p)
        n = p.points
    else:
        n = points
        dx, length = spacing, n * spacing
    cosine = series == "cosine"
    period = 2.0 * length if cosine else length
    if cosine:
        extent = "period of the cosine series 2 L = 2 * points * spacing"

    long_cutoff = period if p.long_cutoff is None else p.long_cutoff
    short_cutoff = 10.0 * dx if p.short_cutoff is None else p.short_cutoff
    long_txt = "long_cutoff" + (
        f" (default: {'2 * length' if cosine else 'length'} = {period!r})" if p.long_cutoff is None else f"={long_cutoff!r}"
    )
    short_txt = "short_cutoff" + (
        f" (default: 10 * spacing = {short_cutoff!r})" if p.short_cutoff is None else f"={short_cutoff!r}"
    )
    if long_cutoff > period * (1 + REL_TOL):
        raise ValueError(f"{long_txt} must not exceed the {extent} = {period!r}")
    if short_cutoff < 2.0 * dx * (1 - REL_TOL):
        raise ValueError(
            f"{short_txt} is below the Nyquist wavelength 2 * spacing = {2.0 * dx!r}; "
            "the grid cannot carry shorter waves"
        )
    if short_cutoff >= long_cutoff:
        raise ValueError(f"{short_txt} must be shorter than {long_txt}")

    knee = long_cutoff
    rolloff = getattr(p, "rolloff_wavelength", None)
    if rolloff is not None:
        if not short_cutoff * (1 - REL_TOL) <= rolloff <= long_cutoff * (1 + REL_TOL):
            raise ValueError(
                f"rolloff_wavelength={rolloff!r} must lie between {short_txt} and {long_txt}"
            )
        knee = min(max(rolloff, short_cutoff), long_cutoff)

    # mode k has wavelength P / k (P the period): keep P / long_cutoff <= k <= P / short_cutoff
    # (inclusive, tolerant), up to the grid's Nyquist wave 2 dx
    k_lo = max(1, math.ceil(period / long_cutoff * (1 - REL_TOL)))
    k_hi = min(n if cosine else n // 2, math.floor(period / short_cutoff * (1 + REL_TOL)))
    if k_lo > k_hi:
        modes = "k pi / L (wavelength 2 L / k" if cosine else "2 pi k / L (wavelength L / k"
        raise ValueError(
            f"no mode q_k = {modes}, L = {length!r}) lies between {short_txt} and {long_txt}: widen the band"
        )
    return Band(n, dx, length, long_cutoff, short_cutoff, knee, k_lo, k_hi, period)


def _log_integral(p: float, ln_r: float) -> float:
    """integral_0^ln_r exp(p t) dt = integral_1^R u^(p-1) du, stable through p = 0 (log case)."""
    x = p * ln_r
    if abs(x) < 1e-8:  # series: expm1(x)/p loses nothing here, but p may be exactly 0
        return ln_r * (1.0 + x / 2.0 + x * x / 6.0)
    return math.expm1(x) / p


def relative_psd(ratio, above: float, below: float):
    """psd / psd(knee) at ratio = q / q_r: ratio^(-above) from the knee up, ratio^below under it
    (below = 0: flat). Values stay in (0, 1] whatever the exponents: no overflow."""
    ratio = np.asarray(ratio, dtype=np.float64)
    if below == 0.0:  # the flat case as one power of a clipped ratio
        return np.maximum(ratio, 1.0) ** (-above)
    return np.where(ratio >= 1.0, ratio ** (-above), np.minimum(ratio, 1.0) ** below)


def band_integral(band: Band, power: float, above: float, below: float) -> float:
    """integral_{q_min}^{q_max} q^power relative_psd(q / q_r) dq in closed form, stable through the
    log cases (power + 1 = above): the moments of every band-limited spectrum, lines and surfaces."""
    qr = band.q_knee
    under = power + below + 1.0  # > 0: the part below the knee is a plain power
    flat = -math.expm1(under * math.log(band.q_min / qr)) / under if band.q_min < qr else 0.0
    return qr ** (power + 1.0) * (flat + _log_integral(power + 1.0 - above, math.log(band.q_max / qr)))


# ------------------------------------------------------------------ synthesis state


@dataclass(frozen=True)
class _Synthesis:
    """Everything ``generate`` needs, derived once from the parameters."""

    band: Band
    psd_knee: float  # psd at the knee (flat level below it)
    rms_height: float  # discrete: sqrt(sum a_k^2 / 2)
    coeff: np.ndarray  # (N/2) a_k for the regular modes k_lo .. k_hi (Nyquist excluded)
    nyquist: float  # N a_k / sqrt(2) for the Nyquist mode if it is kept, else 0.0
    amplitudes: np.ndarray  # a_k, k_lo .. k_hi (Nyquist included)


def line_coefficients(amplitudes: np.ndarray, points: int, k_hi: int) -> tuple[np.ndarray, float]:
    """irfft coefficients of mode amplitudes a_k ending at mode ``k_hi`` of an
    N-point line: ((N/2) a_k for the regular modes, N a / sqrt(2) for the Nyquist
    mode if the modes reach it, else 0.0). The Nyquist coefficient is real, and
    N a/sqrt(2) (-1)^j has variance a^2/2 after irfft."""
    if points % 2 == 0 and k_hi == points // 2:
        return (0.5 * points) * amplitudes[:-1], points * amplitudes[-1] * SQRT_HALF
    return (0.5 * points) * amplitudes, 0.0


def random_phase_line(coeff: np.ndarray, nyquist: float, k_lo: int, points: int, rng: np.random.Generator,
                      *, rayleigh: bool = False) -> np.ndarray:  # fmt: skip
    """An N-point line from the irfft coefficients of ``line_coefficients`` (modes
    k_lo ..), with uniform random phases (fixed amplitudes) or complex Gaussian
    modes (Rayleigh amplitudes), the Nyquist coefficient with a random sign (or a
    Gaussian factor)."""
    m = coeff.size
    # only up to the top mode: irfft zero-pads the rest, and a short fresh buffer is
    # markedly cheaper than an N/2 one (large fresh allocations cost page faults)
    spectrum = np.zeros(k_lo + m + (1 if nyquist else 0), dtype=np.complex128)
    # draw only for the modes in the band: with the default cut-off that is N/10 of them
    if not rayleigh:
        band = spectrum[k_lo : k_lo + m]
        phase = rng.random(m)
        phase *= TWO_PI
        # a_k e^(i phi) by parts: the same numbers as np.exp(1j phi), in 60% of its time
        np.multiply(coeff, np.cos(phase), out=band.real)
        np.multiply(coeff, np.sin(phase), out=band.imag)
        if nyquist:
            spectrum[-1] = nyquist if rng.random() < 0.5 else -nyquist
    else:
        # complex Gaussian, E|g|^2 = 1 after the 1/sqrt(2): uniform phase, Rayleigh modulus
        g = rng.standard_normal(2 * m).view(np.complex128)
        spectrum[k_lo : k_lo + m] = (SQRT_HALF * coeff) * g
        if nyquist:
            spectrum[-1] = nyquist * rng.standard_normal()
    return np.fft.irfft(spectrum, n=points)  # the pocketfft of scipy.fft (same numbers), without its 0.15 s import


class BandParams(PluginParams):
    """The parameters every band-limited spectrum shares, lines and surfaces."""

    hurst: float = Field(
        description="Hurst exponent H: psd ~ q^(-2H-1); 0 <= H <= 1.5 (0 < H <= 1 is usual)",
        ge=0.0,
        le=1.5,
    )
    points: int = Field(description="number of grid points N", ge=8)
    spacing: float | None = Field(
        None, description="grid spacing dx (default 1.0, or length / points); give spacing or length", gt=0.0
    )
    length: float | None = Field(
        None, description="line length L = points * spacing; give spacing or length", gt=0.0
    )
    long_cutoff: float | None = Field(
        None, description="long cut-off wavelength lambda_L = 2 pi / q_min (default: length)", gt=0.0
    )
    short_cutoff: float | None = Field(
        None,
        description="short cut-off wavelength lambda_s = 2 pi / q_max, >= 2 * spacing (default: 10 * spacing)",
        gt=0.0,
    )
    rms_height: float | None = Field(
        None, description="rms height h of the line (default 1.0); give rms_height or c0", gt=0.0
    )
    c0: float | None = Field(
        None, description="PSD prefactor C0 in psd = C0 q^(-2H-1); give rms_height or c0", gt=0.0
    )
    amplitudes: Literal["fixed", "rayleigh"] = Field(
        "fixed",
        description="'fixed': amplitudes sqrt(psd), random phases (the study); "
        "'rayleigh': complex Gaussian modes (random amplitudes too)",
    )

    @model_validator(mode="after")
    def _check_geometry(self):
        if self.rms_height is not None and self.c0 is not None:
            raise ValueError(
                f"rms_height={self.rms_height!r} and c0={self.c0!r} both given: "
                "give at most one of rms_height and c0"
            )
        self.resolve_band()
        return self

    def resolve_band(self) -> Band:
        """The band of these parameters (ValueError naming the fields if inconsistent)."""
        return resolve_band(self)


class LineParams(BandParams):
    """A band-limited line: the shared parameters and the choice of series."""

    series: Literal["fft", "cosine"] = Field(
        "fft",
        description="'fft': periodic line, q_k = 2 pi k / L; 'cosine': non-periodic sum of cosines with "
        "q_k = k pi / L on [0, L) (the study's eq. 6 read literally; long_cutoff defaults to 2 L)",
    )

    height_reference: Literal["nominal", "measured"] = Field(
        "nominal",
        description="'nominal': h (rms_height, or the rms C0 implies) is the ensemble's expected rms height; "
        "'measured': each line is shifted to zero mean and scaled so that its own rms height is h, and f uses "
        "that measured rms (the study's definition of h)",
    )

    def resolve_band(self) -> Band:
        return resolve_band(self, series=self.series)


class BandLimitedSpectrum(SpectrumGenerator):
    """Shared synthesis of ``power-law`` and ``rolloff`` (not registered itself)."""

    references: ClassVar[tuple[str, ...]] = (PERSSON_2005, JACOBS_JUNGE_PASTEWKA_2017)
    points_param: ClassVar[str | None] = "points"

    Params = LineParams

    # ------------------------------------------------------------ cache

    @cached_on_params
    def _synthesis(self) -> _Synthesis:
        p = self.params
        band = p.resolve_band()
        a = 2.0 * p.hurst + 1.0
        k = np.arange(band.k_lo, band.k_hi + 1, dtype=np.float64)
        # shape relative to the knee, in (0, 1]: no overflow whatever q_min, H and C0
        k_knee = band.period / band.knee
        shape = relative_psd(k / k_knee, 0.5 * a, 0.0)  # a_k / a_knee = sqrt(psd ratio)
        if p.c0 is not None:
            # psd at the knee = C0 q_knee^(-a), formed in logs (C0 and q_knee may be extreme)
            log_psd_knee = math.log(p.c0) - a * math.log(band.q_knee)
            if log_psd_knee > 700.0:
                raise ValueError(f"c0={p.c0!r} is too large for this band: the amplitudes overflow")
            psd_knee = math.exp(log_psd_knee)
            amplitudes = (2.0 * math.sqrt(psd_knee * band.dq)) * shape
            h = float(math.sqrt(0.5 * np.dot(amplitudes, amplitudes)))
        else:
            h = 1.0 if p.rms_height is None else p.rms_height
            # discrete normalisation: sum a_k^2 / 2 == h^2 exactly
            scale = h / math.sqrt(0.5 * np.dot(shape, shape))
            amplitudes = scale * shape
            psd_knee = (0.5 * scale) ** 2 / band.dq
        if not (math.isfinite(h) and h > 0 and np.all(np.isfinite(amplitudes))):
            raise ValueError(f"c0={p.c0!r} gives amplitudes that are not finite positive numbers")
        coeff, nyquist = line_coefficients(amplitudes, band.period_points, band.k_hi)
        return _Synthesis(band, psd_knee, h, coeff, nyquist, amplitudes)

    # ------------------------------------------------------------ geometry

    @property
    def band(self) -> Band:
        """Resolved grid and cut-offs (defaults filled in)."""
        return self._synthesis().band

    def wavevectors(self) -> np.ndarray:
        """q_k of the modes a generated line carries."""
        b = self.band
        return b.dq * np.arange(b.k_lo, b.k_hi + 1, dtype=np.float64)

    def c0(self) -> float:
        """The PSD prefactor C0 in use (given, or implied by ``rms_height``; may be huge or tiny)."""
        s = self._synthesis()
        return math.exp(math.log(s.psd_knee) + (2.0 * self.params.hurst + 1.0) * math.log(s.band.q_knee))

    def hurst_exponent(self) -> float:
        return float(self.params.hurst)

    def grid_shape(self) -> tuple[int, ...]:
        return (self.params.points,)

    def caveats(self) -> tuple[str, ...]:
        return band_caveats(self.params.resolve_band(), self.dimension)

    def refined(self, points: int) -> dict:
        """The same continuous line on ``points`` points: length and cut-off wavelengths kept."""
        band = self.band
        return {"points": points, "length": band.length, "spacing": None,
                "long_cutoff": band.long_cutoff, "short_cutoff": band.short_cutoff}  # fmt: skip

    # ------------------------------------------------------------ contract

    def periodic(self) -> bool:
        """True, except for the cosine series, whose line is half a period."""
        return self.params.series == "fft"

    def not_periodic_advice(self) -> tuple[str, str]:
        return (f"spectrum {self.name} is not periodic (series: {self.params.series}, a line whose ends do not meet)",
                "set spectrum.params.series: fft (a periodic line)")  # fmt: skip

    def generate(self, rng: np.random.Generator) -> Profile:
        """One line z_j = sum_k a_k cos(q_k x_j + phi_k), phi_k uniform (or complex Gaussian modes);
        the cosine series is the first half of a line of twice the length."""
        s = self._synthesis()
        heights = random_phase_line(
            s.coeff, s.nyquist, s.band.k_lo, s.band.period_points, rng, rayleigh=self.params.amplitudes != "fixed"
        )[: s.band.points]
        if self.params.height_reference == "measured":  # the line's own rms about its mean is h
            heights = heights - heights.mean()
            heights *= s.rms_height / np.sqrt(np.mean(np.square(heights)))
        return Profile(heights=heights, spacing=s.band.spacing, periodic=self.periodic())

    def profile_rms_height(self, profile: Profile) -> float | None:
        """With ``height_reference: measured``, the line's rms height about its mean (h, to rounding);
        None (the nominal ``rms_height()``) otherwise."""
        if self.params.height_reference != "measured":
            return None
        return float(np.std(profile.heights))

    def rms_height(self) -> float:
        """Discrete rms height sqrt(sum_k a_k^2 / 2): exact for every fixed-amplitude periodic line,
        the expectation (sqrt of the expected mean square) for Rayleigh amplitudes and for the
        cosine series (whose modes are not orthogonal on the line)."""
        return self._synthesis().rms_height

    def rms_slope_discrete(self) -> float:
        """sqrt(sum_k q_k^2 a_k^2 / 2): the rms of the exact derivative of a fixed-amplitude line
        (its spectral derivative on the grid, except that a kept Nyquist mode has zero grid slope)."""
        s = self._synthesis()
        qa = self.wavevectors() * s.amplitudes
        return float(math.sqrt(0.5 * np.dot(qa, qa)))

    def psd(self, q) -> np.ndarray:
        """One-sided PSD: C0 q_r^(-2H-1) for q_min <= q < q_r, C0 q^(-2H-1) for q_r <= q <= q_max,
        zero elsewhere (edges inclusive to a relative 1e-9, like the mode selection)."""
        s = self._synthesis()
        b = s.band
        q = np.asarray(q, dtype=np.float64)
        inside = (q >= b.q_min * (1 - REL_TOL)) & (q <= b.q_max * (1 + REL_TOL))
        shape = relative_psd(q / b.q_knee, 2.0 * self.params.hurst + 1.0, 0.0)
        out = np.where(inside, s.psd_knee * shape, 0.0)
        return out[()] if out.ndim == 0 else out

    def _moment(self, order: int) -> float:
        """2 * integral_{q_min}^{q_max} q^order psd(q) dq in closed form (order 0 or 2)."""
        s = self._synthesis()
        above = 2.0 * self.params.hurst + 1.0
        return 2.0 * s.psd_knee * band_integral(s.band, order, above, 0.0)

    def rms_height_continuum(self) -> float:
        """sqrt(2 * integral psd dq) over the band. Not the limit of ``rms_height()`` as the pixels
        shrink: the discrete modes q_k = 2 pi k / L near the long cut-off carry the rms height, and
        sum to it otherwise than the integral does (by a ratio set by H) at any pixel size."""
        return math.sqrt(self._moment(0))

    def rms_slope(self) -> float:
        """sqrt(2 * integral q^2 psd dq) over the band, closed form (log case at H = 1);
        the continuum limit of ``rms_slope_discrete()``."""
        return math.sqrt(self._moment(2))


class PowerLaw(BandLimitedSpectrum):
    """Self-affine line: psd = C0 q^(-2H-1) between the long and the short cut-off."""

    name: ClassVar[str] = "power-law"
    summary: ClassVar[str] = "Self-affine line: power-law PSD C0 q^(-2H-1) between two cut-offs, random phases"

    class Params(BandLimitedSpectrum.Params):
        pass


class Rolloff(BandLimitedSpectrum):
    """Self-affine line with a rolloff: psd flat below q_r = 2 pi / rolloff_wavelength."""

    name: ClassVar[str] = "rolloff"
    summary: ClassVar[str] = "Self-affine line with a rolloff: flat PSD below q_r, power law C0 q^(-2H-1) above"

    class Params(BandLimitedSpectrum.Params):
        rolloff_wavelength: float = Field(
            description="rolloff wavelength lambda_r = 2 pi / q_r, between short_cutoff and long_cutoff; "
            "psd is flat for longer waves",
            gt=0.0,
        )
