"""The elastic body shared by the solvers: E* = E / (1 - nu^2), its parameters, and
the operator that turns a surface pressure into a surface displacement.

The exact solvers' conjugate gradients see the elastic body only through an
*elastic operator* (:class:`ElasticOperator`): the displacement under a pressure
field, an approximate inverse of it (the preconditioner), and the grid both live
on. :class:`PeriodicHalfSpace` is the periodic one, a diagonal in Fourier space; a
body with free (non-periodic) boundaries is another operator with the same three
members, and the CGs take it unchanged.
"""

from __future__ import annotations

import functools
from typing import Protocol

import numpy as np
from pydantic import Field

from frictionlab import PluginParams

from .arrays import host, is_numpy, namespace, on_device

__all__ = ["ElasticOperator", "ElasticParams", "FFTPair", "PeriodicHalfSpace", "effective_modulus", "elastic_stiffness"]


def effective_modulus(youngs_modulus: float, poisson_ratio: float) -> float:
    """Plane-strain modulus E* = E / (1 - nu^2); infinite is rejected (nu = +-1)."""
    denominator = 1.0 - poisson_ratio * poisson_ratio
    if denominator <= 0.0:
        raise ValueError(
            f"poisson_ratio = {poisson_ratio} gives 1 - nu^2 = {denominator}: "
            "the effective modulus E/(1 - nu^2) is not finite"
        )
    return youngs_modulus / denominator


class ElasticParams(PluginParams):
    """The elastic body of MDR and of the exact (BEM) solvers: E and nu, giving E*."""

    youngs_modulus: float = Field(1.0, gt=0.0, allow_inf_nan=False, description="Young's modulus E of the elastic body")
    poisson_ratio: float = Field(
        0.0,
        gt=-1.0,
        le=0.5,
        allow_inf_nan=False,
        description="Poisson ratio nu of the elastic body; E* = E / (1 - nu^2) (nu = 0.5: incompressible)",
    )


def elastic_stiffness(params: ElasticParams) -> float:
    return effective_modulus(params.youngs_modulus, params.poisson_ratio)


class ElasticOperator(Protocol):
    """What a contact CG needs of the elastic body, in scaled units (pixels, E* = 1).

    ``shape`` is the grid of pressures and displacements. ``displacement`` and
    ``precondition`` write into ``out`` (a float array of ``shape``) and return
    it; both are linear and symmetric, ``displacement`` positive definite on
    the pressures of a partial contact, ``precondition`` positive semi-definite.
    ``displacement_estimate`` is ``displacement`` to single precision (or
    ``displacement`` itself): the CG corrects its gap with it after clipping
    points, and recomputes the gap with ``displacement`` before it stops.
    ``precondition`` approximates the inverse of ``displacement`` (a stiffness),
    and may be rough: it only speeds the CG up. ``point_stiffness`` is the
    pressure on one point per unit of its own displacement (the inverse of the
    diagonal of ``displacement``).

    The displacement's reference (here zero mean, the rigid level of a periodic
    body) is the operator's: the CG finds the rigid level either way.
    """

    shape: tuple[int, ...]
    point_stiffness: float

    def displacement(self, pressure: np.ndarray, out: np.ndarray) -> np.ndarray: ...

    def displacement_estimate(self, pressure: np.ndarray, out: np.ndarray) -> np.ndarray: ...

    def precondition(self, residual: np.ndarray, out: np.ndarray) -> np.ndarray: ...


