"""``frictionlab predict`` on bad input: a damaged or unfinished run folder (exit 5,
naming the file and the field), numbers beyond double precision and options out of
range (exit 2, naming what is out of range); never a traceback or an internal error."""

import io
import json
import math
import shutil
import threading
import zipfile

import numpy as np
import pytest

from frictionlab.cli import main
from frictionlab.compute.fit import percentile_interval, resample_pairs
from frictionlab.errors import ExitCode
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.preset.seeds import bootstrap_rng
from frictionlab.runs.runner import run_to_folder

from ..conftest import SMALL_PRESET, merge
from ..test_resume import CancelAfter

CONTACT = ["--area", "1e-4", "--modulus", "1e9", "--rms-height", "1e-6", "--force", "10"]


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory, registry):
    folder = tmp_path_factory.mktemp("finished") / "run"
    scene = build_scene(merge(SMALL_PRESET, {"output": {"plot": False}}), registry=registry)
    outcome, _ = run_to_folder(scene, folder, RunOptions(workers=1))
    assert outcome.status == "completed"
    return folder


@pytest.fixture
def run_copy(finished_run, tmp_path):
    """A fresh copy of a finished run, to damage."""
    return shutil.copytree(finished_run, tmp_path / "run")


def predict_from(folder, capsys, *extra):
    code = main(["predict", "--from", str(folder), *CONTACT, *extra])
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "internal error" not in err
    return code, out, err


def edit_summary(folder, change):
    path = folder / "summary.json"
    summary = json.loads(path.read_text())
    change(summary)
    path.write_text(json.dumps(summary))


def test_the_undamaged_copy_predicts(run_copy, capsys):
    code, out, _ = predict_from(run_copy, capsys)
    assert code == 0 and "(bootstrap pairs)" in out


# ------------------------------------------------------------------ summary.json damaged


@pytest.mark.parametrize(
    "text, reason",
    [
        ("junk", "not valid JSON"),
        ("", "not valid JSON"),
        ("[1, 2]", "(an array, not a JSON object)"),
        pytest.param("[" * 100_000 + "]" * 100_000, "nested too deeply", id="deep-list"),
        pytest.param('{"a": ' * 100_000 + "1" + "}" * 100_000, "nested too deeply", id="deep-object"),
        pytest.param("\udcff", "not valid JSON", id="not-utf8"),  # a lone byte 0xff once written
        pytest.param('{"fit": {"a": 1, "a": 2}}', "(key 'a' given twice in one object)", id="repeated-key"),  # was the last
    ],
)
def test_a_summary_that_is_not_a_json_object(run_copy, capsys, text, reason):
    (run_copy / "summary.json").write_bytes(text.encode("utf-8", "surrogateescape"))
    code, _, err = predict_from(run_copy, capsys)
    assert code == ExitCode.RUN_FOLDER
    assert "summary.json" in err and reason in err


def test_a_summary_that_is_a_folder(run_copy, capsys):
    (run_copy / "summary.json").unlink()
    (run_copy / "summary.json").mkdir()
    code, _, err = predict_from(run_copy, capsys)
    assert code == ExitCode.RUN_FOLDER and "summary.json" in err and "a folder" in err


@pytest.mark.parametrize(
    "field, value",
    [
        ("fit", "x"),
        ("fit", [1, 2]),
        ("fit", True),
        ("fit.a", "x"),
        ("fit.a", None),
        ("fit.a", True),
        ("fit.a", 1e400),  # json.dumps writes Infinity, which json reads back
        pytest.param("fit.a", 10**400, id="fit.a-int-past-double"),
        ("fit.b", "x"),
        ("fit.b", float("nan")),
        ("fit.confidence", "x"),
        ("fit.confidence", 2),
        ("fit.confidence", 0),
        ("fit.bootstrap", "x"),
        ("fit.bootstrap", -1),
        ("fit.bootstrap", 2.5),
        pytest.param("fit.bootstrap", 100_001, id="fit.bootstrap-beyond-a-preset-s"),  # redrawn: 10**12 ran for hours
        ("fit.points", "x"),
        ("fit.a_ci", "x"),
        ("fit.a_ci", [1, 2, 3]),
        ("fit.a_ci", [2.0, 1.0]),
        ("fit.a_ci", [None, 1.0]),
        ("fit.b_ci", ["x", 1]),
        ("fit.r2", "x"),
        ("seed", "x"),
        ("seed", -3),
    ],
)
def test_a_fit_field_of_the_wrong_type_or_range(run_copy, capsys, field, value):
    def change(summary):
        *parents, last = field.split(".")
        target = summary
        for key in parents:
            target = target[key]
        target[last] = value

    edit_summary(run_copy, change)
    code, _, err = predict_from(run_copy, capsys)
    assert code == ExitCode.RUN_FOLDER
    assert "summary.json" in err and f"'{field}" in err, err  # the field, or an item of it ('fit.b_ci.0')


