"""Benchmark: the study's Fig. 2 scene (N = 1e5, 300 realizations, 400 forces).

Prints wall times and ratios against baselines run in this same process, so a
noisy shared machine shifts all figures together:

* the whole run with the default executor (process pool on all cores), and serially;
* the naive solver (bisection on the level at every force step, ``mdr-bisection``)
  on a few realizations, scaled to 300, and the speed-up over it;
* the FFT floor: only generating the 300 lines, serially, and the ratio to it.

    python benchmarks/bench_fig2.py [--repeat 3] [--naive-realizations 2]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from frictionlab.compute import engine
from frictionlab.options import RunOptions, default_workers
from frictionlab.compute.realization import compute_realization
from frictionlab.preset import load_scene
from frictionlab.preset.seeds import realization_rng

PRESET = Path(__file__).resolve().parents[1] / "presets" / "benad2012-fig2.yaml"


def best_of(repeat: int, work) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs")
    parser.add_argument("--naive-realizations", type=int, default=2, help="realizations timed with the naive solver")
    args = parser.parse_args()
    for name in ("repeat", "naive_realizations"):
        if getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} must be >= 1. Got {getattr(args, name)} instead.")

    scene = load_scene(PRESET, ["fit.bootstrap=1000"])
    m = scene.preset.realizations
    workers = default_workers()

    default = best_of(args.repeat, lambda: engine.run(scene))
    serial = best_of(args.repeat, lambda: engine.run(scene, RunOptions(workers=1)))

    def generate_only():
        for i in range(m):
            scene.spectrum.generate(realization_rng(scene.preset.seed, i))

    floor = best_of(args.repeat, generate_only)

    naive_scene = load_scene(PRESET, ["solver.name=mdr-bisection"])
    k = args.naive_realizations
    start = time.perf_counter()
    for i in range(k):
        compute_realization(naive_scene, i)
    naive_serial = (time.perf_counter() - start) / k * m

    print(f"Fig. 2 scene: N = {scene.spectrum.params.points}, {m} realizations, {scene.loads.size} forces")
    print(f"  whole run, default executor ({workers} workers): {default:8.3f} s   (target < 1.5 s)")
    print(f"  whole run, serial (1 worker):                {serial:8.3f} s")
    print(f"  FFT floor: generating the {m} lines, serial:   {floor:8.3f} s")
    print(f"    serial run / FFT floor:                    {serial / floor:8.2f} x  (target <= 2)")
    print(f"  naive solver (bisection per force), serial, {k} realizations scaled to {m}: {naive_serial:8.1f} s")
    print(f"    naive / serial run:                        {naive_serial / serial:8.0f} x  (target >= 1000)")
    print(f"    naive / default run:                       {naive_serial / default:8.0f} x")


if __name__ == "__main__":
    main()
