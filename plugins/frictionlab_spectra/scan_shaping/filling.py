"""Points a table marks as not measured (NaN: an optical profilometer's dropouts) filled from
their neighbours, as SurfaceTopography fills an instrument file's (``undefined: harmonic``)."""

from __future__ import annotations

import math

import numpy as np

STEPS = ((0, 1), (0, -1), (1, 0), (-1, 0))  # a pixel's neighbours in a map
# The peak of fill_harmonic on a map, measured on square holes of a thousand to a million pixels,
# the worst shape (its sparse LU factors grow as h log h; scattered holes take a third), by the
# growth of the process's peak memory (the factors are allocated outside Python's tracing): 1610
# to 2300 bytes a hole resident, about 100 more each time the holes double, plus the map-sized
# index (int64) and mask and a few MiB whatever the size; and twice that in address space (what
# ``ulimit -v`` counts: the factors grow by reallocation), plus some 50 MiB. The figures add a
# sixth or more.
FILL_BASE = 2 * 2**20
FILL_RESERVED_BASE = 64 * 2**20
MAP_BYTES_PER_POINT = 9
HOLE_BYTES = 400
HOLE_BYTES_PER_DOUBLING = 110
LINE_BYTES_PER_POINT = 40  # a line's: np.interp's index arrays and the filled values


def harmonic_fill_bytes(shape: tuple[int, ...], holes: int, reserved: bool = False) -> int:
    """An upper bound of the memory ``fill_harmonic`` takes on a line or map of ``shape`` with
    ``holes`` NaN, beyond the heights themselves: resident, or (``reserved``) the address space
    it reserves (see the figures above)."""
    if holes <= 0:
        return 0
    if len(shape) == 1:
        return LINE_BYTES_PER_POINT * int(shape[0])
    factors = holes * (HOLE_BYTES + HOLE_BYTES_PER_DOUBLING * math.log2(holes))
    base, factors = (FILL_RESERVED_BASE, 2 * factors) if reserved else (FILL_BASE, factors)
    return math.ceil(base + MAP_BYTES_PER_POINT * math.prod(shape) + factors)


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
