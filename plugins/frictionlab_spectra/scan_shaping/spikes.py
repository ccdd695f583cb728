"""Spikes: the caveats of a map or a line whose highest points stand alone above the median around
them (or whose pits carry its slope), and ``despike``, which replaces such points by the solution
of Laplace's equation from their neighbours."""

from __future__ import annotations

import math

import numpy as np


MAX_SPIKE_FRACTION = 0.05  # despike replaces at most this share of a map's points
SPIKE_K = 6.0  # rms heights above the median around it: what despike's usual value calls a spike
SPIKE_WINDOW = 5  # pixels a side of the square whose median a point is measured from (despike and its caveat)
SPIKE_LOOKED_AT = 16  # the highest points looked at for spikes: those that carry the first contact


def spike_warning(z: np.ndarray, rms: float, pixel: tuple[float, float] = (1.0, 1.0)) -> str | None:
    """The caveat of a map (levelled, not despiked; pixels of ``pixel`` = (dx, dy)) among whose
    SPIKE_LOOKED_AT highest points some stand more than SPIKE_K ``rms`` above the median of the
    5 x 5 pixels around them (edges reflected, as ``despike`` reads them): spikes take the first
    contact alone, and ``despike: 6`` would replace exactly them. Only the highest points are
    looked at (cheap on any map), those above 3 rms: a spike lower than that touches no earlier
    than the surface. ``_spike_slope_note`` adds what they do to the rms slope."""
    if not rms > 0 or min(z.shape) < 3:
        return None
    spikes = _spikes(z, rms)
    if not spikes:
        return _pits_warning(z, rms, pixel, "map", f"despike: {SPIKE_K:g} replaces {{them}}")
    stand, them, they = _agreeing(spikes)
    return (f"{spikes} of the map's {SPIKE_LOOKED_AT} highest points {stand} more than {SPIKE_K:g} rms "
            "heights above the median of the 5 x 5 pixels around them: spikes (dust, an instrument's artefact) take "
            f"the first contact alone, and the law at small loads is theirs{_spike_slope_note(z, rms, pixel, 'map')[0]}; "
            f"despike: {SPIKE_K:g} replaces {them}, if {they} not the surface's own")  # fmt: skip


SPIKE_SLOPE_SHARE = 0.5  # of the mean squared slope: spikes carrying more make the rms slope theirs
LEVEL_REST = 1e-12  # of the mean squared slope: the rest, despiked, carrying less is level (a ratio past 1e6)


def _spike_slope_note(z: np.ndarray, rms: float, pixel: tuple[float, float], what: str) -> tuple[str, int]:
    """A clause for the spike caveat when the points ``despike: 6`` replaces carry more than
    SPIKE_SLOPE_SHARE of ``z``'s mean squared slope: the rms slope xi is measured against,
    and the full-contact estimate E* g, are then theirs (one spike 20 rms high on a map of
    128 x 128 pixels triples it); and how many points those are. Empty otherwise."""
    try:
        cleaned, count = despike(z, SPIKE_K, rms)
    except ValueError:  # too many points for spikes: the spike caveat's count is the story
        return "", 0
    spiky, smooth = mean_square_slope(z, pixel), mean_square_slope(cleaned, pixel)
    if not spiky > 0 or smooth >= (1.0 - SPIKE_SLOPE_SHARE) * spiky:
        return "", count
    level = smooth <= LEVEL_REST * spiky  # rounding's residue, not a slope: no ratio of 1e17 said
    times = ", the rest level" if level else f", {math.sqrt(spiky / smooth):.3g} times what it is without them"
    return (f"; they carry {100 * (1 - smooth / spiky):.0f} % of the {what}'s mean squared slope (its rms slope is "
            f"{math.sqrt(spiky):.3g}{times}), so the rms slope xi divides by, and the full-contact estimate p = E* g, "
            "are theirs too", count)  # fmt: skip


FEW_DIFFERENCES = 0.01  # the largest squared differences looked at: a few points' (a spike has 4, a line's 2)


