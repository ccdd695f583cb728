"""The trade-off study (``frictionlab study``): its axes, metrics, outputs and CLI.

Tiny scenes throughout; ``mdr-bisection`` stands in for the exact reference where
the machinery is tested (it solves the same springs as ``mdr`` by another route,
so their agreement is a known answer), and ``bem-halfplane`` is used once it is
installed.
"""

import csv
import itertools
import math

import matplotlib.image
import numpy as np
import pytest
import yaml
from scipy.optimize import brentq

from frictionlab.cli import main
from frictionlab.errors import ExitCode, FrictionlabError
from frictionlab.registry import Registry
from frictionlab.seeds import realization_rng
from frictionlab.study import report
from frictionlab.study.axes import AXES, COLUMNS, Study, StudyOptions
from frictionlab.study.metrics import curve_errors, interval_half_width, pareto_front
from frictionlab.study.scenes import SceneFactory

# A small line whose preset gives `spacing` (not `length`): shrinking N shortens the
# line, so keeping the f range needs the loads rescaled.
TINY = {
    "name": "tiny",
    "seed": 11,
    "realizations": 8,
    "spectrum": {"name": "power-law", "params": {"hurst": 0.8, "points": 256, "spacing": 1.0, "rms_height": 2.0}},
    "solver": {"name": "mdr", "params": {"youngs_modulus": 3.0, "poisson_ratio": 0.3}},
    "loading": {"start": 1.0, "stop": 60.0, "steps": 12, "spacing": "log"},
    "fit": {"bootstrap": 100},
}

TINY_OPTIONS = dict(
    reference="mdr-bisection",
    grid_factors=(0.5, 1, 2),
    grid_realizations=4,
    realizations_min=2,
    step_levels=(3, 6),
    compare_points=128,
    compare_realizations=4,
    compare_steps=8,
    tolerances=(1e-2, 1e-9),
)


@pytest.fixture(scope="module")
def builtins():
    return Registry(discover=False)


def study_of(data, registry, **options):
    return Study(SceneFactory(data, registry, "test"), StudyOptions(**{**TINY_OPTIONS, **options}))


@pytest.fixture(scope="module")
def tiny_study(builtins):
    study = study_of(TINY, builtins)
    study.run()
    return study


def by_axis(study, axis):
    return [r for r in study.rows if r.axis == axis]


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


# ------------------------------------------------------------------ outputs


def test_outputs_are_written_and_parse(tiny_study, tmp_path):
    text = report.recommendation(tiny_study)
    assert text.startswith("for 2% error in b at H = 0.8: mdr needs N = ")
    files = report.write_outputs(tiny_study, tmp_path, text, command="frictionlab study x.yaml")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.csv", "study.md", "study.png"]
    with open(files["csv"], newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == COLUMNS and len(rows) == len(tiny_study.rows)
    for parsed, row in zip(rows, tiny_study.rows):
        assert parsed["axis"] == row.axis and float(parsed["seconds"]) == row.seconds
        assert parsed["b_err"] == ("" if math.isnan(row.b_err) else repr(row.b_err))
    markdown = files["md"].read_text()
    for axis in AXES:
        assert f"## {axis}\n\n| " in markdown
    table_lines = [line for line in markdown.splitlines() if line.startswith("| ") and not line.startswith("| N ")]
    assert sum(1 for line in table_lines if line[2].isdigit() or line.startswith("| **") or line[2:5] in ("mdr", "win")) >= len(tiny_study.rows)
    assert text in markdown and "`frictionlab study x.yaml`" in markdown
    image = matplotlib.image.imread(files["png"])
    assert image.ndim == 3 and image.shape[0] > 100


def test_a_failed_write_leaves_no_partial_file(tiny_study, tmp_path, monkeypatch):
    def broken(study, fh):
        fh.write(b"\x89PNG half")
        raise RuntimeError("disk full")

    monkeypatch.setattr(report, "plot", broken)
    with pytest.raises(RuntimeError):
        report.write_outputs(tiny_study, tmp_path, "text")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.csv"]  # written before; no png, no temp file


# ------------------------------------------------------------------ CLI


def write(tmp_path, data):
    path = tmp_path / "preset.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_cli_runs_a_study_and_prints_the_recommendation(tmp_path, capsys):
    preset = write(tmp_path, TINY)
    out = tmp_path / "study"
    code = main([
        "study", str(preset), "--out", str(out), "--reference", "mdr-bisection", "--points", "128",
        "--compare-realizations", "3", "--compare-steps", "5", "--grid-realizations", "3",
        "--grid-factors", "1,2", "--tolerances", "1e-3,1e-9", "--axes", "grid,solver,tolerance",
    ])
    captured = capsys.readouterr()
    assert code == ExitCode.OK, captured.err
    assert captured.out.startswith("for 2% error in b at H = 0.8: mdr needs N = 256")
    assert "study: grid" in captured.err and "study: solver" in captured.err
    assert {p.name for p in out.iterdir()} == {"study.csv", "study.md", "study.png"}
    assert "--reference mdr-bisection" in (out / "study.md").read_text()


@pytest.mark.parametrize(
    "args, message",
    [
        (["--reference", "bem-nowhere"], "--reference: no solver plugin named 'bem-nowhere'"),
        (["--axes", "grid,speed"], "--axes must name some of grid, realizations, steps, solver, tolerance"),
        (["--target", "2"], "--target must be > 0 and < 1"),
        (["--tolerances", "1e-3,abc"], "--tolerances must be a comma-separated list of numbers"),
        (["--grid-factors", "1,-2"], "--grid-factors values must be > 0. Got -2.0 instead."),
        (["--points", "4"], "--points must be >= 8. Got 4 instead."),
        (["--set", "spectrum.params.hurst=7"], "spectrum.params.hurst: must be <= 1.5"),
    ],
)
def test_cli_usage_errors_name_the_option(tmp_path, capsys, args, message):
    code = main(["study", str(write(tmp_path, TINY)), "--out", str(tmp_path / "o"), *args])
    err = capsys.readouterr().err
    assert code == ExitCode.USAGE
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_cli_bad_preset_file(tmp_path, capsys):
    (tmp_path / "bad.yaml").write_text("name: [unclosed\n")
    assert main(["study", str(tmp_path / "bad.yaml")]) == ExitCode.USAGE
    assert "not valid YAML" in capsys.readouterr().err
    assert main(["study", str(tmp_path / "missing.yaml")]) == ExitCode.INPUT_FILE
    assert "no such preset file" in capsys.readouterr().err


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
    assert any("every solver sees the same surfaces (mdr presses their MDR-equivalent lines)" in n for n in study.notes)
