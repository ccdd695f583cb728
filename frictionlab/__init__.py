"""frictionlab: rms slope in contact against normal force, over ensembles of
random rough lines pressed into elastic bodies.

The framework (the plugin contract, hooks, registry, presets, engine, fit, result
files) lives here, with its front ends (``cli``, ``tui``) and the studies built on
it (``paper``, ``tradeoff``); the physics lives in plugins (``frictionlab_spectra``,
``frictionlab_solvers``, ``frictionlab_slopes``) that register through the same
hooks as any third-party plugin. ARCHITECTURE.md draws the layers.

For notebooks and scripts: ``frictionlab.run(preset, **overrides)`` returns a
``Result`` (the fit, the table per load step, a plot); ``frictionlab.load(folder)``
reads a finished run back; ``frictionlab.validate(preset)`` checks one and says what
would run (``frictionlab.api``). They are imported on first use,
so ``import frictionlab`` stays cheap.
"""

from ._version import __version__  # a constant: the build reads it from there too

# Every other public name is imported on first use (PEP 562), so that ``import frictionlab``
# (and ``frictionlab --help``) costs almost nothing: numpy and pydantic come with the
# first name that needs them.
_LAZY = {
    "hookimpl": "plugin.hookspecs",
    **dict.fromkeys(("InputFile", "InputFileProblem", "open_regular_file"), "io.inputs"),
    **dict.fromkeys(("RunListener", "SweepListener"), "plugin.listeners"),
    "RunOptions": "options",
    **dict.fromkeys(
        (
            "ContactCurve", "ContactSolver", "Control", "ForceNormalisation", "Plugin", "PluginParams", "Profile",
            "SlopeEstimator", "SolveCancelled", "SolveFailed", "SpectrumGenerator", "contract", "defined_rms", "force_unit", "iteration_done",
            "half_load_points", "load_finished", "mdr_length", "short_cutoff_caveat",
        ),
        "plugin",
    ),  # fmt: skip
    **dict.fromkeys(("run", "load", "validate", "Result", "RunInterrupted", "SweepResult"), "api"),
}


# Modules that moved into the packages by job (io, plugin, preset, compute, runs) keep
# their old names: ``from frictionlab.runner import run_to_folder`` imports the moved module.
_MOVED = {
    **dict.fromkeys(("inputs", "files", "safe_yaml"), "io"),
    **dict.fromkeys(("hookspecs", "listeners", "registry"), "plugin"),
    **dict.fromkeys(("seeds", "loads"), "preset"),
    **dict.fromkeys(
        ("realization", "ensemble", "engine", "executors", "pool", "dask_session", "dask_security", "memory",
         "signals", "fit"),
        "compute",
    ),  # fmt: skip
    **dict.fromkeys(("rundir", "runfolder", "progresslog", "sweeplog", "detached", "results", "runner", "sweep"), "runs"),
}


class _MovedModules:
    """A finder whose loader hands out the moved module itself under its old name."""

    @staticmethod
    def find_spec(fullname, path=None, target=None):
        old = fullname.removeprefix(__name__ + ".")
        if old == fullname or old not in _MOVED:
            return None
        from importlib.util import spec_from_loader

        return spec_from_loader(fullname, _MovedModules)

    @staticmethod
    def create_module(spec):
        from importlib import import_module

        old = spec.name.removeprefix(__name__ + ".")
        module = import_module(f"{__name__}.{_MOVED[old]}.{old}")
        spec.loader_state = module.__spec__  # the import system sets module.__spec__ to this alias's next
        return module

    @staticmethod
    def exec_module(module):
        # The moved module ran when it was imported under its own name. Its own spec comes back:
        # under the alias's, its relative imports warned (ImportWarning: __package__ != __spec__.parent).
        module.__spec__ = module.__spec__.loader_state


def _install_moved_modules() -> None:
    import sys

    if not any(finder is _MovedModules for finder in sys.meta_path):
        sys.meta_path.append(_MovedModules)


_install_moved_modules()


def __getattr__(name: str):
    if name in _LAZY:
        from importlib import import_module

        value = getattr(import_module(f".{_LAZY[name]}", __name__), name)
    else:
        raise AttributeError(f"module 'frictionlab' has no attribute {name!r}")
    globals()[name] = value
    return value


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
    "RunInterrupted",
    "RunListener",
    "RunOptions",
    "SlopeEstimator",
    "SolveCancelled",
    "SolveFailed",
    "SpectrumGenerator",
    "SweepListener",
    "SweepResult",
    "__version__",
    "contract",
    "defined_rms",
    "force_unit",
    "half_load_points",
    "hookimpl",
    "iteration_done",
    "load",
    "load_finished",
    "mdr_length",
    "open_regular_file",
    "run",
    "short_cutoff_caveat",
    "validate",
]
