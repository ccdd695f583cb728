"""profile-file's region: a measured line cropped as it is read, as a map is by surface-file's,
before its undefined points are refused or filled, its levelling and its caveats."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab_spectra import ProfileFile


def trace(n: int = 200, seed: int = 3) -> np.ndarray:
    return np.cumsum(np.random.default_rng(np.random.SeedSequence(seed)).standard_normal(n))


@pytest.mark.parametrize("suffix", [".csv", ".npy"])
def test_a_crop_in_points_or_in_length_gives_the_heights_of_the_files_slice(tmp_path, suffix):
    z = trace()
    path = tmp_path / f"line{suffix}"
    np.save(path, z) if suffix == ".npy" else np.savetxt(path, z)
    np.save(tmp_path / "slice.npy", z[30:150])
    sliced = ProfileFile(path=str(tmp_path / "slice.npy"), spacing=0.25, detrend="tilt").generate(None).heights
    for region in ({"x": [30, 150]}, {"x": [7.5, 37.5], "units": "length"}):
        line = ProfileFile(path=str(path), spacing=0.25, detrend="tilt", region=region)
        assert line.grid_shape() == (120,)  # not the file's 200 points its header says
        np.testing.assert_allclose(line.generate(None).heights, sliced, rtol=0, atol=1e-12)
        assert line.input_summary()["region_pixels"] == [[30, 150]] and line.input_summary()["shape"] == [120]


def test_an_x_column_gives_the_spacing_a_crop_in_length_is_taken_in(tmp_path):
    z = trace()
    np.savetxt(tmp_path / "xz.csv", np.column_stack([0.5 * np.arange(z.size), z]), delimiter=",")
    line = ProfileFile(path=str(tmp_path / "xz.csv"), detrend="mean", region={"x": [10.0, 50.0], "units": "length"})
    np.testing.assert_allclose(line.generate(None).heights, z[20:100] - z[20:100].mean(), rtol=0, atol=1e-12)


def test_undefined_points_outside_the_region_are_left_out_and_inside_refused_or_filled(tmp_path):
    z = trace()
    z[[2, 190]] = np.nan
    np.savetxt(tmp_path / "holes.csv", z)
    kept = ProfileFile(path=str(tmp_path / "holes.csv"), spacing=1.0, region={"x": [5, 180]})
    assert np.isfinite(kept.generate(None).heights).all()
    assert kept.input_summary()["undefined_outside_region"] == 2 and kept.input_summary()["undefined_points"] == 0
    with pytest.raises(ValueError, match=r"in the region's heights not finite .* line 191, column 1 of the file"):
        ProfileFile(path=str(tmp_path / "holes.csv"), spacing=1.0, region={"x": [5, 200]}).generate(None)
    filled = ProfileFile(path=str(tmp_path / "holes.csv"), spacing=1.0, region={"x": [5, 200]}, undefined="harmonic")
    summary = filled.input_summary()
    assert (summary["undefined_points"], summary["undefined_outside_region"], summary["filled_by"]) == (1, 1, "harmonic")
    assert filled.generate(None).heights.size == 195


def test_a_bad_value_of_a_table_is_located_at_its_line_of_the_file_past_a_crop(tmp_path):
    """The first bad value at or past the region's start, not the first of the file (left out)."""
    z = trace(60)
    rows = [f"{i * 0.5:g},{v:.17g}" for i, v in enumerate(z)]
    rows[3] = "1.5,nan"  # outside the region
    rows[40] = "20,inf"  # inside: data row 40 is line 42 of the file, under its header
    (tmp_path / "xz.csv").write_text("x,z\n" + "\n".join(rows) + "\n")
    with pytest.raises(ValueError, match=r"the first at line 42, column 2 of the file"):
        ProfileFile(path=str(tmp_path / "xz.csv"), region={"x": [10, 50]}).generate(None)
    np.save(tmp_path / "z.npy", np.where(np.arange(60) == 40, np.inf, z))
    with pytest.raises(ValueError, match=r"the first at index 40\b"):  # counted in the file
        ProfileFile(path=str(tmp_path / "z.npy"), spacing=1.0, region={"x": [10, 50]}).generate(None)


@pytest.mark.parametrize("region, said", [
    ({"x": [50, 20]}, r"region\.x = \[50, 20\]: needs 0 <= start < stop"),
    ({"x": [2.5, 20]}, r"region\.x = \[2.5, 20\]: pixels are whole numbers"),
    ({"x": [10, 201]}, r"region\.x = \[10, 201\] \(pixels\) is not inside the line, 200 points"),
    ({"x": [0, 60], "units": "length"}, r"region\.x = \[0, 60\] \(length\) is not inside the line, 50 \(the run's"),
    ({"x": [1.0, 1.1], "units": "length"}, r"region\.x = \[1, 1.1\] \(length\) is narrower than one point, 0.25"),
    ({"x": [0, 10], "y": [0, 1]}, r"region\.y = \[0, 1\]: a line has no rows"),
    ({"x": [0, 5]}, r"region\.x keeps 5 points of the line; at least 8"),
])  # fmt: skip
def test_a_bad_span_is_refused_naming_the_field_the_value_and_what_is_allowed(tmp_path, region, said):
    np.save(tmp_path / "line.npy", trace())
    with pytest.raises(ValueError, match=said):
        ProfileFile(path=str(tmp_path / "line.npy"), spacing=0.25, region=region).generate(None)


def test_a_periodic_line_cropped_is_refused(tmp_path):
    np.save(tmp_path / "line.npy", trace())
    with pytest.raises(ValueError, match=r"a periodic line .* no longer repeats once cropped to region; set periodic"):
        ProfileFile(path=str(tmp_path / "line.npy"), spacing=1.0, periodic=True, region={"x": [0, 100]}).generate(None)


def test_validate_refuses_a_region_with_rows_for_a_line(tmp_path, capsys):
    np.save(tmp_path / "line.npy", trace())
    preset = {"name": "r", "realizations": 1, "solver": {"name": "mdr"},
              "loading": {"start": 1e-3, "stop": 1.0, "steps": 3},
              "spectrum": {"name": "profile-file",
                           "params": {"path": "line.npy", "spacing": 1.0, "region": {"x": [0, 100], "y": [0, 1]}}}}  # fmt: skip
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset))
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.USAGE
    out = "".join(capsys.readouterr())
    assert "spectrum.params.region: region.y = [0, 1]: a line has no rows" in out and "Traceback" not in out, out


def test_validate_says_the_points_of_the_file_a_region_kept(tmp_path, capsys):
    np.save(tmp_path / "line.npy", trace())
    preset = {"name": "r", "realizations": 1, "solver": {"name": "mdr"},
              "loading": {"start": 1e-3, "stop": 1.0, "steps": 3},
              "spectrum": {"name": "profile-file", "params": {"path": "line.npy", "spacing": 1.0,
                                                              "region": {"x": [10, 60]}}}}  # fmt: skip
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset))
    assert main(["validate", str(tmp_path / "p.yaml")]) == 0
    out = "".join(capsys.readouterr())
    assert "50 points of 1" in out and "cropped to x 10:60 (points of the file)" in out, out
