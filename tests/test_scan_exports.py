"""Instrument exports as users bring them, read as tables: a Gwyddion text export whose header
states an oblong pixel, a profile scanned right to left, a line with points the instrument
dropped (NaN)."""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab_spectra import ProfileFile, SurfaceFile


def rough(ny: int, nx: int, seed: int = 1) -> np.ndarray:
    return np.random.default_rng(np.random.SeedSequence(seed)).normal(size=(ny, nx))


def gwyddion_matrix(path, z_um: np.ndarray, pixel_um: tuple[float, float]):
    """Gwyddion's 'ASCII data matrix' export: the scan's width and height in its header, heights in um."""
    ny, nx = z_um.shape
    header = (f"# Channel: Height\n# Width: {nx * pixel_um[0]:.3f} µm\n# Height: {ny * pixel_um[1]:.3f} µm\n"
              "# Value units: µm\n")  # fmt: skip
    path.write_text(header + "".join("\t".join(f"{v:.6e}" for v in row) + "\n" for row in z_um), encoding="utf-8")
    return path


def test_a_table_whose_header_states_an_oblong_pixel_is_not_squared_without_a_word(tmp_path):
    """Gwyddion's text export of 32 x 16 pixels of 1 x 0.5 um, read with format: table and
    spacing 1: the pixels were squared without a word, every slope along y half what it is."""
    path = gwyddion_matrix(tmp_path / "scan.txt", rough(16, 32), (1.0, 0.5))
    summary = SurfaceFile(path=str(path), format="table", spacing=1.0).input_summary()
    (caveat,) = [said for said in summary["caveats"] if "not square" in said]
    assert "its header's pixel of 1 x 0.5 um (x by y), which is not square" in caveat
    assert "give spacing_y too (0.5 keeps the file's shape), or read it with format: instrument" in caveat
    kept = SurfaceFile(path=str(path), format="table", spacing=1.0, spacing_y=0.5).input_summary()
    assert not any("not square" in said for said in kept.get("caveats", ()))
    square = gwyddion_matrix(tmp_path / "square.txt", rough(16, 32), (0.5, 0.5))
    said = SurfaceFile(path=str(square), format="table", spacing=0.5).input_summary().get("caveats", ())
    assert not any("not square" in caveat for caveat in said)
