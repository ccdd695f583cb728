"""The axes of the trade-off study: measured rows, references, errors against known limits."""


import itertools
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from frictionlab.errors import FrictionlabError
from frictionlab.preset.seeds import realization_rng
from frictionlab.tradeoff.axes import Study
from frictionlab.tradeoff.options import AXES, StudyOptions
from frictionlab.tradeoff.scenes import SceneFactory

from .conftest import TINY, by_axis, study_of

# ------------------------------------------------------------------ axes


def test_every_axis_gives_measured_rows_and_one_reference(tiny_study):
    for axis in AXES:
        rows = by_axis(tiny_study, axis)
        assert rows, axis
        assert all(r.seconds > 0 and r.peak_bytes > 0 for r in rows), axis
        expected_references = 0 if axis == "realizations" else 1
        assert sum(r.reference for r in rows) == expected_references, axis
    assert [r.value for r in by_axis(tiny_study, "grid")] == [128, 256, 512]
    assert [r.value for r in by_axis(tiny_study, "realizations")] == [2, 4, 8]
    assert [r.value for r in by_axis(tiny_study, "steps")] == [3, 6, 12]
    assert [r.tolerance for r in by_axis(tiny_study, "tolerance")] == [1e-2, 1e-9]
    for axis in ("grid", "steps", "solver", "tolerance"):
        reference = next(r for r in by_axis(tiny_study, axis) if r.reference)
        assert reference.a_err == 0 and reference.b_err == 0, axis


def test_mdr_agrees_with_the_bisection_reference_on_the_same_lines(tiny_study):
    # Same springs solved by a sort and by bisection (contact counts exact for any tolerance): the same
    # xi(f), the same indentation to the bisection's tolerance; the springs' fraction is named as such.
    rows = {r.solver: r for r in by_axis(tiny_study, "solver")}
    assert set(rows) == {"mdr", "mdr-bisection"}
    assert rows["mdr-bisection"].reference and rows["mdr-bisection"].tolerance == 1e-9
    mdr = rows["mdr"]
    assert mdr.xi_err_f < 1e-12 and mdr.b_err < 1e-9 and mdr.approach_err_f < 1e-6
    assert math.isnan(mdr.real_area_first) and 0 < mdr.mdr_springs_first < mdr.mdr_springs_last < 1
    # the indentation from the mean plane: the springs' indentation less their mean compression f h
    outcome = mdr.outcome
    expected = (outcome.indentation - outcome.f * outcome.rms_height) / outcome.rms_height
    assert (mdr.approach_first, mdr.approach_last) == pytest.approx((expected[0], expected[-1]), rel=1e-12)
    for row in by_axis(tiny_study, "tolerance"):
        assert row.xi_err_f < 1e-12


def test_the_comparison_scene_keeps_the_presets_f_range(tiny_study):
    full = by_axis(tiny_study, "realizations")[-1].outcome
    reduced = next(r for r in by_axis(tiny_study, "solver") if r.reference)
    assert reduced.points == 128 and reduced.steps == 8 and reduced.realizations == 4
    # N halved at fixed spacing halves L: the loads were halved to keep f = F / (E* h L).
    np.testing.assert_allclose(reduced.outcome.f[[0, -1]], full.f[[0, -1]], rtol=1e-12)
    np.testing.assert_allclose(reduced.outcome.loads[[0, -1]], [0.5, 30.0], rtol=1e-12)


def test_refining_at_fixed_length_and_cut_offs_samples_the_same_line(builtins):
    factory = SceneFactory(TINY, builtins, "test")
    study = Study(factory, StudyOptions(reference="mdr-bisection", grid_factors=(1, 2), axes=("grid",)))
    study.run()
    coarse, fine = (factory.make({"spectrum.params.points": n, "spectrum.params.length": 256.0,
                                  "spectrum.params.spacing": None, "spectrum.params.short_cutoff": 10.0})
                    for n in (256, 512))
    line = coarse.spectrum.generate(realization_rng(11, 3)).heights
    finer = fine.spectrum.generate(realization_rng(11, 3)).heights
    np.testing.assert_allclose(finer[::2], line, atol=1e-12 * np.abs(line).max())
    assert any("held fixed" in note for note in study.notes)


