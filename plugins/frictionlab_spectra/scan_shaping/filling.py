"""Points a table marks as not measured (NaN: an optical profilometer's dropouts) filled from
their neighbours, as SurfaceTopography fills an instrument file's (``undefined: harmonic``)."""

from __future__ import annotations

import numpy as np

STEPS = ((0, 1), (0, -1), (1, 0), (-1, 0))  # a pixel's neighbours in a map


def fill_harmonic(z: np.ndarray, periodic: bool = False) -> int:
    """Fill the NaN of the line or map ``z`` in place with the solution of Laplace's equation over
    them, the defined heights around them fixed and nothing flowing across the map's edges, or
    across them to the opposite edge where ``periodic`` (on a line: straight between its defined
    neighbours, level past its first or last); return how many. At least one height must be defined."""
    holes = np.isnan(z)
    count = int(np.count_nonzero(holes))
    if not count:
        return 0
    if z.ndim == 1:
        known = np.flatnonzero(~holes)
        z[holes] = np.interp(np.flatnonzero(holes), known, z[known], period=z.size if periodic else None)
        return count
    import scipy.sparse  # imported on first use: most maps have no holes
    import scipy.sparse.linalg

    number = np.full(z.shape, -1, dtype=np.int64)
    number[holes] = np.arange(count)  # hole k is (ys[k], xs[k]): both in row-major order
    ys, xs = np.nonzero(holes)
    degree, known_sum, rows, cols = np.zeros(count), np.zeros(count), [], []
    for dy, dx in STEPS:
        y, x = ys + dy, xs + dx
        if periodic:  # the opposite edge's pixel is a neighbour
            y, x = y % z.shape[0], x % z.shape[1]
        inside = np.flatnonzero((y >= 0) & (y < z.shape[0]) & (x >= 0) & (x < z.shape[1]))
        degree[inside] += 1
        neighbour = number[y[inside], x[inside]]
        rows.append(inside[neighbour >= 0])
        cols.append(neighbour[neighbour >= 0])
        np.add.at(known_sum, inside[neighbour < 0], z[y[inside][neighbour < 0], x[inside][neighbour < 0]])
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    laplacian = scipy.sparse.diags(degree) - scipy.sparse.csr_matrix((np.ones(rows.size), (rows, cols)),
                                                                      shape=(count, count))  # fmt: skip
    z[holes] = scipy.sparse.linalg.spsolve(laplacian.tocsc(), known_sum)
    return count
