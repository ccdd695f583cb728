"""The caveat of a map whose first or last rows or columns carry its slope (an AFM's last lines,
where the scanner settles): the run's rms slope, which xi divides by, is then theirs. A map built
here with known edge lines, and the same map without them."""

from __future__ import annotations

import re

import numpy as np

from frictionlab_slopes import ForwardDifference
from frictionlab_spectra import PowerLawSurface, SurfaceFile

EDGE = re.compile(r"the map's (.*?) carry (\d+) % of its mean squared slope.*its rms slope is ([0-9.e+-]+),.*"
                  r"crop them with region \((.*?), pixels of the file\)")  # fmt: skip


def rough(n: int = 64) -> np.ndarray:
    surface = PowerLawSurface(hurst=0.8, points=n, rms_height=0.05, spacing=0.125)
    return surface.generate(np.random.default_rng(np.random.SeedSequence(11))).heights


def edge_caveats(surface: SurfaceFile) -> list[re.Match]:
    return [m for c in surface.input_summary().get("caveats", ()) if (m := EDGE.search(c))]


def test_the_last_rows_of_a_scan_that_carry_its_slope_are_said_with_the_region_that_crops_them(tmp_path):
    z = rough(128)
    z[-3:] += np.array([[0.6], [-0.4], [0.8]])  # three last lines, each offset by many rms heights
    np.save(tmp_path / "scan.npy", z)
    surface = SurfaceFile(path=str(tmp_path / "scan.npy"), spacing=0.125, unit="um")
    [found] = edge_caveats(surface)
    # the difference from the fourth last row to the third is its forward slope: four rows stand out
    assert found[1] == "last 4 rows" and int(found[2]) > 90 and found[4] == "y: [0, 124]"
    heights = surface.generate(None).heights  # the rms slope it names is the run's (forward differences)
    slopes = ForwardDifference().slopes(heights, 0.125, periodic=False)
    assert float(found[3]) == float(f"{np.sqrt(np.mean(slopes**2)):.3g}")
    cropped = SurfaceFile(path=str(tmp_path / "scan.npy"), spacing=0.125, unit="um", region={"y": [0, 124]})
    assert edge_caveats(cropped) == []


def test_edge_columns_are_named_in_the_files_pixels_past_a_region(tmp_path):
    z = rough()
    z[:, :2] += np.array([0.7, -0.5])  # the first two columns
    np.save(tmp_path / "scan.npy", z)
    surface = SurfaceFile(path=str(tmp_path / "scan.npy"), spacing=0.125, region={"y": [8, 64]})
    [found] = edge_caveats(surface)
    assert found[1] == "first 2 columns" and found[4] == "x: [2, 64]"
    assert edge_caveats(SurfaceFile(path=str(tmp_path / "scan.npy"), spacing=0.125, region={"x": [2, 64]})) == []

