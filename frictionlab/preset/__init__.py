"""Presets: YAML scenes, validated in two phases into a ``Scene``.

Phase one checks the structure (``schema.Preset``); phase two looks up each named
plugin and validates its ``params`` with the plugin's own ``Params`` model
(``scene.build_scene``). Every problem is reported, each as
``dotted.path: what is wrong, got VALUE`` (``problems``). ``reading`` reads
preset files safely; ``paths`` sets values by dotted path (``--set``).
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING

# Each name is imported from its module on first use: listing or reading a preset file
# (the TUI's first screen) needs neither the schema's pydantic models nor numpy.
_LAZY = {
    **dict.fromkeys(
        ("MISSING", "apply_overrides", "differences", "first_unlike", "get_path", "set_path", "yaml_scalar"), "paths"
    ),
    **dict.fromkeys(("format_validation_error", "number_problems"), "problems"),
    **dict.fromkeys(("MAX_PRESET_BYTES", "load_preset_file", "read_preset", "resolve_input_paths"), "reading"),
    **dict.fromkeys(("Scene", "build_scene", "load_scene"), "scene"),
    **dict.fromkeys(
        ("MAX_SWEEP_POINTS", "FitSettings", "Loading", "OutputSettings", "PluginChoice", "Preset", "SweepParameter",
         "SweepSettings", "preset_json_schema"),
        "schema",
    ),  # fmt: skip
}

if TYPE_CHECKING:
    from .paths import MISSING, apply_overrides, differences, first_unlike, get_path, set_path, yaml_scalar
    from .problems import format_validation_error, number_problems
    from .reading import MAX_PRESET_BYTES, load_preset_file, read_preset, resolve_input_paths
    from .scene import Scene, build_scene, load_scene
    from .schema import (
        MAX_SWEEP_POINTS, FitSettings, Loading, OutputSettings, PluginChoice, Preset, SweepParameter,
        SweepSettings, preset_json_schema,
    )


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f".{_LAZY[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted([*globals(), *_LAZY])


__all__ = [
    "MAX_PRESET_BYTES",
    "MAX_SWEEP_POINTS",
    "MISSING",
    "FitSettings",
    "Loading",
    "OutputSettings",
    "PluginChoice",
    "Preset",
    "Scene",
    "SweepParameter",
    "SweepSettings",
    "apply_overrides",
    "build_scene",
    "differences",
    "first_unlike",
    "format_validation_error",
    "get_path",
    "load_preset_file",
    "load_scene",
    "number_problems",
    "preset_json_schema",
    "read_preset",
    "resolve_input_paths",
    "set_path",
    "yaml_scalar",
]
