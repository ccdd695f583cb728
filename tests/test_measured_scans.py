"""Scans as instruments leave them, each read as it is and told what in it can mislead."""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab_spectra import ProfileFile, SurfaceFile

from .test_scan_shaping import band_limited


@pytest.mark.parametrize("side", ["highest", "lowest"])
def test_a_scan_clipped_at_its_instruments_range_is_said(tmp_path, side):
    """An AFM out of its z range writes its limit: 20 % of a map at one height, its peaks cut flat
    where the contact starts, too few neighbours alike for the steps' caveat: read without a word."""
    z, _ = band_limited(64, 64, seed=3, top=0.3)
    limit = np.quantile(z, 0.8 if side == "highest" else 0.2)
    clipped = np.minimum(z, limit) if side == "highest" else np.maximum(z, limit)
    np.save(tmp_path / "clipped.npy", clipped)
    np.save(tmp_path / "whole.npy", z)
    caveats = SurfaceFile(path=str(tmp_path / "clipped.npy"), spacing=0.1).input_summary()["caveats"]
    assert any(f"% of the map's points sit at exactly its {side} height" in c and "clipped" in c for c in caveats), caveats
    assert "caveats" not in SurfaceFile(path=str(tmp_path / "whole.npy"), spacing=0.1).input_summary()
    np.savetxt(tmp_path / "line.csv", clipped[:8].ravel())
    line = ProfileFile(path=str(tmp_path / "line.csv"), spacing=0.1).input_summary()
    assert any(f"of the line's points sit at exactly its {side} height" in c for c in line["caveats"]), line


def test_a_short_lines_few_equal_tops_are_not_called_clipped(tmp_path):
    line = np.round(np.random.default_rng(4).normal(size=64), 1)  # one or two points at the top: rounding
    np.savetxt(tmp_path / "line.csv", line)
    said = ProfileFile(path=str(tmp_path / "line.csv"), spacing=0.1).input_summary().get("caveats", ())
    assert not any("clipped (" in c for c in said), said
