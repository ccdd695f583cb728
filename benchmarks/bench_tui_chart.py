"""Benchmark: the TUI's braille chart against textual-plotext (``pip install textual-plotext``).

The Run tab redraws its chart up to 10 times a second while a run goes on, at the
size it has in an 80x24 terminal (about 48 x 14 cells beside the fit). This
prints, measured in this one process so that the machine's load shifts both alike:

* import: seconds to import each (in a fresh interpreter that has Textual, numpy
  and frictionlab loaded already, the median of ``--repeat`` runs), the size on disk
  of what each adds to an install;
* draw: the median time to draw a 40-point mean curve and its fit line at
  48 x 14 cells (``render_chart`` for the braille chart; plotext's ``build`` of
  a scatter and a line on a log f axis), and the ratio plotext / braille;
* how many of the rows drawn show data (the rest: frame, ticks, labels),
  and what each shows at that size, printed as text to compare by eye.

    python benchmarks/bench_tui_chart.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from frictionlab.tui.chart import Series, render_chart

WIDTH, HEIGHT = 48, 14


def curve():
    f = np.geomspace(1e-3, 4e-2, 40)
    rng = np.random.default_rng(1)
    xi = 1.24 + 0.106 * np.log(f) + rng.normal(0, 0.01, f.size)
    return f, xi, 1.24 + 0.106 * np.log(f[[0, -1]])


def braille_text(f, xi, line) -> str:
    rows = render_chart([Series(f, xi, "cyan"), Series(f[[0, -1]], line, "yellow", line=True)], WIDTH, HEIGHT)
    return "\n".join("".join(chunk for chunk, _ in row) for row in rows)


def plotext_text(f, xi, line) -> str:
    import plotext as plt

    plt.clear_figure()
    plt.plotsize(WIDTH, HEIGHT)
    plt.xscale("log")
    plt.scatter(f, xi, marker="braille", color="cyan")
    plt.plot(f[[0, -1]], line, marker="braille", color="yellow")
    plt.xlabel("f")
    plt.ylabel("xi")
    plt.theme("clear")
    return plt.uncolorize(plt.build())


def median_time(draw, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(20):
            draw()
        times.append((time.perf_counter() - start) / 20)
    return statistics.median(times)


def import_seconds(module: str, repeat: int) -> float:
    code = (
        "import time, textual.widget, numpy, frictionlab; t = time.perf_counter(); "
        f"import {module}; print(time.perf_counter() - t)"
    )
    runs = [float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout)
            for _ in range(repeat)]  # fmt: skip
    return statistics.median(runs)


def installed_size(package: str) -> float:
    spec = importlib.util.find_spec(package)
    folder = Path(spec.origin).parent
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file()) / 1e3


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    if importlib.util.find_spec("textual_plotext") is None:
        raise SystemExit("textual-plotext is not installed: pip install textual-plotext")
    f, xi, line = curve()
    braille = median_time(lambda: braille_text(f, xi, line), args.repeat)
    plotext = median_time(lambda: plotext_text(f, xi, line), args.repeat)
    imp_braille = import_seconds("frictionlab.tui.chart", args.repeat)  # the widget around it is 30 lines
    imp_plotext = import_seconds("textual_plotext", args.repeat)
    print(f"draw {WIDTH}x{HEIGHT} cells: braille {1e3 * braille:.2f} ms, plotext {1e3 * plotext:.2f} ms, "
          f"plotext / braille = {plotext / braille:.1f}")  # fmt: skip
    print(f"import: braille chart {1e3 * imp_braille:.1f} ms, textual_plotext {1e3 * imp_plotext:.1f} ms")
    print(f"added to an install: braille chart 0 kB (part of frictionlab), "
          f"plotext + textual_plotext {installed_size('plotext') + installed_size('textual_plotext'):.0f} kB")
    for name, text in (("braille", braille_text(f, xi, line)), ("plotext", plotext_text(f, xi, line))):
        rows = text.splitlines()
        data_rows = sum(any(0x2800 <= ord(c) <= 0x28FF for c in row) for row in rows)
        print(f"{name}: {data_rows} of the {len(rows)} rows drawn show data points")
    print("\nbraille chart:\n" + braille_text(f, xi, line))
    print("\nplotext:\n" + plotext_text(f, xi, line))


if __name__ == "__main__":
    main()
