"""Benchmark: the exact solver on a GPU (``device: gpu``), 1024^2 to 4096^2.

The scene of ``bench_bem.py`` at larger sides: a periodic self-affine surface
(power-law-2d, H = 0.8, rms height 1, short cut-off 8 pixels, long cut-off the side,
spacing 1), E* = 1, forces log-spaced over the same contact fractions (about 0.5 % to
19 %). For each side it prints the wall time of a cold load (the tenth force alone)
and of a sweep of ``--loads`` forces, on the GPU and, with ``--cpu``, on the CPU
(numpy, ``fft_workers`` threads per FFT) for comparison, with the contact counts of
both (which must agree). The first GPU solve of each side is run untimed (cuFFT plans,
CuPy's kernels compiled).

Needs CuPy and a CUDA GPU (``pip install cupy-cuda12x``)::

    python benchmarks/bench_bem_gpu.py [--sides 1024 2048 4096] [--loads 5] [--cpu] [--fft-workers 2]
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from frictionlab.preset.seeds import realization_rng
from frictionlab_solvers.arrays import namespace
from frictionlab_solvers.bem import BEMHalfSpace
from frictionlab_spectra.surface import PowerLawSurface

SEED = 2024


def scene(side: int, loads: int):
    profile = PowerLawSurface(hurst=0.8, points=side, spacing=1.0, short_cutoff=8.0, rms_height=1.0).generate(
        realization_rng(SEED, 0)
    )
    forces = np.geomspace(20.0, 1000.0, loads) * (side / 512) ** 2  # the contact fractions of bench_bem.py
    return profile, forces


def timed(solver, profile, forces):
    slopes = np.ones_like(profile.heights)
    start = time.perf_counter()
    curve = solver.solve(profile, forces, "force", slopes)  # its results are on the host: the GPU has finished
    return time.perf_counter() - start, curve


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sides", type=int, nargs="+", default=[1024, 2048, 4096], help="surface sides in pixels")
    parser.add_argument("--loads", type=int, default=5, help="forces in the sweep")
    parser.add_argument("--cpu", action="store_true", help="also solve on the CPU, for the ratio")
    parser.add_argument("--fft-workers", type=int, default=1, help="FFT threads of the CPU solve")
    args = parser.parse_args()
    if args.loads < 1 or any(side < 16 for side in args.sides):
        parser.error("--loads must be at least 1 and every side at least 16")
    try:
        namespace("gpu")
    except ValueError as refused:
        print(f"no GPU run: {refused}", file=sys.stderr)
        sys.exit(2)
    import cupy

    device = cupy.cuda.runtime.getDeviceProperties(0)
    print(f"GPU: {device['name'].decode()}, {device['totalGlobalMem'] / 2**30:.0f} GiB; CuPy {cupy.__version__}")
    print(f"{'side':>6} {'what':<22}{'GPU s':>9}{'CPU s':>9}{'CPU / GPU':>11}{'iterations':>12}  contact counts")
    gpu = BEMHalfSpace(device="gpu")
    cpu = BEMHalfSpace(fft_workers=args.fft_workers)
    for side in args.sides:
        profile, forces = scene(side, args.loads)
        cold = forces[len(forces) // 2 : len(forces) // 2 + 1]
        timed(gpu, profile, cold)  # plans and kernels
        for what, loads in ((f"cold load (F {cold[0]:.4g})", cold), (f"{args.loads}-load sweep", forces)):
            on_gpu, curve = timed(gpu, profile, loads)
            line = f"{side:>6} {what:<22}{on_gpu:9.2f}"
            if args.cpu:
                on_cpu, reference = timed(cpu, profile, loads)
                same = "equal" if np.array_equal(curve.contact_count, reference.contact_count) else "DIFFER"
                line += f"{on_cpu:9.2f}{on_cpu / on_gpu:10.1f}x"
            else:
                same = "-"
                line += f"{'-':>9}{'-':>11}"
            print(f"{line}{int(curve.extras['iterations'].sum()):12d}  {same}", flush=True)
        cupy.get_default_memory_pool().free_all_blocks()


if __name__ == "__main__":
    main()
