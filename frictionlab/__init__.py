"""frictionlab: rms slope in contact against normal force, over ensembles of
random rough lines pressed into elastic bodies.

The framework (the plugin contract, hooks, registry, presets, engine, fit, result
files) lives here, with its front ends (``cli``, ``tui``) and the studies built on
it (``paper``, ``tradeoff``); the physics lives in plugins (``frictionlab_spectra``,
``frictionlab_solvers``, ``frictionlab_slopes``) that register through the same
hooks as any third-party plugin. ARCHITECTURE.md draws the layers.
"""

from importlib.metadata import PackageNotFoundError, version

from .hookspecs import hookimpl
from .inputs import InputFile, InputFileProblem, open_regular_file
from .listeners import RunListener, SweepListener
from .options import RunOptions
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
    contract,
    force_unit,
    load_finished,
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
    "RunListener",
    "RunOptions",
    "SlopeEstimator",
    "SpectrumGenerator",
    "SweepListener",
    "__version__",
    "contract",
    "force_unit",
    "hookimpl",
    "load_finished",
    "mdr_length",
    "open_regular_file",
]
