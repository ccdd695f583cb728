"""A Gwyddion map whose width (xreal) or height (yreal) is stored as 0: Gwyddion, and its reader
here, take that size as 1 m, so a 32 um wide map of height 0 was read with pixels 31000 times
longer along y, resampled onto a million rows and run without a word of the zero."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("SurfaceTopography")

from .test_scan_edge_cases import rough, validate, write_gwy  # noqa: E402


@pytest.mark.parametrize(("xreal", "dy", "named"), [(32e-6, 0.0, "height (yreal)"), (0.0, 1e-6, "width (xreal)")])
def test_a_side_of_size_zero_is_refused_by_name_unless_the_preset_gives_the_pixel(tmp_path, capsys, xreal, dy, named):
    path = write_gwy(tmp_path / "scan.gwy", rough(32, 32) * 1e-6, 1e-6, dy, xreal=xreal)
    code, text = validate(tmp_path, capsys, path, unit="um")
    assert code == 2 and "Traceback" not in text
    assert (f"scan.gwy': channel 0 ('Height') states a {named} of 0, which Gwyddion shows as 1 m: its pixels have "
            "no size; give the pixel side with spacing") in text
    code, text = validate(tmp_path, capsys, path, unit="um", spacing=1.0)  # the preset's pixel: the stated sizes unused
    assert code == 0 and "of 0" not in text, text


def test_both_sides_of_size_zero_are_named_together(tmp_path, capsys):
    path = write_gwy(tmp_path / "scan.gwy", rough(32, 32) * 1e-6, 1e-6, 0.0, xreal=0.0)
    code, text = validate(tmp_path, capsys, path, unit="um")
    assert code == 2 and "states a width (xreal) and a height (yreal) of 0" in text


def test_nan_heights_of_a_gwyddion_file_without_a_mask_are_not_said_to_be_under_one(tmp_path):
    """A Gwyddion map with NaN heights and no mask was refused as having points 'under its Gwyddion
    mask', and told to remove a mask it does not have."""
    from frictionlab_spectra import SurfaceFile

    z = rough(16, 16) * 1e-6
    z[2, 3:6] = np.nan
    path = write_gwy(tmp_path / "holes.gwy", z, 1e-6, 1e-6)
    with pytest.raises(ValueError) as refused:
        SurfaceFile(path=str(path), unit="um").generate(None)
    said = str(refused.value)
    assert "3 of 256 points are undefined in the file (not measured); set undefined: harmonic" in said
    assert "mask" not in said
