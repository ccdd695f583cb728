"""What a measured map goes through between the file and the solver, each step a pure
function of the heights: levelling, a crop, removing spikes, and band-limited resampling
(onto square pixels, or onto coarser ones).

Resampling is done by the map's cosine series: a scan's ends do not meet, so its samples
are taken as one half of their even extension (the map reflected across its edges, as the
MDR-equivalent line takes it), whose Fourier series is the discrete cosine transform
(DCT-II). That series is band-limited and passes through every sample; evaluating it on a
new grid is interpolation without a step where the scan ends (a plain FFT would put the
jump between the first and last rows into every mode). For a coarser grid the modes above
the new grid's Nyquist wavenumber are dropped first: an ideal low-pass, so no wavelength
shorter than two new pixels folds back as a false long one (aliasing), and every
wavelength longer than that keeps its amplitude (block averaging damps them by up to 36 %
at the new Nyquist wavenumber and lets some shorter ones through).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

LEVELS = ("none", "mean", "plane", "quadratic")
FLAT = 1e-12  # an rms height below this share of the largest height is the rounding of the numbers: flat
MOST = 0.5  # a tilt or a curvature that carries more than this share of the height variance is warned of


@dataclass(frozen=True)
class Levelling:
    """A map levelled, and how much each part of the least-squares quadratic carried."""

    heights: np.ndarray
    rms_before: float  # about the mean
    rms_after: float  # about the mean, after the levelling
    plane_share: float  # share of the variance (about the mean) carried by the plane
    curvature_share: float  # share carried by the quadratic terms beyond the plane


def _axis(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Centred index t and t^2 less its mean on ``n`` points: with the constant, an orthogonal
    basis of the quadratics along one axis (t is odd, t^2 - mean even about the middle)."""
    t = np.arange(n, dtype=np.float64) - 0.5 * (n - 1)
    return t, t * t - np.mean(t * t)


