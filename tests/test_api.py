"""The Python API: ``frictionlab.run`` in every input form, overrides, ``Result``
(table, pandas, plot, caveats) and ``frictionlab.load`` reading a CLI run back."""

from __future__ import annotations

import doctest
import json
import shutil
import subprocess
import sys

import numpy as np
import pytest
import yaml

import frictionlab
from frictionlab import api
from frictionlab.errors import FrictionlabError, MissingDependency, PresetError, RunFolderError
from frictionlab.preset import Preset

from .conftest import PRESETS, SMALL_PRESET, merge
from .test_registry import fake_dists  # noqa: F401 (a fixture)

FAST = {"workers": 1, "progress": False}


def test_the_docstring_examples_run():
    failures, tried = doctest.testmod(api, optionflags=doctest.ELLIPSIS)
    assert tried > 5 and failures == 0


def test_every_input_form_gives_the_same_numbers(tmp_path):
    path = tmp_path / "small.yaml"
    path.write_text(yaml.safe_dump(SMALL_PRESET))
    forms = [path, str(path), path.read_text(), dict(SMALL_PRESET), Preset.model_validate(SMALL_PRESET)]
    results = [frictionlab.run(form, **FAST) for form in forms]
    for result in results[1:]:
        assert result.fit == results[0].fit
        np.testing.assert_array_equal(result.table["xi"], results[0].table["xi"])
    assert results[0].folder is None and results[0].realizations == (8, 8)


def test_overrides_by_dict_and_by_double_underscore_agree_and_are_applied():
    by_dict = frictionlab.run(SMALL_PRESET, {"spectrum.params.hurst": 0.5, "seed": 3}, **FAST)
    by_keywords = frictionlab.run(SMALL_PRESET, spectrum__params__hurst=0.5, seed=3, **FAST)
    plain = frictionlab.run(SMALL_PRESET, **FAST)
    assert by_dict.fit == by_keywords.fit != plain.fit
    assert by_dict.preset["spectrum"]["params"]["hurst"] == 0.5 and by_dict.preset["seed"] == 3
    assert SMALL_PRESET["spectrum"]["params"]["hurst"] == 0.8  # the caller's dict is left as it was


def test_overrides_may_be_named_as_in_the_signature():
    """``overrides=`` is the second argument named (a preset has no key of that name): once a raw TypeError."""
    named = frictionlab.run(SMALL_PRESET, overrides={"spectrum.params.hurst": 0.5, "seed": 3}, **FAST)
    assert named.preset["spectrum"]["params"]["hurst"] == 0.5 and named.preset["seed"] == 3
    assert frictionlab.validate("quickstart", overrides={"realizations": 7})["realizations"] == 7



@pytest.mark.parametrize(("overrides", "keywords", "said"), [
    ({"spectrum..params": 1}, {}, "'spectrum..params': must be field names joined by dots, e.g. spectrum.params.hurst"),
    ({"": 1, ".seed": 2}, {}, "'': must be field names joined by dots"),
    ({}, {"spectrum____params": 1}, "'spectrum____params': must be field names joined by __, e.g. spectrum__params__hurst"),
    ({}, {"seed__": 1}, "'seed__': must be field names joined by __"),
])  # fmt: skip
def test_an_override_path_with_a_name_left_out_is_refused_as_such(overrides, keywords, said):
    """An override's path with nothing between two dots (or a keyword's between two __) set a key
    named '' and was refused as another field's problem: spectrum____params=1 was 'spectrum: is
    not a known field; allowed: name, params', though spectrum is one (--set refuses a..b so)."""
    with pytest.raises(PresetError) as refused:
        frictionlab.validate("quickstart", overrides, **keywords)
    assert said in str(refused.value)
    assert "is not a known field" not in str(refused.value)

