"""frictionlab: rms slope in contact against normal force, over ensembles of
random rough lines pressed into elastic bodies.

The framework (the plugin contract, hooks, registry, presets, engine, fit, result
files) lives here, with its front ends (``cli``, ``tui``) and the studies built on
it (``paper``, ``tradeoff``); the physics lives in plugins (``frictionlab_spectra``,
``frictionlab_solvers``, ``frictionlab_slopes``) that register through the same
hooks as any third-party plugin. ARCHITECTURE.md draws the layers.

For notebooks and scripts: ``frictionlab.run(preset, **overrides)`` returns a
``Result`` (the fit, the table per load step, a plot); ``frictionlab.load(folder)``
reads a finished run back (``frictionlab.api``). They are imported on first use,
so ``import frictionlab`` stays cheap.
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
    mdr_length,
)

try:
    __version__ = version("frictionlab")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

_LAZY = {"run": "api", "load": "api", "Result": "api"}  # imported on first use (PEP 562)


def __getattr__(name: str):
    if name in _LAZY:
        from importlib import import_module

        value = getattr(import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'frictionlab' has no attribute {name!r}")


def __dir__():
    return sorted([*globals(), *_LAZY])


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
    "Result",
    "RunListener",
    "RunOptions",
    "SlopeEstimator",
    "SpectrumGenerator",
    "SweepListener",
    "__version__",
    "contract",
    "force_unit",
    "hookimpl",
    "load",
    "mdr_length",
    "open_regular_file",
    "run",
]