def cosine_xi(f: float) -> float:
    """Continuum MDR answer for z = a cos(q x) (one period, h = a / sqrt(2)): contact
    |q x| < t carries F = 2 E* a (sin t - t cos t) / q, so f = sqrt(2) (sin t - t cos t) / pi,
    and xi = sqrt(1 - sin(2t) / (2t))."""
    t = brentq(lambda t: math.sqrt(2) * (math.sin(t) - t * math.cos(t)) / math.pi - f, 1e-9, math.pi)
    return math.sqrt(1 - math.sin(2 * t) / (2 * t))


def test_grid_error_is_zero_at_the_reference_and_falls_toward_the_known_limit(builtins):
    # A band with one mode: every realization is a cosine of random phase, whose
    # continuum xi(f) is known in closed form.
    cosine = {
        **TINY,
        "realizations": 2,
        "spectrum": {"name": "power-law", "params": {
            "hurst": 0.8, "points": 32, "length": 64.0, "long_cutoff": 64.0, "short_cutoff": 40.0}},
        "loading": {"start": 0.01, "stop": 0.4, "steps": 30, "spacing": "log"},
        "fit": {"bootstrap": 0},
    }
    study = study_of(cosine, builtins, axes=("grid",), grid_factors=(1, 2, 4, 8, 16, 32))
    rows = study.run()
    errors = [r.xi_err_f for r in rows]
    assert errors[-1] == 0 and rows[-1].reference
    assert all(coarse > fine for coarse, fine in itertools.pairwise(errors)), errors
    finest = rows[-1].outcome
    exact = np.array([cosine_xi(f) for f in finest.f])
    assert np.sqrt(np.mean((finest.xi / exact - 1) ** 2)) < 0.015  # the reference is near the continuum
    assert errors[0] > 0.2  # 32 points: the coarse grid is visibly off


def test_statistical_error_shrinks_like_one_over_sqrt_m(builtins):
    data = {**TINY, "realizations": 256, "spectrum": {"name": "power-law", "params": {
        "hurst": 0.8, "points": 512, "rms_height": 1.0}}, "fit": {"bootstrap": 400}}
    study = study_of(data, builtins, axes=("realizations",), realizations_min=8)
    rows = study.run()
    m = np.array([r.value for r in rows])
    assert list(m) == [8, 16, 32, 64, 128, 256]
    for metric in ("b_ci_rel", "xi_ci_rel"):
        width = np.array([getattr(r, metric) for r in rows])
        slope = np.polyfit(np.log(m), np.log(width), 1)[0]
        assert -0.75 < slope < -0.3, (metric, slope)  # 1/sqrt(M): -0.5
        assert 2.0 < width[1] / width[-1] < 8.0  # 16x the lines: 4x narrower


def test_a_reference_must_solve_the_same_problem_on_the_presets_geometry(builtins):
    with pytest.raises(FrictionlabError, match="--reference: bem-halfplane solves the elastic half-plane "
                                               r"\(plane strain\), but the preset's solver mdr the elastic half-space"):
        study_of(TINY, builtins, reference="bem-halfplane")
    with pytest.raises(FrictionlabError, match="--reference: winkler solves the Winkler foundation"):
        study_of(TINY, builtins, reference="winkler")
    with pytest.raises(FrictionlabError, match="--reference: bem-halfspace cannot run the preset: solver.name: "
                                               "bem-halfspace presses surfaces only"):
        study_of(TINY, builtins, reference="bem-halfspace")


def test_mdr_on_lines_has_no_exact_reference_and_says_where_to_find_one(builtins):
    study = study_of(TINY, builtins, reference=None, axes=("steps", "solver", "tolerance"))
    assert study.reference_choice is None
    study.run()
    assert {r.axis for r in study.rows} == {"steps"}
    assert any("bem-halfspace, presses an isotropic surface" in note for note in study.notes)


# ------------------------------------------------------------------ the exact reference

SURFACE = {
    **TINY,
    "realizations": 3,
    "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 32, "rms_height": 1.0, "short_cutoff": 4.0}},
    "loading": {"start": 0.2, "stop": 2.0, "steps": 5, "spacing": "log"},
}


