"""The fit xi = a + b ln f against exact data, numpy's polyfit and bootstrap coverage."""

import math
import os

import numpy as np
import pytest

from frictionlab.compute.fit import defined_mean, fit_log_law, least_squares, percentile_interval, resample_counts


def drawn_counts(seed: int, realizations: int, resamples: int) -> np.ndarray:
    """The bootstrap's draws, by hand: each resample picks ``realizations`` of them uniformly,
    with replacement, and counts how often it picked each."""
    picks = np.random.default_rng(seed).integers(0, realizations, size=(resamples, realizations))
    return np.array([np.bincount(row, minlength=realizations) for row in picks])


def test_exact_log_law_is_recovered_exactly():
    f = np.geomspace(1e-3, 10, 30)
    xi = 2.5 + 0.13 * np.log(f)
    coef, se, r2, rms = least_squares(f, xi)
    assert coef == pytest.approx([2.5, 0.13], rel=1e-12)
    assert r2 == pytest.approx(1.0, abs=1e-12)
    assert rms < 1e-13
    assert np.all(se < 1e-12)


def test_standard_errors_match_numpy_polyfit_covariance():
    rng = np.random.default_rng(3)
    f = np.linspace(1, 20, 50)
    xi = 1.8 + 0.08 * np.log(f) + rng.normal(0, 0.01, f.size)
    coef, se, r2, _ = least_squares(f, xi)
    poly, cov = np.polyfit(np.log(f), xi, 1, cov=True)  # scaled by ssr / (n - 2)
    assert coef == pytest.approx(poly[::-1], rel=1e-10)
    assert se == pytest.approx(np.sqrt(np.diag(cov))[::-1], rel=1e-8)
    residual = xi - np.polyval(poly, np.log(f))
    assert r2 == pytest.approx(1 - residual @ residual / ((xi - xi.mean()) ** 2).sum(), rel=1e-12)


def test_bootstrap_interval_covers_the_truth_at_about_its_level():
    """Realizations with random offsets and slopes around (a, b): the 90% bootstrap
    intervals of the mean must contain the true a, and the true b, in roughly 90% of ensembles."""
    f = np.geomspace(0.1, 10, 20)
    a, b, hits, b_hits, trials = 2.0, 0.1, 0, 0, 200
    rng = np.random.default_rng(11)
    for _ in range(trials):
        m = 40
        offsets = rng.normal(0, 0.2, (m, 1))
        slopes = rng.normal(0, 0.05, (m, 1))
        xi = a + offsets + (b + slopes) * np.log(f) + rng.normal(0, 0.02, (m, f.size))
        fit = fit_log_law(f, xi, bootstrap=300, confidence=0.9, rng=rng)
        hits += fit.a_ci[0] <= a <= fit.a_ci[1]
        b_hits += fit.b_ci[0] <= b <= fit.b_ci[1]
    # binomial(200, 0.9) has sd 4.2 hits; percentile bootstrap undercovers a little at m = 40
    assert 0.8 <= hits / trials <= 0.97
    assert 0.8 <= b_hits / trials <= 0.97


