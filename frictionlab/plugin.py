"""The plugin contract: everything the framework may use of a spectrum
generator, a contact solver and a slope estimator, declared here and nowhere else.

A plugin is a class with a kebab-case ``name`` (its key in a preset), a one-line
``summary``, optional ``references`` (DOIs) and a nested pydantic ``Params``
model. The constructor only stores validated parameters (scikit-learn style);
all work happens in the methods, and randomness arrives as a
``numpy.random.Generator`` argument.

The framework reads a plugin only through the class attributes and methods
declared on ``SpectrumGenerator``, ``ContactSolver`` and ``SlopeEstimator``
below (optional ones have defaults), listed by ``contract(kind)``;
``frictionlab.testing.check_plugin`` checks each of them. Of ``params`` it reads
the values (the resolved preset) and the fields annotated ``frictionlab.InputFile``:
files it takes relative to the preset's folder, checks before the run and records
with their SHA-256. The dimensionless force f is formed in one place,
``ForceNormalisation.force_unit``, from what the solver declares its load to mean
(``ContactSolver.normalisations``).

Nothing here is physics: the built-in physics lives in ``plugins/``.
"""

from __future__ import annotations

import math
import re
import threading
from collections.abc import Callable, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationError

NAME_PATTERN = re.compile(r"^[a-z][a-z0-9]*(-[a-z0-9]+)*$")

Control = Literal["force", "indentation"]
"""What a sweep's loads are: total loads (see ``LoadMeaning``) or indentations."""


MAX_MAGNITUDE = 1e100  # numbers frictionlab reads: 0, or 1e-100 <= |x| <= 1e100 (products of a few stay finite)


