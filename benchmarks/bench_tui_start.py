"""Benchmark: the TUI's first screen, from the start of its process to its first frame.

Each try is a fresh process that runs ``frictionlab tui --presets DIR --runs DIR`` (the
CLI's own entry, over the shipped presets and an empty runs folder), headless at 80x24.
The clock stops when the app has painted a frame that shows the Presets tab: the tab
bar and the first preset's name in the list (the frames the app sends to the terminal
are read, as the terminal would). The app mounts its other tabs just after that frame;
a key pressed at once waits for them, so the second figure is when a key pressed as the
first screen appears (F5, the Results tab) has been answered. The baseline, in the same
run: a bare Textual app of one line of text, the floor of any Textual app, to its first
frame. Prints the best of --repeat of each (target: the first screen within 1 s).

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

import yaml

from machine_load import busy_beside, check_repeat_and_busy  # this folder's

TARGET = 1.0  # seconds from the process's start to the first screen
PRESETS = Path(__file__).resolve().parents[1] / "presets"
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as a user's shell has it

# the frames the app paints, as text: Textual paints nothing headless, so each frame is rendered
# here as the terminal would receive it, and the clock read when one shows all of `wanted`
PAINTED = r"""
import re, sys, time
from textual._compositor import CompositorUpdate
from textual.app import App
started, wanted, seen = float(sys.argv[1]), sys.argv[2].split("|"), {}
display, painted = App._display, []
def _display(app, screen, renderable):
    display(app, screen, renderable)
    if "frame" not in seen and isinstance(renderable, CompositorUpdate) and not app._batch_count:
        painted.append(re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", renderable.render_segments(app.console)))
        if all(word in "".join(painted) for word in wanted):
            seen["frame"] = time.time() - started
App._display = _display
async def first_frame(pilot):
    while "frame" not in seen:
        await pilot.pause(0.005)
"""

FRICTIONLAB = PAINTED + """
import types
presets, runs = sys.argv[3], sys.argv[4]
import frictionlab.tui
async def first_key(pilot):
    await first_frame(pilot)
    await pilot.press("f5")  # as the first screen appears: answered once the Results tab shows
    seen["key"] = time.time() - started
    assert pilot.app.query_one("#tabs").active == "results", "F5 did not show the Results tab"
    pilot.app.exit()
run = App.run
App.run = lambda app, **_: run(app, headless=True, size=(80, 24), auto_pilot=first_key)
terminal = types.SimpleNamespace(isatty=lambda: True)  # run_app asks for a terminal; the app runs headless
frictionlab.tui.sys = types.SimpleNamespace(stdin=terminal, stdout=terminal)
from frictionlab.cli import main
code = main(["tui", "--presets", presets, "--runs", runs])
print(seen["frame"], seen["key"], code)
"""

BARE = PAINTED + """
from textual.widgets import Static
class Bare(App):
    def compose(self):
        yield Static("frictionlab")
async def then_exit(pilot):
    await first_frame(pilot)
    pilot.app.exit()
Bare().run(headless=True, size=(80, 24), auto_pilot=then_exit)
print(seen["frame"])
"""


def first_preset_name() -> str:
    """The start of the name the list shows first (a long name is cut in its middle)."""
    first = sorted(PRESETS.glob("*.y*ml"))[0]
    return str(yaml.safe_load(first.read_text(encoding="utf-8")).get("name") or first.stem)[:8]


def timed(code: str, *args: str) -> list[float]:
    """The seconds the child printed, from the start of its process."""
    started = time.time()  # the child's clock is the same wall clock
    done = subprocess.run([sys.executable, "-c", code, repr(started), *args], capture_output=True, text=True, env=ENV)
    if done.returncode != 0:
        raise SystemExit(f"the app did not start (exit {done.returncode}): {done.stderr[-800:]}")
    return [float(word) for word in done.stdout.strip().splitlines()[-1].split()]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="best of this many processes")
    parser.add_argument("--busy", type=int, default=0, help="CPU-bound processes running beside the measurements")
    args = parser.parse_args()
    check_repeat_and_busy(parser, args)
    with busy_beside(args.busy), tempfile.TemporaryDirectory() as tmp:
        runs = str(Path(tmp) / "runs")
        ours_wanted = f"F2 Presets|F5 Results|{first_preset_name()}"
        timed(FRICTIONLAB, ours_wanted, str(PRESETS), runs)  # fills the bytecode cache, untimed
        ours, keys, bare = [], [], []
        for _ in range(args.repeat):
            frame, key, code = timed(FRICTIONLAB, ours_wanted, str(PRESETS), runs)
            if code != 0:
                raise SystemExit(f"frictionlab tui exited {code:g}")
            ours.append(frame)
            keys.append(key)
            bare.append(timed(BARE, "frictionlab")[0])
    best, floor = min(ours), min(bare)
    print(f"frictionlab tui, first screen (80x24, {len(list(PRESETS.glob('*.yaml')))} presets): {best:6.3f} s "
          f"(target <= {TARGET:g} s: {'met' if best <= TARGET else 'NOT met'})")  # fmt: skip
    print(f"  a key pressed then (F5) answered:                  {min(keys):6.3f} s")
    print(f"a bare Textual app, first screen:                    {floor:6.3f} s")
    print(f"  beyond Textual's floor: {best - floor:6.3f} s")


if __name__ == "__main__":
    main()
