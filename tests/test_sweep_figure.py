"""sweep.png names its axes by what they are and its title is never clipped."""

from __future__ import annotations

from frictionlab.options import RunOptions
from frictionlab.plot import sweep_figure
from frictionlab.runs.sweep import plan_sweep, run_sweep

from .test_sweep import sweep_preset


def test_axes_are_named_by_their_fields_description(registry):
    sweep = plan_sweep(sweep_preset({"spectrum.params.hurst": {"values": [0.6, 0.8]}, "realizations": {"values": [4, 6]}}),
                       registry=registry)  # fmt: skip
    assert sweep.axis_label("spectrum.params.hurst") == "Hurst exponent H"
    assert "." not in sweep.axis_label("realizations") and sweep.axis_label("realizations") != "realizations"
    assert sweep.axis_label("loading.no_such_key") == "no such key"  # no description: the key, readable


def test_a_one_column_figure_keeps_its_long_title_inside(tmp_path, registry):
    sweep = plan_sweep(sweep_preset({"spectrum.params.hurst": {"values": [0.6, 0.8]}}, name="a-rather-long-sweep-name"),
                       registry=registry)  # fmt: skip
    outcome = run_sweep(sweep, tmp_path / "out", RunOptions(workers=1), plot=False)
    figure = sweep_figure(sweep, outcome.rows)
    assert [ax.get_xlabel() for ax in figure.axes if ax.get_xlabel()] == ["Hurst exponent H"]
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    title = figure._suptitle.get_window_extent(canvas.get_renderer())
    assert title.x0 >= 0 and title.x1 <= figure.bbox.width and title.y1 <= figure.bbox.height
    assert "\n" in figure._suptitle.get_text()  # wrapped, not cut
