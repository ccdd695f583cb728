"""Benchmark: what a run's checks of its plugins cost, on the study's Fig. 2 scene.

* numpy's global random state: one realization's looks (``RandomWatch``: one snapshot, then one
  look after each plugin call) against the six ``np.random.get_state()`` snapshots a realization
  took before (one before and one after each of generate, slopes and solve);
* ``compute_chunk`` of 20 realizations (1 .. 20), best of ``--repeat``;
* the seed check, once a run: realization 0 (made twice more) against itself unchecked.

    python benchmarks/bench_plugin_checks.py [--repeat 7]
"""

from __future__ import annotations

import argparse
import timeit
from pathlib import Path

import frictionlab.compute.realization as realization
from frictionlab.plugin.outputs import RandomWatch, random_state
from frictionlab.preset import load_scene
from bench_fig2 import best_of  # this folder's

PRESET = Path(__file__).resolve().parents[1] / "presets" / "benad2012-fig2.yaml"
LOOKS = 2000  # of each kind, per repeat


def watched() -> None:  # a realization's looks now
    watch = RandomWatch()
    for call in ("generate()", "slopes()", "profile_rms_height()", "solve()"):
        watch.problem(call)


def snapshots() -> None:  # a realization's snapshots before: a pair around each call
    for _ in range(3):
        before = random_state()
        assert random_state() == before


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="best of this many")
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be >= 1. Got {args.repeat} instead.")
    scene = load_scene(PRESET)
    for name, work in (("six get_state() snapshots", snapshots), ("RandomWatch looks", watched)):
        each = min(timeit.repeat(work, number=LOOKS, repeat=args.repeat)) / LOOKS
        print(f"{name}: {each * 1e6:.1f} us a realization")
    realization.compute_chunk(scene, range(1, 3))  # warm: the synthesis, the first pages
    chunk = best_of(args.repeat, lambda: realization.compute_chunk(scene, range(1, 21)))
    print(f"compute_chunk of 20 realizations: {chunk * 1e3:.1f} ms ({chunk / 20 * 1e3:.3f} ms each)")
    checked = realization.seed_problem
    on = best_of(args.repeat, lambda: realization.compute_realization(scene, 0))
    realization.seed_problem = lambda *args: None
    try:
        off = best_of(args.repeat, lambda: realization.compute_realization(scene, 0))
    finally:
        realization.seed_problem = checked
    runs = scene.preset.realizations
    print(f"realization 0: {on * 1e3:.2f} ms checked, {off * 1e3:.2f} ms not: the seed check {(on - off) * 1e3:.2f} ms, "
          f"{100 * (on - off) / (runs * chunk / 20):.2f} % of a run of {runs}")


if __name__ == "__main__":
    main()
