"""despike's spikes are replaced from arrays of their own size: the map's full int64 index of
them (two more copies of the map than the memory estimate counts) is gone, and what it
replaces them with is unchanged."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from scipy import ndimage

from frictionlab_spectra.scan_shaping import despike


def _laplace_filled(z: np.ndarray, spike: np.ndarray) -> np.ndarray:
    """The spikes of ``z`` replaced by the solution of Laplace's equation from their 4 neighbours
    inside the map, solved densely, one equation per spike (the reference)."""
    where = [tuple(p) for p in np.argwhere(spike)]
    number = {p: n for n, p in enumerate(where)}
    matrix, rhs = np.zeros((len(where), len(where))), np.zeros(len(where))
    for n, (i, j) in enumerate(where):
        for a, b in ((i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1)):
            if 0 <= a < z.shape[0] and 0 <= b < z.shape[1]:
                matrix[n, n] += 1.0
                if (a, b) in number:
                    matrix[n, number[(a, b)]] = -1.0
                else:
                    rhs[n] += z[a, b]
    out = z.copy()
    out[spike] = np.linalg.solve(matrix, rhs)
    return out


@pytest.mark.parametrize("shape", [(1, 200), (2, 120), (17, 23), (40, 48)])
def test_despike_fills_spikes_at_edges_corners_and_side_by_side_as_laplace_does(shape):
    z = np.random.default_rng(sum(shape)).normal(size=shape)
    ny, nx = shape
    for i, j in {(0, 0), (ny - 1, nx - 1), (0, nx - 1), (ny // 2, nx // 2), (ny // 2, nx // 2 + 1), (ny - 1, 3)}:
        z[i, j] += 30.0  # corners, an edge, two side by side
    cleaned, count = despike(z, 6.0, 1.0)
    spike = np.abs(z - ndimage.median_filter(z, size=5, mode="reflect")) > 6.0
    assert count == int(spike.sum()) >= 4
    np.testing.assert_allclose(cleaned, _laplace_filled(z, spike), rtol=1e-12, atol=1e-12)


def test_despike_holds_little_more_than_the_median_filters_copy_of_the_map():
    z = np.random.default_rng(7).normal(size=(256, 256))
    z[::37, ::41] += 40.0
    despike(z, 6.0, 1.0)  # scipy's imports and caches before the count
    tracemalloc.start()
    try:
        cleaned, count = despike(z, 6.0, 1.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert count == 49
    assert peak < 2 * z.nbytes, peak / z.nbytes  # the filter's copy, then the copy returned (it held 3.1)


@pytest.mark.parametrize("detrend", ["plane", "quadratic", "none"])
def test_a_map_levelled_and_despiked_holds_at_most_three_copies_of_it(monkeypatch, detrend):
    """HEIGHT_COPIES counts four copies of a map while it is read (the reader's, ours, levelled,
    resampled): levelling held three (a basis xy of the map's size, and its square), and the
    despiked map levelled again five at once."""
    from types import SimpleNamespace

    from frictionlab_spectra import map_pipeline
    from frictionlab_spectra.scan_shaping import levelling, line_offsets

    for module in (levelling, line_offsets):  # blocks of rows a map of millions of points has
        monkeypatch.setattr(module, "LINE_BLOCK", 4096)
    z = np.random.default_rng(9).normal(size=(256, 256))
    z[::37, ::41] += 40.0
    p = SimpleNamespace(region=None, detrend=detrend, despike=6.0, downsample=None)
    map_pipeline.shape_map(z, (1.0, 1.0), p, "w", instrument=True, periodic=False)  # imports before the count
    tracemalloc.start()
    try:
        heights, _, done = map_pipeline.shape_map(z, (1.0, 1.0), p, "w", instrument=True, periodic=False)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert done["despiked"]["points"] == 49
    assert peak < 3 * z.nbytes, peak / z.nbytes  # beyond the map read (it held 6)
