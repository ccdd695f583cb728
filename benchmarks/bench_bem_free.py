"""Benchmark: the free-boundary half-space (bem-halfspace-free) against the periodic one.

One power-law-2d surface (H = 0.8, rms height 1, spacing 1, E = 1, nu = 0) per side,
pressed by both solvers with the same force sweep (5 mean pressures 5e-4 to 1e-2 E*: about 1 to 30 % contact,
warm-started); the periodic solver is the baseline, run in this same process, so a
noisy shared machine shifts both together. Prints the wall time per sweep, their ratio,
the CG iterations (which do not depend on the machine's load) and the contact counts.
The free solver's FFTs are on a grid of 4 times the points, so a ratio of about 4 to 5
is the padding's cost alone.

    python benchmarks/bench_bem_free.py [--sides 128 256] [--repeat 3]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from frictionlab import Profile
from frictionlab.preset.seeds import realization_rng
from frictionlab_solvers import BEMHalfSpace, BEMHalfSpaceFree
from frictionlab_spectra.surface import PowerLawSurface

SEED = 2024


def sweep(solver, profile: Profile, forces: np.ndarray, repeat: int):
    best, curve = np.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        curve = solver.solve(profile, forces, "force", np.ones(profile.heights.shape))
        best = min(best, time.perf_counter() - start)
    return best, curve


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sides", type=int, nargs="+", default=[128, 256])
    parser.add_argument("--repeat", type=int, default=3, help="best of this many sweeps (default 3)")
    args = parser.parse_args()
    print(f"{'side':>5} {'periodic s':>11} {'free s':>9} {'ratio':>6} {'iterations (periodic / free)':>30}  contact")
    for side in args.sides:
        surface = PowerLawSurface(hurst=0.8, points=side, rms_height=1.0, spacing=1.0)
        heights = surface.generate(realization_rng(SEED, 0)).heights
        area_scale = side * side  # the force of mean pressure 1 (E* = 1, pixels of side 1)
        forces = area_scale * np.geomspace(0.0005, 0.01, 5)
        periodic = Profile(heights, 1.0, periodic=True)
        t_periodic, c_periodic = sweep(BEMHalfSpace(), periodic, forces, args.repeat)
        t_free, c_free = sweep(BEMHalfSpaceFree(), Profile(heights, 1.0, periodic=False), forces, args.repeat)
        iterations = f"{int(c_periodic.extras['iterations'].sum())} / {int(c_free.extras['iterations'].sum())}"
        contact = f"{c_periodic.contact_fraction[0]:.3f}..{c_periodic.contact_fraction[-1]:.3f} / " \
                  f"{c_free.contact_fraction[0]:.3f}..{c_free.contact_fraction[-1]:.3f}"  # fmt: skip
        print(f"{side:>5} {t_periodic:>11.3f} {t_free:>9.3f} {t_free / t_periodic:>6.2f} {iterations:>30}  {contact}")


if __name__ == "__main__":
    main()
