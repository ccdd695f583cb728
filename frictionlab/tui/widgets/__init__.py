"""The TUI's widgets: a pane per tab (``presets``, ``editor``, ``run``, ``results``), the
preset form, the chart and the row lists.

Each is imported when first asked for: the first screen (the Presets tab) needs only its own,
and the others bring numpy, the preset schema and the run's modules with them.
"""

from importlib import import_module

_MODULES = {
    "EditPane": "editor",
    "KeysPanel": "keyspanel",
    "ListTable": "tables",
    "PresetForm": "form",
    "PresetsPane": "presets",
    "ResultsPane": "results",
    "RunPane": "run",
}

__all__ = sorted(_MODULES)


def __getattr__(name: str):
    if name not in _MODULES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(import_module(f".{_MODULES[name]}", __name__), name)
