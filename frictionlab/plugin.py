"""The plugin contract: what a spectrum generator, a contact solver and a slope
estimator look like to the engine.

A plugin is a class with a kebab-case ``name`` (its key in a preset), a one-line
``summary``, optional ``references`` (DOIs) and a nested pydantic ``Params``
model. The constructor only stores validated parameters (scikit-learn style);
all work happens in the methods, and randomness arrives as a
``numpy.random.Generator`` argument.

Nothing here is physics: the built-in physics lives in ``plugins/``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, ValidationError

NAME_PATTERN = re.compile(r"^[a-z][a-z0-9]*(-[a-z0-9]+)*$")

Control = Literal["force", "indentation"]


class PluginParams(BaseModel):
    """Base for every plugin's ``Params``: unknown keys are errors, values are
    validated on assignment too (the TUI edits them in place)."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True)

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

    name: ClassVar[str] = ""
    summary: ClassVar[str] = ""
    references: ClassVar[tuple[str, ...]] = ()
    Params: ClassVar[type[PluginParams]] = PluginParams
    kind: ClassVar[str] = ""

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


@dataclass(frozen=True)
class Profile:
    """One periodic rough line, shape (N,), or surface, shape (Ny, Nx), with
    heights on a uniform grid of ``spacing`` (square pixels on a surface)."""

    heights: np.ndarray
    spacing: float

    @property
    def ndim(self) -> int:
        return int(np.ndim(self.heights))

    @property
    def points(self) -> int:
        return int(self.heights.size)

    @property
    def area(self) -> float:
        """Apparent (nominal) area of a surface; the length of a line."""
        return self.points * self.spacing**self.ndim

    @property
    def length(self) -> float:
        """The L of f = F / (k h L): the line's length, or for a surface of
        apparent area A the MDR-equivalent length 2 sqrt(A / pi) (SPEC section 7),
        so lines and surfaces share one f axis."""
        if self.ndim == 1:
            return self.points * self.spacing
        return 2.0 * float(np.sqrt(self.area / np.pi))


@dataclass(frozen=True)
class ContactCurve:
    """A solver's answer for one profile over a whole load sweep.

    Every array has one entry per load step, in the order of the loads given.
    ``slope_rms_contact`` is the rms, over the points in contact, of the slopes
    the engine passed in (from the chosen slope estimator).
    ``extras`` carries solver-specific per-load arrays (iterations, residuals).
    """

    force: np.ndarray
    indentation: np.ndarray
    contact_count: np.ndarray
    contact_fraction: np.ndarray
    slope_rms_contact: np.ndarray
    extras: dict[str, np.ndarray] = field(default_factory=dict)


# ---------------------------------------------------------------- plugin kinds


class SpectrumGenerator(Plugin):
    """Makes random rough lines.

    Subclasses implement ``generate(rng) -> Profile`` and ``rms_height()``, the
    h used in the dimensionless force f = F / (k h L) (the ensemble's nominal rms
    height: exact for fixed amplitudes, the expectation for random ones).
    Synthetic spectra also implement ``psd(q)`` (vectorised, one-sided 1D PSD
    with <z^2> = 2 * integral of psd over q > 0) and, where closed forms exist,
    ``rms_slope()``.
    """

    kind: ClassVar[str] = "spectrum"
    dimension: ClassVar[int] = 1  # 1: makes lines (N,); 2: makes surfaces (Ny, Nx)

    def generate(self, rng: np.random.Generator) -> Profile:  # pragma: no cover - interface
        raise NotImplementedError

    def rms_height(self) -> float:  # pragma: no cover - interface
        raise NotImplementedError

    def psd(self, q: np.ndarray) -> np.ndarray:
        raise NotImplementedError(f"{self.name} has no analytic power spectral density")

    def rms_slope(self) -> float:
        raise NotImplementedError(f"{self.name} has no closed-form rms slope")


class SlopeEstimator(Plugin):
    """Turns a profile into pointwise slopes.

    ``slopes(heights, spacing)`` returns an array of the same shape as
    ``heights``: the slope attributed to each point. The rms slope of the whole
    line and the rms slope over the points in contact are both formed from it,
    so the two always use the same estimator.
    """

    kind: ClassVar[str] = "slope"
    dimensions: ClassVar[tuple[int, ...]] = (1,)  # profile dimensions it accepts

    def slopes(self, heights: np.ndarray, spacing: float) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError


class ContactSolver(Plugin):
    """Presses a rigid profile into an elastic body over a sweep of loads.

    ``solve(profile, loads, control, slopes)`` returns a ``ContactCurve``;
    ``control`` says whether ``loads`` are total forces or indentations (rigid
    body approach, measured from the first touch). ``stiffness()`` is the
    modulus k in f = F / (k h L): E* for MDR, the foundation modulus for Winkler.
    """

    kind: ClassVar[str] = "solver"
    dimensions: ClassVar[tuple[int, ...]] = (1,)  # profile dimensions it accepts

    def solve(
        self, profile: Profile, loads: np.ndarray, control: Control, slopes: np.ndarray
    ) -> ContactCurve:  # pragma: no cover - interface
        raise NotImplementedError

    def stiffness(self) -> float:  # pragma: no cover - interface
        raise NotImplementedError


KINDS: dict[str, type[Plugin]] = {
    "spectrum": SpectrumGenerator,
    "solver": ContactSolver,
    "slope": SlopeEstimator,
}
