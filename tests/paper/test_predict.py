"""The 3D law (the paper's, by MDR): closed form, the worked example, intervals, run folders, CLI."""

import json
import math

import numpy as np
import pytest

from frictionlab import mdr_length
from frictionlab.cli import main
from frictionlab.compute.fit import LogFit, percentile_interval
from frictionlab.errors import FrictionlabError
from frictionlab.options import RunOptions
from frictionlab.paper.predict import (
    bootstrap_pairs,
    dimensionless_force_3d,
    predict_xi,
    prediction_text,
    read_run_law,
)
from frictionlab.runs.runner import run_to_folder


def test_f_is_the_line_f_with_the_mdr_length():
    area, modulus, h, force = 3.7e-4, 2.1e6, 4e-7, 12.0
    length = 2 * math.sqrt(area / math.pi)
    assert mdr_length(area) == pytest.approx(length, rel=1e-15)
    expected = math.sqrt(math.pi) * force / (2 * modulus * h * math.sqrt(area))
    assert dimensionless_force_3d(force, modulus, h, area) == pytest.approx(expected, rel=1e-14)
    assert dimensionless_force_3d(force, modulus, h, area) == pytest.approx(force / (modulus * h * length), rel=1e-14)


def test_the_specs_worked_law():
    # the paper: grad_z_contact / grad_z = 2.9 + 0.14 ln( sqrt(pi) F / (2 E* h sqrt(A)) )
    kw = dict(modulus=1.0, rms_height=1e4, area=math.pi * 0.25e10)  # L = 1e5, so f = F * 1e-9
    p = predict_xi(LogFit(2.9, 0.14), force=7.0, **kw)
    assert p.f == pytest.approx(7e-9, rel=1e-12)
    assert p.xi == pytest.approx(2.9 + 0.14 * math.log(7e-9), rel=1e-12)
    # "a 500-fold force changes the rms slope in contact by a factor of 3 to 4": an additive
    # 0.14 ln 500 = 0.87, i.e. a factor 3 to 4 where xi(F) is 0.29 .. 0.435
    force = math.exp((0.3 - 2.9) / 0.14) / 1e-9  # xi(F) = 0.3
    low, high = predict_xi(LogFit(2.9, 0.14), force=force, **kw), predict_xi(LogFit(2.9, 0.14), force=500 * force, **kw)
    assert high.xi - low.xi == pytest.approx(0.14 * math.log(500), rel=1e-12)
    assert 3 <= high.xi / low.xi <= 4


def test_xi_above_one_warns_that_the_force_may_be_past_the_law():
    """xi = 1 at full contact: a law read past 1 says the force may be past where it holds,
    not that the contact is full (a mean xi can pass 1 before full contact)."""
    kw = dict(modulus=1.0, rms_height=1e4, area=math.pi * 0.25e10)  # f = F * 1e-9
    past = predict_xi(LogFit(2.9, 0.14), force=1e4, **kw)  # xi = 2.9 + 0.14 ln 1e-5 = 1.29
    below = predict_xi(LogFit(2.9, 0.14), force=7.0, **kw)
    assert past.xi > 1 > below.xi and past.beyond_full_contact and not below.beyond_full_contact
    warning = "warning: xi > 1, more than the whole surface's rms slope"
    assert warning in prediction_text(past) and "may be past where the log law holds" in prediction_text(past)
    assert "warning" not in prediction_text(below)


def test_bootstrap_pairs_keep_the_correlation_the_rectangle_loses():
    f0 = 1e-8  # pairs on a line through (ln f0, 0.4): every pair predicts 0.4 there
    b = np.linspace(0.05, 0.09, 101)
    pairs = np.column_stack([0.4 - b * math.log(f0), b])
    kw = dict(force=f0, modulus=1.0, rms_height=1.0, area=math.pi / 4)  # L = 1: f = F
    exact = predict_xi(LogFit(float(np.mean(pairs[:, 0])), 0.07), pairs=pairs, **kw)
    assert exact.xi_ci == pytest.approx((0.4, 0.4), abs=1e-12) and exact.interval == "bootstrap pairs"
    box = predict_xi(LogFit(0.4 - 0.07 * math.log(f0), 0.07, a_ci=(pairs[0, 0], pairs[-1, 0]), b_ci=(0.05, 0.09)), **kw)
    corners = [a + bb * math.log(f0) for a in (pairs[0, 0], pairs[-1, 0]) for bb in (0.05, 0.09)]
    assert box.xi_ci == pytest.approx((min(corners), max(corners)), rel=1e-12) and box.xi_ci[1] - box.xi_ci[0] > 1.0