def test_bad_input_is_a_clear_error_naming_the_field():
    with pytest.raises(PresetError, match="spectrum.params.hurst"):
        frictionlab.run(SMALL_PRESET, spectrum__params__hurst=7.0, **FAST)
    with pytest.raises(FrictionlabError, match="did you mean 'quickstart'"):
        frictionlab.run("quickstrt", **FAST)
    with pytest.raises(FrictionlabError, match="preset must be"):
        frictionlab.run(42, **FAST)
    with pytest.raises(FrictionlabError, match="a sweep writes a run folder per point: give out=FOLDER"):
        frictionlab.run(PRESETS / "benad2012-fig5.yaml", **FAST)


def test_a_sweep_runs_into_its_folder_and_each_point_is_the_run_alone(tmp_path):
    sweep = {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.9]}}}
    result = frictionlab.run(SMALL_PRESET, out=tmp_path / "sweep", sweep=sweep, plot=False, **FAST)
    assert isinstance(result, api.SweepResult) and result.status == "completed"
    assert result.parameters == ["spectrum.params.hurst"] and [r["spectrum.params.hurst"] for r in result.rows] == [0.5, 0.9]
    for row, point in zip(result.rows, result.points, strict=True):
        alone = frictionlab.run(SMALL_PRESET, spectrum__params__hurst=row["spectrum.params.hurst"], **FAST)
        assert point.fit == alone.fit and row["a"] == alone.fit.a and row["b_hi"] == alone.fit.b_ci[1]
    assert frictionlab.load(tmp_path / "sweep").rows == result.rows
    assert list(result.to_pandas()["b"]) == [r["b"] for r in result.rows]
    # every numeric column is labelled, as a Result's are (the frame had no units at all)
    numeric = {key for key, value in result.rows[0].items() if isinstance(value, float | int) and key != "point"}
    assert numeric - set(result.parameters) == set(result.units)
    assert result.to_pandas().attrs["units"] == result.units and result.units["contact_first"].startswith("count")


def test_a_sweep_plots_as_its_sweep_png_does(tmp_path):
    """SweepResult had no plot(): a notebook drew a sweep only by hand. Read back, its figure
    names the axes by their fields, as sweep.png does."""
    import matplotlib.pyplot as plt

    sweep = {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.9]}}}
    frictionlab.run(SMALL_PRESET, out=tmp_path / "sweep", sweep=sweep, plot=False, **FAST)
    figure = frictionlab.load(tmp_path / "sweep").plot()
    assert figure.number in plt.get_fignums()  # through pyplot: a notebook shows it
    assert [ax.get_ylabel() for ax in figure.axes] == ["a", "b"]
    assert [ax.get_xlabel() for ax in figure.axes if ax.get_xlabel()] == ["Hurst exponent H"]
    plt.close(figure)


def test_a_sweep_point_whose_folder_holds_another_run_is_refused_not_read_as_the_point(tmp_path):
    """SweepResult.points read whatever run sat in a point's folder: another sweep's point, or
    another preset's run, moved there came back as the point, its numbers not the row's."""
    sweep = {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.9]}}}
    frictionlab.run(SMALL_PRESET, out=tmp_path / "sweep", sweep=sweep, plot=False, **FAST)
    points = tmp_path / "sweep" / "points"
    first, second = sorted(points.iterdir())
    shutil.rmtree(first)
    shutil.copytree(second, first)  # the H = 0.9 point in the H = 0.5 point's place
    with pytest.raises(RunFolderError, match=r"holds another run than point 1 of sweep 'small' \(its "
                       r"spectrum.params.hurst is 0.9, the point's 0.5\): move it aside"):
        frictionlab.load(tmp_path / "sweep").points
    shutil.rmtree(first)
    frictionlab.run(merge(SMALL_PRESET, {"name": "other"}), out=first, plot=False, **FAST)
    with pytest.raises(RunFolderError, match=r"\(its name is 'other', the point's 'small'\)"):
        frictionlab.load(tmp_path / "sweep").points


