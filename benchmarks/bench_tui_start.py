"""Benchmark: the TUI's first screen, from the start of its process to its first frame.

Each try is a fresh process that starts the app as ``frictionlab tui`` does
(``frictionlab.tui.run_app``, over the shipped presets and an empty runs folder), headless at 80x24, and
notes the clock once the first screen is drawn and the app idle (Textual's pilot). The
baseline, in the same run: a bare Textual app of one line of text, the floor of any
Textual app. Prints the best of --repeat of each (target: the first screen within 1 s).

    python benchmarks/bench_tui_start.py [--repeat 5] [--busy 2]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TARGET = 1.0  # seconds from the process's start to the first screen
PRESETS = Path(__file__).resolve().parents[1] / "presets"
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as a user's shell has it

FRICTIONLAB = """
import sys, time, types
started, presets, runs = float(sys.argv[1]), sys.argv[2], sys.argv[3]
import frictionlab.tui
from frictionlab.options import RunOptions
from textual.app import App
seen = []
async def first_frame(pilot):
    await pilot.pause()
    seen.append(time.time() - started)
    pilot.app.exit()
run = App.run
App.run = lambda app, **_: run(app, headless=True, size=(80, 24), auto_pilot=first_frame)
terminal = types.SimpleNamespace(isatty=lambda: True)  # run_app asks for a terminal; the app runs headless
frictionlab.tui.sys = types.SimpleNamespace(stdin=terminal, stdout=terminal)
frictionlab.tui.run_app(None, presets_dir=presets, runs_dir=runs, options=RunOptions())
print(seen[0])
"""

BARE = """
import sys, time
started = float(sys.argv[1])
from textual.app import App
from textual.widgets import Static
class Bare(App):
    def compose(self):
        yield Static("frictionlab")
seen = []
async def first_frame(pilot):
    await pilot.pause()
    seen.append(time.time() - started)
    pilot.app.exit()
Bare().run(headless=True, size=(80, 24), auto_pilot=first_frame)
print(seen[0])
"""


def first_frame(code: str, *args: str) -> float:
    started = time.time()  # the child's clock is the same wall clock
    done = subprocess.run([sys.executable, "-c", code, repr(started), *args], capture_output=True, text=True, env=ENV)
    if done.returncode != 0:
        raise SystemExit(f"the app did not start (exit {done.returncode}): {done.stderr[-800:]}")
    return float(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="best of this many processes")
    parser.add_argument("--busy", type=int, default=0, help="CPU-bound processes running beside the measurements")
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error(f"--repeat must be >= 1. Got {args.repeat} instead.")
    if args.busy < 0:
        parser.error(f"--busy must be >= 0. Got {args.busy} instead.")
    busy = [subprocess.Popen([sys.executable, "-c", "while 1: pass"]) for _ in range(args.busy)]
    try:
        with tempfile.TemporaryDirectory() as tmp:
            runs = str(Path(tmp) / "runs")
            first_frame(FRICTIONLAB, str(PRESETS), runs)  # fills the bytecode cache, untimed
            ours, bare = [], []
            for _ in range(args.repeat):
                ours.append(first_frame(FRICTIONLAB, str(PRESETS), runs))
                bare.append(first_frame(BARE))
    finally:
        for process in busy:
            process.kill()
            process.wait()
    best, floor = min(ours), min(bare)
    print(f"frictionlab tui, first screen (80x24, {len(list(PRESETS.glob('*.yaml')))} presets): {best:6.3f} s "
          f"(target <= {TARGET:g} s: {'met' if best <= TARGET else 'NOT met'})")  # fmt: skip
    print(f"a bare Textual app, first screen:                    {floor:6.3f} s")
    print(f"  beyond Textual's floor: {best - floor:6.3f} s")


if __name__ == "__main__":
    main()
