"""The realizations of a run as lines of its progress.jsonl, and how long a line may be.

A follower needs each realization's count and outcome, and the run's mean curve: never
each realization's curve, which grew the log by about 10 KB a realization at 400 load steps
(gigabytes for a run of 10^5). So realizations that finish together are written as one
``realizations`` event (``Batch``): their indices, seconds and errors, and the sums of the
curves of those that succeeded. A follower hears each of them (``batch_results``) with its
batch's mean curve: the sums over the run, and so its mean curve, are the run's.
"""

from __future__ import annotations

import json
import math

import numpy as np

from ..compute.realization import RealizationResult
from ..io.values import number_or_nan, whole_or
from .figures import cut

MAX_LINE_BYTES = 1024 * 1024  # an event's line, at most (a realization's curves thinned to fit): within READ_BLOCK
MAX_TEXT = 4000  # characters of a message, in a line that would pass MAX_LINE_BYTES otherwise
CURVES = ("xi", "contact_count", "force")  # what a follower's mean curve needs (force: under indentation control)
MAX_BATCH = 1000  # realizations in one line: its indices and seconds stay far below MAX_LINE_BYTES


def _floats(values) -> list | None:
    return None if values is None else np.asarray(values, float).tolist()


class Batch:
    """Realizations finished since the last line was written, told as one ``realizations`` event."""

    def __init__(self, restored: bool = False):
        self.restored = restored
        self.index: list[int] = []
        self.seconds: list[float | None] = []
        self.errors: dict[str, str] = {}
        self.sums: dict[str, np.ndarray] = {}
        self.ok, self.last, self.done, self.total = 0, None, 0, 0

    def __len__(self) -> int:
        return len(self.index)

    def add(self, result: RealizationResult, done: int, total: int) -> None:
        self.index.append(result.index)
        self.seconds.append(round(result.seconds, 6) if math.isfinite(result.seconds) else None)  # a µs is plenty
        self.done, self.total = done, total
        if not result.ok:
            self.errors[str(result.index)] = str(result.error)
            return
        self.ok, self.last = self.ok + 1, result
        for name in CURVES:
            if getattr(result, name) is not None:
                self.sums[name] = self.sums.get(name, 0.0) + np.asarray(getattr(result, name), float)

    def event(self) -> dict:
        event = {"event": "realizations", "done": self.done, "total": self.total, "index": self.index, "seconds": self.seconds}
        if self.restored:
            event["restored"] = True
        if self.errors:
            event["errors"] = self.errors
        if self.ok:
            last = self.last
            event.update({"ok": self.ok, **{name: _floats(self.sums.get(name)) for name in CURVES}})
            event.update(force_unit=last.force_unit, slope_rms_line=last.slope_rms_line, points=last.points)
        return event


def _curve(value, steps: int, stride: int = 1) -> np.ndarray | None:
    """A curve of ``steps`` load steps, written at every ``stride``-th (NaN at the others)."""
    if not isinstance(value, list) or len(value) != -(-steps // stride):
        return None
    try:
        written = np.array([math.nan if x is None else x for x in value], dtype=float)
    except (TypeError, ValueError):
        return None
    if stride == 1:
        return written
    curve = np.full(steps, math.nan)
    curve[::stride] = written
    return curve


def _outcome(event: dict, steps: int, count: int) -> dict | None:
    """The keywords of a RealizationResult from the ``count`` realizations whose curves ``event``
    sums (one realization's event: count 1), None if its curves are not of the run's load steps."""
    curves = {name: _curve(event.get(name), steps, event.get("stride", 1)) for name in CURVES}
    if curves["xi"] is None or curves["contact_count"] is None:
        return None
    curves = {name: None if curve is None else curve / count for name, curve in curves.items()}
    return dict(**curves, force_unit=number_or_nan(event.get("force_unit")),
                slope_rms_line=number_or_nan(event.get("slope_rms_line")), points=whole_or(event.get("points")))  # fmt: skip


def result_of(event: dict, steps: int) -> RealizationResult | None:
    """The RealizationResult a ``realization`` event tells, None if it does not hold one
    (a curve of another length than the run's load steps, a field of the wrong kind)."""
    index = whole_or(event.get("index"), -1)
    if index < 0:
        return None
    seconds = number_or_nan(event.get("seconds"))
    if event.get("ok") is not True:
        return RealizationResult(index=index, seconds=seconds, error=str(event.get("error") or "failed"))
    outcome = _outcome(event, steps, 1)
    return None if outcome is None else RealizationResult(index=index, seconds=seconds, **outcome)


def batch_results(event: dict, steps: int) -> list[RealizationResult] | None:
    """The RealizationResults a ``realizations`` event tells, in order, each that succeeded with
    the batch's mean curve; None if it does not hold them (as ``result_of``)."""
    index, seconds = event.get("index"), event.get("seconds")
    errors = event.get("errors") if isinstance(event.get("errors"), dict) else {}
    if not isinstance(index, list) or not isinstance(seconds, list) or len(seconds) != len(index):
        return None
    ok = sum(str(i) not in errors for i in index)
    outcome = _outcome(event, steps, ok) if ok else {}
    if outcome is None or (ok and whole_or(event.get("ok")) != ok):
        return None
    return [RealizationResult(index=i, seconds=number_or_nan(s), error=str(errors[str(i)])) if str(i) in errors
            else RealizationResult(index=i, seconds=number_or_nan(s), **outcome) for i, s in zip(index, seconds)]  # fmt: skip


# ------------------------------------------------------------------ the size of a line


def _line(event: dict) -> bytes:
    return (json.dumps(event, separators=(",", ":")) + "\n").encode()


def _cut(value):
    """``value`` with every string in it cut to ``MAX_TEXT`` characters."""
    if isinstance(value, str):
        return cut(value, MAX_TEXT)
    if isinstance(value, dict):
        return {key: _cut(item) for key, item in value.items()}
    return [_cut(item) for item in value] if isinstance(value, list) else value


def fitted_line(event: dict) -> bytes:
    """``event`` as one line of at most ``MAX_LINE_BYTES``, which a reader takes whole: the
    curves of realizations thinned to every ``stride``-th load step (``stride`` in the event;
    a run of ~40000 load steps or more), a longer message cut, else only the event's kind."""
    line = _line(event)
    if len(line) <= MAX_LINE_BYTES:
        return line
    if event.get("event") in ("realization", "realizations") and any(isinstance(event.get(name), list) for name in CURVES):
        stride = -(-len(line) // (MAX_LINE_BYTES * 9 // 10))  # the curves are nearly all of it
        while len(line) > MAX_LINE_BYTES and stride < 2 * MAX_LINE_BYTES:  # each pass halves the curves
            curves = {name: event[name][::stride] for name in CURVES if isinstance(event.get(name), list)}
            line, stride = _line({**event, **curves, "stride": stride}), 2 * stride
        if len(line) <= MAX_LINE_BYTES:
            return line
    line = _line(_cut(event))
    return line if len(line) <= MAX_LINE_BYTES else _line({"event": str(event.get("event"))[:MAX_TEXT], "cut": True})
