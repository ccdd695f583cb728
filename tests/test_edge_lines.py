"""The caveat of a map whose first or last rows or columns carry its slope (an AFM's last lines,
where the scanner settles), and of a line whose first or last points do (a stylus landing, a trace
running off the sample): the run's rms slope, which xi divides by, is then theirs. Maps and lines
built here with known edge lines (points), and the same without them."""

from __future__ import annotations

import re

import numpy as np
import pytest

from frictionlab_slopes import ForwardDifference
from frictionlab_spectra import PowerLaw, PowerLawSurface, ProfileFile, SurfaceFile
from frictionlab_spectra.scan_shaping import edge_lines_warning, edge_points_warning, level_line

EDGE = re.compile(r"the map's (.*?) carry (\d+) % of its mean squared slope.*its rms slope is ([0-9.e+-]+),.*"
                  r"crop them with region \((.*?), pixels of the file\)")  # fmt: skip


LINE_EDGE = re.compile(r"the line's (.*?) carry (\d+) % of its mean squared slope.*its rms slope is ([0-9.e+-]+), "
                       r"([0-9.e+-]+) times the ([0-9.e+-]+) of the rest\).*crop them with region \(x: \[(\d+), (\d+)\], "
                       r"pixels of the file\)")  # fmt: skip


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



def line_from_slopes(slopes: np.ndarray, dx: float) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(slopes * dx)])


def test_a_lines_first_and_last_points_that_carry_its_slope_are_said_with_the_points_to_keep():
    """1000 points 0.5 apart, their slopes +-s in turn but 5 of r at the start and 3 of -q at the
    end. Forward differences give the last point its segment's slope again, so 4 points end it
    steep; the mean squared slope is (5 r^2 + 4 q^2 + 991 s^2) / 1000, the rest's s^2 exactly."""
    n, s, r, q = 1000, 0.01, 0.1, 0.08
    slopes = s * (-1.0) ** np.arange(n - 1)
    slopes[:5], slopes[-3:] = r, -q
    caveat = edge_points_warning(line_from_slopes(slopes, 0.5), 0.5)
    found = LINE_EDGE.search(caveat)
    whole = (5 * r**2 + 4 * q**2 + (n - 9) * s**2) / n
    assert found[1] == "first 5 points and last 4 points" and int(found[2]) == round(100 * (1 - s**2 / whole))  # 43 %
    assert float(found[3]) == pytest.approx(np.sqrt(whole), rel=2e-3) and float(found[5]) == pytest.approx(s, rel=2e-3)
    assert float(found[4]) == pytest.approx(np.sqrt(whole) / s, rel=2e-3)
    assert found.group(6, 7) == ("5", "996")  # half-open: the points 5 to 995 of 1000
    assert edge_points_warning(line_from_slopes(slopes[5:-3], 0.5), 0.5) is None  # the points kept: no caveat
    shifted = LINE_EDGE.search(edge_points_warning(line_from_slopes(slopes, 0.5), 0.5, [[40, 1040]]))
    assert shifted.group(6, 7) == ("45", "1036")  # in the file's points, past a region already given


@pytest.mark.parametrize("steep, said", [(36.0, False), (68.0, True)])  # 14.9 % and 25.1 % of the mean squared slope
def test_edge_points_are_said_when_they_carry_more_than_a_fifth_of_the_mean_squared_slope(steep, said):
    """5 first points of squared slope ``steep`` beside 995 of 1: they carry 1 - 1000 / (5 steep + 995)."""
    slopes = (-1.0) ** np.arange(999)
    slopes[:5] = np.sqrt(steep)
    assert (edge_points_warning(line_from_slopes(slopes, 1.0), 1.0) is not None) is said