def test_load_reads_a_cli_run_back_with_the_same_numbers(tmp_path, cli):
    folder = tmp_path / "cli-run"
    result = cli("run", "quickstart", "--out", folder, "--quiet", "--workers", "2", "--set", "realizations=12")
    assert result.returncode == 0, result.stderr
    loaded = frictionlab.load(folder)
    again = frictionlab.run("quickstart", realizations=12, **FAST)  # in memory, one worker: the same numbers
    assert loaded.fit == again.fit and loaded.fit.bootstrap > 0
    for name, values in again.table.items():
        np.testing.assert_array_equal(loaded.table[name], values, err_msg=name)
    assert loaded.realizations == (12, 12) and loaded.folder == folder
    assert loaded.preset == again.preset and loaded.normalisation == again.normalisation
    assert loaded.files["plot"].is_file()
    with pytest.raises(RunFolderError, match="no summary.json"):
        frictionlab.load(tmp_path)


def test_load_refuses_a_curve_it_did_not_write_naming_the_file(tmp_path):
    folder = tmp_path / "run"
    frictionlab.run(SMALL_PRESET, out=folder, plot=False, **FAST)
    curve = folder / "curve.csv"
    lines = curve.read_text().splitlines()
    curve.write_text("\n".join(["F,f,xi", *(",".join(line.split(",")[:3]) for line in lines[1:])]) + "\n")
    with pytest.raises(RunFolderError, match=r"curve.csv is damaged \(its header does not name the \d+ columns"):
        frictionlab.load(folder)  # columns missing
    curve.write_text("")  # emptied
    with pytest.raises(RunFolderError, match=r"curve.csv is damaged \(empty: no header\)"):
        frictionlab.load(folder)


def test_load_refuses_a_cell_python_reads_as_a_number_but_frictionlab_never_writes(tmp_path):
    """float() takes '1_0' as 10, ' 2' with its space, and Arabic-Indic digits: a curve.csv edited
    so was read as numbers it never held. A cell is a plain decimal number, or empty."""
    folder = tmp_path / "run"
    frictionlab.run(SMALL_PRESET, out=folder, plot=False, **FAST)
    curve = folder / "curve.csv"
    text = curve.read_text()
    first = text.splitlines()[1].split(",")
    for cell in ("1_0", " 2", "\u0661\u0662", "0x10"):
        curve.write_text(text.replace(",".join(first), ",".join([first[0], first[1], cell, *first[3:]]), 1))
        with pytest.raises(RunFolderError, match=r"curve.csv is damaged \(line 2, column 3: not a finite number\)"):
            frictionlab.load(folder)
    curve.write_text(text.replace(",".join(first), ",".join([first[0], first[1], "1E-05", *first[3:]]), 1))
    assert frictionlab.load(folder).table["xi"][0] == 1e-05  # as a float is written, exponent and all


def test_out_writes_the_cli_files_and_plot_false_leaves_out_the_figure(tmp_path):
    r = frictionlab.run(SMALL_PRESET, out=tmp_path / "a", plot=False, **FAST)
    assert {p.name for p in (tmp_path / "a").iterdir()} >= {"summary.json", "curve.csv", "preset.yaml"}
    assert not (tmp_path / "a" / "plot.png").exists()
    assert "plot" not in json.loads((tmp_path / "a" / "summary.json").read_text())["files"]
    drawn = frictionlab.run(SMALL_PRESET, out=tmp_path / "b", **FAST)
    assert json.loads((tmp_path / "b" / "summary.json").read_text())["files"]["plot"] == "plot.png"
    assert drawn.fit == r.fit  # the figure changes no number


