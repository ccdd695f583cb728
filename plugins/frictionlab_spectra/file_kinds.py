"""What a measured-file plugin declares before any file is read: the kinds of file, the length
units, what an instrument file's header says. Light on purpose: every command imports it with
the plugins' classes, while the readers (``instrument_file``, ``text_table``) are imported only
when a file is read."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

MIN_SIDE = 8  # pixels a side of the smallest map surface-file presses
TABLE_SUFFIXES = (".npy", ".csv", ".txt")  # read by frictionlab itself: bare numbers, no unit
# the units a preset may ask for, in metres
# (the angstrom, 1e-10 m, as AFM files state it, spelled \u00c5: a bare "A" is the ampere)
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "nm": 1e-9, "\u00c5": 1e-10, "pm": 1e-12}
Unit = Literal["m", "mm", "um", "nm", "\u00c5", "pm"]
Undefined = Literal["refuse", "harmonic"]
FileFormat = Literal["auto", "table", "instrument"]


@dataclass(frozen=True)
class ScanHeader:
    """What an instrument file's metadata says without its heights being read."""

    shape: tuple[int, ...]  # as ``read_scan`` gives it: (Ny, Nx) for a map, (N,) for a line
    periodic: bool
    pixel: tuple[float, ...] | None = None  # (dx, dy) of a map, in the file's unit, when the file says
    unit: str | None = None  # the file's length unit, when it says


def is_instrument_file(path: Path, format: str = "auto") -> bool:
    """Whether ``path`` goes to SurfaceTopography: ``format`` instrument, or auto and not one
    of frictionlab's own tables (.npy, .csv, .txt)."""
    if format != "auto":
        return format == "instrument"
    return path.suffix.lower() not in TABLE_SUFFIXES


def scan_not_periodic_advice(name: str) -> tuple[str, str]:
    """``SpectrumGenerator.not_periodic_advice`` of a measured line or map."""
    return (f"spectrum {name} is not periodic (periodic: false, a scan whose ends do not meet)",
            "set spectrum.params.periodic: true if its ends meet (after detrend)")  # fmt: skip
