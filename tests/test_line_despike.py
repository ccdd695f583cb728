"""``despike`` on a measured line (profile-file), as on a map: spikes and pits more than k rms
heights from the median of the 5 points around them are replaced by the straight line between
their nearest kept neighbours, and the line is levelled again."""

from __future__ import annotations

import numpy as np
import pytest

from frictionlab_spectra import ProfileFile
from frictionlab_spectra.scan_shaping import despike


def rough_line(n: int = 3000) -> np.ndarray:
    rng = np.random.default_rng(np.random.SeedSequence(21))
    t = np.arange(n, dtype=float)
    return np.sin(2 * np.pi * t / 700.0) + 0.02 * rng.standard_normal(n)


def interpolated(z: np.ndarray, bad: list[int]) -> np.ndarray:
    """The reference: the bad points on the straight line between the nearest good ones (level past an end)."""
    good = np.setdiff1d(np.arange(z.size), bad)
    out = z.copy()
    out[bad] = np.interp(np.asarray(bad, float), good.astype(float), z[good])
    return out


@pytest.mark.parametrize("bad", [[1000], [0], [2999], [10, 11], [500, 1500, 2998, 2999]])
def test_a_lines_spikes_and_pits_are_replaced_by_the_line_between_their_neighbours(bad):
    z = rough_line()
    spiky = z.copy()
    spiky[bad] += np.resize([9.0, -7.0], len(bad))  # up and down: a spike and a pit
    cleaned, count = despike(spiky.reshape(1, -1), 6.0, float(np.std(z)))
    assert count == len(bad)
    np.testing.assert_allclose(cleaned[0], interpolated(spiky, bad), rtol=0, atol=1e-12)


def test_a_profile_files_spike_is_said_with_despike_and_despike_replaces_it(tmp_path):
    z = rough_line()
    z[1234] += 12.0
    np.savetxt(tmp_path / "trace.csv", z)
    said = ProfileFile(path=str(tmp_path / "trace.csv"), spacing=0.5).input_summary()["caveats"]
    assert any("1 of the line's 16 highest points stands" in c and "despike: 6 replaces it, if it is not" in c for c in said)
    cleaned = ProfileFile(path=str(tmp_path / "trace.csv"), spacing=0.5, despike=6.0)
    summary = cleaned.input_summary()
    assert summary["despiked"] == {"k": 6.0, "points": 1} and "caveats" not in summary
    expected = interpolated(z, [1234])
    expected -= expected.mean()  # a table's line is levelled by its mean
    np.testing.assert_allclose(cleaned.generate(None).heights, expected, rtol=0, atol=1e-12)
    # what levelling removed is said of the line without its spike (as a map's record is)
    assert summary["rms_before_detrend"] == pytest.approx(float(np.std(interpolated(z, [1234]))), rel=1e-12)


def test_a_despike_that_would_replace_the_line_itself_is_refused_naming_the_file(tmp_path):
    np.savetxt(tmp_path / "trace.csv", rough_line())
    with pytest.raises(ValueError, match=r"profile-file .*trace\.csv.*despike 0\.001 takes \d+ of 3000 points"):
        ProfileFile(path=str(tmp_path / "trace.csv"), spacing=0.5, despike=0.001).rms_height()


@pytest.mark.parametrize("spikes", [1, 2])
def test_validate_says_how_many_points_despike_replaced_in_english(tmp_path, spikes):
    from frictionlab.io.inputs import describe_input

    z = rough_line()
    z[[700, 1900][:spikes]] += 12.0
    np.savetxt(tmp_path / "trace.csv", z)
    summary = ProfileFile(path=str(tmp_path / "trace.csv"), spacing=0.5, despike=6.0).input_summary()
    said = "1 point replaced" if spikes == 1 else "2 points replaced"
    assert f"despike 6 rms: {said}" in describe_input(summary)