def test_to_pandas_gives_a_frame_with_pandas_and_names_the_extra_without(monkeypatch):
    result = frictionlab.run(SMALL_PRESET, **FAST)
    frame = result.to_pandas()
    assert list(frame.columns) == ["F", "f", "xi", "xi_sem", "lines_used", "contact_count", "contact_fraction", "indentation",
                                     "half_load_points"]
    np.testing.assert_array_equal(frame["xi"].to_numpy(), result.table["xi"])
    monkeypatch.setitem(sys.modules, "pandas", None)  # as if not installed
    with pytest.raises(MissingDependency, match=r'Result.to_pandas\(\) needs pandas, .*pip install "frictionlab\[pandas\]"'):
        result.to_pandas()


def test_plot_draws_the_points_and_the_fit_on_the_given_axes():
    from matplotlib.figure import Figure

    result = frictionlab.run(SMALL_PRESET, **FAST)
    ax = Figure().subplots()
    assert result.plot(ax) is ax
    points, fit_line = ax.lines[0], ax.lines[1]
    np.testing.assert_array_equal(points.get_ydata(), result.table["xi"])
    x, y = fit_line.get_data()
    np.testing.assert_allclose(y, result.fit.a + result.fit.b * np.log(x))
    assert ax.get_xscale() == "log" and ax.get_title() == "small"


def test_few_contacts_at_the_first_load_carry_a_caveat_everywhere(tmp_path):
    tiny = {**SMALL_PRESET, "loading": {**SMALL_PRESET["loading"], "start": 1e-6}}
    result = frictionlab.run(tiny, out=tmp_path / "tiny", plot=False, **FAST)  # its figure: result.plot below
    assert result.table["contact_count"][0] < 3
    assert "fewer than 3 points in contact" in result.caveats[0]
    # and, from F = 1e-6 on, one point carries half the force at most loads
    assert len(result.caveats) == 2 and "fewer than 5 points carry half the force" in result.caveats[1]
    assert json.loads((tmp_path / "tiny" / "summary.json").read_text())["caveats"] == result.caveats
    ax = __import__("matplotlib.figure").figure.Figure().subplots()
    result.plot(ax)
    assert any("caveat: fewer than 3" in t.get_text() for t in ax.texts)
    assert frictionlab.run(SMALL_PRESET, **FAST).caveats == []


def test_import_frictionlab_imports_neither_the_api_nor_matplotlib_nor_scipy():
    code = "import sys, frictionlab; print(sorted(m for m in ('frictionlab.api', 'matplotlib', 'scipy', 'rich') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
    assert callable(frictionlab.run) and frictionlab.Result is api.Result


def test_every_public_name_resolves_lazily():
    code = "import frictionlab; [getattr(frictionlab, n) for n in frictionlab.__all__]; from frictionlab import *; print('ok')"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.strip() == "ok", done.stderr
    # every lazily imported name is public (defined_rms, which the contract tells a solver to use, was left out)
    assert set(frictionlab._LAZY) <= set(frictionlab.__all__)


def test_loads_that_press_the_whole_line_flat_carry_a_caveat_from_where_it_starts(tmp_path):
    # MDR springs: all N springs touch once the load exceeds about N dx E* times the height range
    heavy = {**SMALL_PRESET, "loading": {**SMALL_PRESET["loading"], "start": 1.0, "stop": 1e6, "steps": 12}}
    result = frictionlab.run(heavy, out=tmp_path / "heavy", plot=False, **FAST)
    fraction = result.table["contact_fraction"]
    first = int(np.flatnonzero(fraction >= 0.999)[0])
    assert 0 < first < fraction.size and np.all(fraction[first:] >= 0.999)
    assert np.allclose(result.table["xi"][first:], 1.0)  # the rms slope in contact is the whole line's
    full = [c for c in result.caveats if "the whole profile is in contact" in c]
    assert full == [f"the whole profile is in contact from load {first + 1} of 12 on (load {result.table['F'][first]:.4g}): "
                    "xi is 1 there by definition, so those loads measure no roughness; lower the loads"]  # fmt: skip
    assert json.loads((tmp_path / "heavy" / "summary.json").read_text())["caveats"] == result.caveats