def level(z: np.ndarray, mode: str) -> Levelling:
    """``z`` less its least-squares ``mode`` (none, mean, plane: a + bx + cy, quadratic: also
    x^2, xy, y^2). On a grid the basis 1, x, y, x^2 - <x^2>, xy, y^2 - <y^2> is orthogonal, so
    each term is one projection (no design matrix of six copies of the map), a factor along y times
    one along x removed a block of rows at a time: one copy of the map (a basis xy was two more)."""
    mean = float(np.mean(z))
    out = z - mean
    ny, nx = z.shape
    x, x2 = _axis(nx)
    y, y2 = _axis(ny)
    along_x, along_y = np.ones(ny), np.ones(nx)  # the other factor of a term along one axis
    rows, columns = out.sum(axis=1), out.sum(axis=0)  # projections of separable terms need only these
    plane = [(columns @ x / (ny * (x @ x)), along_x, x), (rows @ y / (nx * (y @ y)), y, along_y)]
    curved = [(y @ (out @ x) / ((x @ x) * (y @ y)), y, x)]
    if nx > 2:
        curved.append((columns @ x2 / (ny * (x2 @ x2)), along_x, x2))
    if ny > 2:
        curved.append((rows @ y2 / (nx * (y2 @ y2)), y2, along_y))
    size = float(z.size)
    variance = float(np.vdot(out, out)) / size  # no temporary the size of the map
    share = [sum(c * c * (a @ a) * (b @ b) for c, a, b in terms) / size for terms in (plane, curved)]
    removed = plane if mode == "plane" else plane + curved if mode == "quadratic" else []
    block = max(1, LINE_BLOCK // nx)
    for coefficient, a, b in removed:
        for start in range(0, ny, block):
            term = a[start : start + block, None] * b[None, :]
            out[start : start + block] -= np.multiply(term, coefficient, out=term)
    rms_after = math.sqrt(float(np.vdot(out, out)) / size)  # every term removed is orthogonal to the constant
    if mode == "none":
        out = None  # let go before the copy, bit for bit what the file holds
        out = z.copy()
    scale = variance if variance > 0 else math.inf
    return Levelling(out, math.sqrt(variance), rms_after, share[0] / scale, share[1] / scale)


def level_line(z: np.ndarray, mode: str) -> np.ndarray:
    """A new array: the line ``z`` less its least-squares ``mode`` (none: a copy; mean; tilt: also
    t; quadratic: also t^2), one projection per term of the orthogonal basis ``_axis`` (``level``'s
    along one axis)."""
    if mode == "none":
        return z.copy()
    out = z - z.mean()
    t, t2 = _axis(z.size)
    removed = {"tilt": (t,), "quadratic": (t, t2) if z.size > 2 else (t,)}.get(mode, ())
    for basis in removed:  # each orthogonal to the constant and to the other: one projection each
        out -= (np.dot(basis, out) / np.dot(basis, basis)) * basis
    return out


def levelling_warning(levelled: Levelling, mode: str) -> str | None:
    """The caveat of a map whose height is mostly a tilt or a curvature left in it."""
    plane, curvature = levelled.plane_share, levelled.curvature_share
    if mode in ("none", "mean") and plane + curvature > MOST:
        return _form_kept(plane, curvature, "map", mode, "plane")
    # the share of what the plane leaves, from the levelled heights' own rms: 1 - plane loses every digit
    # when a tilt carries all but 1e-16 of the variance (it gave 'inf %', or a share below zero)
    left = curvature * (levelled.rms_before / levelled.rms_after) ** 2 if levelled.rms_after > 0 else 0.0
    if mode == "plane" and left > MOST:
        return (f"a curvature carries {100 * left:.1f} % of the levelled map's height variance: "
                "the contact sits where the form puts it; detrend: quadratic removes it, if it is not the "
                "surface's own shape")  # fmt: skip
    return None


def line_form_warning(z: np.ndarray, mode: str) -> str | None:
    """The caveat of a line (as read) whose height is mostly a form that ``mode`` leaves in
    it: a tilt and a curvature (none, mean) or a curvature (tilt), the least-squares terms'
    share of the variance about the mean (of the variance about the line, after a tilt)."""
    if mode not in ("none", "mean", "tilt"):
        return None
    t, t2 = _axis(z.size)
    centred = z - np.mean(z)
    variance = float(np.dot(centred, centred))
    if not variance > 0:
        return None
    along, norm = float(np.dot(t, centred)), float(np.dot(t, t))
    tilt = along**2 / norm / variance
    curvature = float(np.dot(t2, centred)) ** 2 / float(np.dot(t2, t2)) / variance if z.size > 2 else 0.0
    if mode == "tilt":  # the share of what the tilt leaves, summed from it (1 - tilt is rounding on a steep line)
        rest = centred - (along / norm) * t
        left = curvature * variance / float(np.dot(rest, rest)) if np.any(rest) else 0.0
        if left > MOST:
            return (f"a curvature carries {100 * left:.1f} % of the levelled line's height "
                    "variance: the contact sits where the form puts it; detrend: quadratic removes it, if it is "
                    "not the surface's own shape")  # fmt: skip
        return None
    if tilt + curvature <= MOST:
        return None
    return _form_kept(tilt, curvature, "line", mode, "tilt")


def _form_kept(tilt: float, curvature: float, what: str, mode: str, levels_tilt: str) -> str:
    """The caveat of a form kept (shares of the variance), with the levelling that removes it: the
    tilt's (``levels_tilt``) only if what that leaves is not mostly the curvature, which it keeps."""
    part = "a tilt" if tilt >= curvature else "a curvature"
    remedy = "quadratic" if curvature > MOST * (1.0 - tilt) else f"{levels_tilt} (or quadratic)"
    return (f"{part} carries {100 * (tilt + curvature):.1f} % of the {what}'s height variance (detrend: {mode}): the "
            f"contact sits where the tilt or the form puts it, not on the roughness; detrend: {remedy} levels it")  # fmt: skip


def cosine_resample(z: np.ndarray, axis: int, step: float, new_step: float) -> np.ndarray:
    """``z`` sampled every ``step`` along ``axis`` (the first sample at 0), resampled every
    ``new_step`` from 0 to the last sample, by its band-limited cosine series; for a coarser
    grid, the modes the new grid cannot hold (shorter than two new pixels) are dropped."""
    import scipy.fft  # imported on first use

    n = z.shape[axis]
    points = resampled_points(n, step, new_step)
    coefficients = scipy.fft.dct(z, type=2, axis=axis, norm="ortho")
    ratio = step / new_step
    kept = n if ratio >= 1 else max(1, math.ceil(n * ratio - 1e-9))  # k < n * step / new_step: below the new Nyquist
    t = np.arange(points, dtype=np.float64) / ratio
    k = np.arange(kept, dtype=np.float64)
    # the inverse orthonormal DCT-II, evaluated off the grid: z(t) = sum_k w_k c_k cos(pi k (t + 1/2) / n)
    weights = np.full(kept, math.sqrt(2.0 / n))
    weights[0] = math.sqrt(1.0 / n)
    basis = weights[None, :] * np.cos(np.pi * np.outer(t + 0.5, k) / n)  # (points, kept)
    kept_coefficients = np.take(coefficients, np.arange(kept), axis=axis)
    return np.moveaxis(np.tensordot(basis, np.moveaxis(kept_coefficients, axis, 0), axes=1), 0, axis)


def resampled_points(n: int, step: float, new_step: float) -> int:
    """Points of ``n`` samples every ``step`` resampled every ``new_step`` (``cosine_resample``):
    positions m new_step from the first sample to the last."""
    return math.floor((n - 1) * step / new_step + 1e-9) + 1


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


def _spike_slope_note(z: np.ndarray, rms: float, pixel: tuple[float, float], what: str) -> tuple[str, int]:
    """A clause for the spike caveat when the points ``despike: 6`` replaces carry more than
    SPIKE_SLOPE_SHARE of ``z``'s mean squared slope: the rms slope xi is measured against,
    and the full-contact estimate E* g, are then theirs (one spike 20 rms high on a map of
    128 x 128 pixels triples it); and how many points those are. Empty otherwise."""
    try:
        cleaned, count = despike(z, SPIKE_K, rms)
    except ValueError:  # too many points for spikes: the spike caveat's count is the story
        return "", 0
    spiky, smooth = _mean_square_slope(z, pixel), _mean_square_slope(cleaned, pixel)
    if not spiky > 0 or smooth >= (1.0 - SPIKE_SLOPE_SHARE) * spiky:
        return "", count
    times = f", {math.sqrt(spiky / smooth):.3g} times what it is without them" if smooth > 0 else ""
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


def _mean_square_slope(z: np.ndarray, pixel: tuple[float, float]) -> float:
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
        return _pits_warning(line, rms, (spacing, spacing), "line", "remove {them} from the profile")
    stand, them, they = _agreeing(spikes)
    return (f"{spikes} of the line's {SPIKE_LOOKED_AT} highest points {stand} more than {SPIKE_K:g} rms heights above "
            f"the median of the {SPIKE_WINDOW} points around them: spikes (dust, an instrument's artefact) take the "
            f"first contact alone, and the law at small loads is theirs{_spike_slope_note(line, rms, (spacing, spacing), 'line')[0]}; "
            f"remove {them} from the profile, if {they} "
            "not the surface's own")  # fmt: skip


OUTLIER_RATIO = 5.0  # rms height over the robust one: Gaussian heights 1, a sine's 0.67, a map with a sentinel 100s
OUTLIER_MIN_POINTS = 64  # fewer, and the median says too little
MAD_TO_SIGMA = 1.4826  # the median absolute deviation of Gaussian heights times this is their rms height


def outlier_warning(z: np.ndarray, what: str) -> str | None:
    """The caveat of a levelled map or line (``what``) whose rms height is more than
    OUTLIER_RATIO times its robust one (MAD_TO_SIGMA times the median distance from the median,
    which a few points cannot move): a value an instrument writes for a missing pixel (-9999,
    1e38), spikes down as much as up, scratches. The rms height h, and with it f's unit E* h L,
    are then theirs. ``spike_warning`` looks only at the points that touch first, and measures
    them in the rms height these points inflate. Takes one copy of the map."""
    if z.size < OUTLIER_MIN_POINTS:
        return None
    values = np.array(z, dtype=np.float64).ravel()
    largest = max(float(values.max()), -float(values.min()))  # no temporary |values|
    if not 0 < largest < math.inf:
        return None
    values /= largest  # no overflow from heights of 1e200
    rms = math.sqrt(float(np.dot(values, values)) / values.size)
    middle = values.size // 2
    values.partition(middle)
    np.subtract(values, values[middle], out=values)
    np.abs(values, out=values)
    values.partition(middle)
    robust = MAD_TO_SIGMA * float(values[middle])
    if rms <= OUTLIER_RATIO * robust:
        return None
    ratio = f"{rms / robust:.3g} times" if robust > 0 else f"more than {OUTLIER_RATIO:g} times"
    zero = "" if robust > 0 else "; here zero: more than half of them have one height"
    return (f"the {what}'s rms height is {ratio} what most of its points say ({MAD_TO_SIGMA} times their median "
            f"distance from the median, the rms height of Gaussian heights{zero}): a few points far from the rest make the "
            "rms height h, and with it f's unit E* h L, theirs. A value written for a missing pixel, spikes or "
            "scratches: remove them (despike, region) or mark them undefined in the file, if they are not the "
            "surface's own")  # fmt: skip


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
    MAX_SPIKE_FRACTION of the points would be (``k`` too small: the scan itself, not its spikes)."""
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


FLAT_SHARE = 0.25  # of neighbouring pixels at exactly one height: from here on, the slopes are the steps'


def flat_neighbours_warning(z: np.ndarray, rms: float, what: str) -> str | None:
    """The caveat of a map or line as read (``z``, before levelling, which would make its equal
    heights unequal) whose neighbouring pixels have exactly the same height more often than
    FLAT_SHARE: heights quantized in steps coarser than the roughness between pixels (an
    instrument's height resolution), or clipped flat. Their slopes are zero: a smooth scan
    rounded to steps of a quarter of its rms height pressed to half its b, without a word."""
    if not rms > 0:
        return None
    pairs = equal = 0
    for axis in range(z.ndim):  # views: one boolean the size of the map at a time
        whole = [slice(None)] * z.ndim
        ahead, behind = tuple(whole[:axis] + [slice(1, None)]), tuple(whole[:axis] + [slice(None, -1)])
        pairs, equal = pairs + z[ahead].size, equal + int(np.count_nonzero(z[ahead] == z[behind]))
    if not pairs or equal <= FLAT_SHARE * pairs:
        return _clipped_warning(z, what)
    steps = np.abs(np.diff(z.ravel()))  # along the rows, and from a row's end to the next's start
    step = float(steps[steps > 0].min())  # some: the map is not flat (rms > 0)
    points = "pixels" if what == "map" else "points"
    return (f"{100 * equal / pairs:.0f} % of the {what}'s neighbouring {points} have exactly the same height: its heights "
            f"are steps (the smallest {step:.3g}, {step / rms:.2g} rms heights) coarser than the roughness between "
            f"{points}, or clipped flat; their slopes are zero, so the rms slope and xi are the steps', not the "
            "surface's; measure or export the heights at a finer resolution (a float channel in double precision, or "
            "less their mean: single precision keeps 7 digits of heights far from zero)")  # fmt: skip


CLIPPED_SHARE = 0.01  # of the points at exactly the highest (lowest) height: a range exceeded, not a surface's peaks
CLIPPED_POINTS = 8  # and at least this many: a few points alike at the top are a short line's rounding


def _clipped_warning(z: np.ndarray, what: str) -> str | None:
    """The caveat of a map or line as read with more than CLIPPED_SHARE of its points at its highest (lowest)
    height: an instrument out of its range (an AFM's z saturated), too few neighbours alike for the steps'."""
    for side, edge in (("highest", z.max()), ("lowest", z.min())):
        if (count := int(np.count_nonzero(z == edge))) >= CLIPPED_POINTS and count > CLIPPED_SHARE * z.size:
            return (f"{100 * count / z.size:.3g} % of the {what}'s points sit at exactly its {side} height, {float(edge):.6g}: "
                    "clipped (an instrument's height range exceeded), or a value written for missing points; "
                    f"{'the first contact lands on that plateau, and ' if side == 'highest' else ''}its slopes are "
                    f"zero; measure with a larger height range, or leave the clipped part out "
                    f"({'region' if what == 'map' else 'of the profile'}), if it is not the surface's own")  # fmt: skip
    return None


LINE_JUMP_SHARE = 0.5  # of the height change across lines that whole lines standing apart carry: said from here on
LINE_JUMP_CORRELATION = -0.4  # successive lines' jumps anticorrelated (a line's own offset in both): not a smooth form
LINE_HALVES_APART = 0.25  # the two halves of a line offset alike (their offsets' mean square difference, of theirs)
LINE_BLOCK = 2**20  # points of the map looked at a time
LINES_LOOKED_AT = 512  # consecutive lines (of a larger map) whose offsets are measured: enough to tell, in a second


def line_offset_warning(z: np.ndarray) -> str | None:
    """The caveat of a map whose rows (or columns) stand apart by a height the same all along
    each: a scanner's offsets between lines, left unless its lines were aligned. A line's offset
    against its neighbours is the median along it of its heights less the mean of its two
    neighbours' (zero for any plane, and any form along the line). Said when offsets carry most of
    that difference's variance (LINE_JUMP_SHARE), successive ones are anticorrelated (a line's
    own offset enters its own and its neighbours'; a form across the lines makes them correlated),
    and each line's two halves have the same offset (a surface whose lines differ by a wandering
    height has them apart). Offsets of a twentieth of the rms height took 40 % off MDR's b."""
    for axis, lines in ((0, "rows"), (1, "columns")):
        share, correlation, halves = _line_offsets(z if axis == 0 else z.T)
        if share > LINE_JUMP_SHARE and correlation < LINE_JUMP_CORRELATION and halves < LINE_HALVES_APART:
            along = "x" if axis == 0 else "y"
            return (f"the map's {lines} stand apart: {100 * share:.0f} % of its height change across them (a line "
                    f"against the mean of its two neighbours) is whole {lines} offset, by one height all along each "
                    "(a scanner's offsets between lines, as an AFM leaves them unless its lines are aligned): the "
                    f"slopes across the {lines}, and xi, are the offsets'; align the {lines} (Gwyddion: Align Rows, "
                    f"median) before exporting, if they are not the surface's own (grooves along {along})")  # fmt: skip
    return None


def _line_offsets(z: np.ndarray) -> tuple[float, float, float]:
    """For the rows of ``z`` less the mean of their neighbours: the share of the variance that each
    row's median carries, the lag-1 correlation of those medians, and the mean square difference
    of the medians of each row's two halves over that of the medians; a block of rows at a time."""
    ny, nx = z.shape
    rows, half = max(1, LINE_BLOCK // nx), nx // 2
    first = max(1, (ny - LINES_LOOKED_AT) // 2)  # a band of consecutive lines in the middle: offsets are everywhere
    last = min(ny - 1, first + LINES_LOOKED_AT)
    medians, apart, total = [], 0.0, 0.0
    for start in range(first, last, rows):
        stop = min(start + rows, last)
        against = z[start:stop] - 0.5 * (z[start - 1 : stop - 1] + z[start + 1 : stop + 1])
        total += float(np.vdot(against, against))
        medians.append(np.median(against, axis=1))
        difference = np.median(against[:, :half], axis=1) - np.median(against[:, half:], axis=1)
        apart += float(np.dot(difference, difference))
    offsets = np.concatenate(medians) if medians else np.zeros(0)
    power = float(np.dot(offsets, offsets))
    if not total > 0 or offsets.size < 3 or half < 1 or not power > 0:
        return 0.0, 0.0, math.inf
    return power * nx / total, float(np.dot(offsets[1:], offsets[:-1])) / power, apart / power


def flat_rms(rms: float, largest: float) -> tuple[str, str]:
    """The rms height of a map or line refused as flat (below FLAT of its ``largest`` height), as its
    message says it, and what it is: zero, or the rounding of its numbers (5 + 1e-14 noise is not 'zero')."""
    if rms == 0:
        return "zero", ""
    return f"{rms:.3g}", f", below {FLAT:g} of its largest height {largest:.3g}: the rounding of its numbers"
