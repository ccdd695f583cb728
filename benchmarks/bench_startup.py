"""Benchmark: what starting frictionlab costs, against what it is compared with.

Printed in one run, each the best of --repeat fresh processes:

* ``frictionlab --help`` against ``python -c "import numpy"`` (target: no slower);
* the Fig. 2 preset run from the command line, whole process, against the engine
  time it reports itself (``elapsed_seconds`` of summary.json; target: within
  0.3 s), three ways: with ``--no-plot``; until the fit is printed (the figure is
  drawn after it); and to the end with the figure.

The processes run as an installed command does: Python caches each module's
compiled bytecode (``PYTHONDONTWRITEBYTECODE``, if set here, is dropped for them),
and a first run, not timed, fills that cache.

    python benchmarks/bench_startup.py [--repeat 5] [--workers N]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_fig2 import best_of  # the same timing rule in every benchmark (run as a script: its folder is on sys.path)

CLI = [sys.executable, "-m", "frictionlab"]
HELP_TARGET = 1.0  # --help / import numpy
OVERHEAD_TARGET = 0.3  # seconds of the whole process beyond the engine's
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


def best_fig2(repeat: int, *extra: str) -> tuple[float, float, float]:
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(repeat):
            runs.append(fig2_run(Path(tmp) / f"run{i}", *extra))
    return min(runs, key=lambda r: r[0] - r[2])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="best of this many processes")
    parser.add_argument("--workers", type=int, help="worker processes of the Fig. 2 run (default: every core)")
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be >= 1. Got {args.repeat} instead.")
    extra = [] if args.workers is None else ["--workers", str(args.workers)]

    with tempfile.TemporaryDirectory() as tmp:  # fills the bytecode cache, untimed
        fig2_run(Path(tmp) / "warm", *extra)
    numpy = best_of(args.repeat, lambda: timed_process([sys.executable, "-c", "import numpy"]))
    helped = best_of(args.repeat, lambda: timed_process([*CLI, "--help"]))
    ratio = helped / numpy
    print(f"frictionlab --help        {helped:6.3f} s")
    print(f"python -c 'import numpy'  {numpy:6.3f} s")
    print(f"  ratio {ratio:.2f} (target <= {HELP_TARGET:g}): {'met' if ratio <= HELP_TARGET else 'NOT met'}")

    print(f"\nFig. 2 (frictionlab run benad2012-fig2 {' '.join(extra)}), best of {args.repeat} by overhead:")
    for label, flags in (("--no-plot", ["--no-plot"]), ("with plot.png", [])):
        whole, printed, engine = best_fig2(args.repeat, *extra, *flags)
        print(f"  {label:14s} whole process {whole:6.3f} s, fit printed at {printed:6.3f} s, engine {engine:6.3f} s")
        for what, seconds in (("whole", whole), ("fit printed", printed)):
            overhead = seconds - engine
            if flags or what == "fit printed":
                verdict = f"(target <= {OVERHEAD_TARGET} s): {'met' if overhead <= OVERHEAD_TARGET else 'NOT met'}"
            else:  # the figure is drawn after the fit is printed; --no-plot skips it
                verdict = "(of which the figure, drawn after the fit is printed: the difference with --no-plot)"
            print(f"    {what:12s} - engine = {overhead:6.3f} s {verdict}")


if __name__ == "__main__":
    main()