@pytest.mark.parametrize("field", ["a", "b"])
def test_a_law_edited_beyond_its_own_resamples_is_refused(run_copy, capsys, field):
    """A fit.a (or b) far from what realizations.npz gives, intervals untouched: the
    prediction would be no run's. Refused naming the field, what was stored and the refit."""
    summary = json.loads((run_copy / "summary.json").read_text())
    low, high = summary["fit"][f"{field}_ci"]
    edit_summary(run_copy, lambda s: s["fit"].update({field: high + 100 * (high - low) + 1.0}))
    code, _, err = predict_from(run_copy, capsys)
    assert code == ExitCode.RUN_FOLDER
    forged = high + 100 * (high - low) + 1.0
    assert f"fit.{field} = {forged:.6g} is not the fit of realizations.npz's mean curve ({field} = " in err, err


@pytest.mark.parametrize("field", ["a", "b"])
def test_an_interval_edited_is_refused_as_not_its_resamples(run_copy, capsys, field):
    """A fit.a_ci (or b_ci) widened, the law untouched: the interval printed beside the
    prediction would be no run's. Refused naming the field, what was stored and the redrawn one."""
    summary = json.loads((run_copy / "summary.json").read_text())
    low, high = summary["fit"][f"{field}_ci"]
    wider = [low - (high - low), high + (high - low)]
    edit_summary(run_copy, lambda s: s["fit"].update({f"{field}_ci": wider}))
    code, out, err = predict_from(run_copy, capsys)
    assert code == ExitCode.RUN_FOLDER and not out
    assert f"fit.{field}_ci = [{wider[0]:.6g}, {wider[1]:.6g}] is not the interval of its 200 bootstrap resamples" in err, err


@pytest.mark.parametrize("field", ["a", "b"])
@pytest.mark.parametrize("where", ["among its resamples", "with few resamples"])
def test_a_law_edited_is_refused_as_not_the_fit_of_its_realizations(run_copy, capsys, field, where):
    """A fit.a (or b) edited to a value among its resamples, or in a run of fewer than 100
    resamples (whose span says nothing: a = 1e30 gave xi = 1e30 beside the run's interval),
    was taken as the run's law: it is refitted from realizations.npz, to rounding."""
    summary = json.loads((run_copy / "summary.json").read_text())
    low, high = summary["fit"][f"{field}_ci"]
    if where == "among its resamples":
        edit_summary(run_copy, lambda s: s["fit"].update({field: (low + high) / 2}))
    else:  # the run's 20 resamples, the interval they give, and a forged a or b
        pairs = resample_pairs(np.load(run_copy / "realizations.npz")["f"], np.load(run_copy / "realizations.npz")["xi"],
                               20, bootstrap_rng(summary["seed"]))  # fmt: skip
        ci = percentile_interval(pairs, summary["fit"]["confidence"], axis=0)
        edit_summary(run_copy, lambda s: s["fit"].update({"bootstrap": 20, field: 1e30, "a_ci": [ci[0][0], ci[1][0]],
                                                          "b_ci": [ci[0][1], ci[1][1]]}))  # fmt: skip
    code, out, err = predict_from(run_copy, capsys)
    assert code == ExitCode.RUN_FOLDER and not out
    assert f"fit.{field} = " in err and "is not the fit of realizations.npz's mean curve" in err, err


def test_a_summary_without_a_fit(run_copy, capsys):
    edit_summary(run_copy, lambda summary: summary.update(fit=None))
    code, _, err = predict_from(run_copy, capsys)
    assert code == ExitCode.RUN_FOLDER and "summary.json" in err and "field 'fit' is null, but realizations were done" in err


def test_a_run_stopped_before_its_summary_says_how_to_finish_it(run_copy, capsys):
    """A run killed (kill -9) before its end leaves run.json and chunks, no summary.json: it was told
    only 'no such summary.json'."""
    (run_copy / "summary.json").unlink()
    code, _, err = predict_from(run_copy, capsys)
    assert code == ExitCode.RUN_FOLDER and "holds a run that wrote no summary.json" in err
    assert f"frictionlab resume {run_copy}" in err and f"frictionlab follow {run_copy}" in err


