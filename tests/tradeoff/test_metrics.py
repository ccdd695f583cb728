"""The trade-off study's metrics: curve errors, the Pareto front against brute force."""


import math

import numpy as np
import pytest

from frictionlab.tradeoff.metrics import curve_errors, interval_half_width, pareto_front

# ------------------------------------------------------------------ metrics


def brute_force_front(cost, error):
    n = len(cost)
    front = []
    for i in range(n):
        dominated = any(
            cost[j] <= cost[i] and error[j] <= error[i] and (cost[j] < cost[i] or error[j] < error[i])
            for j in range(n)
        )
        front.append(not dominated)
    return np.array(front)


def test_pareto_front_matches_brute_force_with_ties():
    rng = np.random.default_rng(5)
    for _ in range(200):
        n = int(rng.integers(1, 12))
        cost = rng.integers(1, 6, n).astype(float)  # few distinct values: many ties and duplicates
        error = rng.integers(1, 6, n).astype(float)
        np.testing.assert_array_equal(pareto_front(cost, error), brute_force_front(cost, error))


def test_pareto_front_of_a_hand_made_set():
    cost = [1.0, 2.0, 3.0, 2.5, 0.5, np.nan, 4.0]
    error = [0.5, 0.2, 0.1, 0.3, 0.9, 0.01, 0.1]
    assert pareto_front(cost, error).tolist() == [True, True, True, False, True, False, False]


def test_curve_errors_on_one_axis_and_across_axes():
    x_ref = np.geomspace(1e-3, 1e-1, 9)
    xi_ref = 1 + 0.1 * np.log(x_ref)
    assert curve_errors(x_ref, xi_ref, x_ref, xi_ref) == (0.0, 0.0, 9)
    # 10% above the reference, sampled on another, wider grid: linear in ln x, so interpolation is exact.
    x = np.geomspace(5e-4, 0.2, 40)
    rms, bias, n = curve_errors(x, 1.1 * (1 + 0.1 * np.log(x)), x_ref, xi_ref)
    assert n == 9 and rms == pytest.approx(0.1, rel=1e-9) and bias == pytest.approx(0.1, rel=1e-9)
    # Only part of the reference range covered: compared there only.
    _, _, n = curve_errors(x_ref[:4], xi_ref[:4], x_ref, xi_ref)
    assert n == 4
    rms, bias, n = curve_errors([1.0, 2.0], [1.0, 1.0], x_ref, xi_ref)
    assert n == 0 and math.isnan(rms) and math.isnan(bias)
    assert interval_half_width((0.9, 1.3), 1.0) == pytest.approx(0.2)