def _pits_warning(z: np.ndarray, rms: float, pixel: tuple[float, float], what: str, fix: str) -> str | None:
    """The caveat of a map or line (``z``, 2-D) with no spike up whose points ``despike: 6``
    replaces (pits, a dropout written as a height) carry most of its mean squared slope: they
    touch no earlier than the surface, but the rms slope is theirs. The median filter runs only
    when the largest FEW_DIFFERENCES of the squared differences carry that share (1.5 s on 2048^2)."""
    total = largest = 0.0
    for square in _squared_slopes(z, pixel):  # one axis at a time: one copy of the map
        top = min(square.size, max(2, int(FEW_DIFFERENCES * square.size)))
        total += float(square.sum())
        square = square.ravel()
        square.partition(square.size - top)
        largest += float(square[-top:].sum())
    if not total > 0 or largest <= SPIKE_SLOPE_SHARE * total:
        return None
    note, count = _spike_slope_note(z, rms, pixel, what)
    if not note:
        return None
    around = f"{SPIKE_WINDOW} x {SPIKE_WINDOW} pixels" if z.shape[0] > 1 else f"{SPIKE_WINDOW} points"
    stand, them, they = _agreeing(count)
    return (f"{count} of the {what}'s points {stand} more than {SPIKE_K:g} rms heights from the median of the {around} "
            "around them, none a spike among its highest points: pits, or dropouts an instrument wrote as heights "
            f"rather than leaving them undefined{note}; {fix.format(them=them)}, if {they} not the surface's own")  # fmt: skip


def mean_square_slope(z: np.ndarray, pixel: tuple[float, float]) -> float:
    """The mean squared gradient of map ``z`` (a line: one row) by forward differences on pixels of (dx, dy)."""
    return sum(float(np.mean(square)) for square in _squared_slopes(z, pixel))


def _squared_slopes(z: np.ndarray, pixel: tuple[float, float]):
    """The squared forward differences of ``z`` over (dx, dy), along x and (a map) along y, one at a time."""
    for axis, step in ((1, pixel[0]), (0, pixel[1])):
        if z.shape[axis] > 1:
            square = np.diff(z, axis=axis)
            square /= step
            yield np.square(square, out=square)


def _agreeing(spikes: int) -> tuple[str, str, str]:
    """The verb and pronouns that agree with a count of spikes: one stands, two stand."""
    return ("stands", "it", "it is") if spikes == 1 else ("stand", "them", "they are")


def line_spike_warning(z: np.ndarray, rms: float, spacing: float = 1.0) -> str | None:
    """The caveat of a line (levelled, points ``spacing`` apart) with spikes, by ``spike_warning``'s
    criterion along the line: the median of the SPIKE_WINDOW points around each of its highest points."""
    if not rms > 0 or z.size < SPIKE_WINDOW:
        return None
    line = z.reshape(1, -1)
    spikes = _spikes(line, rms)
    if not spikes:
        return _pits_warning(line, rms, (spacing, spacing), "line", f"despike: {SPIKE_K:g} replaces {{them}}")
    stand, them, they = _agreeing(spikes)
    return (f"{spikes} of the line's {SPIKE_LOOKED_AT} highest points {stand} more than {SPIKE_K:g} rms heights above "
            f"the median of the {SPIKE_WINDOW} points around them: spikes (dust, an instrument's artefact) take the "
            f"first contact alone, and the law at small loads is theirs{_spike_slope_note(line, rms, (spacing, spacing), 'line')[0]}; "
            f"despike: {SPIKE_K:g} replaces {them}, if {they} not the surface's own")  # fmt: skip