class PeriodicHalfSpace:
    """The periodic elastic half-space (2D grids) or half-plane in plane strain (1D):
    ``u_q = 2 p_q / |q|`` in Fourier space, its inverse ``|q| / 2`` the preconditioner.

    The mean mode q = 0 has no finite stiffness: it is the rigid-body level, and
    displacements have zero mean. The preconditioner leaves that mode out too (a
    uniform pressure moves nothing, so no displacement asks for one).

    ``xp`` is the array namespace the fields live in (numpy by default; CuPy on a GPU;
    any array-API namespace with the ``fft`` extension); ``workers`` the threads of each
    FFT on numpy (``FFTPair``).
    """

    def __init__(self, shape: tuple[int, ...], xp=None, workers: int = 1):
        self.shape = tuple(shape)
        self.axes = tuple(range(len(self.shape)))
        self.xp = namespace("cpu") if xp is None else xp
        self.workers = workers
        self.pair = FFTPair(self.shape, self.xp, workers)
        q = _wave_number(self.shape)
        compliance = np.zeros(q.shape)
        np.divide(2.0, q, out=compliance, where=q > 0)
        stiffness = q / 2.0  # zero for the mean mode: exact inverse on zero-mean fields
        self.compliance = on_device(self.xp, compliance)
        self.stiffness = on_device(self.xp, stiffness)
        self.stiffness32 = on_device(self.xp, stiffness.astype(np.float32))
        self.compliance32 = on_device(self.xp, compliance.astype(np.float32))

    @functools.cached_property
    def point_stiffness(self) -> float:
        """Pressure on one point per unit of its own displacement (an inverse FFT:
        computed when first asked for)."""
        import scipy.fft  # imported on first use: a run that needs no FFT here starts faster

        return 1.0 / float(scipy.fft.irfftn(host(self.compliance), s=self.shape).flat[0])

    def displacement(self, pressure, out):
        """Zero-mean surface displacement under ``pressure``, written into ``out``."""
        return self._apply(self.compliance, pressure, out)

    def displacement_estimate(self, pressure, out):
        """``displacement`` in single precision (rounding 6e-8 relative), for the
        corrections the CG recomputes exactly before it stops."""
        return self._apply_single(self.compliance32, pressure, out)

    def precondition(self, residual, out):
        """The stiffness ``|q| / 2`` applied to ``residual``, in single precision:
        a preconditioner need only be close to the inverse (its rounding changes no
        stop and no step's exactness)."""
        return self._apply_single(self.stiffness32, residual, out)

    def precondition_single(self, residual32):
        """``precondition`` of a float32 grid, returned as a new float32 grid (the CG reads
        it on its working set only)."""
        return self._apply_single(self.stiffness32, residual32, None)

    def displacement_single(self, pressure32):
        """``displacement_estimate`` of a float32 grid, returned as a new float32 grid."""
        return self._apply_single(self.compliance32, pressure32, None)

    def pressure_of(self, displacement: np.ndarray) -> np.ndarray:
        """The zero-mean pressure (numpy) that makes ``displacement`` (numpy; exact inverse, zero mean)."""
        out = self.xp.empty(self.shape, dtype=self.xp.float64)
        return host(self._apply(self.stiffness, on_device(self.xp, displacement), out))

    def _apply(self, kernel, field, out):
        return self.pair.apply(kernel, field, out)

    def _apply_single(self, kernel, field, out):
        """``_apply`` in float32: about half the time of a float64 pair."""
        return self.pair.apply(kernel, field, out, single=True)


class FFTPair:
    """``out = irfftn(kernel * rfftn(field))`` on a grid of ``shape``, in namespace ``xp``.

    On numpy with one thread, numpy's FFTs write into this pair's buffers (``out=``):
    no allocation, half the time of ``scipy.fft``, which returns new arrays. With
    ``workers`` > 1 on numpy, ``scipy.fft`` on that many threads; on any other namespace
    its ``fft`` extension (CuPy's cuFFT on a GPU). Single precision (``single``) always
    takes the new-array path: numpy's float32 FFTs measured slower than scipy's."""

    def __init__(self, shape: tuple[int, ...], xp, workers: int = 1):
        self.shape, self.axes, self.xp, self.workers = tuple(shape), tuple(range(len(shape))), xp, workers
        self.numpy = is_numpy(xp)
        half = (*self.shape[:-1], self.shape[-1] // 2 + 1)
        self.buffers = (np.empty(half, dtype=complex), np.empty(self.shape)) if self.numpy and workers == 1 else None

    def apply(self, kernel, field, out=None, single: bool = False):
        """Into ``out`` (a float64 grid), or into this pair's own buffer (returned) on the
        numpy path, a new array otherwise."""
        xp = self.xp
        if single:
            field = xp.astype(field, xp.float32, copy=False)  # not overwritten below
        elif self.buffers is not None:
            spectrum = np.fft.rfftn(field, axes=self.axes, out=self.buffers[0])
            spectrum *= kernel
            return np.fft.irfftn(spectrum, s=self.shape, axes=self.axes, out=self.buffers[1] if out is None else out)
        if self.numpy:
            import scipy.fft

            spectrum = scipy.fft.rfftn(field, axes=self.axes, workers=self.workers)
            spectrum *= kernel
            result = scipy.fft.irfftn(spectrum, s=self.shape, axes=self.axes, workers=self.workers, overwrite_x=True)
            if out is not None:
                out[...] = result  # cast from float32 as it is copied: one pass
        else:
            spectrum = xp.fft.rfftn(field, axes=self.axes)
            spectrum *= kernel
            result = xp.fft.irfftn(spectrum, s=self.shape, axes=self.axes)
            if out is not None:
                out[...] = xp.astype(result, out.dtype)  # the array API casts no dtype on assignment
        return result if out is None else out


def _wave_number(shape: tuple[int, ...]) -> np.ndarray:
    """``|q|`` in radians per pixel on the rfftn grid of ``shape``."""
    import scipy.fft  # imported on first use: a run that needs no FFT here starts faster

    axes = [2 * np.pi * scipy.fft.fftfreq(n) for n in shape[:-1]]
    axes.append(2 * np.pi * scipy.fft.rfftfreq(shape[-1]))
    grids = np.meshgrid(*axes, indexing="ij", sparse=True)
    return np.sqrt(sum(np.square(grid) for grid in grids))
