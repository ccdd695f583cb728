"""The TUI's modal screens."""

from .dialogs import ConfirmScreen, NewPresetScreen, PathScreen

__all__ = ["ConfirmScreen", "NewPresetScreen", "PathScreen"]
