"""plot.png's log axes are labelled in plain text (10⁻⁸, 2×10⁻⁹, 4), on the ticks
matplotlib's own log formatter labels: its labels were mathtext, whose parser was about
half of drawing the figure, the last thing a run waits for."""

from __future__ import annotations

import io
import math

import pytest
from matplotlib.figure import Figure
from matplotlib.ticker import LogFormatterSciNotation

from frictionlab.compute import engine
from frictionlab.runs.figures import CurveFigure
from frictionlab.options import RunOptions
from frictionlab.plot import PlainLogFormatter, plain_log_labels, plot_curve

from .conftest import SMALL_PRESET

_DIGITS = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹−", "-0123456789-")


def value_of(label: str) -> float:
    """The number a plain label names (``2×10⁻⁹``, ``10⁻⁸``, ``4``)."""
    if "10" in label and any(c in label for c in "⁻⁰¹²³⁴⁵⁶⁷⁸⁹"):
        coeff, _, power = label.rpartition("10")
        return float(coeff.rstrip("×") or 1) * 10.0 ** int(power.translate(_DIGITS))
    return float(label.translate(_DIGITS))


@pytest.mark.parametrize("low, high", [(1e-9, 2e-8), (3.0, 12.0), (1.0, 1000.0), (1e-3, 1e5), (2e-7, 5e-7), (0.2, 0.9)])
def test_the_same_ticks_are_labelled_each_with_its_value(low, high):
    ax = Figure().subplots()
    ax.set_xscale("log")
    ax.set_xlim(low, high)
    theirs = [LogFormatterSciNotation(labelOnlyBase=False), LogFormatterSciNotation(labelOnlyBase=False)]
    plain_log_labels(ax.xaxis)
    for axis_formatter, reference, minor in ((ax.xaxis.get_major_formatter(), theirs[0], False),
                                             (ax.xaxis.get_minor_formatter(), theirs[1], True)):  # fmt: skip
        locs = ax.xaxis.get_minorticklocs() if minor else ax.xaxis.get_majorticklocs()
        reference.set_axis(ax.xaxis)
        for formatter in (axis_formatter, reference):
            formatter.set_locs(locs)
        labelled = 0
        for x in locs:
            ours, expected = axis_formatter(x), reference(x)
            assert bool(ours) == bool(expected), (x, ours, expected)
            if ours:
                labelled += 1
                assert "$" not in ours
                assert value_of(ours) == pytest.approx(x, rel=1e-9)
        assert labelled or minor


def test_labels_read_as_written():
    formatter = PlainLogFormatter(labelOnlyBase=False)
    formatter.set_axis(Figure().subplots().xaxis)
    assert [formatter(x) for x in (1e-8, 2e-9, 1e5)] == ["10⁻⁸", "2×10⁻⁹", "10⁵"]
    assert [formatter(x) for x in (1.0, 4.0, 20.0, 1000.0)] == ["1", "4", "20", "1000"]


def test_plot_png_is_drawn_without_mathtext(make_scene, monkeypatch):
    import matplotlib.mathtext

    def refused(*args, **kwargs):
        raise AssertionError("mathtext parsed a label")

    monkeypatch.setattr(matplotlib.mathtext.MathTextParser, "parse", refused)
    scene = make_scene({"realizations": 3})
    outcome = engine.run(scene, RunOptions(workers=1))
    fh = io.BytesIO()
    plot_curve(CurveFigure.of(scene, outcome), fh)
    assert fh.getvalue().startswith(b"\x89PNG") and math.isfinite(outcome.fit.a)


def test_the_definition_of_f_under_plot_png_is_inside_the_figure(make_scene, monkeypatch, tmp_path):
    """A measured map pressed by MDR defines f with the equivalent line's length and the apparent
    area, 125 characters: on one line it ran past the figure's right edge, cut at 'A the surface's app'."""
    import numpy as np
    from matplotlib.figure import Figure

    np.save(tmp_path / "map.npy", np.random.default_rng(1).normal(size=(16, 16)))
    spectrum = {"name": "surface-file", "params": {"path": str(tmp_path / "map.npy"), "spacing": 0.1}}
    scene = make_scene({"realizations": 2}, base={**SMALL_PRESET, "spectrum": spectrum})
    outcome = engine.run(scene, RunOptions(workers=1))
    drawn = []
    save = Figure.savefig
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: (drawn.append(fig), save(fig, *a, **k))[1])
    plot_curve(CurveFigure.of(scene, outcome), io.BytesIO())
    fig = drawn[0]
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    label = fig.axes[1].xaxis.label
    assert "A the surface's apparent area" in label.get_text().replace("\n", " ")
    box, inside = label.get_window_extent(renderer), fig.bbox
    assert box.x0 >= inside.x0 and box.x1 <= inside.x1 and box.y0 >= inside.y0, (box, inside)
    ticks = max(t.get_window_extent(renderer).y0 for t in fig.axes[1].get_xticklabels() if t.get_text())
    assert box.y1 <= ticks  # under the tick labels, not over them