# ------------------------------------------------------------------ arguments, named


def _nested(depth: int) -> dict:
    top = inner = {}
    for _ in range(depth):
        inner["a"] = {}
        inner = inner["a"]
    return top


def _containing_itself() -> dict:
    data = {"name": "loop"}
    data["self"] = data
    return data


@pytest.mark.parametrize(
    "call, said",
    [
        (lambda: frictionlab.run("quickstart", 5, **FAST), "overrides must be a mapping of dotted keys to values, got int"),
        (lambda: frictionlab.run("quickstart", [("seed", 3)], **FAST), "overrides must be a mapping of dotted keys to values, got list"),
        (lambda: frictionlab.run("quickstart", {3: 1}, **FAST), "key 3 is of type int, not str"),
        (lambda: frictionlab.run("quickstart", {"spectrum": _nested(10_000)}, **FAST), "overrides is nested more than 64 levels deep"),
        (lambda: frictionlab.run(_nested(10_000), **FAST), "preset is nested more than 64 levels deep"),
        (lambda: frictionlab.run(_containing_itself(), **FAST), "preset is nested more than 64 levels deep"),
        (lambda: frictionlab.run({"name": "wide", "x": list(range(30_000))}, **FAST), "preset holds more than 20,000 values"),
        (lambda: frictionlab.run("quickstart", {"seed": object()}, **FAST), "overrides.seed must be a str, number, bool, None, list or mapping, got object"),
        (lambda: frictionlab.run("quickstart", seed={1, 2}, **FAST), "keyword overrides.seed must be a str, number"),
        (lambda: frictionlab.run("quickstart", out=5, **FAST), "out must be a path to a folder to write the run into (a str or pathlib.Path), got int"),
        (lambda: frictionlab.run("quickstart", scheduler=5, **FAST), "scheduler must be a Dask scheduler's address (a str), got int"),
        (lambda: frictionlab.run("quickstart", resume="yes", **FAST), "resume must be True or False, got 'yes' (str)"),
        (lambda: frictionlab.run("quickstart", workers=1, progress=1), "progress must be True or False, got 1 (int)"),
        (lambda: frictionlab.run("", **FAST), "preset must be a path to a preset file, or a built-in's name, got an empty string"),
        (lambda: frictionlab.run("quickstart", {"seed": 3}, overrides={"seed": 4}, **FAST), "overrides given twice"),
        (lambda: frictionlab.run("quickstart", preset="quickstart", **FAST), "preset given twice"),
        (lambda: frictionlab.validate("quickstart", overrides=5), "overrides must be a mapping of dotted keys to values, got int"),
        # run's options copied into validate: named as run's, not as unknown preset fields
        (lambda: frictionlab.validate("quickstart", workers=1, progress=False), "validate takes no workers=, progress=: that is"),
        (lambda: frictionlab.load(None), "folder must be a path to a run folder (a str or pathlib.Path), got NoneType"),
        (lambda: frictionlab.load(""), "folder must be a path to a run folder, got an empty string"),
        (lambda: frictionlab.load("a\0b"), "folder must be a path to a run folder, got a string with a NUL character"),
        # longer than any Linux or macOS file system takes (255 bytes a name): said, not an OSError
        (lambda: frictionlab.run("a" * 300, **FAST), "preset: 'aaa"),
        (lambda: frictionlab.validate("a" * 300), "a file name too long for this file system (at most a name 255 bytes"),
        (lambda: frictionlab.run("quickstart", out="x/" * 3000, **FAST), "out: 'x/x/"),
        (lambda: frictionlab.load("a" * 300), "folder: 'aaa"),
    ],
)
def test_a_wrong_argument_is_a_frictionlab_error_naming_it(call, said):
    with pytest.raises(FrictionlabError) as raised:
        call()
    assert said in str(raised.value)


