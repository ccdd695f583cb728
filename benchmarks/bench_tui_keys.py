"""Benchmark: what a keystroke costs in the TUI's preset form.

Types into a number field of the form (each key re-validates the preset and marks
the fields) and, as the baseline measured in this same process, into a bare Textual
input, each key sent as Textual's test pilot sends it (it waits until the app is
idle). Prints the median milliseconds per key of each and their ratio, and the time
to open a preset (the form built from the models).

    python benchmarks/bench_tui_keys.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import asyncio
import os
import shutil
import statistics
import tempfile
import time
from pathlib import Path

from textual.app import App
from textual.widgets import Input

from frictionlab.options import RunOptions
from frictionlab.plugin.registry import Registry
from frictionlab.tui.app import FrictionlabApp

PRESET = Path(__file__).resolve().parents[1] / "presets" / "quickstart.yaml"  # the form a newcomer opens first
KEYS = "0.75310.7531"


class Bare(App):
    def compose(self):
        yield Input(id="field")


async def per_key(app, field_id: str) -> float:
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        app.query_one(field_id).focus()
        await pilot.pause()
        start = time.perf_counter()
        for key in KEYS:
            await pilot.press(key)
        return (time.perf_counter() - start) / len(KEYS)


async def open_seconds(folder: Path) -> tuple[float, float]:
    app = FrictionlabApp(presets_dir=folder, runs_dir=folder / "runs", options=RunOptions(workers=1),
                         registry=Registry(discover=False))  # fmt: skip
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        start = time.perf_counter()
        await pilot.press("enter")
        await pilot.pause()
        opened = time.perf_counter() - start
    form = FrictionlabApp(folder / "bench.yaml", presets_dir=folder, runs_dir=folder / "runs",
                          options=RunOptions(workers=1), registry=Registry(discover=False))  # fmt: skip
    return opened, await per_key(form, "#field--spectrum--params--hurst")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp())
    shutil.copy(PRESET, folder / "bench.yaml")
    os.chdir(folder)
    bare, form, opened = [], [], []
    for _ in range(args.repeat):
        bare.append(asyncio.run(per_key(Bare(), "#field")))
        seconds, key = asyncio.run(open_seconds(folder))
        opened.append(seconds)
        form.append(key)
    b, f = statistics.median(bare), statistics.median(form)
    print(f"per key: form {1e3 * f:.0f} ms, bare input {1e3 * b:.0f} ms, form / bare = {f / b:.1f}")
    print(f"open a preset (build the form): {1e3 * statistics.median(opened):.0f} ms")


if __name__ == "__main__":
    main()
