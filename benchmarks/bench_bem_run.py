"""Benchmark: an exact 20-load sweep end to end through ``frictionlab run``, against Tamaas.

The scene of ``bench_bem.py`` written as a preset: a 512 x 512 periodic self-affine
surface (power-law-2d, H = 0.8, rms height 1, short cut-off 8 pixels, long cut-off the
side, spacing 1), ``bem-halfspace`` with E* = 1, 20 forces log-spaced from 20 to 1000
(about 0.5 % to 19 % contact), one realization. Each round, alternating:

* ``frictionlab run PRESET --workers 1 --quiet --out DIR``: the whole process, from its
  start to its exit, plot.png and every file included;
* Tamaas's ``PolonskyKeerRey`` at tolerance 1e-10 on the same surface (the run's own,
  generated from the preset's seed), its 20 loads on one solver object (warm), in this
  process (``tamaas.initialize(1)``: one thread).

Both run on one core (``OMP_NUM_THREADS=1`` and its kin for both). Printed: the best
wall time of ``--repeat`` rounds of each, their ratio (target: Tamaas at least 12 times
the run), and the contact counts of the run's curve.csv against Tamaas's at every load.
``--busy N`` runs N CPU-bound processes (``python -c 'while 1: pass'``) beside both, as a
busy machine has.

    python benchmarks/bench_bem_run.py [--repeat 3] [--busy 2] [--side 512]

Needs Tamaas (``pip install tamaas``).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ONE_CORE = {name: "1" for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
os.environ.update(ONE_CORE)  # before numpy and Tamaas load their threads

from frictionlab.preset import load_scene  # noqa: E402
from frictionlab.preset.seeds import realization_rng  # noqa: E402
from machine_load import busy_beside, check_repeat_and_busy  # noqa: E402  (this folder's)
from tamaas_reference import load_tamaas, tamaas_sweep  # noqa: E402  (this folder's)

SEED = 2024
TARGET = 12.0  # Tamaas's sweep / the run's whole process, at least
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as a user's shell has it
PRESET = """\
name: {name}
seed: {seed}
realizations: 1
spectrum:
  name: power-law-2d
  params: {{hurst: 0.8, points: {side}, spacing: 1.0, short_cutoff: 8.0, rms_height: 1.0}}
solver:
  name: bem-halfspace
  params: {{youngs_modulus: 1.0, poisson_ratio: 0.0}}
slope:
  name: forward-difference
loading: {{control: force, start: {first}, stop: {last}, steps: 20, spacing: log}}
"""


def run_process(preset: Path, out: Path) -> tuple[float, float]:
    """(whole process, engine) seconds of ``frictionlab run PRESET --workers 1``."""
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "frictionlab", "run", str(preset), "--workers", "1", "--quiet", "--out", str(out)],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=ENV,
    )  # fmt: skip
    whole = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"frictionlab run failed (exit {done.returncode}): {done.stderr[-500:]}")
    return whole, json.loads((out / "summary.json").read_text())["elapsed_seconds"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="best of this many rounds")
    parser.add_argument("--busy", type=int, default=0, help="CPU-bound processes running beside the measurements")
    parser.add_argument("--side", type=int, default=512, help="surface side in pixels (forces scale with the area)")
    args = parser.parse_args()
    check_repeat_and_busy(parser, args)
    if args.side < 16:
        parser.error(f"--side must be at least 16. Got {args.side} instead.")
    tamaas = load_tamaas()
    if tamaas is None:
        raise SystemExit("this benchmark needs Tamaas: pip install tamaas, or the 'bench' extra")
    scale = (args.side / 512) ** 2  # the same contact fractions at any side
    with busy_beside(args.busy), tempfile.TemporaryDirectory() as tmp:
        measure(Path(tmp), tamaas, args, 20.0 * scale, 1000.0 * scale)


def measure(tmp: Path, tamaas, args, first: float, last: float) -> None:
    preset = tmp / "bench-bem-run.yaml"
    preset.write_text(PRESET.format(name="bench-bem-run", seed=SEED, side=args.side, first=first, last=last))
    scene = load_scene(preset, [])
    heights = scene.spectrum.generate(realization_rng(SEED, 0)).heights  # the run's surface
    run_process(preset, tmp / "warm")  # fills the bytecode cache, untimed
    runs, sweeps = [], []
    for i in range(args.repeat):
        runs.append(run_process(preset, tmp / f"run{i}"))
        (_, wall), _, counts = tamaas_sweep(tamaas, heights, scene.loads)
        sweeps.append((wall, counts))
    with open(tmp / "run0" / "curve.csv", newline="") as fh:
        counts = np.array([round(float(row["contact_count"])) for row in csv.DictReader(fh)])
    differ = int(np.count_nonzero(counts != sweeps[0][1]))
    whole, engine = min(runs)
    tamaas_s = min(s for s, _ in sweeps)
    print(f"bem-halfspace, {args.side} x {args.side}, 20 forces {first:g} .. {last:g}, one core each, "
          f"{args.busy} busy processes beside, best of {args.repeat}")  # fmt: skip
    print(f"  frictionlab run --workers 1, whole process  {whole:8.2f} s (engine {engine:.2f} s, "
          f"{whole - engine:.2f} s around it)")  # fmt: skip
    print(f"  Tamaas PolonskyKeerRey 1e-10, warm sweep    {tamaas_s:8.2f} s")
    verdict = "met" if tamaas_s / whole >= TARGET else "NOT met"
    print(f"  Tamaas / run: {tamaas_s / whole:.1f} x (target >= {TARGET:g}): {verdict}")
    print(f"  contact counts: {'equal at every load' if differ == 0 else f'{differ} of 20 loads differ'}")


if __name__ == "__main__":
    main()