def test_the_standard_errors_shown_are_the_spread_between_lines_not_the_fit_s_residuals():
    """Lines each on an exact log law of their own, a_i + b_i ln f: the mean curve is an exact log
    law, so the least-squares errors over the force grid are 0, while a and b are known only to
    std(a_i) / sqrt(M) and std(b_i) / sqrt(M). The table showed the former ('std.err 0.0228'
    beside an interval 0.23 wide); it shows the bootstrap's, which estimates the latter."""
    f = np.geomspace(0.1, 10, 25)
    rng = np.random.default_rng(4)
    m = 400
    a_i, b_i = 1.2 + rng.normal(0, 0.3, m), 0.05 + rng.normal(0, 0.04, m)
    xi = a_i[:, None] + b_i[:, None] * np.log(f)
    fit = fit_log_law(f, xi, bootstrap=2000, rng=np.random.default_rng(1))
    assert fit.a_se < 1e-12 and fit.b_se < 1e-12  # the fit's own: the mean curve is exact
    truth = np.std(a_i, ddof=1) / math.sqrt(m), np.std(b_i, ddof=1) / math.sqrt(m)
    assert fit.a_se_bootstrap == pytest.approx(truth[0], rel=0.08)  # a bootstrap of 2000: a few per cent
    assert fit.b_se_bootstrap == pytest.approx(truth[1], rel=0.08)
    assert fit.standard_errors == (fit.a_se_bootstrap, fit.b_se_bootstrap)
    # no bootstrap, or one curve resampled (no spread between lines): the least-squares ones are shown
    noisy = xi + rng.normal(0, 0.01, xi.shape)
    for without in (fit_log_law(f, noisy, bootstrap=0), fit_log_law(f, np.vstack([noisy[0]] * 5), bootstrap=200,
                                                                       rng=np.random.default_rng(2))):  # fmt: skip
        assert math.isnan(without.a_se_bootstrap) and without.standard_errors == (without.a_se, without.b_se) > (0, 0)


def test_bootstrap_is_reproducible_and_brackets_the_estimate():
    rng = np.random.default_rng(5)
    f = np.linspace(1, 20, 40)
    xi = 1.5 + 0.06 * np.log(f) + rng.normal(0, 0.05, (30, f.size))
    one = fit_log_law(f, xi, bootstrap=400, rng=np.random.default_rng(9))
    two = fit_log_law(f, xi, bootstrap=400, rng=np.random.default_rng(9))
    assert one == two
    assert one.a_ci[0] < one.a < one.a_ci[1]
    assert one.b_ci[0] < one.b < one.b_ci[1]


def test_no_bootstrap_with_one_realization_or_zero_resamples():
    f = np.linspace(1, 2, 5)
    single = fit_log_law(f, np.log(f)[None, :], bootstrap=100, rng=np.random.default_rng(0))
    assert single.bootstrap == 0 and math.isnan(single.a_ci[0])
    none = fit_log_law(f, np.vstack([np.log(f)] * 3), bootstrap=0)
    assert math.isnan(none.b_ci[1])
    assert none.to_dict()["b_ci"] == [None, None]  # JSON has no NaN


def test_one_bootstrap_resample_is_refused_as_no_interval(capsys):
    """fit.bootstrap: 1 printed a '95% CI [1.0868, 1.0868]' of no width beside a = 1.1275: one
    resample's numbers called an interval. 0 (none) and 2 or more are taken."""
    import frictionlab
    from frictionlab.cli import main
    from frictionlab.errors import ExitCode, PresetError

    assert main(["validate", "quickstart", "--set", "fit.bootstrap=1"]) == ExitCode.USAGE
    assert "fit.bootstrap: must be 0 (no intervals) or at least 2: one resample gives an interval of one point, not " \
           "a spread, got 1" in capsys.readouterr().err
    with pytest.raises(PresetError, match="fit.bootstrap: must be 0"):
        frictionlab.validate("quickstart", {"fit.bootstrap": 1})
    for bootstrap in (0, 2):
        assert main(["validate", "quickstart", "--set", f"fit.bootstrap={bootstrap}"]) == ExitCode.OK


@pytest.mark.parametrize(
    "f, message",
    [(np.array([0.0, 1.0, 2.0]), "f must be finite and > 0"), (np.array([1.0, 1.0, 1.0]), "two distinct forces")],
)
def test_bad_force_grids_are_refused(f, message):
    with pytest.raises(ValueError, match=message):
        least_squares(f, np.ones_like(f))


