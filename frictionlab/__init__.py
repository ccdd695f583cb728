"""frictionlab: rms slope in contact against normal force, over ensembles of
random rough lines pressed into elastic bodies.

The framework (hooks, registry, presets, engine, fit, result files, CLI) lives
here; the physics lives in plugins (``frictionlab_spectra``,
``frictionlab_solvers``, ``frictionlab_slopes``) that register through the same
hooks as any third-party plugin.
"""

from importlib.metadata import PackageNotFoundError, version

from .hookspecs import hookimpl
from .inputs import InputFile, InputFileProblem, open_regular_file
from .plugin import (
    ContactCurve,
    ContactSolver,
    Control,
    ForceNormalisation,
    Plugin,
    PluginParams,
    Profile,
    SlopeEstimator,
    SpectrumGenerator,
    force_unit,
    mdr_length,
)

try:
    __version__ = version("frictionlab")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

__all__ = [
    "ContactCurve",
    "ContactSolver",
    "Control",
    "ForceNormalisation",
    "InputFile",
    "InputFileProblem",
    "Plugin",
    "PluginParams",
    "Profile",
    "SlopeEstimator",
    "SpectrumGenerator",
    "__version__",
    "force_unit",
    "hookimpl",
    "mdr_length",
    "open_regular_file",
]
