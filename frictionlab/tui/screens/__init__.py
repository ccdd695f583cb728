"""The TUI's modal screens."""

from .dialogs import ConfirmScreen, NewPresetScreen, PathScreen
from .help import HelpScreen

__all__ = ["ConfirmScreen", "HelpScreen", "NewPresetScreen", "PathScreen"]
