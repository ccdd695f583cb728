"""Benchmark: what a command costs around its compute, each figure against its baseline.

Printed in one run, each the best of --repeat fresh processes (rounds alternate the
figure and its baseline, so a shared machine's drift shifts both):

* ``frictionlab --help`` against ``python -c "import numpy"`` (target: at most 1x);
* ``frictionlab run benad2012-fig2 --no-plot``: the whole process less the engine time it
  reports (``elapsed_seconds`` of summary.json), against the numpy import (target: at most 2.5x),
  and beside it its floor: a process that only imports numpy, PyYAML and the preset's pydantic
  models, which every run needs before it can validate its preset;
* ``frictionlab run benad2012-fig2 --quiet`` (plot.png drawn), the whole process, against a
  plain one-core sort-based reference run in this process: the same 300 lines (the
  preset's generator and seeds), forward-difference slopes, and every one of the 400 forces
  solved from one full sort of each line's depths (target: at most 0.5x); its numbers are
  checked against the run's curve.csv;
* the modules each of ``--help``, ``validate`` and ``run --no-plot`` imports (``python -X
  importtime``): the benchmark exits 1, naming them, if a heavy one (matplotlib, scipy,
  textual, dask, pandas, SurfaceTopography, rich) is among them.

``--busy N`` runs N CPU-bound processes (``python -c 'while 1: pass'``) beside everything,
as a busy machine has. The processes run as an installed command does: Python caches each
module's compiled bytecode (``PYTHONDONTWRITEBYTECODE``, if set here, is dropped for
them), and a first run, not timed, fills that cache.

    python benchmarks/bench_startup.py [--repeat 5] [--busy 2] [--workers N]
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from frictionlab.preset import load_scene
from frictionlab.preset.seeds import realization_rng
from machine_load import busy_beside, check_repeat_and_busy  # this folder's

CLI = [sys.executable, "-m", "frictionlab"]
PRESET = Path(__file__).resolve().parents[1] / "presets" / "benad2012-fig2.yaml"
HELP_TARGET = 1.0  # --help / import numpy
NO_PLOT_TARGET = 2.5  # (run --no-plot - its engine) / import numpy
FIG2_TARGET = 0.5  # whole run / sort-based reference
# what every run needs before its preset is validated: no run above its engine can take less
VALIDATION_FLOOR = "import numpy, yaml, frictionlab.preset.schema"
HEAVY = ("matplotlib", "scipy", "textual", "dask", "distributed", "pandas", "SurfaceTopography", "rich")
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as a user's shell has it


def timed_process(args: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=ENV)
    return time.perf_counter() - start


def fig2_run(folder: Path, *extra: str) -> tuple[float, float, float]:
    """(whole process, until the first line of the fit on stdout, engine) seconds."""
    start = time.perf_counter()
    process = subprocess.Popen(
        [*CLI, "run", "benad2012-fig2", "--out", str(folder), "--quiet", *extra],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=ENV,
    )  # fmt: skip
    first = process.stdout.readline()
    printed = time.perf_counter() - start
    process.stdout.read()
    if process.wait() != 0 or not first:
        raise SystemExit(f"frictionlab run benad2012-fig2 failed (exit {process.returncode})")
    whole = time.perf_counter() - start
    engine = json.loads((folder / "summary.json").read_text())["elapsed_seconds"]
    return whole, printed, engine


def sort_reference(scene) -> np.ndarray:
    """The ensemble's mean xi at every force, plainly: for each line (the preset's own,
    seeded as the run seeds it) one full sort of its depths below the top, then at each
    force the indentation from the cumulative sums and the rms slope over the points above it."""
    loads = scene.loads
    params = scene.spectrum.params
    spring = scene.solver.stiffness() * params.length / params.points  # E* dx: one spring per point
    total = np.zeros(loads.size)
    for i in range(scene.preset.realizations):
        profile = scene.spectrum.generate(realization_rng(scene.preset.seed, i))
        z = profile.heights
        slopes = (np.roll(z, -1) - z) / profile.spacing
        depth = z.max() - z
        order = np.argsort(depth, kind="stable")
        u = depth[order]
        onset = np.concatenate(([0.0], np.cumsum(np.arange(1, u.size) * np.diff(u))))  # force / K at each new touch
        n = np.searchsorted(onset, loads / spring, side="left")
        squares = np.cumsum(np.square(slopes[order]))
        total += np.sqrt(squares[n - 1] / n) / np.sqrt(np.mean(np.square(slopes)))
    return total / scene.preset.realizations


def imported_modules(args: list[str], cwd: Path) -> set[str]:
    """The modules ``frictionlab ARGS`` imports (``python -X importtime``)."""
    done = subprocess.run([sys.executable, "-X", "importtime", "-m", "frictionlab", *args], cwd=cwd,
                          capture_output=True, text=True, env=ENV)  # fmt: skip
    if done.returncode != 0:
        raise SystemExit(f"frictionlab {' '.join(args)} failed (exit {done.returncode}): {done.stderr[-500:]}")
    return set(re.findall(r"^import time:\s+\d+ \|\s+\d+ \|\s*(\S+)$", done.stderr, flags=re.MULTILINE))


def heavy_modules(modules: set[str]) -> list[str]:
    return sorted({name.split(".")[0] for name in modules if name.split(".")[0] in HEAVY})


def verdict(ratio: float, target: float) -> str:
    return f"ratio {ratio:.2f} (target <= {target:g}): {'met' if ratio <= target else 'NOT met'}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="best of this many processes")
    parser.add_argument("--busy", type=int, default=0, help="CPU-bound processes running beside the measurements")
    parser.add_argument("--workers", type=int, help="worker processes of the Fig. 2 run (default: every core)")
    args = parser.parse_args()
    check_repeat_and_busy(parser, args)
    extra = [] if args.workers is None else ["--workers", str(args.workers)]
    with busy_beside(args.busy):
        failed = measure(args.repeat, extra)
    if failed:
        raise SystemExit(failed)


def measure(repeat: int, extra: list[str]) -> str | None:
    """Print every figure; what failed the import check, or None."""
    scene = load_scene(PRESET, [])
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        fig2_run(tmp / "warm", *extra)  # fills the bytecode cache, untimed
        numpy_s, help_s, no_plot, whole, reference, floor = [], [], [], [], [], []
        for i in range(repeat):
            numpy_s.append(timed_process([sys.executable, "-c", "import numpy"]))
            floor.append(timed_process([sys.executable, "-c", VALIDATION_FLOOR]))
            help_s.append(timed_process([*CLI, "--help"]))
            no_plot.append(fig2_run(tmp / f"no-plot{i}", "--no-plot", *extra))
            whole.append(fig2_run(tmp / f"plot{i}", *extra))
            start = time.perf_counter()
            mean_xi = sort_reference(scene)
            reference.append(time.perf_counter() - start)
        with open(tmp / "plot0" / "curve.csv", newline="") as fh:
            run_xi = np.array([float(row["xi"]) for row in csv.DictReader(fh)])
        agree = float(np.max(np.abs(run_xi - mean_xi) / run_xi))
        modules = {
            "--help": imported_modules(["--help"], tmp),
            "validate": imported_modules(["validate", "benad2012-fig2"], tmp),
            "run --no-plot": imported_modules(["run", "benad2012-fig2", "--no-plot", "--quiet", "--out", "x"], tmp),
        }

    numpy_best, help_best = min(numpy_s), min(help_s)
    print(f"frictionlab --help        {help_best:6.3f} s")
    print(f"python -c 'import numpy'  {numpy_best:6.3f} s")
    print(f"  {verdict(help_best / numpy_best, HELP_TARGET)}")

    no_whole, no_printed, no_engine = min(no_plot, key=lambda r: r[0] - r[2])
    print(f"\nFig. 2 --no-plot: whole process {no_whole:6.3f} s, engine {no_engine:6.3f} s, "
          f"above the engine {no_whole - no_engine:6.3f} s")  # fmt: skip
    print(f"  (whole - engine) / import numpy: {verdict((no_whole - no_engine) / numpy_best, NO_PLOT_TARGET)}")
    print(f"  its floor, a process that only imports numpy, PyYAML and the preset's pydantic models: "
          f"{min(floor):6.3f} s ({min(floor) / numpy_best:.2f}x the numpy import)")  # fmt: skip

    best_whole, best_printed, best_engine = min(whole, key=lambda r: r[0])
    ref = min(reference)
    print(f"\nFig. 2 with plot.png: whole process {best_whole:6.3f} s (fit printed at {best_printed:6.3f} s, "
          f"engine {best_engine:6.3f} s)")  # fmt: skip
    print(f"plain one-core sort-based reference, same 300 lines and 400 forces: {ref:6.3f} s "
          f"(its mean xi agrees with curve.csv to {agree:.1e} relative)")  # fmt: skip
    print(f"  whole process / reference: {verdict(best_whole / ref, FIG2_TARGET)}")

    print("\nheavy modules imported (any of " + ", ".join(HEAVY) + "):")
    failed = []
    for command, names in modules.items():
        heavy = heavy_modules(names)
        print(f"  frictionlab {command:14s} {len(names):4d} modules, heavy: {', '.join(heavy) or 'none'}")
        if heavy:
            failed.append(f"frictionlab {command} imports {', '.join(heavy)}")
    return "; ".join(failed) if failed else None


if __name__ == "__main__":
    main()