def test_a_missing_folder_is_a_run_folder_error(tmp_path, capsys):
    code, _, err = predict_from(tmp_path / "nothing", capsys)
    assert code == ExitCode.RUN_FOLDER and "no readable summary.json there (no such folder)" in err


def test_a_file_given_as_the_run_folder_is_named_a_file_not_missing(run_copy, capsys):
    """--from RUN/summary.json was told 'no such folder' of a file that is there."""
    code, _, err = predict_from(run_copy / "summary.json", capsys)
    assert code == ExitCode.RUN_FOLDER and "(not a folder: give the run's folder)" in err and "no such" not in err


# ------------------------------------------------------------------ realizations.npz damaged


def _junk(path):
    path.write_text("junk\n")


def _empty(path):
    path.write_bytes(b"")


def _truncated(path):
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])


def _pickled(path):
    with np.load(path) as data:
        arrays = dict(data)
    arrays["xi"] = arrays["xi"].astype(object)
    np.savez(path.with_suffix(".tmp.npz"), **arrays)
    path.with_suffix(".tmp.npz").replace(path)


def _without_xi(path):
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files if k != "xi"}
    with path.open("wb") as fh:
        np.savez(fh, **arrays)


def _all_nan(path):
    with np.load(path) as data:
        arrays = dict(data)
    arrays["xi"] = np.full_like(arrays["xi"], np.nan)
    with path.open("wb") as fh:
        np.savez(fh, **arrays)


def _one_xi_negative(path):  # an rms slope over another is never below 0: a file edited, not a run's
    with np.load(path) as data:
        arrays = dict(data)
    arrays["xi"][0, 0] = -0.01
    with path.open("wb") as fh:
        np.savez(fh, **arrays)


def _one_xi_huge(path):  # finite and >= 0, a and b still among the resamples: the interval of xi went to 1e306, now refitted
    with np.load(path) as data:
        arrays = dict(data)
    arrays["xi"][0, 0] = 1e308
    with path.open("wb") as fh:
        np.savez(fh, **arrays)


def _f_not_positive(path):
    with np.load(path) as data:
        arrays = dict(data)
    arrays["f"][0] = 0.0
    with path.open("wb") as fh:
        np.savez(fh, **arrays)


def _xi_of_other_shape(path):
    with np.load(path) as data:
        arrays = dict(data)
    arrays["xi"] = arrays["xi"][:, :3]
    with path.open("wb") as fh:
        np.savez(fh, **arrays)


def _xi_as_text(path):
    with np.load(path) as data:
        arrays = dict(data)
    arrays["xi"] = arrays["xi"].astype("<U1")  # one character (4 bytes): wider text unpacks past a float64 array's room
    with path.open("wb") as fh:
        np.savez(fh, **arrays)


def _fewer_rows(path):  # realizations of another run: fewer than summary.json says were done
    with np.load(path) as data:
        arrays = dict(data)
    arrays["xi"] = arrays["xi"][:3]
    with path.open("wb") as fh:
        np.savez(fh, **arrays)


def _xi_claimed(path, shape):  # a header may claim any shape, over 64 bytes of data
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": shape})
    with np.load(path) as data:
        f = data["f"]
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("xi.npy", header.getvalue() + bytes(64))
        with archive.open("f.npy", "w") as member:
            np.save(member, f)


def _array_claimed_past_memory(path):  # 7 TiB were asked of the machine for a 3 kB file
    _xi_claimed(path, (10**6, 10**6))


def _array_of_a_gigabyte(path):  # 1 GB was allocated, then 'EOF: reading array data'
    _xi_claimed(path, (50, 2_500_000))


def _one_array(path):
    with path.open("wb") as fh:
        np.save(fh, np.ones(4))


def _folder(path):
    path.unlink()
    path.mkdir()