def test_a_long_title_of_plot_png_is_inside_the_figure(make_scene, monkeypatch):
    """The title names the preset, what is pressed, the solver and the slope estimator: with a
    name of 60 characters it ran past both edges of the figure on one line."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    name = "a-long-preset-name-as-a-study-gives-it-h08-n1024-seed2026-run"
    scene = make_scene({"realizations": 2, "name": name})
    outcome = engine.run(scene, RunOptions(workers=1))
    drawn = []
    save = Figure.savefig
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: (drawn.append(fig), save(fig, *a, **k))[1])
    plot_curve(CurveFigure.of(scene, outcome), io.BytesIO())
    canvas = FigureCanvasAgg(drawn[0])
    canvas.draw()
    title, inside = drawn[0].axes[0].title, drawn[0].bbox
    assert name in title.get_text().replace("\n", " ")
    box = title.get_window_extent(canvas.get_renderer())
    assert box.x0 >= inside.x0 and box.x1 <= inside.x1 and box.y1 <= inside.y1, (box, inside)


def test_caveats_of_several_lines_each_are_all_readable_none_over_another():
    """Each caveat was placed 0.09 of the axes above the last, whatever its lines: two of five lines
    each (a measured line's edge points) were drawn one over the other, neither readable."""
    import itertools

    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from frictionlab.plot import draw_curve

    edge = ("the line's first 8 points and last 6 points carry 81 % of its mean squared slope, each more than 10 times "
            "a typical point's: points a scan starts or ends with, whose slopes the rms slope xi divides by, are then "
            "theirs; crop them with region (x: [8, 2994], pixels of the file), if they are not the surface's own")  # fmt: skip
    caveats = [edge, "fewer than 3 points in contact at the first load", edge.replace("81 %", "64 %")]
    fig = Figure(figsize=(6.4, 5.6))
    ax = fig.subplots()
    f = np.geomspace(1e-9, 2e-8, 40)
    draw_curve(ax, f, 0.3 + 0.02 * np.log(f / f[0]), np.full(40, 0.01), None, done=8, caveats=caveats)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    said = [t for t in ax.texts if "caveat: " in t.get_text()]
    text = " ".join(" ".join(t.get_text().split()) for t in said)
    assert all(f"caveat: {caveat}" in text for caveat in caveats), text
    boxes = [t.get_window_extent(canvas.get_renderer()) for t in said]
    assert not any(a.overlaps(b) for a, b in itertools.combinations(boxes, 2)), boxes
    assert all(box.y1 <= ax.bbox.y1 for box in boxes)  # inside the axes, under the legend's row at most


def test_a_folder_with_thousands_of_long_caveats_is_drawn_with_the_first_few_and_how_many_more(tmp_path, monkeypatch):
    """A run folder is untrusted: its summary.json (up to 64 MB) may hold any number of caveats.
    2000 of 2000 characters each kept `frictionlab plot` drawing for minutes; a figure shows the
    first few, each cut, and says how many more the folder holds. A name and f's definition of
    300000 characters left no room for the axes (matplotlib's 'bottom cannot be >= top')."""
    import json

    import yaml
    from matplotlib.figure import Figure

    from frictionlab import load
    from frictionlab.cli.main import main
    from frictionlab.runs.figures import SHOWN_CAVEAT_CHARS, SHOWN_CAVEATS, SHOWN_LABEL_CHARS

    (tmp_path / "p.yaml").write_text(yaml.safe_dump({**SMALL_PRESET, "realizations": 2}))
    assert main(["run", str(tmp_path / "p.yaml"), "--out", str(tmp_path / "run"), "--quiet", "--no-plot"]) == 0
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    summary["caveats"] = [f"caveat number {i} " + "x" * 2000 for i in range(2000)]
    summary["preset"]["name"], summary["normalisation"]["f"] = "n" * 300_000, "f " * 150_000
    (tmp_path / "run" / "summary.json").write_text(json.dumps(summary))
    drawn = []
    save = Figure.savefig
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: (drawn.append(fig), save(fig, *a, **k))[1])
    assert main(["plot", str(tmp_path / "run"), "--quiet"]) == 0
    title, label = drawn[0].axes[0].get_title(), drawn[0].axes[1].get_xlabel()
    assert title.startswith("nnn") and len("".join(title.split())) <= SHOWN_LABEL_CHARS + 3
    assert label.startswith("f f") and len(label) <= 2 * SHOWN_LABEL_CHARS
    ax = load(tmp_path / "run").plot(Figure().subplots())  # and in a notebook
    assert len(ax.get_title()) == len(ax.get_xlabel()) == SHOWN_LABEL_CHARS + 3
    for texts in (drawn[0].axes[0].texts, ax.texts):
        [block] = [t.get_text() for t in texts if "caveat: " in t.get_text()]
        said = block.split("caveat: ")[1:]
        assert len(said) == SHOWN_CAVEATS + 1 and all(f"caveat number {i} " in said[i] for i in range(SHOWN_CAVEATS))
        assert all(len("".join(part.split())) <= SHOWN_CAVEAT_CHARS + 3 for part in said)
        assert f"and {2000 - SHOWN_CAVEATS} more, not shown here" in " ".join(said[-1].split())
