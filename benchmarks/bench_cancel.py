"""Benchmark: how soon SIGTERM or Ctrl-C (SIGINT) ends an exact run in the middle of its solve.

A 4096 x 4096 ``bem-halfspace`` run of one realization (power-law-2d, H = 0.8, short
cut-off 8 pixels, 20 forces at the same contact fractions as ``bench_bem.py``'s 512 x 512
scene), ``frictionlab run --workers 1``, gets the signal ``--after`` seconds after its
start, deep in a CG whose iterations take a second or more; printed is the time from the
signal to the process's exit, with its exit code (143 for SIGTERM, 130 for SIGINT),
against the target of 1 s.

    python benchmarks/bench_cancel.py [--side 4096] [--after 20]
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_bem_run import PRESET, SEED  # this folder's: the same scene, larger

TARGET = 1.0  # seconds from the signal to the exit
EXPECTED = {"SIGTERM": 143, "SIGINT": 130}


def signalled(preset: Path, out: Path, name: str, after: float) -> tuple[float, int]:
    """(seconds from the signal to the exit, exit code) of a run sent ``name`` after ``after`` s."""
    process = subprocess.Popen(
        [sys.executable, "-m", "frictionlab", "run", str(preset), "--workers", "1", "--quiet", "--out", str(out)],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env={**os.environ, "OMP_NUM_THREADS": "1"},
    )  # fmt: skip
    time.sleep(after)
    if process.poll() is not None:
        raise SystemExit(f"the run ended (exit {process.returncode}) before {after:g} s: give a larger --side or a smaller --after")
    start = time.perf_counter()
    process.send_signal(getattr(signal, name))
    code = process.wait()
    return time.perf_counter() - start, code


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=4096, help="surface side in pixels")
    parser.add_argument("--after", type=float, default=20.0, help="seconds from the run's start to the signal")
    args = parser.parse_args()
    if args.side < 16:
        parser.error(f"--side must be at least 16. Got {args.side} instead.")
    if not args.after > 0:
        parser.error(f"--after must be > 0 seconds. Got {args.after} instead.")
    scale = (args.side / 512) ** 2
    with tempfile.TemporaryDirectory() as tmp:
        preset = Path(tmp) / "bench-cancel.yaml"
        preset.write_text(PRESET.format(name="bench-cancel", seed=SEED, side=args.side, first=20.0 * scale, last=1000.0 * scale))
        print(f"bem-halfspace, {args.side} x {args.side}, frictionlab run --workers 1, signal {args.after:g} s after its start")
        for name, expected in EXPECTED.items():
            seconds, code = signalled(preset, Path(tmp) / name, name, args.after)
            verdict = "met" if seconds <= TARGET and code == expected else "NOT met"
            print(f"  {name:8s} exit {code} (expected {expected}) {seconds:6.2f} s after the signal "
                  f"(target <= {TARGET:g} s): {verdict}")  # fmt: skip


if __name__ == "__main__":
    main()