def test_numpy_numbers_in_a_preset_are_its_numbers_and_its_files_hold_plain_ones(tmp_path):
    """A realizations count or a seed that is a numpy integer (an array's size, a draw) was
    refused as 'must be a str, number, ... got int64'; a float32 load too. They are read as
    the numbers they are, in the preset, its overrides and its sweep, and preset.yaml and
    sweep.json hold plain numbers."""
    data = merge(SMALL_PRESET, {"realizations": np.int64(4), "loading": {"start": np.float32(0.5)}, "output": {"plot": False},
                                "sweep": {"parameters": {"seed": {"values": [np.int64(1), np.uint8(2)]}}}})  # fmt: skip
    swept = frictionlab.run(data, {"fit.bootstrap": np.int32(20)}, out=tmp_path / "sweep", **FAST)
    assert [row["seed"] for row in swept.rows] == [1, 2] and "np." not in (tmp_path / "sweep" / "sweep.json").read_text()
    one = frictionlab.run(merge(data, {"sweep": None}), seed=np.int64(3), out=tmp_path / "one", **FAST)
    stored = yaml.safe_load((tmp_path / "one" / "preset.yaml").read_text())
    assert (stored["realizations"], stored["seed"], stored["fit"]["bootstrap"]) == (4, 3, 200) and one.realizations == (4, 4)
    with pytest.raises(FrictionlabError, match="preset.output.plot must be a str, number, bool, None, list or mapping, got numpy.bool"):
        frictionlab.run(merge(data, {"output": {"plot": np.bool_(False)}}), **FAST)


def test_a_result_plot_names_a_wrong_axes(tmp_path):
    result = frictionlab.run(SMALL_PRESET, realizations=2, **FAST)
    with pytest.raises(FrictionlabError, match="ax must be a matplotlib Axes or None, got int"):
        result.plot(ax=5)
    import matplotlib.pyplot as plt

    figure = plt.figure()
    for projection in ("3d", "polar"):  # a TypeError (3d's fill_between) or a NotImplementedError from inside
        with pytest.raises(FrictionlabError, match=f"ax must be a flat .rectilinear. matplotlib Axes or None, got a "
                                                   f"'{projection}' projection"):
            result.plot(ax=figure.add_subplot(projection=projection))
    plt.close(figure)