def test_pairs_from_a_run_folder_are_the_runs_own(tmp_path, make_scene):
    outcome, _ = run_to_folder(make_scene({"realizations": 10, "output": {"plot": False}}), tmp_path, RunOptions(workers=1))
    pairs = bootstrap_pairs(tmp_path)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert pairs.shape == (summary["fit"]["bootstrap"], 2)
    low, high = percentile_interval(pairs, outcome.fit.confidence, axis=0)  # the fit's own function, its own tails
    assert (low[0], high[0]) == pytest.approx(tuple(summary["fit"]["a_ci"]), rel=1e-12, abs=1e-15)
    assert (low[1], high[1]) == pytest.approx(tuple(summary["fit"]["b_ci"]), rel=1e-12, abs=1e-15)
    law, fitted_f, law_pairs = read_run_law(tmp_path)
    assert fitted_f == (outcome.f.min(), outcome.f.max())
    assert (law.a, law.b, law.a_ci, law.b_ci) == (outcome.fit.a, outcome.fit.b, outcome.fit.a_ci, outcome.fit.b_ci)
    np.testing.assert_array_equal(law_pairs, pairs)
    inside = predict_xi(law, force=1.0, modulus=1.0, rms_height=1.0, area=1.0, pairs=law_pairs)
    assert inside.xi_ci[0] <= inside.xi <= inside.xi_ci[1]


