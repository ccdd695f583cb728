"""The real contact area of a pixelated contact, corrected for its perimeter.

A boundary-element solution counts a pixel as in contact when its pressure is
positive. Near a contact edge the pressure falls to zero as the square root of the
distance to the edge, and the pixels the edge crosses count whole: the pixel count
overestimates the area by a strip along the perimeter, an error that decays only as
1 / resolution. Yastrebov, Anciaux and Molinari (Tribol. Int. 2017, arXiv
1701.02727) derive the strip from that edge profile, per pixel edge crossed:

    A* = N - c M pixels,  c = (pi - 1 + ln 2) / 24 = 0.1181,

with N the pixels in contact and M the edges between a contact and a free pixel
along rows and columns. The derivation is for the pixel edges of a surface on a
half-space; the solvers of lines report no corrected area. On a periodic map the
last row and column neighbour the first; on a scan (a free boundary) they do not,
and the scan's border is no contact edge (the pressure there is cut, not falling to zero).
"""

from __future__ import annotations

import math

import numpy as np

YASTREBOV_ANCIAUX_MOLINARI = "10.48550/arXiv.1701.02727"  # Tribol. Int. 2017
PERIMETER_COEFFICIENT = (math.pi - 1.0 + math.log(2.0)) / 24.0


def contact_edges(contact: np.ndarray, periodic: bool = True) -> int:
    """M: edges between a contact and a free pixel along the rows and columns of a
    map: with ``periodic``, the last row and column neighbour the first; without, only
    the pairs inside the map count."""
    contact = np.asarray(contact, dtype=bool)
    if contact.ndim != 2:
        raise ValueError(f"contact must be a map of shape (Ny, Nx). Got shape {contact.shape} instead.")
    edges = 0
    for axis in (0, 1):
        inner = np.count_nonzero(np.diff(contact, axis=axis))  # pairs that differ inside the map
        wrap = np.count_nonzero(contact.take(0, axis=axis) != contact.take(-1, axis=axis))
        edges += inner + (wrap if periodic and contact.shape[axis] > 1 else 0)
    return int(edges)


def corrected_area_fraction(contact: np.ndarray, periodic: bool = True) -> float:
    """(N - c M) / pixels: the perimeter-corrected real area, a fraction of the nominal
    area, of the contact map ``contact`` (True where in contact; ``contact_edges``)."""
    contact = np.asarray(contact, dtype=bool)
    count = int(np.count_nonzero(contact))
    return (count - PERIMETER_COEFFICIENT * contact_edges(contact, periodic)) / contact.size


def contact_weights(contact: np.ndarray, *, periodic: bool = True) -> np.ndarray:
    """Each pixel's share of the corrected area: 1 - c m for a contact pixel with m free
    neighbours along its row and column, 0 for a free pixel; they sum to N - c M, the
    corrected area of ``corrected_area_fraction`` (each edge has one contact pixel). On a
    periodic map the last row and column neighbour the first; on a scan (``periodic``
    False) the map's border is no edge: what lies beyond it is unknown."""
    contact = np.asarray(contact, dtype=bool)
    if contact.ndim != 2:
        raise ValueError(f"contact must be a map of shape (Ny, Nx). Got shape {contact.shape} instead.")
    free_neighbours = np.zeros(contact.shape, dtype=np.int8)
    for axis in (0, 1):
        if contact.shape[axis] < 2:
            continue
        for shift in (1, -1):
            neighbour = np.roll(contact, shift, axis=axis)
            differs = contact & ~neighbour
            if not periodic:  # the row or column rolled in from the far side is no neighbour
                border = [slice(None)] * 2
                border[axis] = 0 if shift == 1 else -1
                differs[tuple(border)] = False
            free_neighbours += differs
    return np.where(contact, 1.0 - PERIMETER_COEFFICIENT * free_neighbours, 0.0)


def corrected_gradient_rms(contact: np.ndarray, slopes: np.ndarray, *, periodic: bool = True) -> float:
    """g_r: the rms of ``slopes`` (|grad z| per pixel) over the real contact, each contact
    pixel weighted by its share of the corrected area (``contact_weights``), so that the
    gradient and the area are corrected alike. NaN without contact."""
    weights = contact_weights(contact, periodic=periodic)
    total = float(weights.sum())
    if total <= 0.0:
        return float("nan")
    inside = weights > 0.0
    return float(np.sqrt(np.sum(weights[inside] * np.square(np.asarray(slopes, float)[inside])) / total))


def contact_spots(contact: np.ndarray, *, periodic: bool = True) -> int:
    """The number of contact spots: clusters of contact pixels joined along rows and
    columns, a cluster crossing the periodic boundary counted once (``periodic``); on a
    scan the border joins nothing."""
    from scipy import ndimage

    contact = np.asarray(contact, dtype=bool)
    labels, count = ndimage.label(contact)  # 4-connectivity
    if not periodic or count < 2:
        return int(count)
    parent = list(range(count + 1))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    merged = 0
    for first, last in ((labels[0], labels[-1]), (labels[:, 0], labels[:, -1])):
        for a, b in set(zip(first[(first > 0) & (last > 0)].tolist(), last[(first > 0) & (last > 0)].tolist())):
            ra, rb = root(a), root(b)
            if ra != rb:
                parent[ra] = rb
                merged += 1
    return int(count - merged)
