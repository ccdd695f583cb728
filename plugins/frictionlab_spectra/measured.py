"""What a spectrum read from a measured file does alike for a line (``profile-file``) and a
map (``surface-file``): each reads its file once (``_measured``), and may say its shape and
periodicity from the file's header without reading the heights (``_header``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from frictionlab import Profile, SpectrumGenerator

from .instrument_file import ScanHeader, is_instrument_file, scan_not_periodic_advice


@dataclass(frozen=True)
class Measured:
    """A measured line or map as read and levelled."""

    heights: np.ndarray  # detrended, read-only
    spacing: float
    rms_height: float
    periodic: bool
    summary: dict[str, Any]  # what was read, and where each value came from


class MeasuredFile(SpectrumGenerator):
    """The contract's methods that read nothing but what ``_measured`` and ``_header`` give;
    every ``generate`` returns the same heights."""

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