def _spikes(z: np.ndarray, rms: float) -> int:
    """How many of the SPIKE_LOOKED_AT highest points of ``z`` (above 3 ``rms``) stand more than
    SPIKE_K ``rms`` above the median of the SPIKE_WINDOW x SPIKE_WINDOW pixels around them."""
    high = np.flatnonzero(z > 3.0 * rms)  # a boolean of the map, the indices of its tallest points
    if high.size > SPIKE_LOOKED_AT:
        high = high[np.argpartition(z.ravel()[high], high.size - SPIKE_LOOKED_AT)[-SPIKE_LOOKED_AT:]]
    ny, nx = z.shape
    spikes = 0
    for index in high:
        row, column = divmod(int(index), nx)
        half = SPIKE_WINDOW // 2
        rows = [_reflect(r, ny) for r in range(row - half, row + half + 1)] if ny > 1 else [0]  # a line: its row
        columns = [_reflect(c, nx) for c in range(column - half, column + half + 1)]
        if z[row, column] - np.median(z[np.ix_(rows, columns)]) > SPIKE_K * rms:
            spikes += 1
    return spikes


def _reflect(i: int, n: int) -> int:
    """Index ``i`` on ``n`` points with the edges reflected (d c b a | a b c d), scipy's ``reflect``."""
    return -i - 1 if i < 0 else 2 * n - i - 1 if i >= n else i


def despike(z: np.ndarray, k: float, rms: float) -> tuple[np.ndarray, int]:
    """``z`` with every point more than ``k`` ``rms`` from the median of the 5 x 5 pixels around
    it (a spike up to a few pixels wide cannot move that median) replaced by the solution of
    Laplace's equation from its neighbours; and how many were replaced. ValueError when more than
    MAX_SPIKE_FRACTION of the points would be (``k`` too small: the scan itself, not its spikes).
    A line is one row: the median of the 5 points around, and the straight line between the
    nearest points kept (Laplace's equation on a line; level from the one kept past an end)."""
    from scipy import ndimage
    from scipy.sparse.linalg import spsolve

    local = ndimage.median_filter(z, size=SPIKE_WINDOW, mode="reflect")
    np.subtract(z, local, out=local)  # in place: the filter's copy of the map is the only one made
    spike = np.abs(local, out=local) > k * rms
    del local
    flat = np.flatnonzero(spike)  # sorted: a neighbour is a spike where searchsorted finds it
    del spike
    count = int(flat.size)
    if count > MAX_SPIKE_FRACTION * z.size:  # refused before one equation per point is built (a 4096^2 map: hours)
        raise ValueError(
            f"despike {k:g} takes {count} of {z.size} points ({100 * count / z.size:.1f} %) for spikes: a spike is a "
            f"rare point, and replacing more than {100 * MAX_SPIKE_FRACTION:g} % of a scan replaces the scan itself; "
            "give a larger despike (6 rms heights is usual)"
        )
    if not count:  # (every point a spike was refused above)
        return z, 0
    matrix, rhs = _laplace_system(z, flat)
    out = z.copy()
    out.ravel()[flat] = spsolve(matrix, rhs)  # out is contiguous: ravel is a view
    return out, count


def _laplace_system(z: np.ndarray, flat: np.ndarray):
    """Laplace's equation on the points of ``z`` at the sorted flat indices ``flat`` from their 4 neighbours
    inside the map (one among them an unknown): arrays of their size (a map's index was two copies)."""
    from scipy import sparse

    ny, nx = z.shape
    count = flat.size
    own = np.arange(count)
    i, j = np.divmod(flat, nx)
    degree, rhs = np.zeros(count), np.zeros(count)
    rows, cols = [own], [own]
    for di, dj in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        a, b = i + di, j + dj
        inside = (a >= 0) & (a < ny) & (b >= 0) & (b < nx)
        a, b = np.clip(a, 0, ny - 1), np.clip(b, 0, nx - 1)
        at = np.minimum(np.searchsorted(flat, a * nx + b), count - 1)
        unknown = inside & (flat[at] == a * nx + b)
        degree += inside
        rhs += np.where(inside & ~unknown, z[a, b], 0.0)
        rows.append(own[unknown]), cols.append(at[unknown])
    values = np.concatenate([degree, -np.ones(sum(r.size for r in rows[1:]))])
    matrix = sparse.csr_matrix((values, (np.concatenate(rows), np.concatenate(cols))), shape=(count, count))
    return matrix, rhs
