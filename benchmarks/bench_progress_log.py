"""Benchmark: what a run pays for writing its progress to progress.jsonl (the file a
detached run writes, and a TUI or ``frictionlab follow`` reads), and what following it costs.

The built-in quickstart preset (MDR springs, cheap realizations: the worst case for a
per-realization cost), run serially into a folder three ways, alternated so that a noisy
shared machine shifts them together (after a warm-up run; each goes first in turn): without a listener (the baseline), with
``ProgressLog``, and with ``ProgressLog`` then a ``Follower`` replaying the whole file.
Prints the median wall times and their ratios to the baseline, and the file's size.

    python benchmarks/bench_progress_log.py [--realizations 2000] [--repeat 6]
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import tempfile
import time
from pathlib import Path

from frictionlab.options import RunOptions
from frictionlab.preset import build_scene, read_preset
from frictionlab.preset.builtin import resolve_preset_path
from frictionlab.runs.progresslog import PROGRESS_FILE, Follower, ProgressLog
from frictionlab.runs.runner import run_to_folder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--realizations", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=6)
    args = parser.parse_args()
    scene = build_scene(read_preset(str(resolve_preset_path("quickstart")), [f"realizations={args.realizations}"]))
    options = RunOptions(workers=1)
    times: dict[str, list[float]] = {"baseline": [], "progress log": [], "log + follow": []}
    size = 0
    with tempfile.TemporaryDirectory() as tmp:
        run_to_folder(scene, Path(tmp) / "warm-up", options, plot=False)  # imports, caches: paid by none of the three
        names = list(times)
        for repeat in range(args.repeat):
            for name in names[repeat % 3:] + names[: repeat % 3]:  # each goes first in turn
                out = Path(tmp) / name.replace(" ", "-")
                shutil.rmtree(out, ignore_errors=True)
                listeners = [] if name == "baseline" else [ProgressLog(out)]
                started = time.perf_counter()
                run_to_folder(scene, out, options, listeners=listeners, plot=False)
                if name == "log + follow":
                    follower = Follower(out, scene)
                    while follower.poll():
                        pass
                times[name].append(time.perf_counter() - started)
                if name != "baseline":
                    size = (out / PROGRESS_FILE).stat().st_size
    base = statistics.median(times["baseline"])
    print(f"quickstart, {args.realizations} realizations of {scene.loads.size} loads, serial, median of {args.repeat}")
    for name, values in times.items():
        median = statistics.median(values)
        print(f"  {name:<14} {median:7.3f} s   x{median / base:.3f}")
    print(f"  {PROGRESS_FILE}: {size / 1024:.0f} KiB ({size / args.realizations:.0f} bytes a realization)")


if __name__ == "__main__":
    main()
