"""Benchmark: the boundary-element solvers (bem-halfspace, bem-halfplane).

Prints wall times and ratios against baselines run in this same process, so a
noisy shared machine shifts the figures together:

* bem-halfspace on a 512 x 512 random power-law surface (H = 0.8, short
  cut-off 4 pixels), one cold load at contact fractions of about 2, 10 and 30 %,
  to a relative residual of 1e-8; the FFT floor (one rfft2 + irfft2 pair per
  CG step costs at least this) and the time per CG iteration;
* a 20-load sweep (contact fraction about 2 .. 30 %) warm-started, against
  20 times one cold load of the sweep's middle;
* bem-halfplane on an 8192-point line, one load and a 20-load sweep;
* the same 512 x 512 load with FFTs on all cores (``FFT_WORKERS = -1``);
* the warm-start law (``--law``): CG iterations of a start from the solution
  at a nearby load against a cold start, for load steps 1e-4 .. 50 % and
  tolerances 1e-4 .. 1e-8 (iteration counts are deterministic, so this table
  does not depend on the machine's load), and a sweep over a narrow load range.

    python benchmarks/bench_bem.py [--repeat 3] [--points 512] [--law] [--law-points 256]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.fft

from frictionlab import Profile
from frictionlab_solvers import bem


def power_law(shape, hurst, cutoff, rng):
    """Random-phase power-law surface (or line), unit rms height, pixel units."""
    freqs = [scipy.fft.fftfreq(n) for n in shape[:-1]] + [scipy.fft.rfftfreq(shape[-1])]
    grids = np.meshgrid(*freqs, indexing="ij", sparse=True)
    q = np.sqrt(sum(g**2 for g in grids))
    band = (q > 0) & (q <= 1.0 / cutoff)
    amplitude = np.zeros(q.shape)
    amplitude[band] = q[band] ** (-hurst - len(shape) / 2)
    z = scipy.fft.irfftn(amplitude * np.exp(2j * np.pi * rng.random(q.shape)), s=shape)
    return z / z.std()


def rms_gradient(z):
    return float(np.sqrt(sum(np.mean(np.square(np.roll(z, -1, a) - z)) for a in range(z.ndim))))


def best_of(repeat, work):
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - start)
    return min(times), result


def loads_for(z, fractions):
    """Forces whose mean pressure gives about these contact fractions (A/A0 ~ 2 p / (E* grad h))."""
    return np.asarray(fractions) * rms_gradient(z) / 2 * z.size


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs")
    parser.add_argument("--points", type=int, default=512, help="surface side (pixels)")
    parser.add_argument("--line-points", type=int, default=8192, help="line length (pixels)")
    parser.add_argument("--law", action="store_true", help="also print the warm-start law (iteration counts)")
    parser.add_argument("--law-points", type=int, default=256, help="surface side for the warm-start law")
    args = parser.parse_args()
    rng = np.random.default_rng(np.random.SeedSequence(2024))
    n = args.points

    surface = power_law((n, n), 0.8, 4, rng)
    profile = Profile(surface, 1.0)
    slopes = np.ones_like(surface)
    solver = bem.BEMHalfSpace(tolerance=1e-8)

    def fft_pair():
        scipy.fft.irfft2(scipy.fft.rfft2(surface, workers=bem.FFT_WORKERS), s=surface.shape, workers=bem.FFT_WORKERS)

    floor, _ = best_of(args.repeat * 10, fft_pair)
    print(f"bem-halfspace, {n} x {n}, H = 0.8, tolerance 1e-8 (FFT_WORKERS = {bem.FFT_WORKERS})")
    print(f"  FFT floor: one rfft2 + irfft2 pair: {floor * 1e3:7.2f} ms")
    singles = {}
    for fraction in (0.02, 0.1, 0.3):
        load = loads_for(surface, [fraction])
        seconds, curve = best_of(args.repeat, lambda: solver.solve(profile, load, "force", slopes))
        its = int(curve.extras["iterations"][0])
        singles[fraction] = seconds
        print(
            f"  one load, contact {curve.contact_fraction[0]:6.1%}: {seconds:7.3f} s  {its:4d} iterations  "
            f"{seconds / its * 1e3:6.2f} ms/iteration = {seconds / its / floor:4.1f} FFT pairs  (target < 2 s)"
        )

    sweep_loads = loads_for(surface, np.geomspace(0.02, 0.3, 20))
    middle = sweep_loads[10:11]
    cold, curve_mid = best_of(args.repeat, lambda: solver.solve(profile, middle, "force", slopes))
    sweep, curve = best_of(1, lambda: solver.solve(profile, sweep_loads, "force", slopes))
    print(
        f"  20-load sweep (contact {curve.contact_fraction[0]:.1%} .. {curve.contact_fraction[-1]:.1%}), warm starts: "
        f"{sweep:7.3f} s, {int(curve.extras['iterations'].sum())} iterations"
    )
    print(
        f"    sweep / one cold load of its middle ({cold:.3f} s, {int(curve_mid.extras['iterations'][0])} it.): "
        f"{sweep / cold:5.1f} x  (20 cold loads: 20 x; target well under 20)"
    )

    line = power_law((args.line_points,), 0.8, 4, rng)
    line_profile = Profile(line, 1.0)
    plane = bem.BEMHalfPlane(tolerance=1e-8)
    line_loads = loads_for(line, np.geomspace(0.02, 0.3, 20))
    one, c1 = best_of(args.repeat, lambda: plane.solve(line_profile, line_loads[10:11], "force", np.ones_like(line)))
    many, c20 = best_of(args.repeat, lambda: plane.solve(line_profile, line_loads, "force", np.ones_like(line)))
    print(f"bem-halfplane, {args.line_points} points, H = 0.8, tolerance 1e-8")
    print(f"  one load, contact {c1.contact_fraction[0]:6.1%}: {one * 1e3:8.1f} ms  {int(c1.extras['iterations'][0])} iterations")
    print(f"  20-load sweep: {many * 1e3:8.1f} ms  {int(c20.extras['iterations'].sum())} iterations  ({many / one:4.1f} x one load)")

    saved = bem.FFT_WORKERS
    bem.FFT_WORKERS = -1
    try:
        load = loads_for(surface, [0.1])
        threaded, _ = best_of(args.repeat, lambda: solver.solve(profile, load, "force", slopes))
    finally:
        bem.FFT_WORKERS = saved
    print(f"  512 x 512 at 10 % with FFT_WORKERS = -1: {threaded:7.3f} s  ({singles[0.1] / threaded:4.2f} x the default)")

    if args.law:
        cold_total = sum(
            int(solver.solve(profile, sweep_loads[j : j + 1], "force", slopes).extras["iterations"][0])
            for j in range(sweep_loads.size)
        )
        print(
            f"  the same 20 loads solved independently (cold): {cold_total} iterations; "
            f"the warm sweep is {int(curve.extras['iterations'].sum()) / cold_total:.2f} x that"
        )
        narrow = loads_for(surface, np.geomspace(0.1, 0.11, 20))
        narrow_curve = solver.solve(profile, narrow, "force", slopes)
        total = int(narrow_curve.extras["iterations"].sum())
        print(
            f"  20-load sweep within 10 % of one load (contact {narrow_curve.contact_fraction[0]:.1%} .. "
            f"{narrow_curve.contact_fraction[-1]:.1%}): {total} iterations = "
            f"{total / int(curve_mid.extras['iterations'][0]):4.1f} x one load"
        )
        warm_start_law(power_law((args.law_points,) * 2, 0.8, 4, rng))


def warm_start_law(surface: np.ndarray) -> None:
    """Iterations from the converged solution at load W, scaled to W (1 + step),
    against the solver's cold start at W (1 + step): what a warm start saves
    depends on how close the loads are, and little on the tolerance."""
    depth = surface.max() - surface
    depth /= depth.max()
    cg = bem.ConstrainedCG(depth)
    load = loads_for(surface, [0.1])[0] / surface.size  # scaled mean pressure, about 10 % contact
    exact, *_ = cg.solve(bem._cold_start(depth, load), mean_pressure=load, tolerance=1e-12, max_iterations=100_000)
    exact = exact.copy()
    steps = (1e-4, 1e-3, 1e-2, 0.05, 0.15, 0.5)
    print(f"warm-start law, {surface.shape[0]} x {surface.shape[1]}, about 10 % contact: "
          "CG iterations warm / cold at load W (1 + step)")
    print("  tolerance " + "".join(f"{step:>12g}" for step in steps))
    for tolerance in (1e-4, 1e-6, 1e-8):
        cells = []
        for step in steps:
            target = load * (1 + step)
            solve = lambda start: cg.solve(start, mean_pressure=target, tolerance=tolerance, max_iterations=100_000)[2]
            warm = solve(exact * (1 + step))
            cold = solve(bem._cold_start(depth, target))
            cells.append(f"{warm:>5d} / {cold:<4d}")
        print(f"  {tolerance:9g} " + "".join(f"{cell:>12s}" for cell in cells))


if __name__ == "__main__":
    main()
