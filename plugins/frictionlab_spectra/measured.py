"""What a spectrum read from a measured file does alike for a line (``profile-file``) and a
map (``surface-file``): each reads its file once (``_measured``), and may say its shape and
periodicity from the file's header without reading the heights (``_header``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, ClassVar

import numpy as np
from pydantic import Field, field_validator, model_validator

from frictionlab import InputFile, PluginParams, Profile, SpectrumGenerator

from .file_kinds import (
    LENGTH_UNITS, FileFormat, ScanHeader, Undefined, Unit, is_instrument_file, scan_not_periodic_advice,
)


@dataclass(frozen=True)
class Measured:
    """A measured line or map as read and levelled."""

    heights: np.ndarray  # detrended, read-only
    spacing: float
    rms_height: float
    periodic: bool
    summary: dict[str, Any]  # what was read, and where each value came from


ANGSTROM = ("\u212b", "angstrom", "angstroms")  # the angstrom sign, and in words (any case)


class MeasuredParams(PluginParams):
    """The parameters a measured line and a measured map share, in the order of their forms:
    each file kind words ``path``, ``spacing`` and ``detrend`` for itself."""

    path: InputFile = Field(description="file of heights", min_length=1)
    spacing: float | None = Field(None, description="grid spacing", gt=0.0)
    unit: Unit | None = Field(
        None,
        description="length unit of the heights and the spacing in this run (m, mm, um, nm, \u00c5, pm): an instrument "
        "file's are converted to it (default: the file's own); a table's numbers are taken to be in it (default: the "
        "unit its header names, if any)",
    )
    undefined: Undefined = Field(
        "refuse",
        description="what to do with points a file leaves undefined (an instrument file's, a table's NaN): refuse "
        "the file, or fill them from their neighbours (harmonic: the solution of Laplace's equation)",
    )
    detrend: str | None = Field(None, description="levelling")
    channel: str | Annotated[int, Field(ge=0)] | None = Field(
        None, description="an instrument file's channel, by name (the first of that name) or index; default: the "
        "file's default channel (validate lists them when there are several); a table has none, and is refused one",
    )
    format: FileFormat = Field(
        "auto", description="how to read the file: auto (by suffix: .npy, .csv, .txt are tables), table (bare "
        "numbers), instrument (an instrument's file or export, such as a profilometer's or an XYZ .csv, read by "
        "SurfaceTopography)",
    )
    periodic: bool | None = Field(
        None,
        description="whether the heights repeat (a line's last point is followed by its first, a map's opposite "
        "edges meet); default: as an instrument file says, else false (a measured scan does not)",
    )

    @field_validator("unit", mode="before")
    @classmethod
    def _micro_sign(cls, unit: object) -> object:
        # um as an instrument writes it: with the micro sign or the Greek mu, or as microns; the angstrom too
        if unit == "A":  # the ampere's symbol, or an angstrom in ASCII: never guessed
            raise ValueError(f"must be a length unit ({', '.join(LENGTH_UNITS)}): A is the ampere; an angstrom "
                             "(1e-10 m) is written \u00c5")  # fmt: skip
        if isinstance(unit, str) and (unit in ANGSTROM or unit.lower() in ANGSTROM):
            return "\u00c5"
        return "um" if unit in ("\u00b5m", "\u03bcm", "micron", "microns") else unit

    @model_validator(mode="after")
    def _channel_of_an_instrument_file(self):
        # a table holds one array of heights: the channel asked of it was ignored without a word
        if self.channel is not None and not is_instrument_file(Path(self.path), self.format):
            raise ValueError(
                f"channel {self.channel!r} picks a channel of an instrument file, but {Path(self.path).name!r} is read "
                "as a table (one array of heights, by its suffix .npy, .csv or .txt, or format: table): leave channel "
                "out, or give format: instrument for an instrument's export"
            )
        return self


def table_unit(path: Path, where: str, p: MeasuredParams, text: bool) -> dict[str, str | None]:
    """A table's unit and where it came from, for its input summary: the preset's ``unit``, else
    the one the header of a ``text`` table names (``check_table_header``, which refuses another
    than the preset's), else none: bare numbers."""
    from .header_units import check_table_header  # the readers, only when a file is read

    named = check_table_header(path, where, p.unit, p.format) if text else None
    return {"unit": p.unit or named, "unit_from": "preset" if p.unit is not None else "header" if named else "none"}


class MeasuredFile(SpectrumGenerator):
    """The contract's methods that read nothing but what ``_measured`` and ``_header`` give;
    every ``generate`` returns the same heights."""

    deterministic: ClassVar[bool] = True  # the rng is not used: every realization is the measured profile

    def _measured(self) -> Measured:
        raise NotImplementedError

    def _header(self) -> ScanHeader | None:
        raise NotImplementedError

    def generate(self, rng: np.random.Generator) -> Profile:
        """The measured heights (a fresh copy each call); ``rng`` is not used."""
        measured = self._measured()
        return Profile(heights=measured.heights.copy(), spacing=measured.spacing, periodic=measured.periodic)

    def periodic(self) -> bool:
        if self.params.periodic is not None or not is_instrument_file(Path(self.params.path), self.params.format):
            return bool(self.params.periodic)  # known without reading the file
        header = self._header()
        return header.periodic if header is not None else self._measured().periodic

    def not_periodic_advice(self) -> tuple[str, str]:
        return scan_not_periodic_advice(self.name)

    def input_summary(self) -> dict[str, Any]:
        """The heights as read: file, format, size, spacing, unit, rms height, and where each came from."""
        return dict(self._measured().summary)

    def rms_height(self) -> float:
        """rms of the detrended heights about their mean (a constant offset, which does not
        change a contact, does not count)."""
        return self._measured().rms_height
