"""Levelling a map or a line: its least-squares mean, plane (tilt) or quadratic removed, and the
caveat of a tilt or a curvature the chosen levelling leaves in it."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

LEVELS = ("none", "mean", "plane", "quadratic")
MOST = 0.5  # a tilt or a curvature that carries more than this share of the height variance is warned of
LINE_BLOCK = 2**20  # points of the map looked at a time (levelling and the line offsets: one block of rows)


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


def periodic_levelling_problem(detrend: str | None, what: str) -> str | None:
    """What is wrong with levelling a periodic map (``what``: or line) by more than its mean: the
    least-squares plane (tilt) or parabola of heights that repeat is no form of theirs, and taking
    it off leaves a step where they repeat (the rms slope of a sine map doubled)."""
    if detrend in (None, "none", "mean"):
        return None
    form = "plane" if what == "map" else "tilt"
    return (f"detrend: {detrend!r} on a periodic {what} (periodic: true, or as the file says) takes off a {form} or "
            f"parabola that heights which repeat do not have, and leaves a step where the {what} repeats; give "
            "detrend: mean or none, or set periodic: false")  # fmt: skip


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
    (part, share), (other, more) = sorted((("a tilt", tilt), ("a curvature", curvature)), key=lambda kv: -kv[1])
    also = f" and {other} {100 * more:.1f} % more" if more >= 0.0005 else ""  # each its own share, as rounded
    remedy = "quadratic" if curvature > MOST * (1.0 - tilt) else f"{levels_tilt} (or quadratic)"
    return (f"{part} carries {100 * share:.1f} %{also} of the {what}'s height variance (detrend: {mode}): the "
            f"contact sits where the tilt or the form puts it, not on the roughness; detrend: {remedy} levels it")  # fmt: skip