def test_mdr_against_the_elastic_half_space_on_the_same_surfaces(builtins):
    study = study_of(SURFACE, builtins, reference=None, axes=("solver", "tolerance"), compare_points_surface=32,
                     compare_realizations=3, compare_steps=5, tolerances=(1e-3, 1e-8))  # fmt: skip
    assert study.reference_choice["name"] == "bem-halfspace"  # the exact solver of MDR's problem
    study.run()
    solver = {r.solver: r for r in by_axis(study, "solver")}
    mdr, reference = solver["mdr"], solver["bem-halfspace"]
    assert reference.reference and reference.xi_err_f == 0 and reference.b_err == 0
    # one f axis: MDR's line is 2 sqrt(A / pi) long, the half-space's f uses that L
    np.testing.assert_allclose(mdr.outcome.f, reference.outcome.f, rtol=1e-12)
    assert math.isfinite(mdr.xi_err_f) and mdr.xi_err_f > 0 and math.isfinite(mdr.approach_err_f)
    # each contact measure in its own column; MDR's springs are not the real area
    assert math.isnan(mdr.real_area_first) and math.isnan(reference.mdr_springs_first)
    assert 0 < reference.real_area_first < reference.real_area_last < 1
    assert mdr.mdr_springs_first > reference.real_area_first
    tolerance = by_axis(study, "tolerance")
    tightest = next(r for r in tolerance if r.reference)
    assert tightest.tolerance == 1e-8 and tightest.xi_err_f == 0 and tightest.b_err == 0
    assert all(math.isfinite(r.xi_err_f) for r in tolerance)


def test_a_scan_is_compared_with_the_free_half_space_by_default(builtins, tmp_path):
    """A non-periodic measured surface: the periodic half-space refuses it, so the exact
    reference is the free-boundary one (it was bem-halfspace, and the study ended refused)."""
    heights = np.random.default_rng(0).standard_normal((24, 24)).cumsum(axis=0).cumsum(axis=1)
    np.save(tmp_path / "scan.npy", heights)
    scan = {**SURFACE, "spectrum": {"name": "surface-file", "params": {"path": str(tmp_path / "scan.npy"), "spacing": 1.0}}}
    study = study_of(scan, builtins, reference=None, axes=("solver",), compare_points_surface=24,
                     compare_realizations=1, compare_steps=5, tolerances=(1e-8,))  # fmt: skip
    assert study.reference_choice["name"] == "bem-halfspace-free"
    periodic = {**scan, "spectrum": {**scan["spectrum"], "params": {**scan["spectrum"]["params"], "periodic": True}}}
    assert study_of(periodic, builtins, reference=None, axes=("solver",), compare_points_surface=24,
                    compare_realizations=1, compare_steps=5, tolerances=(1e-8,)).reference_choice["name"] == "bem-halfspace"


def test_a_scan_study_compares_no_indentation_with_the_free_half_space_and_names_its_grid(builtins, tmp_path):
    """The free half-space measures its indentation from the undeformed body and its mean
    displacement differs from surface to surface: the study leaves the approach columns
    empty and says why, instead of comparing against an indentation shifted by nothing.
    A file's grid is its points per side (the longer side of a 20 x 24 map), never 0."""
    from frictionlab.tradeoff.outputs import recommendation, scene_summary

    heights = np.random.default_rng(1).standard_normal((20, 24)).cumsum(axis=0).cumsum(axis=1)
    np.save(tmp_path / "scan.npy", heights)
    scan = {**SURFACE, "spectrum": {"name": "surface-file", "params": {"path": str(tmp_path / "scan.npy"), "spacing": 1.0}}}
    study = study_of(scan, builtins, reference=None, axes=("solver",), compare_points_surface=24,
                     compare_realizations=1, compare_steps=5, tolerances=(1e-8,))  # fmt: skip
    study.run()
    rows = by_axis(study, "solver")
    assert {r.solver for r in rows} == {"mdr", "bem-halfspace-free"}
    assert all(r.points == 24 for r in rows)
    free, mdr = (next(r for r in rows if r.solver == name) for name in ("bem-halfspace-free", "mdr"))
    assert math.isnan(free.approach_first) and math.isnan(free.approach_last)
    assert math.isfinite(mdr.approach_first) and math.isfinite(mdr.approach_last)  # MDR knows its mean plane
    assert all(math.isnan(r.approach_err_f) for r in rows)
    assert all(math.isfinite(r.xi_err_f) for r in rows)  # xi is still compared
    assert any("indentations not compared: bem-halfspace-free" in note for note in study.notes)
    text = recommendation(study)
    assert "at N = 24" in text and "N = 0" not in text and "its indentation not compared" in text
    assert "N = 24 per side" in scene_summary(study)


