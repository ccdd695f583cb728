"""Benchmark: drawing plot.png of the study's Fig. 2 run, as ``frictionlab run`` draws it
after printing the fit.

The ensemble is computed once here; each timing is a fresh process that has imported
``frictionlab.plot`` (as a run imports it while its workers compute) and then draws the
figure once, its first, as a run does. Printed, each the best of --repeat (rounds alternate
the figure and its baseline):

* plot.png as drawn (the figure built, drawn, its PNG encoded; the file's size);
* the baseline: the same figure as matplotlib draws it by default (a tick made at every
  location the locators give, hinted text, zlib's default level), and the ratio.

    python benchmarks/bench_plot.py [--repeat 5] [--busy 2]
"""

from __future__ import annotations

import argparse
import json
import pickle
import subprocess
import sys
import tempfile
from pathlib import Path

from frictionlab.compute import engine
from frictionlab.preset import load_scene
from machine_load import busy_beside, check_repeat_and_busy  # this folder's

PRESET = Path(__file__).resolve().parents[1] / "presets" / "benad2012-fig2.yaml"

DRAW = """
import io, json, pickle, sys, time
from matplotlib.backends.backend_agg import FigureCanvasAgg
from frictionlab import plot
from frictionlab.runs.figures import CurveFigure
scene, outcome = pickle.load(open(sys.argv[1], "rb"))
if sys.argv[2] == "baseline":
    plot.ticks_in_view, plot.UNHINTED, plot.FAST_PNG = (lambda ax: None), {}, {}
marks = {}
draw = FigureCanvasAgg.draw
def timed_draw(canvas):
    marks["built"] = time.perf_counter()
    draw(canvas)
    marks["drawn"] = time.perf_counter()
FigureCanvasAgg.draw = timed_draw
fh = io.BytesIO()
start = time.perf_counter()
plot.plot_curve(CurveFigure.of(scene, outcome), fh)
end = time.perf_counter()
print(json.dumps({"whole": end - start, "built": marks["built"] - start, "drawn": marks["drawn"] - marks["built"],
                  "png": end - marks["drawn"], "bytes": len(fh.getvalue())}))
"""


def drawn(state: Path, kind: str) -> dict:
    out = subprocess.run([sys.executable, "-c", DRAW, str(state), kind], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="best of this many fresh processes")
    parser.add_argument("--busy", type=int, default=0, help="CPU-bound processes run beside the measurement")
    args = parser.parse_args()
    check_repeat_and_busy(parser, args)

    scene = load_scene(PRESET, [])
    outcome = engine.run(scene)
    with tempfile.TemporaryDirectory() as folder:
        state = Path(folder) / "run.pickle"
        state.write_bytes(pickle.dumps((scene, outcome)))
        drawn(state, "plot")  # the bytecode caches filled, not timed
        runs: dict[str, list[dict]] = {"plot": [], "baseline": []}
        with busy_beside(args.busy):
            for _ in range(args.repeat):
                for kind in runs:
                    runs[kind].append(drawn(state, kind))
    best = {kind: min(times, key=lambda t: t["whole"]) for kind, times in runs.items()}
    ours, theirs = best["plot"], best["baseline"]
    print(f"plot.png of {scene.preset.name}, drawn cold (best of {args.repeat}, {args.busy} busy beside)")
    for name, t in (("as drawn", ours), ("matplotlib's defaults", theirs)):
        print(f"  {name:22s} {1e3 * t['whole']:6.1f} ms: built {1e3 * t['built']:5.1f}, drawn {1e3 * t['drawn']:5.1f}, "
              f"PNG {1e3 * t['png']:5.1f} ms; {t['bytes']} bytes")
    print(f"  as drawn / defaults    {ours['whole'] / theirs['whole']:6.2f}")


if __name__ == "__main__":
    main()