def test_api_errors_name_a_built_in_preset_as_the_cli_does(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # no file called quickstart here: the built-in
    with pytest.raises(PresetError) as raised:
        frictionlab.run("quickstart", {"spectrum.params.hurst": 7}, **FAST)
    message = str(raised.value)
    assert message.startswith("built-in preset 'quickstart': 1 problem in preset") and "site-packages" not in message
    assert "quickstart.yaml" not in message
    from frictionlab.cli import main

    assert main(["run", "quickstart", "--set", "spectrum.params.hurst=7"]) == 2
    assert "built-in preset 'quickstart' --set spectrum.params.hurst=7: 1 problem in preset" in capsys.readouterr().err
    (tmp_path / "mine.yaml").write_text((PRESETS / "quickstart.yaml").read_text())
    with pytest.raises(PresetError, match=r"^mine.yaml: 1 problem in preset"):  # a file the user gave: as given
        frictionlab.run("mine.yaml", {"spectrum.params.hurst": 7}, **FAST)


def test_load_reads_a_folder_written_before_the_lines_used_column(tmp_path):
    folder = tmp_path / "run"
    frictionlab.run(SMALL_PRESET, out=folder, plot=False, **FAST)
    curve = folder / "curve.csv"
    rows = [line.split(",") for line in curve.read_text().splitlines()]
    dropped = next(i for i, cell in enumerate(rows[0]) if cell.startswith("lines_used"))
    curve.write_text("\n".join(",".join(r[:dropped] + r[dropped + 1 :]) for r in rows) + "\n")
    old = frictionlab.load(folder)
    assert "lines_used" not in old.table
    assert np.array_equal(old.table["xi"], frictionlab.run(SMALL_PRESET, plot=False, **FAST).table["xi"])
    # a column out of its place is still refused
    curve.write_text("\n".join(",".join([r[1], r[0], *r[2:]]) for r in rows) + "\n")
    with pytest.raises(RunFolderError, match="is damaged"):
        frictionlab.load(folder)


def test_the_units_of_the_columns_are_curve_csvs_in_memory_on_disk_and_in_pandas(tmp_path):
    result = frictionlab.run(SMALL_PRESET, out=tmp_path / "run", plot=False, **FAST)
    header = (tmp_path / "run" / "curve.csv").read_text().splitlines()[0]
    assert f"F [{result.units['F']}]" in header and f"indentation [{result.units['indentation']}]" in header
    assert result.units["F"] == "force: modulus x length^2" and result.units["indentation"].startswith("length")
    assert frictionlab.load(tmp_path / "run").units == result.units
    assert frictionlab.run(SMALL_PRESET, **FAST).units == result.units  # kept in memory: the same
    assert result.to_pandas().attrs["units"] == result.units
    # every column is labelled, those curve.csv gives no brackets too (xi had no entry: a KeyError)
    assert set(result.units) == set(result.table)
    assert result.units["xi"].startswith("dimensionless") and result.units["lines_used"].startswith("count")


STIFFNESS_RAISES = '''
import frictionlab
from tests.testing.fakes import GoodSolver


class Raising(GoodSolver):
    name = "raising-solver"

    def stiffness(self):
        return 1 / 0


@frictionlab.hookimpl
def register_solvers(register):
    register(Raising)
'''


def test_an_exception_in_an_installed_plugin_is_told_as_its_fault_not_raised_raw(fake_dists):  # noqa: F811
    """frictionlab.run and validate raised the plugin's ZeroDivisionError out of frictionlab's
    frames, where the CLI named the plugin. Now both do."""
    from frictionlab.errors import PluginError
    from frictionlab.plugin import registry as registry_module

    fake_dists("acme-raising", "raising", "acme_raising", STIFFNESS_RAISES, "1.2")
    registry_module.default_registry.cache_clear()
    try:
        raising = {"solver.name": "raising-solver", "solver.params": {}}
        for call in (lambda: frictionlab.validate("quickstart", raising),
                     lambda: frictionlab.run("quickstart", raising, workers=1, progress=False, plot=False)):
            with pytest.raises(PluginError) as excinfo:
                call()
            assert str(excinfo.value).startswith("solver 'raising-solver' (acme_raising.Raising from acme-raising) "
                                                 "raised ZeroDivisionError: division by zero in stiffness() at ")
            assert excinfo.value.__suppress_context__ and isinstance(excinfo.value.__context__, ZeroDivisionError)
    finally:
        registry_module.default_registry.cache_clear()


def test_a_refused_scheduler_is_named_as_the_keyword_given_not_the_command_line_option():
    """frictionlab.run(scheduler=...) was told '--scheduler must be ...', an option it has not."""
    with pytest.raises(FrictionlabError) as excinfo:
        frictionlab.run("quickstart", scheduler="nonsense", progress=False, plot=False)
    assert str(excinfo.value) == ("scheduler must be an address like tcp://HOST:PORT or tls://HOST:PORT. "
                                  "Got 'nonsense' instead.")


class _SometimesBroken:
    """A solver whose solve() raises on every other call: realizations 0, 2, 4... of a serial run."""

    calls: list[int]

    def solve(self, profile, loads, control, slopes):
        self.calls.append(1)
        if len(self.calls) % 2:
            raise RuntimeError("this one broke")
        return super().solve(profile, loads, control, slopes)


@pytest.mark.parametrize("realizations", [6, 1])
def test_a_run_with_failed_realizations_is_read_back_not_called_damaged(make_scene, tmp_path, realizations):
    """summary.json counts done (finished) and failed apart; read_summary took done to count the
    failed too, and called any run with a failed realization damaged: load() refused it."""
    from frictionlab.options import RunOptions
    from frictionlab.preset import Scene
    from frictionlab.runs.runner import run_to_folder

    scene = make_scene({"realizations": realizations, "seed": 3})
    broken = type("Sometimes", (_SometimesBroken, type(scene.solver)), {"calls": []})(scene.solver.params)
    scene = Scene(preset=scene.preset, spectrum=scene.spectrum, solver=broken, slope=scene.slope)
    outcome, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, executor="serial"))
    assert len(outcome.failures) == (realizations + 1) // 2 and outcome.done == realizations // 2
    read = frictionlab.load(tmp_path / "run")
    assert read.realizations == (outcome.done, realizations) and read.status == outcome.status


