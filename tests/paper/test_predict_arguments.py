"""predict_xi from Python: a law, forces read from a table (numpy scalars) and bootstrap
pairs as a notebook holds them; bad ones are a FrictionlabError naming the argument."""

import math

import numpy as np
import pytest

from frictionlab.compute.fit import LogFit
from frictionlab.errors import FrictionlabError
from frictionlab.paper.predict import predict_xi

KW = dict(modulus=1.0, rms_height=1e4, area=math.pi * 0.25e10)  # L = 1e5: f = F * 1e-9
LAW = LogFit(2.9, 0.14, a_ci=(2.8, 3.0), b_ci=(0.13, 0.15))


@pytest.mark.parametrize("force", [np.float32(7.0), np.int64(7), np.float64(7.0)])
def test_numpy_scalars_are_numbers(force):
    p = predict_xi(LAW, force=force, **KW)
    assert p.xi == pytest.approx(2.9 + 0.14 * math.log(7e-9), rel=1e-6)


@pytest.mark.parametrize(
    ("law", "said"),
    [
        (None, "law must be a frictionlab.compute.fit.LogFit, e.g. LogFit(a, b, a_ci=(lo, hi), b_ci=(lo, hi)). "
               "Got NoneType (a run's fit is None when no realization finished) instead."),
        ({"a": 2.9, "b": 0.14}, "law must be a frictionlab.compute.fit.LogFit"),
        (LogFit("2.9", 0.14), "a must be a finite number. Got '2.9' instead."),
        (LogFit(2.9, 0.14, a_ci=(1, 2, 3)), "a_ci must be two finite numbers LO <= HI. Got (1, 2, 3) instead."),
    ],
)  # fmt: skip
def test_a_law_that_is_none_names_what_is_wanted(law, said):
    with pytest.raises(FrictionlabError) as caught:
        predict_xi(law, force=7.0, **KW)
    assert said in str(caught.value)


@pytest.mark.parametrize(
    ("pairs", "said"),
    [([1.0, 2.0, 3.0], "Got shape (3,) instead"), ([[1.0, math.nan]], "Got 1 values that are not finite instead"),
     ([["a", "b"]], "Got list instead")],
)  # fmt: skip
def test_pairs_of_the_wrong_shape_are_named(pairs, said):
    with pytest.raises(FrictionlabError) as caught:
        predict_xi(LAW, force=7.0, pairs=pairs, **KW)
    assert str(caught.value).startswith("pairs must be bootstrap (a, b) pairs: an array of shape (n, 2)")
    assert said in str(caught.value)


def test_rms_slope_of_a_wrong_type_is_named():
    with pytest.raises(FrictionlabError, match=r"rms_slope must be a finite number > 0\. Got '0\.1' instead"):
        predict_xi(LAW, force=7.0, rms_slope="0.1", **KW)


def test_a_run_folder_from_python_is_named_as_python_names_it(tmp_path):
    from frictionlab.paper.predict import bootstrap_pairs, read_run_law

    with pytest.raises(FrictionlabError, match=r"^run folder .*nothere: no readable summary\.json there \(no such folder\)$"):
        bootstrap_pairs(tmp_path / "nothere")  # not '--from', an option of the command line
    with pytest.raises(FrictionlabError, match=r"^run_dir must be a path to a run folder .*got int$"):
        read_run_law(3)


def test_a_prediction_shows_rounded_with_its_flags_and_prints_as_the_command_does():
    from frictionlab.paper.predict import prediction_text

    p = predict_xi(LAW, force=7.0, fitted_f=(1e-3, 1e-1), rms_slope=0.5, **KW)
    assert repr(p) == (f"Prediction(f = 7e-09, xi = {p.xi:.4f} [{p.xi_ci[0]:.4f}, {p.xi_ci[1]:.4f}] "
                       f"(95% CI, rectangle of a_ci x b_ci), rms slope in contact = {p.slope_contact:.4g}, extrapolated)")  # fmt: skip
    assert str(p) == prediction_text(p) and "extrapolated" in str(p)
    assert p.xi == pytest.approx(2.9 + 0.14 * math.log(p.f), rel=1e-12)  # the field keeps every digit
