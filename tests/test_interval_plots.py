"""Every plot of an interval draws it from its low end to its high end, wherever its
estimate lies.

A bootstrap's percentile interval need not contain its estimate (6 realizations, 20
resamples): error bars measured from the estimate then had a negative length, and
matplotlib refused the whole figure (``'yerr' must not contain negative values``: the
report of a small study ended with exit 70). Here each figure that draws intervals (a
sweep's, the report's Fig. 5, the exact 3D study's convergence) gets an estimate above
its interval and one below, and must draw both intervals as they are.
"""

from __future__ import annotations

import io
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.figure import Figure

from frictionlab.plot import draw_interval, sweep_figure

# (estimate, low, high): above, below, inside its interval
POINTS = [(0.30, 0.10, 0.20), (0.05, 0.10, 0.20), (0.15, 0.10, 0.20)]


def drawn_intervals(ax) -> list[tuple[float, float, float]]:
    """(x, low, high) of the vertical bars on ``ax``."""
    bars = []
    for collection in ax.collections:
        for segment in collection.get_segments():
            if len(segment) == 0:  # a missing end: nothing drawn
                continue
            (x0, y0), (x1, y1) = segment
            assert x0 == pytest.approx(x1)
            bars.append((x0, min(y0, y1), max(y0, y1)))
    return sorted(bars)


def test_an_interval_is_drawn_end_to_end_with_its_estimate_outside_or_inside():
    ax = Figure().subplots()
    x = [1.0, 2.0, 3.0]
    estimate, low, high = np.array(POINTS).T
    draw_interval(ax, x, estimate, low, high, "o-", color="C0", label="points")
    assert drawn_intervals(ax) == [pytest.approx((xi, lo, hi)) for xi, lo, hi in zip(x, low, high)]
    (line,) = ax.get_lines()[-1:]
    assert list(line.get_ydata()) == pytest.approx(estimate) and line.get_label() == "points"


def test_a_missing_end_draws_no_interval_but_its_estimate():
    ax = Figure().subplots()
    draw_interval(ax, [1.0, 2.0], [0.3, 0.4], [np.nan, 0.1], [0.5, 0.6], "o", color="C1")
    assert drawn_intervals(ax) == [pytest.approx((2.0, 0.1, 0.6))]
    assert list(ax.get_lines()[-1].get_ydata()) == pytest.approx([0.3, 0.4])


def _rows(path):
    return [{path: h, "a": a, "a_lo": lo, "a_hi": hi, "b": -a, "b_lo": -hi, "b_hi": -lo}
            for h, (a, lo, hi) in zip((0.6, 0.7, 0.8), POINTS)]  # fmt: skip


def test_a_sweeps_figure_draws_intervals_that_miss_their_estimates(registry):
    from frictionlab.runs.sweep import plan_sweep

    from .test_sweep import sweep_preset

    path = "spectrum.params.hurst"
    sweep = plan_sweep(sweep_preset({path: {"values": [0.6, 0.7, 0.8]}}), registry=registry)
    figure = sweep_figure(sweep, _rows(path))
    a_axis, b_axis = figure.axes[:2]
    assert drawn_intervals(a_axis) == [pytest.approx((h, lo, hi)) for h, (_, lo, hi) in zip((0.6, 0.7, 0.8), POINTS)]
    assert drawn_intervals(b_axis) == [pytest.approx((h, -hi, -lo)) for h, (_, lo, hi) in zip((0.6, 0.7, 0.8), POINTS)]
    figure.savefig(io.BytesIO(), format="png")


def _recording(monkeypatch, module):
    """Calls of ``module.draw_interval`` recorded (and drawn) as (estimate, low, high) rows."""
    calls = []

    def record(ax, x, estimate, low, high, *args, **kwargs):
        calls.append(np.column_stack([estimate, low, high]))
        draw_interval(ax, x, estimate, low, high, *args, **kwargs)

    monkeypatch.setattr(module, "draw_interval", record)
    return calls


def test_the_reports_fig5_draws_intervals_that_miss_their_estimates(monkeypatch):
    from frictionlab.paper import plots

    calls = _recording(monkeypatch, plots)
    path = "spectrum.params.hurst"
    run = SimpleNamespace(sweep=SimpleNamespace(paths=[path]), sweep_outcome=SimpleNamespace(rows=_rows(path)))
    plots.plot_fig5(run, io.BytesIO())
    a, b = calls
    assert a == pytest.approx(np.array(POINTS)) and b == pytest.approx(-np.array(POINTS)[:, [0, 2, 1]])


def _fit(a, b):
    return SimpleNamespace(a=a[0], a_ci=a[1:], b=b[0], b_ci=b[1:])


def test_the_exact3d_convergence_figure_draws_intervals_that_miss_their_estimates(monkeypatch):
    from frictionlab.exact3d import figures

    calls = _recording(monkeypatch, figures)
    grids = [SimpleNamespace(pixels_per_short_cutoff=p, quoted=p >= 16) for p in (8, 16, 32)]
    value, low, high = np.array(POINTS).T
    limit = SimpleNamespace(limit=0.4, interval=(0.1, 0.2), estimated=True)  # a limit outside its interval too
    quantities = {
        "a": SimpleNamespace(values=value, low=low, high=high, limit=limit),
        "b": SimpleNamespace(values=-value, low=-high, high=-low, limit=None),
        "κ": SimpleNamespace(values=2 + value, low=2 + low, high=2 + high, limit=None),
    }
    numbers = SimpleNamespace(convergence={0.8: SimpleNamespace(grids=grids, surfaces=16, quantities=quantities)})
    figures.plot_convergence(SimpleNamespace(), numbers, io.BytesIO())
    a, a_limit, b, kappa = calls
    assert a == pytest.approx(np.array(POINTS)) and kappa == pytest.approx(2 + np.array(POINTS))
    assert b == pytest.approx(-np.array(POINTS)[:, [0, 2, 1]])
    assert a_limit == pytest.approx(np.array([[0.4, 0.1, 0.2]]))