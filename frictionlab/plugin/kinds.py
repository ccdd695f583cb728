"""The three kinds of plugin, each a base class declaring all the framework may use
of it (``contract(kind)``, checked by ``frictionlab.testing``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar, Literal

import numpy as np

from .base import Control, Plugin
from .data import ContactCurve, Profile
from .normalisation import ContactMeasure, ForceNormalisation



class SpectrumGenerator(Plugin):
    """Makes random rough lines (``dimension`` 1) or surfaces (``dimension`` 2).

    Required: ``generate(rng) -> Profile`` and ``rms_height()``, the h of the
    dimensionless force f (the ensemble's nominal rms height: exact for fixed
    amplitudes, the expectation for random ones).

    Optional, with the default the framework then uses:

    - ``psd(q)``: vectorised one-sided PSD (1D: ``<z^2> = 2 * integral of psd`` over
      q > 0); ``rms_slope()``: a closed-form rms slope. Default: NotImplementedError.
    - ``periodic()``: whether generated profiles repeat (default True). A measured
      scan is not periodic: slopes never wrap, periodic solvers refuse it.
    - ``not_periodic_advice()``: when ``periodic()`` is False, why (with the parameter
      at cause) and how to make the profile periodic, as ``(why, how)``: a refusal by a
      periodic-only solver or estimator says both. Default: general advice.
    - ``deterministic`` (False): True for a generator that ignores its rng by design (one that
      reads a measured profile): every realization is then the same profile. A run asks of
      realization 0, once, that a fresh generator of its seed give the same heights again and,
      unless ``deterministic``, that another seed give other heights; the conformance kit asks
      the same.
    - ``grid_shape()``: the shape of a generated profile, known without generating
      (memory estimates). Default None: the framework generates one profile.
    - ``points_param``: the ``Params`` field that sets the points (per side); the
      framework names it in advice ("spectrum.params.points <= ..."). Default None.
    - ``refined(points)``: the ``Params`` changes that sample the same continuous
      spectrum (same length, same cut-off wavelengths) on ``points`` points per
      side: the trade-off study's grid axis. Default None (cannot be refined).
    - ``equivalent_line()``: for a surface, its MDR-equivalent line (a spectrum of
      lines whose length is ``mdr_length`` of the surface's area), which a solver
      of lines presses instead. Default None (no MDR mapping).
    - ``equivalent_line_bytes()``: the peak memory ``equivalent_line()`` allocates (reading
      a measured map included), known without making the line: the memory check runs
      before it is made. Default None: the framework assumes its own upper bound per point
      of ``grid_shape()`` (``frictionlab.compute.memory.EQUIVALENT_LINE_BYTES_PER_POINT``).
    - ``c0()``: the prefactor C0 of a power-law PSD. Default NotImplementedError.
    - ``hurst_exponent()``: H of a self-affine spectrum, or None (the default).
    - ``input_summary()``: for a profile or surface read from a file, what was read and
      used, JSON-ready: at least ``file``, ``shape``, ``spacing``, ``unit`` (None when the
      numbers carry none) and ``rms_height``, and where each came from (the file or the
      preset). ``frictionlab validate``, the API, the TUI and summary.json show it.
      Default None (nothing read).
    - ``caveats()``: what a reader of any run of this spectrum should know, from its
      parameters alone (a short cut-off on too few pixels:
      ``frictionlab.short_cutoff_caveat``), as sentences; the run lists them with its
      own caveats and ``frictionlab validate`` prints them. Default ``()``.
    - ``profile_rms_height(profile)``: the h of f for one generated profile, when it is
      the profile's own (its measured rms height); None (the default) when it is the
      nominal ``rms_height()``. The lines of one ensemble must then share one h (to a
      relative 1e-9: the spectrum scales each to it), since f is one axis for all.
    """

    kind: ClassVar[str] = "spectrum"
    register_hook: ClassVar[str] = "register_spectra"
    dimension: ClassVar[int] = 1  # 1: makes lines (N,); 2: makes surfaces (Ny, Nx)
    points_param: ClassVar[str | None] = None
    deterministic: ClassVar[bool] = False

    def generate(self, rng: np.random.Generator) -> Profile:  # pragma: no cover - interface
        raise NotImplementedError

    def rms_height(self) -> float:  # pragma: no cover - interface
        raise NotImplementedError

    def psd(self, q: np.ndarray) -> np.ndarray:
        raise NotImplementedError(f"{self.name} has no analytic power spectral density")

    def rms_slope(self) -> float:
        raise NotImplementedError(f"{self.name} has no closed-form rms slope")

    def periodic(self) -> bool:
        return True

    def not_periodic_advice(self) -> tuple[str, str]:
        return (f"spectrum {self.name} is not periodic with these parameters",
                "choose spectrum parameters that make a periodic profile (frictionlab schema lists them)")  # fmt: skip

    def grid_shape(self) -> tuple[int, ...] | None:
        return None

    def refined(self, points: int) -> dict[str, Any] | None:
        return None

    def equivalent_line(self) -> SpectrumGenerator | None:
        return None

    def equivalent_line_bytes(self) -> int | None:
        return None

    def c0(self) -> float:
        raise NotImplementedError(f"{self.name} is not a power-law spectrum: it has no prefactor C0")

    def hurst_exponent(self) -> float | None:
        return None

    def input_summary(self) -> dict[str, Any] | None:
        return None

    def caveats(self) -> tuple[str, ...]:
        return ()

    def profile_rms_height(self, profile: Profile) -> float | None:
        return None


class SlopeEstimator(Plugin):
    """Turns a profile into pointwise slopes.

    ``slopes(heights, spacing, periodic)`` returns an array of the same shape as
    ``heights``: the slope attributed to each point, dz/dx with its sign on a line and the
    gradient's magnitude |grad z| >= 0 on a surface (a tilted plane's every slope is its
    tilt; ``frictionlab.testing`` checks both). The rms slope of the whole
    line and the rms slope over the points in contact are both formed from it,
    so the two always use the same estimator. With ``periodic=False`` (a scan
    whose ends do not meet) no difference may reach across the ends.

    ``periodic_only``: True for an estimator that cannot treat a non-periodic
    profile (a preset pairing it with one is refused).

    ``undefined_points(periodic)``: True when ``slopes(..., periodic)`` leaves some
    points (the ends of a non-periodic line) without a slope, as NaN. Those points
    count in no rms, and a solver must declare ``undefined_slopes`` to be given
    them. Default False: every slope is finite.
    """

    kind: ClassVar[str] = "slope"
    register_hook: ClassVar[str] = "register_slope_estimators"
    dimensions: ClassVar[tuple[int, ...]] = (1,)  # profile dimensions it accepts
    periodic_only: ClassVar[bool] = False

    def slopes(self, heights: np.ndarray, spacing: float, periodic: bool = True) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def undefined_points(self, periodic: bool) -> bool:
        return False


IndentationReference = Literal["undeformed body", "mean surface"]
"""Where a solver's indentation is measured from: both start at the first touch of
the highest point; "undeformed body": against the elastic body far from the
contact (springs: their base does not move); "mean surface": against the mean
plane of the deformed elastic surface (a periodic elastic body, whose mean
displacement is its rigid-body mode)."""


class ContactSolver(Plugin):
    """Presses a rigid profile into an elastic body over a sweep of loads.

    Required:

    - ``solve(profile, loads, control, slopes) -> ContactCurve``: ``control`` says
      whether ``loads`` are total loads or indentations (rigid-body approach from
      the first touch).
    - ``stiffness()``: the modulus k of f = F / (k h X).
    - ``normalisations``: for each profile dimension in ``dimensions``, what the
      load means and which combination is dimensionless (``ForceNormalisation``).
      The framework forms f from it only (``force_unit``).
    - ``problem``: the physical problem solved, in a few words ("elastic
      half-space"); solvers of one problem can be compared at equal f.

    Optional, with defaults:

    - ``approximation`` (False): True when the solver models its problem only
      approximately (MDR for the half-space); the study compares it with an exact one.
    - ``contact_measure`` ("real contact"): what ``contact_fraction`` measures.
    - ``corrected_area`` (False): True when ``solve`` also gives the real area
      corrected for the contact's perimeter (``ContactCurve.real_area_corrected``);
      the results then carry it beside the pixel count.
    - ``real_gradient`` (False): True when ``solve`` also gives g_r, the rms slope over
      the perimeter-corrected real contact (``ContactCurve.real_gradient_rms``); the
      results then carry it, with kappa and kappa_r, beside the area.
    - ``counts_spots`` (False): True when ``solve`` also counts the contact spots
      (``ContactCurve.contact_spots``); the results then carry their number.
    - ``indentation_reference`` ("undeformed body") and ``mean_displacement(f, h)``
      (zero): the mean displacement of the elastic surface in the indentation's
      frame, so that ``indentation - mean_displacement`` is measured from the mean
      plane of the deformed surface for every solver.
    - ``mean_displacement_known`` (True): False for a solver whose mean displacement
      depends on each surface, not on f and h alone, so ``mean_displacement`` cannot
      give it (a free-boundary half-space): a study then compares no indentations.
    - ``periodic_only`` (False): True for a solver of periodic profiles only.
    - ``mdr_lines`` (False): True for a solver of lines alone (``dimensions`` ``(1,)``) whose line
      models a surface by the method of dimensionality reduction (MDR): a surface is then pressed
      as its spectrum's MDR-equivalent line (``SpectrumGenerator.equivalent_line()``). False: a
      preset giving it a surface is refused; a solver of lines does not press a surface's line
      unless it says that line stands for the surface.
    - ``body_params`` (()): the ``Params`` fields describing the elastic body (not
      the numerics); a study carries them from one solver to another that has them.
    - ``tolerance_param`` (None): the ``Params`` field of the relative tolerance of
      an iterative solver; ``tolerance()`` reads it (None for a direct solver).
    - ``bytes_per_point`` (None): the peak memory ``solve`` allocates per grid point,
      beyond the profile and slopes it is given (memory estimates before a run).
      None: the framework's figure for a line solver (``memory.BYTES_PER_POINT``).
    - ``max_f`` (None): the largest dimensionless force f the solver's arithmetic holds
      (an iterative solver's single-precision steps overflow past it); the framework
      refuses a load past it before the run. None: no limit short of double precision.
    - ``full_contact_load(profile)`` (None): the load at which every point of ``profile``
      is in contact, exactly, where the solver knows it without a solve (springs, from
      the heights); ``frictionlab validate`` shows it. None: not known short of solving.
    - ``full_contact_indentation(profile)`` (None): the indentation that no finite load
      reaches, where there is one (a periodic half-space: the approach to the mean surface
      saturates at max z - mean z, at full contact); an indentation at or past it is
      refused before the run. None: every indentation has a finite load.
    - ``undefined_slopes`` (False): True when ``solve`` takes slopes with NaN at
      points that have no slope, and forms ``slope_rms_contact`` over the contact
      points whose slope is defined (``defined_rms``), NaN at a load where none is.
    """

    kind: ClassVar[str] = "solver"
    register_hook: ClassVar[str] = "register_solvers"
    dimensions: ClassVar[tuple[int, ...]] = (1,)  # profile dimensions it accepts
    normalisations: ClassVar[Mapping[int, ForceNormalisation]] = {}
    problem: ClassVar[str] = ""
    approximation: ClassVar[bool] = False
    contact_measure: ClassVar[ContactMeasure] = "real contact"
    corrected_area: ClassVar[bool] = False
    real_gradient: ClassVar[bool] = False
    counts_spots: ClassVar[bool] = False
    indentation_reference: ClassVar[IndentationReference] = "undeformed body"
    mean_displacement_known: ClassVar[bool] = True
    periodic_only: ClassVar[bool] = False
    mdr_lines: ClassVar[bool] = False
    body_params: ClassVar[tuple[str, ...]] = ()
    tolerance_param: ClassVar[str | None] = None
    bytes_per_point: ClassVar[int | None] = None
    undefined_slopes: ClassVar[bool] = False
    max_f: ClassVar[float | None] = None

    def solve(
        self, profile: Profile, loads: np.ndarray, control: Control, slopes: np.ndarray
    ) -> ContactCurve:  # pragma: no cover - interface
        raise NotImplementedError

    def stiffness(self) -> float:  # pragma: no cover - interface
        raise NotImplementedError

    @classmethod
    def normalisation(cls, dimension: int) -> ForceNormalisation:
        """The normalisation of f on a profile of ``dimension`` (1 or 2)."""
        try:
            return cls.normalisations[dimension]
        except KeyError:
            raise ValueError(f"{cls.name} declares no normalisation of f for {dimension}D profiles") from None

    def mean_displacement(self, f: np.ndarray, rms_height: float) -> np.ndarray:
        """Mean displacement of the elastic surface at dimensionless force ``f``, in
        the frame of the reported indentation (zero: measured from the mean plane)."""
        return np.zeros_like(np.asarray(f, dtype=float))

    def full_contact_load(self, profile: Profile) -> float | None:
        """The load at which every point of ``profile`` is in contact; None when only a solve would say."""
        return None

    def full_contact_indentation(self, profile: Profile) -> float | None:
        """The indentation of ``profile`` no finite load reaches; None when there is none."""
        return None

    def tolerance(self) -> float | None:
        """The relative tolerance the solver iterates to; None for a direct solver."""
        if self.tolerance_param is None:
            return None
        return float(self.params.model_dump()[self.tolerance_param])




def contract(kind: str) -> frozenset[str]:
    """Every name the framework may use of a plugin of ``kind``: the public attributes and
    methods of its base class (and of ``Plugin``), declared above; nothing else. ValueError
    naming the kinds for another ``kind``."""
    if kind not in KINDS:  # a bare KeyError('solvers') said neither what is allowed nor what was asked
        raise ValueError(f"kind must be one of {', '.join(map(repr, KINDS))}. Got {kind!r} instead.")
    base = KINDS[kind]
    annotated = {name for cls in base.__mro__ for name in cls.__dict__.get("__annotations__", {})}
    return frozenset(name for name in {*dir(base), *annotated} if not name.startswith("_"))


REQUIRED: dict[str, tuple[str, ...]] = {  # the methods a plugin of each kind must implement itself
    "spectrum": ("generate", "rms_height"),
    "solver": ("solve", "stiffness"),
    "slope": ("slopes",),
}

KINDS: dict[str, type[Plugin]] = {  # by the name of each kind's section in a preset
    "spectrum": SpectrumGenerator,
    "solver": ContactSolver,
    "slope": SlopeEstimator,
}
