"""A table's pixel per axis: ``spacing`` along x and ``spacing_y`` along y. A map exported as a
.npy or a matrix of text with the slow axis coarser than the fast one could only be declared
square (``spacing`` alone), every slope across its rows off by the sides' ratio; with both, it is
resampled onto square pixels as an instrument file's rectangular pixels are."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab_spectra import SurfaceFile

from .test_scan_shaping import band_limited, rms_gradient


def validated_surface(folder, capsys, params: dict) -> str:
    """What ``frictionlab validate`` prints of a one-realization preset reading ``params``' map."""
    preset = {"name": "sides", "realizations": 1, "spectrum": {"name": "surface-file", "params": params},
              "solver": {"name": "mdr"}, "loading": {"start": 0.01, "stop": 0.1, "steps": 3, "unit": "f"}}  # fmt: skip
    (folder / "p.yaml").write_text(yaml.safe_dump(preset))
    assert main(["validate", str(folder / "p.yaml")]) == ExitCode.OK
    return capsys.readouterr().out


def test_a_table_on_rectangular_pixels_keeps_its_surfaces_gradient(tmp_path):
    _, surface = band_limited(40, 48, seed=11, top=0.3)  # every wave held by the coarse rows too
    y, x = np.mgrid[0:40, 0:48].astype(float)
    fine = surface(x, y)  # every pixel along y: square pixels of 0.1
    rows = np.arange(0, 40, 2.5)
    coarse = surface(x[: rows.size], np.broadcast_to(rows[:, None], (rows.size, 48)))  # every 0.25 along y
    np.save(tmp_path / "coarse.npy", coarse)
    read = SurfaceFile(path=str(tmp_path / "coarse.npy"), spacing=0.1, spacing_y=0.25, detrend="none")
    heights = read.generate(None).heights
    assert heights.shape == (38, 48) and read.generate(None).spacing == pytest.approx(0.1)
    assert "0.1 x 0.25 resampled onto square pixels of 0.1 along y" in read.input_summary()["pixels"]
    expected = rms_gradient(fine[:38], 0.1, 0.1)
    assert rms_gradient(heights, 0.1, 0.1) == pytest.approx(expected, rel=0.03)
    square = SurfaceFile(path=str(tmp_path / "coarse.npy"), spacing=0.1, detrend="none").generate(None).heights
    assert rms_gradient(square, 0.1, 0.1) > 1.2 * expected  # taken as square: the slopes across the rows too steep


def test_spacing_y_needs_spacing_and_is_said_where_it_replaces_the_files(tmp_path, capsys):
    np.save(tmp_path / "map.npy", np.random.default_rng(0).normal(size=(16, 16)))
    with pytest.raises(ValueError, match="spacing_y = 0.2 gives the pixel's side along y beside spacing's along x: give "
                       "spacing too"):  # fmt: skip
        SurfaceFile(path=str(tmp_path / "map.npy"), spacing_y=0.2)
    from SurfaceTopography import Topography

    Topography(np.random.default_rng(1).normal(size=(24, 16)), (2.4, 3.2), unit="µm").to_x3p(str(tmp_path / "s.x3p"))
    out = validated_surface(tmp_path, capsys, {"path": "s.x3p", "unit": "um", "spacing": 0.1, "spacing_y": 0.25})
    assert "the file's pixels of 0.1 x 0.2 um replaced by the preset's pixels of 0.1 x 0.25" in out, out
    assert "24 x 16 -> 24 x 38 pixels" in out, out


def test_a_resampling_that_changes_the_maps_area_says_so_in_the_line_and_the_record(tmp_path, capsys):
    # 64 rows of 125 nm onto 50 nm: 158 rows, 7900 of the scan's 8000 nm (its points end at the last row)
    np.save(tmp_path / "rows.npy", np.random.default_rng(3).normal(size=(64, 160)))
    read = SurfaceFile(path=str(tmp_path / "rows.npy"), spacing=50.0, spacing_y=125.0, unit="nm")
    assert read.generate(None).heights.shape == (158, 160)
    extent = read.input_summary()["extent"]
    assert extent["scan"] == pytest.approx([8000.0, 8000.0]) and extent["pressed"] == pytest.approx([8000.0, 7900.0])
    out = validated_surface(tmp_path, capsys, {"path": "rows.npy", "unit": "nm", "spacing": 50.0, "spacing_y": 125.0})
    assert "the map pressed covers 8000 x 7900 nm of the scan's 8000 x 8000 nm (x by y), 1.25 % less area" in out, out
    square = SurfaceFile(path=str(tmp_path / "rows.npy"), spacing=50.0, unit="nm")  # nothing resampled: nothing said
    assert "extent" not in square.input_summary()
