"""What the Run tab shows of a sweep: the point line and one table row per finished point.

No Textual here: the app follows a sweep's process (``following.FollowedSweep``)
with a ``SweepPoster`` (the sweep listener protocol), which only forwards the
events to ``post``. The cells are formatted from ``PointResult.row()``, the same
dict ``sweep.csv`` is written from.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from ..compute.fit import ci_label, format_interval
from ..plugin.listeners import SweepListener
from ..runs.sweep import PointResult, Sweep, SweepPoint, yaml_scalar
from .text import format_count


class SweepPoster(SweepListener):
    """A sweep's listener: calls ``post(kind, point, result)``;
    each point's run tells the listeners ``run_listeners(point)`` makes."""

    def __init__(self, post: Callable[[str, SweepPoint, PointResult | None], None], run_listeners=lambda point: []):
        self.post = post
        self.make_run_listeners = run_listeners

    def run_listeners(self, point: SweepPoint) -> list[object]:
        return self.make_run_listeners(point)

    def point_started(self, sweep: Sweep, point: SweepPoint) -> None:
        self.post("started", point, None)

    def point_finished(self, sweep: Sweep, point: SweepPoint, result: PointResult) -> None:
        self.post("finished", point, result)


def short_name(path: str) -> str:
    return path.rsplit(".", 1)[-1]


def shown_value(value: Any) -> str:
    """A swept value as the Run and Results tabs show it: a float to 6 significant digits (a
    linspace's 0.533333333333 widened the table's column, its contacts cut at 80 columns)."""
    if isinstance(value, float) and math.isfinite(value):
        text = f"{value:.6g}"
        return text if "." in text or "e" in text else text + ".0"  # 1.0, as the preset writes it
    return yaml_scalar(value)


def point_line(sweep: Sweep, point: SweepPoint) -> str:
    """``point 3/8: hurst=0.7``"""
    values = ", ".join(f"{short_name(p)}={shown_value(v)}" for p, v in point.values.items())
    return f"point {point.number}/{len(sweep.points)}: {values}"


STATUS_MARKS = {
    "running": "▶", "completed": "✓", "cancelled": "c", "interrupted": "i", "failed": "!", "error": "!", "pending": "-",
    "damaged": "✗",
}  # fmt: skip


def table_columns(paths: list[str], intervals: bool, confidence: float | None) -> list[str]:
    """The sweep table's headers: short, so a one-parameter sweep fits 80 columns (60 without
    the ``intervals``). ``confidence``: the intervals' level, None where the points differ in it."""
    level = "CI" if confidence is None else ci_label(confidence)
    a, b = (f"a [{level}]", f"b [{level}]") if intervals else ("a", "b")
    return ["#", *(short_name(p) for p in paths), "", a, b, "R^2", "contacts"]


def sweep_confidence(sweep: Sweep) -> float | None:
    """The level of a sweep's intervals (its points' ``fit.confidence``), None where they differ."""
    levels = {point.scene.preset.fit.confidence for point in sweep.points}
    return levels.pop() if len(levels) == 1 else None


def _estimate(row: dict[str, Any], name: str, intervals: bool) -> str:
    value, ci = row[name], (row[f"{name}_lo"], row[f"{name}_hi"])
    if value is None:
        return "-"
    interval = format_interval(ci, digits=3, missing="", sep=",") if intervals else ""  # 80 columns
    return f"{value:.4f}" + (f" {interval}" if interval else "")


def row_cells(paths: list[str], row: dict[str, Any], intervals: bool = True) -> list[str]:
    """One row of the table from a row of sweep.csv (``PointResult.row()`` or a
    point of sweep.json): the point number, the swept values, a status mark,
    a and b (with their ``intervals``), R^2, points in contact at the first .. last load."""
    first, last = row["contact_first"], row["contact_last"]
    contacts = "-" if first is None else f"{format_count(first)}..{format_count(last)}"
    return [
        str(row["point"]),
        *(shown_value(row[p]) for p in paths),
        STATUS_MARKS.get(row["status"], "?"),
        _estimate(row, "a", intervals),
        _estimate(row, "b", intervals),
        "-" if row["r2"] is None else f"{row['r2']:.3f}",
        contacts,
    ]