@pytest.mark.parametrize(
    "damage, words",
    [
        (_junk, "is damaged (not an .npz archive"),
        (_empty, "is damaged"),
        (_truncated, "is damaged"),
        (_pickled, "pickled Python objects, which are never loaded"),
        (_array_claimed_past_memory, "is damaged (array 'xi': its header claims shape (1000000, 1000000) of float64 "
                                    f"({10**12 * 8:,} bytes), but its entry holds 64 bytes of data)"),
        (_array_of_a_gigabyte, f"array 'xi': its header claims shape (50, 2500000) of float64 ({50 * 2_500_000 * 8:,} bytes)"),
        (_without_xi, "no array 'xi'"),
        (_all_nan, "'xi' must hold finite numbers, or NaN where a line has no xi, with xi defined at two loads or "
                   "more (no line has xi at "),  # said as it is: it once said "(0 of ... are infinite)"
        (_one_xi_negative, "'xi' must hold numbers >= 0, or NaN where a line has no xi (1 of "),
        (_one_xi_huge, "is not the fit of realizations.npz's mean curve (a = "),
        (_f_not_positive, "'f' must hold finite numbers > 0"),
        (_xi_of_other_shape, "one per load step"),
        (_xi_as_text, "'xi' must be 2-D numbers"),
        (_fewer_rows, "not of one run"),
        (_one_array, "not an .npz archive: it does not start as a zip file does"),
        (_folder, "a folder"),
    ],
)
def test_damaged_realizations(run_copy, capsys, damage, words):
    damage(run_copy / "realizations.npz")
    code, _, err = predict_from(run_copy, capsys)
    assert code == ExitCode.RUN_FOLDER
    assert "realizations.npz" in err and words in err, err


# ------------------------------------------------------------------ a run that did not complete


def test_a_cancelled_run_is_refused_naming_its_status(tmp_path, capsys, registry):
    scene = build_scene(merge(SMALL_PRESET, {"realizations": 40, "output": {"plot": False}}), registry=registry)
    cancel = threading.Event()
    outcome, _ = run_to_folder(
        scene, tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(4, cancel)], cancel=cancel
    )
    assert outcome.status == "cancelled" and outcome.fit is not None and outcome.done < 40
    code, out, err = predict_from(tmp_path / "run", capsys)
    assert code == ExitCode.RUN_FOLDER and not out
    assert "'cancelled'" in err and f"({outcome.done} of 40 realizations)" in err and "frictionlab resume" in err


# ------------------------------------------------------------------ numbers beyond double precision

LAW = ["--a", "1", "--b", "0.1"]


@pytest.mark.parametrize(
    "area, modulus, rms_height, force",
    [
        ("1e-300", "1e-300", "1e-300", "1e300"),  # f about 1e1050
        ("1e300", "1e300", "1e300", "1e-300"),  # f about 1e-1050
        ("1", "1", "1e-300", "1e300"),  # f about 1e600
    ],
)
def test_an_f_beyond_double_precision_is_a_usage_error(capsys, area, modulus, rms_height, force):
    code = main(["predict", *LAW, "--area", area, "--modulus", modulus, "--rms-height", rms_height, "--force", force])
    out, err = capsys.readouterr()
    assert code == ExitCode.USAGE and not out
    assert "f = sqrt(pi) F / (2 E* h sqrt(A))" in err and "beyond double precision" in err
    assert f"force {float(force)!r}" in err and f"area {float(area)!r}" in err


@pytest.mark.parametrize(
    "area, modulus, rms_height, force",
    [
        (1e-300, 1e300, 1e300, 1e300),  # E* h overflows, f = 0.886e-150 does not
        (1e300, 1e-300, 1e-300, 1e-300),  # E* h underflows, f = 0.886e150 does not
        (1e-320, 1.0, 1.0, 1e-160),  # a subnormal area (A / pi keeps 3 of its digits)
    ],
)
def test_an_f_double_precision_holds_is_found_whatever_the_products_do(capsys, area, modulus, rms_height, force):
    code = main(["predict", "--a", "1", "--b", "0.001", "--area", repr(area), "--modulus", repr(modulus),
                 "--rms-height", repr(rms_height), "--force", repr(force), "--json"])  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    ln_f = math.log(math.sqrt(math.pi) / 2) + math.log(force) - math.log(modulus) - math.log(rms_height)
    ln_f -= 0.5 * math.log(area)
    assert math.log(out["f"]) == pytest.approx(ln_f, abs=1e-12)
    assert out["xi"] == pytest.approx(1 + 0.001 * ln_f, rel=1e-12)  # b small: xi > 0 at ln f = -345


# ------------------------------------------------------------------ options out of range


