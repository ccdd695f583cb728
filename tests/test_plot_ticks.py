"""plot.png makes its ticks only where they show (matplotlib made a tick for each
location its locators gave, up to a decade beyond a log axis's ends, and drew 36 of 83),
and is the same picture for it; its PNG is compressed at zlib's fastest level, its text
drawn unhinted."""

from __future__ import annotations

import io
import struct
import zlib

import numpy as np
import pytest
from matplotlib.figure import Figure

from frictionlab import plot
from frictionlab.compute import engine
from frictionlab.runs.figures import CurveFigure
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene

from .conftest import SMALL_PRESET, merge


@pytest.fixture(scope="module")
def small_run(registry):
    scene = build_scene(merge(SMALL_PRESET, {"realizations": 3}), registry=registry)
    return scene, engine.run(scene, RunOptions(workers=1))


def drawn_figure(small_run, monkeypatch) -> tuple[Figure, bytes]:
    drawn = []
    save = Figure.savefig
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: (drawn.append(fig), save(fig, *a, **k))[1])
    fh = io.BytesIO()
    plot.plot_curve(CurveFigure.of(*small_run), fh)
    return drawn[0], fh.getvalue()


def in_view(axis, locs) -> int:
    scale = axis.get_transform()
    low, high = np.sort(scale.transform(np.array(axis.get_view_interval())))
    at = scale.transform(np.asarray(locs, dtype=float)) if len(locs) else np.array([])
    return int(np.count_nonzero((at >= low - 1e-9 * (high - low)) & (at <= high + 1e-9 * (high - low))))


def test_no_more_ticks_are_made_than_show(small_run, monkeypatch):
    """As many ticks as show on each axis (one at least: matplotlib makes one as it builds an axis)."""
    fig, _ = drawn_figure(small_run, monkeypatch)
    shown = 0
    for axis in (a for ax in fig.axes for a in (ax.xaxis, ax.yaxis)):
        for made, locs in ((axis.majorTicks, axis.get_majorticklocs()), (axis.minorTicks, axis.get_minorticklocs())):
            assert len(made) <= max(1, in_view(axis, locs)), (axis.axis_name, len(made), in_view(axis, locs))
            shown += in_view(axis, locs)
    assert shown >= 8  # both panels ticked


def test_the_ticks_in_view_draw_the_same_picture(small_run, monkeypatch):
    _, ours = drawn_figure(small_run, monkeypatch)
    monkeypatch.setattr(plot, "ticks_in_view", lambda ax: None)
    _, everything = drawn_figure(small_run, monkeypatch)
    assert ours == everything


def png_chunks(data: bytes):
    at = 8
    while at < len(data):
        (length,) = struct.unpack(">I", data[at : at + 4])
        yield data[at + 4 : at + 8], data[at + 8 : at + 8 + length]
        at += 12 + length


def test_plot_png_is_compressed_at_zlibs_fastest_level(small_run, monkeypatch):
    _, png = drawn_figure(small_run, monkeypatch)
    idat = b"".join(body for kind, body in png_chunks(png) if kind == b"IDAT")
    assert idat[1] >> 6 == 0, "the zlib header's FLEVEL: 0 is the fastest level"  # 2 is zlib's default (6)
    width, height = struct.unpack(">II", next(body for kind, body in png_chunks(png) if kind == b"IHDR")[:8])
    assert len(zlib.decompress(idat)) == height * (1 + 4 * width)  # RGBA rows, each with its filter byte


def test_plot_png_text_is_drawn_unhinted_and_the_settings_are_left_as_they_were(small_run, monkeypatch):
    """FreeType's hinting, run for each glyph, was 15% of drawing plot.png."""
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    seen = []
    draw = FigureCanvasAgg.draw
    def noted(canvas):
        seen.append(matplotlib.rcParams["text.hinting"])
        return draw(canvas)

    monkeypatch.setattr(FigureCanvasAgg, "draw", noted)
    with matplotlib.rc_context({"text.hinting": "force_autohint"}):
        plot.plot_curve(CurveFigure.of(*small_run), io.BytesIO())
        assert matplotlib.rcParams["text.hinting"] == "force_autohint"
    assert seen == ["no_hinting"]
