"""Benchmark: the boundary-element solvers (bem-halfspace, bem-halfplane).

Prints wall times and ratios against baselines run in this same process, so a
noisy shared machine shifts the figures together; iteration counts are printed
beside them because they do not depend on the machine's load.

* default: bem-halfspace on a 512 x 512 power-law-2d surface, one cold load at
  about 1, 3 and 20 % contact (default settings), the FFT floor and the time per
  CG iteration; bem-halfplane on an 8192-point line, one load and a 20-load sweep.
* ``--law``: the force sweep of a study at the solver's default settings: a
  512 x 512 power-law-2d surface (H = 0.8, rms height 1, spacing 1, E = 1,
  nu = 0), 20 forces log-spaced from 20 to 1000, warm-started, against one cold
  solve (median of a low, a middle and a high load) and against 20 independent
  cold solves at tolerance 1e-12 (largest relative difference of xi and of the
  real contact area, and the number of points whose contact state differs).
* ``--vs-tamaas``: one load on 512 x 512 and 2048 x 2048 surfaces against
  Tamaas's Polonsky-Keer solver (``pip install tamaas``; the ``bench`` extra),
  single-threaded both. Tamaas runs at tolerance 1e-8 of its own error measure;
  frictionlab then runs to the residual that Tamaas's answer reached in
  frictionlab's measure (largest gap error on contact points or penetration
  elsewhere, over the rms height), so it is at least as converged in that
  measure, and the contact sets are compared point by point.

    python benchmarks/bench_bem.py [--repeat 3] [--law] [--vs-tamaas [--sides 512 2048]]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from frictionlab import Profile
from frictionlab.seeds import realization_rng
from frictionlab_solvers import bem
from frictionlab_spectra.power_law import PowerLaw
from frictionlab_spectra.surface import PowerLawSurface

SEED = 2024


def study_surface(points: int) -> Profile:
    """A power-law-2d surface as a study makes it: H = 0.8, rms height 1, spacing 1."""
    return PowerLawSurface(hurst=0.8, points=points, spacing=1.0).generate(realization_rng(SEED, 0))


def gradient_norm(z: np.ndarray) -> np.ndarray:
    """|grad z| by forward differences, both components (the 2D slope of a study)."""
    return np.hypot(np.roll(z, -1, 0) - z, np.roll(z, -1, 1) - z)


def best_of(repeat, work):
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - start)
    return min(times), result


def residual(depth_like_gap: np.ndarray, pressure: np.ndarray, rms: float) -> tuple[float, float]:
    """frictionlab's measure of a state: the largest gap on contact points (after
    removing the rigid level, their mean) and the largest penetration of a free
    point, over the rms height."""
    contact = pressure > 0
    gap = depth_like_gap - depth_like_gap[contact].mean()
    return float(np.abs(gap[contact]).max() / rms), float(max(0.0, -gap[~contact].min()) / rms)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs")
    parser.add_argument("--law", action="store_true", help="the 20-force sweep against cold solves")
    parser.add_argument("--vs-tamaas", action="store_true", help="one load against Tamaas")
    parser.add_argument("--sides", type=int, nargs="+", default=[512, 2048], help="surface sides for --vs-tamaas")
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be at least 1. Got {args.repeat} instead.")
    if args.law:
        law(args.repeat)
    if args.vs_tamaas:
        versus_tamaas(args.sides, args.repeat)
    if not (args.law or args.vs_tamaas):
        single_loads(args.repeat)


def single_loads(repeat: int) -> None:
    profile = study_surface(512)
    z = profile.heights
    slopes = gradient_norm(z)
    solver = bem.BEMHalfSpace()

    cg = bem.ConstrainedCG(z - z.min())
    out = np.empty_like(z)
    floor, _ = best_of(repeat * 10, lambda: cg.displacement(z, out))
    print("bem-halfspace, 512 x 512 power-law-2d H = 0.8, default settings")
    print(f"  FFT floor: one displacement (rfft2, kernel, irfft2): {floor * 1e3:7.2f} ms")
    for force in (20.0, 150.0, 1000.0):
        seconds, curve = best_of(repeat, lambda: solver.solve(profile, np.array([force]), "force", slopes))
        its = int(curve.extras["iterations"][0])
        print(
            f"  force {force:6g}, contact {curve.contact_fraction[0]:6.2%}: {seconds:7.3f} s  {its:4d} iterations  "
            f"{seconds / its * 1e3:6.2f} ms/iteration = {seconds / its / floor:4.1f} FFT pairs"
        )

    line_profile = PowerLaw(hurst=0.8, points=8192, spacing=1.0).generate(realization_rng(SEED, 1))
    heights = line_profile.heights
    plane = bem.BEMHalfPlane()
    forces = np.geomspace(0.5, 20.0, 20)
    line_slopes = np.diff(heights, append=heights[:1])
    one, c1 = best_of(repeat, lambda: plane.solve(line_profile, forces[10:11], "force", line_slopes))
    many, c20 = best_of(repeat, lambda: plane.solve(line_profile, forces, "force", line_slopes))
    print("bem-halfplane, 8192 points, H = 0.8, default settings")
    print(f"  one load, contact {c1.contact_fraction[0]:6.2%}: {one * 1e3:8.1f} ms  {int(c1.extras['iterations'][0])} iterations")
    print(
        f"  20-load sweep ({c20.contact_fraction[0]:.2%} .. {c20.contact_fraction[-1]:.2%}): {many * 1e3:8.1f} ms  "
        f"{int(c20.extras['iterations'].sum())} iterations  ({many / one:4.1f} x one load)"
    )


def law(repeat: int) -> None:
    profile = study_surface(512)
    z = profile.heights
    slopes = gradient_norm(z)
    forces = np.geomspace(20.0, 1000.0, 20)
    solver = bem.BEMHalfSpace()  # default settings
    print(f"force sweep, 512 x 512 power-law-2d H = 0.8, 20 forces {forces[0]:g} .. {forces[-1]:g}, default settings")
    cold_seconds, cold_iterations = [], []
    for j in (0, 10, 19):
        seconds, curve = best_of(repeat, lambda: solver.solve(profile, forces[j : j + 1], "force", slopes))
        cold_seconds.append(seconds)
        cold_iterations.append(int(curve.extras["iterations"][0]))
        print(
            f"  cold load {j:2d} (force {forces[j]:7.1f}, contact {curve.contact_fraction[0]:6.2%}): "
            f"{seconds:6.3f} s  {cold_iterations[-1]:4d} iterations"
        )
    sweep_seconds, sweep = best_of(repeat, lambda: solver.solve(profile, forces, "force", slopes))
    iterations = sweep.extras["iterations"]
    print(f"  sweep: {sweep_seconds:6.3f} s  {int(iterations.sum())} iterations  per load: {' '.join(map(str, iterations))}")
    print(
        f"  sweep / one cold load (median of the three): {sweep_seconds / np.median(cold_seconds):5.2f} x in time, "
        f"{iterations.sum() / np.median(cold_iterations):5.2f} x in iterations  (target <= 5)"
    )

    tight = bem.BEMHalfSpace(tolerance=1e-12)
    start = time.perf_counter()
    references = [tight.solve(profile, forces[j : j + 1], "force", slopes) for j in range(forces.size)]
    tight_seconds = time.perf_counter() - start
    xi = np.array([c.slope_rms_contact[0] for c in references])
    count = np.array([c.contact_count[0] for c in references])
    xi_error = np.abs(sweep.slope_rms_contact / xi - 1)
    area_error = np.abs(sweep.contact_count / count - 1)
    print(f"  20 cold solves at tolerance 1e-12: {tight_seconds:6.1f} s")
    print(
        f"  largest relative difference from them: xi {xi_error.max():.2e}, real contact area {area_error.max():.2e}; "
        f"contact counts differ at {np.count_nonzero(sweep.contact_count != count)} of 20 loads  (target 1e-6)"
    )
    where_the_iterations_go(z, forces)


def where_the_iterations_go(z: np.ndarray, forces: np.ndarray) -> None:
    """The earliest any stopping rule on the contact set could stop: the iteration
    after which the set no longer changes (known only in hindsight), for the sweep's
    warm starts and for cold starts, at the default tolerance."""
    scale = float(z.max() - z.min())
    depth = (z.max() - z) / scale
    cg = bem.ConstrainedCG(depth)
    means = forces / z.size / scale
    tolerance = bem.PeriodicBEM.Params().tolerance

    def settle(start, mean):
        last = {"set": None, "since": 0}

        def watch(iteration, _residual, contact):
            if last["set"] is None or not np.array_equal(contact, last["set"]):
                last["set"], last["since"] = contact.copy(), iteration

        pressure, _, iterations, _ = cg.solve(start, mean_pressure=mean, tolerance=tolerance,
                                              max_iterations=100_000, monitor=watch)
        return pressure.copy(), iterations, last["since"]

    rows, previous = [], None
    for j, mean in enumerate(means):
        _, cold_its, cold_settled = settle(bem._cold_start(depth, mean), mean)
        start = bem._cold_start(depth, mean) if previous is None else previous * (mean / means[j - 1])
        previous, warm_its, warm_settled = settle(start, mean)
        rows.append((cold_its, cold_settled, warm_its, warm_settled))
    rows = np.array(rows)
    print("  where the iterations go: iterations to the tolerance / iteration after which the contact set stayed final")
    print("    load:  " + " ".join(f"{j:>7d}" for j in range(0, 20, 3)))
    print("    cold:  " + " ".join(f"{a:>3d}/{b:<3d}" for a, b in rows[::3, :2]))
    print("    warm:  " + " ".join(f"{a:>3d}/{b:<3d}" for a, b in rows[::3, 2:]))
    median_cold = np.median(rows[[0, 10, 19], 0])
    median_settled = np.median(rows[[0, 10, 19], 1])
    print(
        f"    sweep / one cold load in iterations: {rows[:, 2].sum() / median_cold:5.2f} x at the tolerance; "
        f"{rows[:, 3].sum() / median_settled:5.2f} x for a rule that stopped the moment each set is final"
    )


def versus_tamaas(sides: list[int], repeat: int) -> None:
    """Best of ``repeat`` runs each up to 1024 pixels a side, one run above (a
    2048 x 2048 load took Tamaas 15 minutes on a shared 2-core machine)."""
    try:
        import tamaas
    except ImportError:
        print("--vs-tamaas: Tamaas is not installed (pip install tamaas, or the 'bench' extra)")
        return
    tamaas.set_log_level(tamaas.LogLevel.error)
    print(f"one load against Tamaas {tamaas.__version__} PolonskyKeerRey (single thread both; E* = 1, spacing 1)")
    print("  side   force  contact   Tamaas s  residual   frictionlab s  its  residual   speed-up  set diff  runs")
    for side in sides:
        runs = repeat if side <= 1024 else 1
        profile = study_surface(side)
        z = np.ascontiguousarray(profile.heights)
        rms = float(z.std())
        force = 150.0 * (side / 512) ** 2  # about 3 % contact

        def run_tamaas():
            model = tamaas.ModelFactory.createModel(tamaas.model_type.basic_2d, [float(side)] * 2, [side, side])
            model.E, model.nu = 1.0, 0.0
            solver = tamaas.PolonskyKeerRey(model, z, 1e-8)
            solver.max_iter = 100_000
            start = time.perf_counter()
            solver.solve(force / z.size)
            return time.perf_counter() - start, model

        def run_ours():  # what bem-halfspace's solve does for one load, with the pressure kept
            start = time.perf_counter()
            depth = (z.max() - z) / (z.max() - z.min())
            cg = bem.ConstrainedCG(depth)
            mean = force / z.size / (z.max() - z.min())
            p, _, iterations, _ = cg.solve(
                bem._cold_start(depth, mean), mean_pressure=mean, tolerance=tolerance, max_iterations=100_000
            )
            return time.perf_counter() - start, cg, p, iterations

        # Tamaas first, to find the residual it reaches in frictionlab's measure
        tamaas_runs = [run_tamaas()]
        model = tamaas_runs[0][1]
        p_tamaas = np.array(model.traction).reshape(z.shape)
        # Tamaas's gap: displacement minus heights (its displacement has its own mean)
        tamaas_contact, tamaas_free = residual(np.array(model.displacement).reshape(z.shape) - z, p_tamaas, rms)
        tolerance = max(tamaas_contact, tamaas_free, 1e-14)
        # then both alternately, so that they see the same load of a shared machine
        our_runs = [run_ours()]
        for _ in range(runs - 1):
            tamaas_runs.append(run_tamaas())
            our_runs.append(run_ours())
        tamaas_seconds = min(run[0] for run in tamaas_runs)
        our_seconds, cg, p_ours, our_iterations = min(our_runs, key=lambda run: run[0])
        our_contact, our_free = residual(cg.gap.copy(), p_ours, cg.rms)
        differ = int(np.count_nonzero((p_ours > 0) != (p_tamaas > 0)))
        print(
            f"  {side:4d} {force:8.0f} {np.mean(p_tamaas > 0):7.2%}  {tamaas_seconds:8.2f}  "
            f"{max(tamaas_contact, tamaas_free):9.2e}  {our_seconds:12.2f}  {our_iterations:4d}  "
            f"{max(our_contact, our_free):9.2e}  {tamaas_seconds / our_seconds:8.2f}x  {differ:8d}  {runs:4d}"
        )


if __name__ == "__main__":
    main()