@pytest.mark.parametrize("given", [{"seed": 9}, {"overrides": {"seed": 9}}])
def test_an_override_of_a_swept_path_is_refused(given):
    """run(sweep_over_seed, seed=9) ran seeds 1 and 2, the keyword ignored without a word."""
    preset = merge(SMALL_PRESET, {"sweep": {"parameters": {"seed": {"values": [1, 2]}}}})
    with pytest.raises(PresetError, match="seed: is swept by the preset's sweep, which sets it at each point"):
        frictionlab.validate(preset, **given)
    assert frictionlab.validate(preset, sweep=None, seed=9)["name"] == SMALL_PRESET["name"]  # the preset once


def test_numpy_bools_are_taken_as_flags(tmp_path):
    """A flag computed in a notebook (``array.any()``) is numpy's bool: taken, not refused."""
    result = frictionlab.run("quickstart", realizations=2, workers=1, progress=np.False_, plot=np.bool_(False),
                             out=tmp_path / "run")  # fmt: skip
    assert result.status == "completed"
    assert not (tmp_path / "run" / "plot.png").exists()


@pytest.mark.parametrize("swept", [False, True])
def test_a_resume_into_a_folder_that_is_not_there_is_refused_and_makes_none(tmp_path, swept):
    """The API made the folder, then refused it as holding no run (left behind empty); a sweep's
    resume ran afresh. The CLI (run --resume --out NEW) made nothing."""
    preset = merge(SMALL_PRESET, {"realizations": 2, "output": {"plot": False}})
    if swept:
        preset["sweep"] = {"parameters": {"spectrum.params.hurst": {"values": [0.6, 0.8]}}}
    with pytest.raises(RunFolderError, match="is not a run folder to resume \\(it does not exist"):
        frictionlab.run(preset, out=tmp_path / "new", resume=True, workers=1, progress=False)
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize("overrides", ["seed=3", {"seed": 3}, 5])
def test_overrides_that_are_not_a_list_are_refused_as_such(overrides):
    """load_scene("quickstart", "seed=3") was told letter by letter ("--set 's': must look like
    dotted.path=value", six times); a mapping as "--set 'seed'"; a number as a TypeError."""
    from frictionlab.preset import load_scene

    with pytest.raises(PresetError) as refused:
        load_scene("quickstart", overrides)
    assert refused.value.problems == [f"overrides must be a list of 'dotted.path=value' strings, e.g. ['seed=3']. Got "
                                      f"{overrides!r} ({type(overrides).__name__}) instead"]  # fmt: skip
    assert load_scene("quickstart", ("seed=3",)).preset.seed == 3  # a tuple is a list of them


def test_the_contract_of_an_unknown_kind_names_the_kinds():
    """frictionlab.contract("solvers") raised a bare KeyError: 'solvers'."""
    with pytest.raises(ValueError, match=r"^kind must be one of 'spectrum', 'solver', 'slope'. Got 'solvers' instead.$"):
        frictionlab.contract("solvers")
    assert {"solve", "stiffness"} <= frictionlab.contract("solver")
