"""What each event of a progress log must hold to be read: a line that is not so is skipped,
as a line that is not JSON (a run folder is untrusted input)."""

from __future__ import annotations

from typing import Annotated

from pydantic import Field, ValidationError, model_validator

from .runfolder import Finite, Record

# What an event's numbers must be, as summary.json's (``results.SummaryRecord``): a count is a
# whole number from 0 to MAX_COUNT (a preset's realizations and load steps are far below it),
# a part never more than its whole. An event that is not so is skipped, as a line that is not JSON.
MAX_COUNT = 10**9
MAX_PID = 2**22  # Linux's largest
Whole = Annotated[int, Field(ge=0, le=MAX_COUNT, strict=True)]
Pid = Annotated[int, Field(ge=1, le=MAX_PID, strict=True)]


class _Event(Record):
    time: Annotated[float, Field(allow_inf_nan=False, strict=True)] | None = None

    @model_validator(mode="after")
    def _parts_within_wholes(self):
        for part, whole in (("done", "total"), ("resumed", "total"), ("done", "requested"), ("number", "total")):
            if {part, whole} <= self.model_fields_set:  # both written
                if getattr(self, whole) is not None and getattr(self, part) > getattr(self, whole):
                    raise ValueError(f"{part} is more than {whole}")
        return self


class _Started(_Event):
    pid: Pid | None = None
    total: Whole = 0
    workers: Whole = 1
    resumed: Whole = 0
    retried: Whole = 0


class _Load(_Event):
    """Realization ``index``'s loads solved, ``done`` of ``total``. A realization's event counts
    the run's realizations instead, and adds its outcome."""

    index: Whole = 0
    done: Whole = 0
    total: Whole = 0


class _Realization(_Load):
    ok: bool = False
    seconds: Finite | None = None
    stride: Annotated[int, Field(ge=1, le=MAX_COUNT, strict=True)] = 1
    error: str | None = None


class _Batch(_Event):
    done: Whole = 0
    total: Whole = 0
    index: Annotated[list[Whole], Field(max_length=MAX_COUNT)] = []
    seconds: list[Finite | None] = []
    ok: Whole = 0
    errors: dict[str, str] = {}
    stride: Annotated[int, Field(ge=1, le=MAX_COUNT, strict=True)] = 1

    @model_validator(mode="after")
    def _as_many_as_done(self):
        if len(self.index) > self.done:
            raise ValueError("more realizations than done")
        return self


class _Iteration(_Event):
    index: Whole = 0
    load: Whole = 0
    iteration: Whole = 0
    residual: float | None = None


class _Finished(_Event):
    status: str = "?"
    done: Whole = 0
    requested: Whole = 0
    failed: Whole = 0
    error: str | None = None


class _Error(_Event):
    pid: Pid | None = None
    message: str = "failed"
    exit_code: Annotated[int, Field(ge=0, le=255, strict=True)] = 1


class _Warning(_Event):
    pid: Pid | None = None
    message: str = ""


class _SweepStarted(_Event):
    pid: Pid | None = None
    total: Whole = 0


class _PointStarted(_Event):
    number: Whole = 0
    total: Whole | None = None


class _SweepFinished(_Event):
    status: str = "?"
    done: Whole = 0
    total: Whole = 0


EVENT_RECORDS = {"started": _Started, "realization": _Realization, "realizations": _Batch, "load": _Load,
                 "iteration": _Iteration, "finished": _Finished, "error": _Error, "warning": _Warning, "sweep_started": _SweepStarted,
                 "point_started": _PointStarted, "point_finished": _PointStarted, "sweep_finished": _SweepFinished}  # fmt: skip


def checked_event(event: dict) -> dict | None:
    """``event`` (a parsed line) once its fields are what its kind's record says, None if
    not. Only those fields are validated (a realization's curves are checked by ``result_of``)."""
    record = EVENT_RECORDS.get(event["event"])
    if record is None:
        return event  # a kind a later frictionlab writes: its followers skip it
    try:
        record.model_validate({name: event[name] for name in record.model_fields if name in event})
    except ValidationError:
        return None
    return event
