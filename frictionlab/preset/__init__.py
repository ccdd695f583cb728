"""Presets: YAML scenes, validated in two phases into a ``Scene``.

Phase one checks the structure (``schema.Preset``); phase two looks up each named
plugin and validates its ``params`` with the plugin's own ``Params`` model
(``scene.build_scene``). Every problem is reported, each as
``dotted.path: what is wrong, got VALUE`` (``problems``). ``reading`` reads
preset files safely; ``paths`` sets values by dotted path (``--set``).
"""

from .paths import MISSING, apply_overrides, differences, get_path, set_path, yaml_scalar
from .problems import format_validation_error, number_problems
from .reading import MAX_PRESET_BYTES, load_preset_file, read_preset, resolve_input_paths
from .scene import Scene, build_scene, load_scene
from .schema import (
    MAX_SWEEP_POINTS,
    FitSettings,
    Loading,
    OutputSettings,
    PluginChoice,
    Preset,
    SweepParameter,
    SweepSettings,
    preset_json_schema,
)

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