def test_cli(tmp_path, capsys, make_scene):
    args = ["predict", "--area", "1e10", "--modulus", "1", "--rms-height", "1e4", "--force", "5"]
    assert main([*args, "--a", "2.9", "--b", "0.14", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["xi"] == pytest.approx(2.9 + 0.14 * math.log(out["f"]), rel=1e-12)
    run_to_folder(make_scene({"output": {"plot": False}}), tmp_path, RunOptions(workers=1))
    fitted = read_run_law(tmp_path)[1]  # a force inside the run's range of f: xi > 0 there
    inside = math.sqrt(fitted[0] * fitted[1]) / dimensionless_force_3d(1.0, 1.0, 1e4, 1e10)
    assert main([*args[:-1], repr(inside), "--from", str(tmp_path)]) == 0
    assert "(bootstrap pairs)" in capsys.readouterr().out
    assert main([*args]) == 2
    assert "--a A --b B" in capsys.readouterr().err
    assert main(["predict", "--a", "1", "--b", "0.1", "--area", "-1", "--modulus", "1", "--rms-height", "1", "--force", "1"]) == 2
    assert "--area must be a finite number > 0. Got -1.0 instead." in capsys.readouterr().err  # the option's name
    assert main([*args, "--from", str(tmp_path / "nothing")]) == 5  # a run folder that cannot be used
    assert "no readable summary.json" in capsys.readouterr().err


def test_pairs_from_a_run_whose_lines_lack_xi_at_low_forces(tmp_path):
    """The cosine series with the last point's slope undefined: some lines have no xi at the
    first loads (NaN in realizations.npz); the pairs redrawn from the folder are still the run's own."""
    from frictionlab.preset import build_scene

    data = {
        "name": "ends", "seed": 4, "realizations": 30, "fit": {"bootstrap": 200}, "output": {"plot": False},
        "spectrum": {"name": "power-law", "params": {"hurst": 1.0, "points": 2048, "series": "cosine"}},
        "slope": {"name": "forward-difference", "params": {"line_end": "undefined"}},
        "loading": {"start": 1e-7, "stop": 1e-2, "steps": 12, "spacing": "log"},
    }  # fmt: skip
    outcome, _ = run_to_folder(build_scene(data), tmp_path, RunOptions(workers=1))
    assert outcome.lines_used[0] < 30 and np.isnan(outcome.per_realization["xi"]).any()
    assert f"up to {30 - outcome.lines_used.min()} of 30 lines have no xi at a load" in outcome.caveats[-1]
    pairs = bootstrap_pairs(tmp_path)
    low, high = percentile_interval(pairs, outcome.fit.confidence, axis=0)  # the fit's own function, its own tails
    assert (low[0], high[0]) == pytest.approx(outcome.fit.a_ci, rel=1e-12, abs=1e-15)
    assert (low[1], high[1]) == pytest.approx(outcome.fit.b_ci, rel=1e-12, abs=1e-15)


def test_from_a_run_that_failed_with_every_realization_done_says_why_not_resume(tmp_path, capsys, make_scene):
    """A run whose loads all press beyond full contact finishes every realization and fails with
    'no law'. predict --from said its law 'would come from fewer realizations than it asked for;
    finish it with frictionlab resume', which gives no law either. It now says the run's own error."""
    scene = make_scene({"output": {"plot": False}, "loading": {"start": 1e6, "stop": 1e7, "spacing": "log"}})
    outcome, _ = run_to_folder(scene, tmp_path, RunOptions(workers=1))
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["realizations"]["done"] == summary["realizations"]["requested"]
    args = ["predict", "--from", str(tmp_path), "--area", "1", "--modulus", "1", "--rms-height", "1", "--force", "1"]
    assert main(args) == 5
    err = capsys.readouterr().err
    assert "the run failed with all its realizations finished" in err and "holds no law: no law: the whole" in err
    assert "frictionlab resume" not in err and "fewer realizations" not in err


def test_a_run_without_realizations_npz_keeps_its_fitted_range(tmp_path, capsys, make_scene):
    """output.realizations: false leaves no realizations.npz: the range of f came back
    [nan, nan], and every prediction, inside the loads or not, was called extrapolated."""
    scene = make_scene({"output": {"plot": False, "realizations": False}})
    outcome, _ = run_to_folder(scene, tmp_path, RunOptions(workers=1))
    assert not (tmp_path / "realizations.npz").exists()
    _, fitted_f, pairs = read_run_law(tmp_path)
    assert pairs is None and fitted_f == pytest.approx((outcome.f.min(), outcome.f.max()), rel=1e-12)
    (tmp_path / "curve.csv").unlink()
    assert read_run_law(tmp_path)[1] is None  # not known: no warning either way
    assert main(["predict", "--from", str(tmp_path), "--area", "1", "--modulus", "1", "--rms-height", "1",
                 "--force", "1", "--json"]) == 0  # fmt: skip
    assert json.loads(capsys.readouterr().out)["extrapolated"] is False



def test_an_xi_at_or_below_zero_is_refused_naming_the_inputs(capsys):
    """An rms slope in contact of xi <= 0 (h in m beside A and F of another system) was printed
    with a warning and exit 0: no contact has one; it is refused (exit 2) naming the inputs."""
    args = ["predict", "--a", "1.88", "--b", "0.08", "--area", "1e-4", "--modulus", "1e9", "--rms-height", "1", "--force", "1e-5"]
    assert main(args) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "Traceback" not in captured.err
    assert "an rms slope in contact must be > 0" in captured.err and "= -0.3401 at f = 8.86227e-13" in captured.err
    assert "Check --force, --modulus, --rms-height, --area" in captured.err and "consistent system of units" in captured.err
    with pytest.raises(FrictionlabError, match="must be > 0"):
        predict_xi(LogFit(1.88, 0.08), force=1e-5, modulus=1e9, rms_height=1.0, area=1e-4)
    assert predict_xi(LogFit(1.88, 0.08), force=1e-5, modulus=1e9, rms_height=1e-6, area=1e-4).xi > 0
