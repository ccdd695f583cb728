"""The TUI's modal screens."""

from .dialogs import ConfirmScreen, NewPresetScreen, PathScreen, QuitDuringRunScreen, QuitUnsavedScreen

__all__ = ["ConfirmScreen", "NewPresetScreen", "PathScreen", "QuitDuringRunScreen", "QuitUnsavedScreen"]
