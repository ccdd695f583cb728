"""The plugin contract: everything the framework may use of a spectrum
generator, a contact solver and a slope estimator, declared in this package and nowhere else.

A plugin is a class with a kebab-case ``name`` (its key in a preset), a one-line
``summary``, optional ``references`` (DOIs) and a nested pydantic ``Params``
model. The constructor only stores validated parameters (scikit-learn style);
all work happens in the methods, and randomness arrives as a
``numpy.random.Generator`` argument.

The framework reads a plugin only through the class attributes and methods
declared on ``SpectrumGenerator``, ``ContactSolver`` and ``SlopeEstimator``
(``kinds``; optional ones have defaults), listed by ``contract(kind)``;
``frictionlab.testing.check_plugin`` checks each of them. Of ``params`` it reads
the values (the resolved preset) and the fields annotated ``frictionlab.InputFile``:
files it takes relative to the preset's folder, checks before the run and records
with their SHA-256. The dimensionless force f is formed in one place,
``ForceNormalisation.force_unit``, from what the solver declares its load to mean
(``ContactSolver.normalisations``).

Nothing here is physics: the built-in physics lives in ``plugins/``.
"""


from .base import MAX_MAGNITUDE, NAME_PATTERN, Control, Plugin, PluginParams
from .data import ContactCurve, Profile, half_load_points, mdr_length
from .kinds import KINDS, ContactSolver, IndentationReference, SlopeEstimator, SpectrumGenerator, contract
from .resolution import MIN_SHORT_CUTOFF_PIXELS, short_cutoff_caveat
from .normalisation import ContactMeasure, Extent, ForceNormalisation, LoadMeaning, PressureArea, defined_rms, force_unit
from .solve_progress import SolveCancelled, SolveFailed, iteration_done, listening_to_iterations, listening_to_loads, load_finished

__all__ = [
    "KINDS", "MAX_MAGNITUDE", "MIN_SHORT_CUTOFF_PIXELS", "NAME_PATTERN",
    "ContactCurve", "ContactSolver", "Control", "Extent",
    "ContactMeasure", "ForceNormalisation", "IndentationReference", "LoadMeaning", "PressureArea", "Plugin", "PluginParams", "Profile", "SlopeEstimator",
    "SolveCancelled", "SolveFailed", "SpectrumGenerator", "contract", "defined_rms", "force_unit", "half_load_points",
    "iteration_done", "listening_to_iterations", "listening_to_loads", "load_finished", "mdr_length",
    "short_cutoff_caveat",
]  # fmt: skip