def test_a_profile_files_steep_ends_are_said_in_its_caveats_with_the_runs_rms_slope(tmp_path):
    """A measured-like trace (two sines and noise) whose stylus lands over its first 6 points and
    runs off the sample over its last 4, read from a table: the caveat is among the line's, its
    rms slope the forward difference's of the heights the run is given; the region it says to crop
    them with, given in the preset, draws none."""
    rng = np.random.default_rng(np.random.SeedSequence(8))
    t = np.arange(2000.0)
    z = np.sin(2 * np.pi * t / 700.0) + 0.3 * np.cos(2 * np.pi * t / 130.0) + 0.01 * rng.standard_normal(t.size)
    z[:6] += np.linspace(3.0, 0.5, 6)  # landing
    z[-4:] -= np.linspace(0.5, 2.0, 4)  # running off
    np.savetxt(tmp_path / "trace.csv", z)
    [found] = [m for c in ProfileFile(path=str(tmp_path / "trace.csv"), spacing=0.25).input_summary()["caveats"]
               if (m := LINE_EDGE.search(c))]  # fmt: skip
    assert found[1] == "first 6 points and last 5 points" and found.group(6, 7) == ("6", "1995")
    heights = ProfileFile(path=str(tmp_path / "trace.csv"), spacing=0.25).generate(None).heights
    slopes = ForwardDifference().slopes(heights, 0.25, periodic=False)
    assert float(found[3]) == float(f"{np.sqrt(np.mean(slopes**2)):.3g}")
    region = {"x": [int(found[6]), int(found[7])]}
    said = ProfileFile(path=str(tmp_path / "trace.csv"), spacing=0.25, region=region).input_summary().get("caveats", ())
    assert not any(LINE_EDGE.search(c) for c in said), said


@pytest.mark.parametrize("hurst", [0.3, 0.8])
def test_self_affine_and_smooth_noisy_lines_draw_no_edge_caveat(hurst):
    """Lines with no edge of their own: self-affine ones as a run makes them (rough down to two
    points, or smooth below ten), levelled as a scan is, and a smooth trace with noise."""
    rng = np.random.default_rng(np.random.SeedSequence(21))
    for short in (2.0, 10.0):
        line = PowerLaw(hurst=hurst, points=1024, spacing=1.0, short_cutoff=short, series="cosine")
        for _ in range(20):
            assert edge_points_warning(level_line(line.generate(rng).heights, "tilt"), 1.0) is None
    t = np.arange(4096.0)
    for _ in range(20):
        z = np.sin(2 * np.pi * t / rng.uniform(300, 3000) + rng.uniform(0, 6)) + 0.02 * rng.standard_normal(t.size)
        assert edge_points_warning(level_line(z, "tilt"), 0.1) is None


def test_edge_lines_and_points_on_a_level_rest_are_said_without_a_ratio():
    """A map level but for its last row, a line but for its first step: the rest's rms slope is 0,
    and the ratio to it was a division by zero."""
    z = np.zeros((40, 16))
    z[-1] = 1.0
    said = edge_lines_warning(z - z.mean(), (1.0, 1.0))
    assert "the map's last 2 rows carry 100 %" in said and "(its rms slope is 0.224, the rest level)" in said
    assert "the map's first row carries 100 %" in edge_lines_warning(z[::-1] - z.mean(), (1.0, 1.0))
    line = np.r_[0.0, np.full(39, 2.0)]
    assert "the line's first point carries 100 %" in edge_points_warning(line - line.mean(), 1.0)


def test_a_periodic_map_or_line_has_no_edges_to_crop(tmp_path):
    """The first and last lines of a periodic scan are neighbours, and a region is refused for it:
    the steep rows or points said of the same heights read as not periodic are not said of it."""
    z = rough(128)
    z[-3:] += np.array([[0.6], [-0.4], [0.8]])
    np.save(tmp_path / "scan.npy", z)
    assert edge_caveats(SurfaceFile(path=str(tmp_path / "scan.npy"), spacing=0.125))
    assert edge_caveats(SurfaceFile(path=str(tmp_path / "scan.npy"), spacing=0.125, periodic=True)) == []
    with pytest.raises(ValueError, match="periodic"):
        SurfaceFile(path=str(tmp_path / "scan.npy"), spacing=0.125, periodic=True, region={"y": [0, 124]}).generate(None)
    t = np.arange(2000.0)
    line = np.sin(2 * np.pi * t / 500.0)
    line[:6] += np.linspace(3.0, 0.5, 6)
    np.savetxt(tmp_path / "trace.csv", line)
    def said(**periodic):
        caveats = ProfileFile(path=str(tmp_path / "trace.csv"), spacing=0.25, **periodic).input_summary().get("caveats", ())
        return [c for c in caveats if LINE_EDGE.search(c)]
    assert said() and said(periodic=True) == []
