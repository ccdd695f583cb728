"""The TUI's widgets: a pane per tab (``presets``, ``editor``, ``run``, ``results``), the
preset form, the chart and the row lists."""

from .editor import EditPane
from .form import PresetForm
from .presets import PresetsPane
from .results import ResultsPane
from .run import RunPane
from .tables import ListTable

__all__ = ["EditPane", "ListTable", "PresetForm", "PresetsPane", "ResultsPane", "RunPane"]