@pytest.mark.parametrize("factors", [(1, 1), (0.5, 1, 1), (1, 1.0001)])
def test_a_grid_given_twice_is_run_once_not_taken_as_its_own_reference(builtins, factors):
    """Grid factors that give the same N (a factor listed twice, or two that round to one N)
    ran the same ensemble twice, and its copy, the reference, said the grid had no error:
    'frictionlab study quickstart --grid-factors 1,1' recommended 'N = 4096 (against N = 4096)'.
    Each N is run once, the repeat named in the notes, and the coarsest distinct grid keeps its
    error against the finest (none is measured where one grid is left)."""
    study = study_of(TINY, builtins, axes=("grid",), grid_factors=factors)
    rows = study.run()
    n = [row.value for row in rows]
    assert len(n) == len(set(n)) == len(set(round(256 * f) for f in factors)), n
    assert rows[-1].reference and sum(row.reference for row in rows) == 1
    assert any("gives N = 256 again; each grid is run once" in note for note in study.notes), study.notes


@pytest.mark.parametrize("factors", [(1, 1), (0.01, 1)])
def test_a_grid_axis_of_its_reference_alone_does_not_say_a_finer_grid_is_needed(builtins, factors):
    """The grid axis left with its reference only (a factor repeated, or the other one's N below
    the spectrum's least) compared nothing, yet the recommendation said 'N > 256 (not reached on
    the grid axis)', as if 256 had been measured and found too coarse."""
    from frictionlab.tradeoff.outputs import recommendation

    study = study_of(TINY, builtins, axes=("grid",), grid_factors=factors)
    assert len(study.run()) == 1
    said = recommendation(study)
    assert "not reached" not in said, said
    assert "an N the grid axis did not measure (it ran only its reference, N = 256: see the notes)" in said, said


def test_a_study_that_measured_nothing_says_why_on_the_terminal(builtins):
    """Every axis asked skipped (the solver axis of a preset of lines, which no exact solver
    presses): the recommendation, the one line the terminal shows, said only 'no axis
    measured enough to recommend anything', the reason left in study.md's notes."""
    from frictionlab.tradeoff.outputs import recommendation

    study = study_of(TINY, builtins, reference=None, axes=("solver",))
    study.run()
    assert study.rows == []
    said = recommendation(study)
    assert said.startswith("for 2% error in b at H = 0.8: no axis measured enough to recommend anything; solver, "
                           "tolerance: skipped: no installed solver solves"), said  # fmt: skip


def test_a_study_of_one_measured_line_recommends_one_realization(builtins, tmp_path):
    """Every realization of a profile read from a file is the same curve: its interval has no
    spread, and the study recommended the smallest M measured (M = 2 here) as if it had one.
    It says the ensemble is one surface and recommends M = 1; a random preset's study does not."""
    from frictionlab.tradeoff.outputs import recommendation

    np.save(tmp_path / "line.npy", np.random.default_rng(3).standard_normal(256).cumsum())
    scan = {**TINY, "spectrum": {"name": "profile-file", "params": {"path": str(tmp_path / "line.npy"), "spacing": 1.0}}}
    study = study_of(scan, builtins, axes=("realizations",))
    study.run()
    assert any("realizations: all 8 realizations gave the same curve" in note for note in study.notes), study.notes
    assert "M = 1 (every realization is the same surface)" in recommendation(study)
    random = study_of(TINY, builtins, axes=("realizations",))
    random.run()
    assert not random.one_surface and "same surface" not in recommendation(random)


@pytest.mark.parametrize("changes", [{"fit": {"bootstrap": 0}}, {"realizations": 1}])
def test_a_study_with_no_interval_of_b_recommends_no_realizations(builtins, changes):
    """fit.bootstrap 0 (or one realization) measures no interval of b: the study said 'M = 8
    (extrapolated as 1/sqrt(M) from M = 8)' and 'mdr-bisection needs M = 4', of no error at all."""
    from frictionlab.tradeoff.outputs import recommendation

    study = study_of({**TINY, **changes}, builtins, axes=("realizations", "solver"))
    study.run()
    said = recommendation(study)
    assert "extrapolated" not in said and "needs M =" not in said and "+-" not in said, said
    assert said.count("an unknown M (no interval of b at M = ") == 2, said
    assert "fit.bootstrap is 0, or there is a single realization" in said and "no interval of b from" in said, said