@pytest.mark.parametrize(
    "options, named",
    [
        (["--a", "nan", "--b", "0.1"], "--a must be a finite number. Got nan"),
        (["--a", "inf", "--b", "0.1"], "--a must be a finite number. Got inf"),
        (["--a", "1", "--b=-inf"], "--b must be a finite number. Got -inf"),
        ([*LAW, "--confidence", "2"], "--confidence must be a number between 0 and 1 (exclusive). Got 2.0"),
        ([*LAW, "--confidence", "-1"], "--confidence must be a number between 0 and 1 (exclusive). Got -1.0"),
        ([*LAW, "--confidence", "1"], "--confidence must be a number between 0 and 1 (exclusive). Got 1.0"),
        ([*LAW, "--confidence", "nan"], "--confidence must be a number between 0 and 1 (exclusive). Got nan"),
        ([*LAW, "--a-ci", "2", "1", "--b-ci", "0", "1"], "--a-ci must be two finite numbers LO <= HI. Got 2.0, 1.0"),
        ([*LAW, "--a-ci", "nan", "1", "--b-ci", "0", "1"], "--a-ci must be two finite numbers LO <= HI. Got nan, 1.0"),
        ([*LAW, "--a-ci", "0", "1", "--b-ci", "0", "inf"], "--b-ci must be two finite numbers LO <= HI. Got 0.0, inf"),
        # xi = a + b ln f, with ln f = -0.12 here (18.3 at F = 1e9), overflows
        (["--a", "1.7e308", "--b=-1e308"], "xi = a + b ln f is beyond double precision"),
        ([*LAW, "--a-ci", "0", "1.7e308", "--b-ci", "0", "1e308", "--force", "1e9"], "the interval of xi"),
        ([*LAW, "--rms-slope", "1e308", "--force", "1e9"], "rms_slope is too large"),
        ([*LAW, "--rms-slope", "nan"], "--rms-slope must be a finite number > 0. Got nan"),
        ([*LAW, "--rms-height", "0"], "--rms-height must be a finite number > 0. Got 0.0"),  # not rms_height
        ([*LAW, "--from", ""], "--from names no folder (it is empty)"),  # not "give the law"
        # a level of no interval: it was printed as '50% interval n/a (none)', the option ignored
        ([*LAW, "--confidence", "0.5"], "--confidence 0.5 is the level of --a-ci and --b-ci, but there are none"),
        # a typo (a and b swapped, a digit lost): xi was printed beside an interval that left it out
        (["--a", "1.88", "--b", "0.08", "--a-ci", "0.07", "0.09", "--b-ci", "1.8", "1.9"],
         "--a 1.88 lies outside its interval --a-ci 0.07 0.09"),
        (["--a", "1.88", "--b", "0.08", "--a-ci", "1.8", "1.9", "--b-ci", "0.8", "0.9"],
         "--b 0.08 lies outside its interval --b-ci 0.8 0.9"),
    ],
)
def test_options_out_of_range_are_usage_errors(capsys, options, named):
    code = main(["predict", *CONTACT, *options])
    out, err = capsys.readouterr()
    assert code == ExitCode.USAGE and not out
    assert named in err and "Traceback" not in err


@pytest.mark.parametrize("option", [["--a-ci", "0", "1"], ["--confidence", "0.9"], ["--b", "0.1"]])
def test_the_law_by_hand_and_from_a_run_do_not_mix(finished_run, capsys, option):
    code, out, err = predict_from(finished_run, capsys, *option)
    assert code == ExitCode.USAGE and not out and f"{option[0]} with --from" in err


def test_huge_but_finite_numbers_print_short(capsys):
    contact = [*CONTACT[:-1], "100"]  # ln f > 0: xi > 0
    assert main(["predict", *contact, "--a", "1", "--b", "1e307", "--a-ci", "0", "2", "--b-ci", "1e306", "1e307"]) == 0
    out = capsys.readouterr().out
    assert "e+307" in out and max(len(line) for line in out.splitlines() if not line.startswith("warning:")) < 120


@pytest.mark.parametrize("option", ["--area", "--modulus", "--rms-height", "--force"])
def test_a_number_too_small_for_a_double_is_named_as_typed_not_as_zero(option, capsys):
    """1e-400 reads as 0.0: the message said 'Got 0.0 instead', a value nobody typed."""
    given = {"--area": "1", "--modulus": "1", "--rms-height": "1", "--force": "1", option: "1e-400"}
    args = ["predict", "--a", "1", "--b", "0.1", *(word for pair in given.items() for word in pair)]
    with pytest.raises(SystemExit) as ended:
        main(args)
    assert ended.value.code == ExitCode.USAGE
    err = capsys.readouterr().err
    assert f"argument {option}: 1e-400 is below the smallest number above 0" in err and "0.0" not in err