def test_bootstrap_equals_refitting_every_resampled_mean_curve():
    """Brute force: draw the same resamples, average the curves, refit each one."""
    rng = np.random.default_rng(8)
    f = np.geomspace(0.5, 20, 25)
    xi = 1.2 + 0.05 * np.log(f) + rng.normal(0, 0.1, (12, f.size))
    fit = fit_log_law(f, xi, bootstrap=200, confidence=0.8, rng=np.random.default_rng(4))
    counts = drawn_counts(4, 12, 200)
    refits = np.array([least_squares(f, c @ xi / 12)[0] for c in counts])
    low, high = np.percentile(refits, [10, 90], axis=0)
    assert fit.a_ci == pytest.approx((low[0], high[0]), rel=1e-12)
    assert fit.b_ci == pytest.approx((low[1], high[1]), rel=1e-12)


def _undefined_at_low_forces(rng, lines=12, forces=25):
    """Per-line curves where some lines have no xi (NaN) at the first forces (their contact had no slope)."""
    f = np.geomspace(0.5, 20, forces)
    xi = 1.2 + 0.05 * np.log(f) + rng.normal(0, 0.1, (lines, forces))
    for line, first_defined in ((0, 3), (4, 6), (7, 1), (9, 25)):  # line 9: xi nowhere defined
        xi[line, :first_defined] = np.nan
    return f, xi


def test_undefined_xi_is_left_out_of_the_mean_the_fit_and_every_resample():
    """Brute force: at each force the mean over the lines whose xi is defined; each resample
    the same, with the resampled counts as weights; every resample here has a defined xi at
    every force (line 0 etc. are undefined at a few forces only, most lines everywhere)."""
    from frictionlab.compute.ensemble import defined_statistics

    f, xi = _undefined_at_low_forces(np.random.default_rng(8))
    mean, sem, used = defined_statistics(xi)
    for j in range(f.size):
        values = [v for v in xi[:, j] if not math.isnan(v)]
        assert used[j] == len(values)
        assert mean[j] == pytest.approx(sum(values) / len(values), rel=1e-13)
        assert sem[j] == pytest.approx(np.std(values, ddof=1) / math.sqrt(len(values)), rel=1e-12)
    assert used[0] == 8 and used[-1] == 11
    fit = fit_log_law(f, xi, bootstrap=200, confidence=0.8, rng=np.random.default_rng(4))
    assert (fit.a, fit.b) == pytest.approx(tuple(least_squares(f, mean)[0]), rel=1e-12)
    counts = drawn_counts(4, 12, 200)
    refits = []
    for c in counts:
        curve = [sum(c[i] * xi[i, j] for i in range(12) if not math.isnan(xi[i, j]))
                 / sum(c[i] for i in range(12) if not math.isnan(xi[i, j])) for j in range(f.size)]  # fmt: skip
        refits.append(least_squares(f, np.array(curve))[0])
    low, high = np.percentile(refits, [10, 90], axis=0)
    assert fit.a_ci == pytest.approx((low[0], high[0]), rel=1e-12)
    assert fit.b_ci == pytest.approx((low[1], high[1]), rel=1e-12)


def test_a_force_where_no_line_has_xi_is_left_out_of_the_fit():
    f, xi = _undefined_at_low_forces(np.random.default_rng(9))
    xi[:, :2] = np.nan
    fit = fit_log_law(f, xi, bootstrap=50, rng=np.random.default_rng(1))
    assert fit.points == f.size - 2
    kept = fit_log_law(f[2:], xi[:, 2:], bootstrap=50, rng=np.random.default_rng(1))
    assert (fit.a, fit.b, fit.a_ci, fit.b_ci) == (kept.a, kept.b, kept.a_ci, kept.b_ci)


