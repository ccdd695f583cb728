"""The page's statistics against known answers: synthetic data with a known law and noise.

* Richardson on Q(N) = Q + C N^-p recovers Q and p to rounding, for p = 1 and 2, rising
  or falling; changes of unlike sign or that do not shrink are said, not extrapolated;
* with noise, the extrapolation's interval (the order re-estimated on every paired draw)
  holds the true limit in most of 40 trials, and is wider than the finest grid's alone;
* the paired bootstrap of a difference between two grids of the same surfaces is far
  narrower than the unpaired one when the surfaces' own scatter dominates, and holds the
  true difference;
* the model test picks the true model from a log law, a power law with a large exponent,
  and a log law with curvature, each with noise; the runs test finds the curve left in
  the residuals of a straight line fitted to a curved truth, and none in the right model's.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from frictionlab.exact3d.statistics import (
    compare_models,
    extrapolate,
    fit_models,
    paired_bootstrap,
    preferred,
    richardson,
    runs_test,
)


@pytest.mark.parametrize("order", [1.0, 1.37, 2.0])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_richardson_recovers_the_limit_and_order_of_a_known_sequence(order, sign):
    limit, c = 0.8, sign * 3.0
    values = [limit + c * n**-order for n in (512, 1024, 2048)]
    result = richardson(values)
    assert result.estimated and result.order == pytest.approx(order, rel=1e-9)
    assert result.limit == pytest.approx(limit, abs=1e-12)


def test_richardson_on_grids_tripled_recovers_the_order():
    points = (64, 192, 576)
    result = richardson([0.8 + 40.0 * n**-1.5 for n in points], points)
    assert result.estimated and result.order == pytest.approx(1.5, rel=1e-9)
    assert result.limit == pytest.approx(0.8, abs=1e-12)


def test_richardson_on_grids_not_doubled_recovers_the_limit():
    points = (64, 96, 128)
    values = [0.8 + 40.0 * n**-1.5 for n in points]
    result = richardson(values, points)
    assert result.estimated and result.order == pytest.approx(1.5, rel=1e-9)
    assert result.limit == pytest.approx(0.8, abs=1e-12)
    assert richardson(values).limit != pytest.approx(0.8, abs=1e-3)  # taken as doubled grids it would be wrong


def test_richardson_says_why_it_does_not_extrapolate():
    assert not richardson([1.0, 1.1, 1.05]).estimated and "sign" in richardson([1.0, 1.1, 1.05]).reason
    grows = richardson([1.0, 1.1, 1.3])
    assert not grows.estimated and "shrink" in grows.reason and grows.limit == 1.3
    assert richardson([1.0, 1.0, 1.0]).limit == 1.0


def test_the_extrapolation_interval_holds_the_limit_and_the_orders_uncertainty():
    rng = np.random.default_rng(7)
    limit, c, order, surfaces = 0.03, -20.0, 1.0, 16
    covered, widths = 0, []
    for _ in range(40):
        per_surface = rng.normal(0, 0.01, surfaces)  # each surface's own offset, the same on every grid
        grids = [limit + c / n**order + per_surface + rng.normal(0, 0.0005, surfaces) for n in (512, 1024, 2048)]
        means = paired_bootstrap(grids, lambda *g: np.array([x.mean() for x in g]), rng=rng, bootstrap=300)
        draws = means.draws
        assert draws.shape == (300, 3)
        result = extrapolate(means.value, draws)
        low, high = result.interval
        covered += low <= limit <= high
        finest = np.percentile(draws[:, 2], [2.5, 97.5])
        widths.append((high - low) / (finest[1] - finest[0]))
    assert covered >= 34  # about 95 % of 40; at least 85 %
    assert np.median(widths) > 1.0  # the extrapolation adds its own uncertainty


def test_an_order_not_estimated_widens_the_interval_and_says_so():
    rng = np.random.default_rng(3)
    values = [1.0, 1.1, 1.05]
    draws = np.array(values) + rng.normal(0, 0.001, (200, 3))
    result = extrapolate(values, draws)
    assert not result.estimated and result.reason
    low, high = result.interval
    assert low <= 1.0 + 1e-3 and high >= 1.0  # spans the finest value and the limit at order 1 (1.0)


def test_the_paired_bootstrap_cancels_what_the_surfaces_share():
    rng = np.random.default_rng(11)
    covered = 0
    for _ in range(30):
        surfaces = rng.normal(0, 1.0, 24)  # large per-surface scatter, shared by both grids
        coarse = surfaces + rng.normal(0, 0.01, 24)
        fine = surfaces + 0.05 + rng.normal(0, 0.01, 24)
        paired = paired_bootstrap([coarse, fine], lambda a, b: b.mean() - a.mean(), rng=rng, bootstrap=300)
        low, high = paired.interval
        covered += low <= 0.05 <= high
        assert high - low < 0.03
    assert covered >= 24  # about 95 % of 30; at least 80 %
    unpaired = [np.mean(fine[rng.integers(0, 24, 24)]) - np.mean(coarse[rng.integers(0, 24, 24)]) for _ in range(500)]
    assert np.subtract(*np.percentile(unpaired, [97.5, 2.5])) > 10 * (high - low)
    with pytest.raises(ValueError, match="same surfaces"):
        paired_bootstrap([coarse, fine[:-1]], lambda a, b: 0.0, rng=rng)


F = np.logspace(-3, 1.3, 31)


@pytest.mark.parametrize(
    "truth,xi",
    [
        ("log law", lambda f: 0.8 + 0.03 * np.log(f)),
        ("power law", lambda f: 0.9 * f**0.12),
        ("log law + curvature", lambda f: 0.8 + 0.03 * np.log(f) - 0.004 * np.log(f) ** 2),
    ],
)
def test_the_model_test_picks_the_true_model(truth, xi):
    rng = np.random.default_rng(5)
    picks = []
    for _ in range(20):
        rows = xi(F) + rng.normal(0, 0.002, (8, F.size))
        picks.append(compare_models(F, rows).mean_choice)
    # the right model, or undecided between it and one that nests it: never a wrong one
    assert picks.count(truth) >= 14, picks
    if truth != "log law":
        assert "log law" not in picks
    fits = fit_models(F, xi(F) + rng.normal(0, 0.002, F.size))
    assert abs(fits[truth].runs_z) < 3


def test_the_runs_test_finds_a_curve_left_in_the_residuals():
    curved = 0.8 + 0.03 * np.log(F) - 0.004 * np.log(F) ** 2
    fits = fit_models(F, curved + np.random.default_rng(2).normal(0, 0.0005, F.size))
    assert fits["log law"].runs_z < -3 and abs(fits["log law + curvature"].runs_z) < 3
    assert runs_test(np.array([1, -1, 1, -1, 1, -1.0])) > 1 and runs_test(np.ones(5)) == -math.inf


def test_undecided_when_the_best_two_are_within_the_margin():
    from frictionlab.exact3d.statistics import ModelFit

    fits = {name: ModelFit(name, (), np.zeros(3), 0.0, bic, 0.0) for name, bic in (("a", 1.0), ("b", 2.5), ("c", 9.0))}
    assert preferred(fits) is None and preferred(fits, margin=1.0) == "a"


def test_the_convergence_statistic_recovers_a_b_and_kappa_of_known_rows():
    from frictionlab.exact3d.evidence import _law_and_kappa

    f = np.logspace(-2, 1, 12)
    rows = [0.8 + 0.03 * np.log(f) + np.zeros((5, 1)), 0.7 + 0.05 * np.log(f) + np.zeros((5, 1))]
    kappas = [np.full((5, 12), 2.4), np.full((5, 12), 2.2)]
    kappas[1][:, :6] = 9.0  # outside the window: left out
    windows = [np.ones(12, bool), np.arange(12) >= 6]
    np.testing.assert_allclose(_law_and_kappa(f, windows, *rows, *kappas), [0.8, 0.7, 0.03, 0.05, 2.4, 2.2], atol=1e-12)


def test_the_drift_of_kappa_is_its_relative_slope_against_ln_p():
    from frictionlab.exact3d.evidence import _drift

    x = np.logspace(-3, -1, 9)
    steady = np.full((4, 9), 2.0)
    falling = 2.0 - 0.1 * np.log(x / x[0]) + np.zeros((4, 1))
    value = _drift(x, falling, steady)
    assert value[0] == pytest.approx(-0.1 / falling.mean(), rel=1e-12) and value[1] == pytest.approx(0.0, abs=1e-12)
    assert value[2] == pytest.approx(abs(value[0]), rel=1e-12)  # the steady one is closer to constant


def test_the_few_spot_loads_are_those_below_the_first_with_many_spots():
    from types import SimpleNamespace

    from frictionlab.exact3d.evidence import MANY_SPOTS, few_spots

    spots = np.array([[1, 3, 8, 30, 80, 40, 5.0]] * 2)  # merging again at the largest loads: not "few"
    force = np.geomspace(1, 1000, 7)
    area = 1e-4 * force ** (2 / 3) + np.zeros((2, 1))
    e = SimpleNamespace(outcome=SimpleNamespace(force=force, per_realization={"contact_spots": spots, "real_area_corrected": area}))
    s = few_spots(e)
    np.testing.assert_array_equal(s.few, [True, True, True, False, False, False, False])
    assert MANY_SPOTS == 10
    np.testing.assert_allclose(s.exponent, 2 / 3, rtol=1e-12)
    e.outcome.per_realization["contact_spots"] = np.full((2, 7), np.nan)  # a run from before spots were counted
    assert few_spots(e) is None
