"""What a load means: the force unit that makes f = F / (E* h X) dimensionless,
formed in one place from what a solver declares its load to be."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from .data import Profile, mdr_length

if TYPE_CHECKING:
    from .kinds import ContactSolver


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
_MODULUS_DEFINITIONS = {
    "E*": "E* = E / (1 - nu^2) the contact modulus",
    "k": "k the foundation's modulus",
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
    # What the modulus is, in words, for a symbol other than E* and k (``"G the shear modulus"``);
    # "" says "<modulus> the solver's modulus".
    modulus_words: str = ""
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
        """``f = F / (E* h L), F the force, E* = E / (1 - nu^2) ...``: the formula with its symbols explained."""
        where = [f"{self.load_symbol} the {self.load}", self.modulus_definition, "h the rms height"]
        if self.extent != "one":
            where.append(self.extent_words or _EXTENT_DEFINITIONS[self.extent])
        return f"f = {self.formula}, " + ", ".join(where)

    @property
    def modulus_definition(self) -> str:
        """``E* = E / (1 - nu^2) the contact modulus``: what the modulus of f is."""
        known = _MODULUS_DEFINITIONS.get(self.modulus, f"{self.modulus} the solver's modulus")
        return self.modulus_words or known

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