@pytest.mark.parametrize("samples", [1, 2, 3, 7, 40, 1000])
@pytest.mark.parametrize("confidence", [0.0, 0.5, 0.683, 0.9, 0.95, 0.99, 1.0])
def test_percentile_interval_is_numpys_percentile_bit_for_bit(samples, confidence):
    rng = np.random.default_rng(samples)
    tail = 100 * (1 - confidence) / 2
    pairs = rng.normal(size=(samples, 2))
    expected = np.percentile(pairs, [tail, 100 - tail], axis=0)
    np.testing.assert_array_equal(percentile_interval(pairs, confidence, axis=0), expected)
    flat = rng.lognormal(size=samples)
    np.testing.assert_array_equal(percentile_interval(flat, confidence), np.percentile(flat, [tail, 100 - tail]))
    pairs[rng.integers(samples), 1] = np.nan  # a NaN makes its column's bounds NaN, as numpy's
    np.testing.assert_array_equal(
        percentile_interval(pairs, confidence, axis=0), np.percentile(pairs, [tail, 100 - tail], axis=0)
    )


def test_a_fit_runs_blas_on_its_own_thread_only_and_leaves_the_limit_as_it_was():
    """OpenBLAS's helper threads, once woken by a product, spin for ~0.1 s of a core: on a
    machine with as many cores as workers that is taken from the workers after every fit."""
    from threadpoolctl import threadpool_info

    def blas_threads():
        return [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"]

    before = blas_threads()
    seen = []

    def average(weights):  # the fit's own average, heard from inside the fit's products
        seen.append(blas_threads())
        return defined_mean(xi, weights)

    f = np.linspace(1.0, 20.0, 40)
    xi = 1.0 + 0.1 * np.log(f) + 0.01 * np.random.default_rng(3).standard_normal((30, 40))
    fit = fit_log_law(f, xi, bootstrap=200, rng=np.random.default_rng(4), average=average)
    assert seen and all(threads == [1] * len(before) for threads in seen)
    assert blas_threads() == before  # restored for the rest of the program
    plain = fit_log_law(f, xi, bootstrap=200, rng=np.random.default_rng(4))
    np.testing.assert_allclose([fit.a, fit.b, *fit.a_ci, *fit.b_ci], [plain.a, plain.b, *plain.a_ci, *plain.b_ci], rtol=1e-12)


def test_a_blas_library_loaded_after_the_first_fit_is_limited_too():
    """scipy brings an OpenBLAS of its own. The fit's controller of the BLAS libraries was made
    once, at the first fit: a library loaded later (scipy imported after it, as a run's solver
    or the TUI does) ran the fit's products on all its threads. In a fresh process: a fit, then
    scipy.linalg imported, then a fit that hears the BLAS thread counts from inside it."""
    script = """
import json, numpy as np
from threadpoolctl import threadpool_info
from frictionlab.compute.fit import fit_log_law, defined_mean
f = np.linspace(1.0, 20.0, 40)
xi = 1.0 + 0.1 * np.log(f) + 0.01 * np.random.default_rng(3).standard_normal((30, 40))
fit_log_law(f, xi, bootstrap=20, rng=np.random.default_rng(4))
import scipy.linalg
libraries = [lib for lib in threadpool_info() if lib["user_api"] == "blas"]
seen = []
def average(weights):
    seen.append([lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"])
    return defined_mean(xi, weights)
fit_log_law(f, xi, bootstrap=20, rng=np.random.default_rng(4), average=average)
print(json.dumps({"libraries": len(libraries), "seen": seen}))
"""
    import json
    import subprocess
    import sys

    env = {**os.environ, "OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2"}  # more than one thread to limit
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, check=True)
    heard = json.loads(done.stdout.strip().splitlines()[-1])
    assert heard["seen"] and all(threads == [1] * heard["libraries"] for threads in heard["seen"])


