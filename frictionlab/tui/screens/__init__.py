"""The TUI's modal screens."""

from .dialogs import (ConfirmScreen, Dialog, NewPresetScreen, PathScreen, QuitDuringRunScreen, QuitRunEndedScreen,
                      QuitUnsavedScreen)

__all__ = ["ConfirmScreen", "Dialog", "NewPresetScreen", "PathScreen", "QuitDuringRunScreen", "QuitRunEndedScreen",
           "QuitUnsavedScreen"]
