"""The array library the exact solvers compute with: numpy on the CPU, CuPy on a GPU.

The elastic operators and the contact CG are written against the array API standard
(through ``array_api_compat``), so the same code runs on either. The solvers hand the
CG host (numpy) arrays and get host arrays back; ``on_device`` and ``host`` make the
copies, which are no copies at all on the CPU.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DEVICES", "host", "is_cupy", "is_numpy", "namespace", "namespace_of", "on_device"]

DEVICES = ("cpu", "gpu")


def namespace(device: str):
    """The array namespace of ``device`` ('cpu': numpy; 'gpu': CuPy on the first CUDA GPU).
    A ValueError naming the parameter, the value and what is missing when the GPU's is not
    there."""
    import array_api_compat

    if device == "cpu":
        return array_api_compat.array_namespace(np.empty(0))
    if device != "gpu":
        raise ValueError(f"device must be one of {', '.join(DEVICES)}. Got {device!r} instead.")
    try:
        import cupy
    except ImportError:
        raise ValueError(
            "device 'gpu' needs CuPy, which is not installed (pip install cupy-cuda12x, or the wheel of "
            "your CUDA version); or use device 'cpu'"
        ) from None
    try:
        count = cupy.cuda.runtime.getDeviceCount()
    except Exception as exc:  # the CUDA runtime's own error (no driver, no device)
        raise ValueError(f"device 'gpu' needs a CUDA GPU, and CuPy found none ({type(exc).__name__}); or use device 'cpu'") from None
    if count < 1:
        raise ValueError("device 'gpu' needs a CUDA GPU, and CuPy found none on this machine; or use device 'cpu'")
    return array_api_compat.array_namespace(cupy.empty(0))


def namespace_of(array):
    import array_api_compat

    return array_api_compat.array_namespace(array)


def is_numpy(xp) -> bool:
    import array_api_compat

    return array_api_compat.is_numpy_namespace(xp)


def is_cupy(xp) -> bool:
    import array_api_compat

    return array_api_compat.is_cupy_namespace(xp)


def on_device(xp, array: np.ndarray):
    """``array`` (numpy) in namespace ``xp``: itself on numpy (or with no namespace given)."""
    return array if xp is None or is_numpy(xp) else xp.asarray(array)


def host(array) -> np.ndarray:
    """A numpy array of ``array``: itself if it is one, else a copy to the host."""
    if isinstance(array, np.ndarray):
        return array
    if hasattr(array, "get"):  # CuPy
        return array.get()
    return np.from_dlpack(array)  # any other array on the CPU (array_api_strict)