@pytest.mark.parametrize(("averaged", "realizations", "forces"), [(False, 2000, 12), (True, 2000, 12), (True, 20, 2000)])
def test_the_bootstrap_forms_its_counts_a_block_at_a_time_with_the_draws_of_one_call(
    monkeypatch, averaged, realizations, forces
):
    """The counts of every resample and realization (B x M int64), and under an average each resample's
    curve (B x forces), were formed at once, after the run: a bootstrap of 100,000 over 10,000
    realizations needed 7.5 GiB and failed there under a 2 GiB limit. They now come in blocks (of a
    1 MiB budget here), the same draws as one call, the same pairs."""
    import tracemalloc

    from frictionlab.compute import fit

    monkeypatch.setattr(fit, "BOOTSTRAP_BLOCK_BYTES", 2**20, raising=False)
    resamples = 1000  # drawn whole: 16 MB of counts or curves, and as much again in float
    f = np.geomspace(1e-3, 1e-1, forces)
    xi = np.random.default_rng(0).normal(0.5, 0.1, size=(realizations, f.size))
    average = (lambda weights: defined_mean(xi, weights)) if averaged else None
    tracemalloc.start()
    try:
        pairs = fit.bootstrap_coefficients(f, xi, resamples, np.random.default_rng(3), average)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 6 * 2**20, peak
    counts = drawn_counts(3, realizations, resamples)
    projector = np.linalg.pinv(np.column_stack([np.ones(f.size), np.log(f)]))
    whole = (defined_mean(xi, counts) if averaged else counts @ xi / realizations) @ projector.T
    np.testing.assert_allclose(pairs, whole, rtol=1e-10, atol=1e-13)


@pytest.mark.parametrize("resamples, confidence, said", [(1, 0.95, True), (39, 0.95, True), (40, 0.95, False),
                                                         (19, 0.9, True), (20, 0.9, False), (0, 0.95, False)])
def test_intervals_from_too_few_resamples_for_both_tails_carry_a_caveat(resamples, confidence, said):
    """A percentile interval at confidence c leaves (1 - c) / 2 of the resamples in each tail: under
    2 / (1 - c) of them a tail holds none; with 1 the interval is that resample, which may not hold
    the estimate (0: no intervals, nothing to say)."""
    from frictionlab.compute.ensemble import few_resamples_caveat

    rng = np.random.default_rng(3)
    f = np.geomspace(1, 20, 12)
    xi = 1.0 + 0.05 * np.log(f) + 0.02 * rng.standard_normal((30, f.size))
    fit = fit_log_law(f, xi, bootstrap=resamples, confidence=confidence, rng=np.random.default_rng(1))
    caveat = few_resamples_caveat(fit)
    assert (caveat is not None) == said
    if said:
        assert f"rest on {resamples} bootstrap" in caveat and f"fewer than {round(2 / (1 - confidence))}" in caveat
    if resamples == 1:  # what the caveat warns of: one resample's interval is a point
        assert fit.a_ci[0] == fit.a_ci[1]


def test_a_run_with_too_few_resamples_says_so_in_its_caveats():
    import frictionlab

    from .conftest import SMALL_PRESET, merge

    few = frictionlab.run(merge(SMALL_PRESET, {"fit": {"bootstrap": 5}}), workers=1, progress=False)
    enough = frictionlab.run(merge(SMALL_PRESET, {"fit": {"bootstrap": 40}}), workers=1, progress=False)
    assert any("rest on 5 bootstrap" in c for c in few.caveats)
    assert not any("bootstrap resample" in c for c in enough.caveats)


def test_resample_counts_are_multinomial_with_equal_chances():
    """Each resample draws M realizations with replacement: its counts sum to M, and over many
    resamples each count has the multinomial's mean 1 and variance 1 - 1/M, and two realizations'
    counts the covariance -1/M."""
    realizations, resamples = 10, 40_000
    counts = resample_counts(np.random.default_rng(11), realizations, resamples)
    assert counts.shape == (resamples, realizations) and counts.min() >= 0
    assert (counts.sum(axis=1) == realizations).all()
    sigma = math.sqrt((1 - 1 / realizations) / resamples)  # of a mean count
    assert np.abs(counts.mean(axis=0) - 1).max() < 5 * sigma
    covariance = np.cov(counts, rowvar=False)
    assert np.diag(covariance) == pytest.approx(np.full(realizations, 1 - 1 / realizations), abs=0.05)
    off = covariance[~np.eye(realizations, dtype=bool)]
    assert off == pytest.approx(np.full(off.size, -1 / realizations), abs=0.03)