class PluginParams(BaseModel):
    """Base for every plugin's ``Params``: unknown keys are errors, values are
    validated on assignment too (the TUI edits them in place). Each validator is built
    when its plugin is first used, not when its module is imported (``defer_build``):
    a run pays for its own plugins only."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True, defer_build=True)

    def __setattr__(self, name, value):
        # pydantic keeps a value that fails a model-level check on assignment;
        # put the old one back so a rejected edit leaves the params valid.
        previous = dict(self.__dict__)
        try:
            super().__setattr__(name, value)
        except ValidationError:
            self.__dict__.update(previous)
            raise


class Plugin:
    """Common base: stores parameters, nothing else.

    ``Plugin(params)`` takes a ready ``Params`` instance; ``Plugin(**kwargs)``
    validates keyword arguments through ``Params``.
    """

    name: ClassVar[str] = ""  # kebab-case, the plugin's key in a preset
    summary: ClassVar[str] = ""  # one line
    references: ClassVar[tuple[str, ...]] = ()  # DOIs
    Params: ClassVar[type[PluginParams]] = PluginParams
    kind: ClassVar[str] = ""  # set by the kind's base class, never by a plugin
    params: PluginParams  # the validated parameters, the only state the constructor keeps

    def __init__(self, params: PluginParams | None = None, **kwargs):
        if params is not None and kwargs:
            raise TypeError("give either a Params instance or keyword arguments, not both")
        if params is None:
            params = self.Params(**kwargs)
        elif not isinstance(params, self.Params):
            raise TypeError(
                f"params must be an instance of {type(self).__name__}.Params. "
                f"Got {type(params).__name__} instead."
            )
        self.params = params

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.model_dump().items())
        return f"{type(self).__name__}({args})"


# --------------------------------------------------------------------------- data


def mdr_length(area: float) -> float:
    """L = 2 sqrt(A / pi): the length of the MDR line that stands for a surface of
    apparent area A (the diameter of a disc of that area)."""
    return 2.0 * math.sqrt(area / math.pi)


@dataclass(frozen=True)
class Profile:
    """One rough line, shape (N,), or surface, shape (Ny, Nx), with heights on a
    uniform grid of ``spacing`` (square pixels on a surface).

    ``periodic``: whether the profile repeats (its last point is followed by its
    first), as a synthetic spectrum's lines do; a measured scan's ends do not
    meet, so slopes are never taken across them and periodic solvers refuse it.
    """

    heights: np.ndarray
    spacing: float
    periodic: bool = True

    @property
    def ndim(self) -> int:
        return int(np.ndim(self.heights))

    @property
    def points(self) -> int:
        return int(self.heights.size)

    @property
    def area(self) -> float:
        """The measure of the grid: a line's length N dx, a surface's apparent area A."""
        return self.points * self.spacing**self.ndim


@dataclass(frozen=True)
class ContactCurve:
    """A solver's answer for one profile over a whole load sweep.

    Every array has one entry per load step, in the order of the loads given.
    ``force`` holds the total loads (their meaning: the solver's ``LoadMeaning``);
    ``indentation`` the rigid-body approach from the first touch, in the frame the
    solver declares (``ContactSolver.indentation_reference``).
    ``contact_fraction`` is ``contact_count / points`` (what it measures: the
    solver's ``contact_measure``).
    ``slope_rms_contact`` is the rms, over the points in contact, of the slopes
    the engine passed in (from the chosen slope estimator).
    ``real_area_corrected``: the real contact area corrected for the pixels the
    contact's perimeter crosses, a fraction of the nominal area; given exactly when
    the solver declares ``corrected_area``, None otherwise.
    ``real_gradient_rms``: g_r, the rms of the slopes over the real contact, each contact
    pixel weighted by its share of the perimeter-corrected area (N - c M pixels, with
    ``c = 0`` it is ``slope_rms_contact``); dimensionless, a slope. Given exactly when the
    solver declares ``real_gradient``, None otherwise.
    ``contact_spots``: the number of contact spots (clusters of contact pixels joined along
    rows and columns), given exactly when the solver declares ``counts_spots``.
    ``half_load_points``: how many points carry half the load (the fewest whose loads,
    largest first, sum to half the total): a spike or a single island carrying the
    load shows as a small number; None when the solver does not say.
    ``extras`` carries solver-specific per-load arrays (iterations, residuals).
    """

    force: np.ndarray
    indentation: np.ndarray
    contact_count: np.ndarray
    contact_fraction: np.ndarray
    slope_rms_contact: np.ndarray
    real_area_corrected: np.ndarray | None = None
    real_gradient_rms: np.ndarray | None = None
    contact_spots: np.ndarray | None = None
    extras: dict[str, np.ndarray] = field(default_factory=dict)
    half_load_points: np.ndarray | None = None


def half_load_points(point_loads: np.ndarray) -> int:
    """How many points carry half the load: the fewest of ``point_loads`` (each point's
    share, >= 0), taken largest first, whose sum reaches half the total; 0 for no load."""
    loads = np.sort(np.ravel(np.asarray(point_loads, dtype=float)))[::-1]
    total = float(loads.sum())
    if not total > 0:
        return 0
    return int(np.searchsorted(np.cumsum(loads), 0.5 * total) + 1)


# ------------------------------------------------------------ what a load means

LoadMeaning = Literal["force", "force per unit depth"]
"""A solver's load: a total force (a 3D contact, or a line of springs), or a force
per unit depth (plane strain: a profile straight in the third direction)."""

Extent = Literal["one", "length", "area", "mdr length"]
"""The size X in f = F / (k h X): nothing (one), the line's length L = N dx, the
surface's apparent area A, or a surface's MDR length 2 sqrt(A / pi)."""

_LOAD_SYMBOLS = {"force": "F", "force per unit depth": "F'"}
_EXTENT_SYMBOLS = {"one": "", "length": " L", "area": " A", "mdr length": " L"}
_EXTENT_DEFINITIONS = {
    "one": "",
    "length": "L the line's length",
    "area": "A the surface's apparent area",
    "mdr length": "L = 2 sqrt(A / pi), A the surface's apparent area",
}
_EXTENT_DIMENSIONS = {"one": (1, 2), "length": (1,), "area": (2,), "mdr length": (2,)}
_EXTENT_POWERS = {"one": 0, "length": 1, "area": 2, "mdr length": 1}  # X ~ length^power

PressureArea = Literal["", "profile", "mdr disc"]
"""The area A of a nominal pressure p = load / A, where p over the modulus is dimensionless:
"profile" (a surface's apparent area; a line's length for a force per unit depth),
"mdr disc" (the disc of area pi L^2 / 4 whose MDR line has length L), "" (none: the
modulus is not a stress, or the line stands for no area)."""
_PRESSURE_EXTENTS = {"profile": ("one", "mdr length"), "mdr disc": ("length",), "": tuple(_EXTENT_SYMBOLS)}


@dataclass(frozen=True)
class ForceNormalisation:
    """What a solver's load means and which combination of it is dimensionless:
    ``f = F / (k h X)``, k the solver's ``stiffness()`` (named ``modulus``, e.g.
    ``"E*"``), h the spectrum's ``rms_height()``, X the profile's ``extent``.

    A quantity so formed does not change when the unit of length or of force
    changes (every length x s, every modulus x m, the load as k h X: a force x m s^2
    against a stress), provided ``stiffness()`` is a modulus of the right unit: a
    stress (E*, or a foundation modulus per unit length of a line) when the extent
    is a length or one, a stress per length when it is an area. So the extent fixes
    the load: a force per unit depth over k h (extent one), a force otherwise.
    """

    load: LoadMeaning
    modulus: str
    extent: Extent
    # What X is, in words, where the profile's own words would mislead (an MDR-equivalent
    # line: its length is 2 sqrt(A / pi) of the surface it stands for); "" for the usual ones.
    extent_words: str = ""
    # Where a load may be given as a nominal pressure over the modulus, p / k (``PressureArea``).
    pressure_area: PressureArea = ""

    def __post_init__(self):
        if self.load not in _LOAD_SYMBOLS:
            raise ValueError(f"load must be one of {', '.join(_LOAD_SYMBOLS)}. Got {self.load!r} instead.")
        if self.extent not in _EXTENT_SYMBOLS:
            raise ValueError(f"extent must be one of {', '.join(_EXTENT_SYMBOLS)}. Got {self.extent!r} instead.")
        expected = "force per unit depth" if self.extent == "one" else "force"
        if self.load != expected:
            raise ValueError(
                f"a load over k h{_EXTENT_SYMBOLS[self.extent]} is a {expected} (k a modulus of the right unit), "
                f"not a {self.load}: f would not be dimensionless"
            )
        if self.extent not in _PRESSURE_EXTENTS.get(self.pressure_area, ()):
            raise ValueError(
                f"pressure_area {self.pressure_area!r} is not a dimensionless pressure with extent {self.extent!r}: "
                "'profile' goes with extent 'one' or 'mdr length', 'mdr disc' with 'length'"
            )
        if not (isinstance(self.modulus, str) and self.modulus.strip()):
            raise ValueError(f"modulus must name the stiffness, e.g. 'E*'. Got {self.modulus!r} instead.")

    @property
    def load_symbol(self) -> str:
        """F for a force, F' for a force per unit depth."""
        return _LOAD_SYMBOLS[self.load]

    @property
    def load_unit(self) -> str:
        """The unit of the load in the units of the preset, that of k h X: ``modulus x length^2``
        for a force against a stress (``modulus x length^3`` against a modulus per area)."""
        power = 1 + _EXTENT_POWERS[self.extent]
        return "modulus x length" + (f"^{power}" if power > 1 else "")

    @property
    def formula(self) -> str:
        """``F / (E* h L)``: the dimensionless force in symbols."""
        return f"{self.load_symbol} / ({self.modulus} h{_EXTENT_SYMBOLS[self.extent]})"

    @property
    def definition(self) -> str:
        """``f = F / (E* h L), L = 2 sqrt(A / pi), ...``: the formula with its symbols explained."""
        where = [f"{self.load_symbol} the {self.load}", "h the rms height"]
        if self.extent != "one":
            where.append(self.extent_words or _EXTENT_DEFINITIONS[self.extent])
        return f"f = {self.formula}, " + ", ".join(where)

    def extent_of(self, profile: Profile) -> float:
        """X of f = F / (k h X) for ``profile``."""
        if profile.ndim not in _EXTENT_DIMENSIONS[self.extent]:
            raise ValueError(f"the extent {self.extent!r} is not defined for a {profile.ndim}D profile")
        if self.extent == "one":
            return 1.0
        if self.extent == "mdr length":
            return mdr_length(profile.area)
        return profile.area  # a line's length, or a surface's area

    def nominal_area(self, profile: Profile) -> float | None:
        """A of the nominal pressure p = load / A on ``profile`` (``pressure_area``); None where
        p over the modulus is not dimensionless."""
        if not self.pressure_area:
            return None
        if self.pressure_area == "mdr disc":
            return math.pi * profile.area**2 / 4.0  # the line's length is 2 sqrt(A / pi)
        return profile.area

    def force_unit(self, stiffness: float, rms_height: float, extent: float) -> float:
        """k h X: the load at which f = 1. The one place where f is formed: f = load / force_unit."""
        return float(stiffness) * float(rms_height) * float(extent)

    def describe(self, stiffness: float, rms_height: float, extent: float) -> dict[str, Any]:
        """The normalisation as summary.json records it."""
        return {
            "f": self.definition,
            "formula": self.formula,
            "load": self.load,
            "load_symbol": self.load_symbol,
            "load_unit": self.load_unit,
            "modulus": self.modulus,
            "stiffness": stiffness,
            "rms_height": rms_height,
            "extent": self.extent,
            "extent_value": extent,
            "force_unit": self.force_unit(stiffness, rms_height, extent),
        }


ContactMeasure = Literal["real contact", "mdr springs"]
"""What ``contact_fraction`` measures: the real contact (area fraction of a surface,
length fraction of a line, of the solver's physical problem), or the fraction of
MDR springs in contact, which is not the real area of the surface MDR stands for."""


def force_unit(solver: "ContactSolver", rms_height: float, profile: Profile) -> float:
    """k h X: the load at which f = 1 for ``solver`` pressing ``profile`` of rms height h
    (the spectrum's ``profile_rms_height``), as the solver's ``normalisation`` forms it
    (``ForceNormalisation.force_unit``)."""
    normalisation = solver.normalisation(profile.ndim)
    return normalisation.force_unit(solver.stiffness(), rms_height, normalisation.extent_of(profile))


def defined_rms(values: np.ndarray) -> float:
    """The root mean square of the values that are defined (not NaN): a slope
    estimator may leave points without a slope (``SlopeEstimator.undefined_points``).
    NaN if none is; for all-defined values, exactly sqrt(mean(values^2))."""
    squares = np.square(values)
    mean = float(np.mean(squares))
    if math.isnan(mean):  # some value is undefined: one more pass, only then
        squares = squares[~np.isnan(squares)]
        mean = float(np.mean(squares)) if squares.size else math.nan
    return math.sqrt(mean)


# ---------------------------------------------------------------- plugin kinds


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
    - ``c0()``: the prefactor C0 of a power-law PSD. Default NotImplementedError.
    - ``hurst_exponent()``: H of a self-affine spectrum, or None (the default).
    - ``input_summary()``: for a profile or surface read from a file, what was read and
      used, JSON-ready: at least ``file``, ``shape``, ``spacing``, ``unit`` (None when the
      numbers carry none) and ``rms_height``, and where each came from (the file or the
      preset). ``frictionlab validate``, the API, the TUI and summary.json show it.
      Default None (nothing read).
    - ``profile_rms_height(profile)``: the h of f for one generated profile, when it is
      the profile's own (its measured rms height); None (the default) when it is the
      nominal ``rms_height()``. The lines of one ensemble must then share one h (to a
      relative 1e-9: the spectrum scales each to it), since f is one axis for all.
    """

    kind: ClassVar[str] = "spectrum"
    register_hook: ClassVar[str] = "register_spectra"
    dimension: ClassVar[int] = 1  # 1: makes lines (N,); 2: makes surfaces (Ny, Nx)
    points_param: ClassVar[str | None] = None

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

    def c0(self) -> float:
        raise NotImplementedError(f"{self.name} is not a power-law spectrum: it has no prefactor C0")

    def hurst_exponent(self) -> float | None:
        return None

    def input_summary(self) -> dict[str, Any] | None:
        return None

    def profile_rms_height(self, profile: Profile) -> float | None:
        return None


class SlopeEstimator(Plugin):
    """Turns a profile into pointwise slopes.

    ``slopes(heights, spacing, periodic)`` returns an array of the same shape as
    ``heights``: the slope attributed to each point. The rms slope of the whole
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

    def tolerance(self) -> float | None:
        """The relative tolerance the solver iterates to; None for a direct solver."""
        if self.tolerance_param is None:
            return None
        return float(self.params.model_dump()[self.tolerance_param])


# ------------------------------------------------------------ progress of a solve

_listening = threading.local()  # per thread: ``load`` and ``iteration``, the listeners of the solve it runs


def load_finished(done: int, total: int) -> None:
    """A solver whose loads take long calls this after each load of ``solve``: ``done``
    of its ``total`` loads are solved. The run forwards it to its listeners
    (``RunListener.load_done``); outside a run that listens it does nothing."""
    listener = getattr(_listening, "load", None)
    if listener is not None:
        listener(done, total)


class SolveCancelled(Exception):
    """Raised by ``iteration_done`` inside a solver's loop when the run it belongs to
    is cancelled (the TUI's cancel, Ctrl-C, SIGTERM). A solver lets it propagate: the
    realization is then neither stored nor counted as failed, and runs again on resume."""


def iteration_done(iteration: int, residual: float) -> None:
    """An iterative solver calls this once per iteration of its inner loop: ``iteration``
    steps of the current load are done and its relative residual is ``residual``. The run
    forwards it, coalesced, to its listeners as progress within a load, and raises
    ``SolveCancelled`` here once the run is cancelled, so a long solve stops within a
    fraction of a second. Outside a run that listens it does nothing (and costs a call)."""
    listener = getattr(_listening, "iteration", None)
    if listener is not None:
        listener(iteration, residual)


@contextmanager
def _listening_to(kind: str, listener):
    previous = getattr(_listening, kind, None)
    setattr(_listening, kind, listener)
    try:
        yield
    finally:
        setattr(_listening, kind, previous)


def listening_to_loads(listener: Callable[[int, int], None] | None):
    """Within the block, ``load_finished(done, total)`` calls ``listener`` (this thread only)."""
    return _listening_to("load", listener)


def listening_to_iterations(listener: Callable[[int, float], None] | None):
    """Within the block, ``iteration_done(iteration, residual)`` calls ``listener``, which
    may raise ``SolveCancelled`` (this thread only: a solve abandoned in another thread
    never hears the next run's listeners)."""
    return _listening_to("iteration", listener)


def contract(kind: str) -> frozenset[str]:
    """Every name the framework may use of a plugin of ``kind``: the public attributes and
    methods of its base class (and of ``Plugin``), declared above; nothing else."""
    base = KINDS[kind]
    annotated = {name for cls in base.__mro__ for name in cls.__dict__.get("__annotations__", {})}
    return frozenset(name for name in {*dir(base), *annotated} if not name.startswith("_"))


KINDS: dict[str, type[Plugin]] = {  # by the name of each kind's section in a preset
    "spectrum": SpectrumGenerator,
    "solver": ContactSolver,
    "slope": SlopeEstimator,
}
