"""What a person sees and what each key does, checked on the screen itself (its
text at 80x24 or 120x40), not only in the app's state: text shown verbatim,
names and paths that fit, messages in the status line, focus where the problem
is, no keystroke lost."""

import asyncio
import json
from pathlib import Path
from typing import ClassVar, Literal

import numpy as np
import pytest
import yaml
from pydantic import Field
from textual.widgets import Input

from frictionlab import PluginParams, SlopeEstimator
from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab.options import RunOptions
from frictionlab.preset import load_scene
from frictionlab.preset.builtin import find_builtin
from frictionlab.tui.app import FrictionlabApp
from frictionlab.tui.screens import PathScreen

from ..conftest import merge
from .conftest import (
    SIZE, TINY, fits_width, make_app, make_runs, new_preset, open_first_preset, post_keys, press_run, press_settled,
    run_to_the_end, runs_app, screen_text, started, status_text, sync, type_into, wait_until,
)

BIG = (120, 40)
BRACKETS = "Uses [bold] and [1] as written; [red]not red[/red] either."


def write_preset(folder, name, data):
    (folder / "presets" / f"{name}.yaml").write_text(yaml.safe_dump(data, sort_keys=False))


# ------------------------------------------------------------------ text shown verbatim


class BracketSlope(SlopeEstimator):
    """A third-party plugin whose summary has square brackets (a citation, a markup tag)."""

    name: ClassVar[str] = "bracket-difference"
    summary: ClassVar[str] = "forward difference as in [1]; [bold]not bold[/bold]"

    class Params(PluginParams):
        ends: Literal["wrap [1]", "[b]cut[/b]"] = Field("[b]cut[/b]", description="ends of the line, as in [2]")

    def slopes(self, heights, spacing, periodic=True):
        return np.diff(heights, append=heights[:1]) / spacing


@sync
async def test_descriptions_summaries_and_names_show_their_brackets(folders, register_plugin):
    registry = register_plugin(BracketSlope)
    write_preset(folders, "tiny", merge(TINY, {"description": BRACKETS, "slope": {"name": "bracket-difference"}}))
    make_runs(folders, registry)
    (folders / "runs" / "seed1").rename(folders / "runs" / "try[1]")
    app = make_app(registry)
    async with started(app, size=BIG) as pilot:
        presets_tab = screen_text(app)
        await open_first_preset(pilot)
        app.query_one("#field--slope--params--ends").focus()  # the plugin's summary is above its first field
        await pilot.pause()
        edit_tab = screen_text(app)
        await press_settled(pilot, "f5")
        results_tab = screen_text(app)
    assert BRACKETS in presets_tab
    assert BracketSlope.summary in edit_tab
    assert "[b]cut[/b]" in edit_tab  # a choice's text
    assert "ends of the line, as in [2]" in edit_tab  # a description, in the help line
    assert "try[1]" in results_tab


# ------------------------------------------------------------------ layouts that fit and grow


LONG_NAME = "a-longer-study-20261125-210620"
MID = (100, 30)


@pytest.mark.parametrize("size", [SIZE, MID, BIG])
@sync
async def test_run_names_use_the_width_they_have(folders, registry, size):
    """Found by a new user: at 100 columns `quickstart…1125-235755` with half the
    screen free; the list now widens for its names while the plot keeps 40 columns."""
    make_runs(folders, registry)
    (folders / "runs" / "seed1").rename(folders / "runs" / LONG_NAME)
    (folders / "runs" / "seed2").rename(folders / "runs" / ("x" * 70 + "-20261125-235755"))
    app = make_app(registry)
    async with started(app, size=size) as pilot:
        await press_settled(pilot, "f5")
        shown = screen_text(app)
        table, chart = app.query_one("#runs-table"), app.query_one("#results-chart")
        whole, plot_width = fits_width(table), chart.size.width
    if size == SIZE:  # shortened: where it starts and its time stamp stay (the year goes first)
        assert "a-lon…1125-210620" in shown
    else:
        assert LONG_NAME in shown  # 30 characters: whole at 100 columns and more
    assert [line for line in shown.splitlines() if "xxx…" in line and "235755 " in line]  # too long: shortened
    assert whole and plot_width >= 40


@sync
async def test_the_run_header_shows_the_output_folder_at_80_columns(folders, registry, tmp_path):
    deep = tmp_path / "a-folder-with-a-long-name" / "and-another-one-below-it" / "runs"
    app = make_app(registry, preset="presets/tiny.yaml")
    app.runs_dir = deep
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        shown = screen_text(app)
        out_dir = app.last_out_dir
    assert len(str(out_dir)) > 80
    assert out_dir.name in shown  # the end of the path: the run's own folder
    assert str(out_dir)[:10] in shown  # and where it starts


@sync
async def test_a_long_description_is_shown_from_its_start(folders, registry):
    description = "Starts here: " + " ".join(f"word{i}" for i in range(40)) + " ends here."
    write_preset(folders, "tiny", merge(TINY, {"description": description}))
    app = make_app(registry)
    async with started(app) as pilot:
        assert "Starts here: word0" in screen_text(app)  # the presets list's line about it
        await open_first_preset(pilot)
        app.query_one("#field--description", Input).focus()
        await pilot.pause()
        shown = screen_text(app)
    assert "Starts here: word0" in shown


@sync
async def test_messages_never_cover_the_data(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await run_to_the_end(pilot)
        toasts = list(app.query("Toast"))
        status = status_text(app)
        fit = str(app.query_one("#run-fit").render())
        shown = screen_text(app)
    assert toasts == []
    assert status.startswith("Run completed: 8/8 realizations")
    assert all(line in shown for line in fit.splitlines()[:4])  # the fit is on screen, whole


# ------------------------------------------------------------------ keys


@sync
async def test_ctrl_r_with_a_problem_says_it_and_focuses_the_field_at_fault(folders, registry):
    write_preset(folders, "tiny", merge(TINY, {"spectrum": {"params": {"rms_height": -1.0}}}))
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        app.query_one("#field--seed").focus()
        await press_settled(pilot, "f4", "ctrl+r")
        pointed = app.focused.id  # the form: q, ? still act, nothing types into the field
        status = status_text(app)
        shown = screen_text(app)
        await pilot.press("enter")  # into the field at fault
        focused = app.focused.id
    assert pointed == "form" and focused == "field--spectrum--params--rms_height"
    assert status == "Cannot run: 1 problem: spectrum.params.rms_height: must be > 0.0, got -1.0"
    assert "rms_height" in shown and "-1.0" in shown  # the field scrolled into view


@sync
async def test_the_status_takes_back_why_ctrl_r_refused_once_that_problem_is_fixed(folders, registry):
    """Found by a new user: `Cannot run: 1 problem: realizations: ...` stayed after the
    value was fixed and the form said valid."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await type_into(pilot, "field--realizations", "abc")
        await type_into(pilot, "field--seed", "x")
        await press_settled(pilot, "ctrl+r")
        refused = screen_text(app)
        await type_into(pilot, "field--realizations", "8")  # the problem the status does not give: it stays
        kept = status_text(app)
        await type_into(pilot, "field--seed", "x2")  # the status's problem gone, another in its field
        fixed = screen_text(app)
    assert "Cannot run: 2 problems: seed: must be a whole number, got 'x'" in refused
    assert kept == "Cannot run: 2 problems: seed: must be a whole number, got 'x'"
    assert "Cannot run" not in fixed and "got 'x2'" in fixed  # the form gives the new one


@sync
async def test_the_status_says_valid_once_the_one_refused_problem_is_fixed(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await type_into(pilot, "field--realizations", "abc")
        await press_settled(pilot, "ctrl+r")
        refused = status_text(app)
        await type_into(pilot, "field--realizations", "8")
        await pilot.pause()
        fixed = screen_text(app)
    assert refused == "Cannot run: 1 problem: realizations: must be a whole number, got 'abc'"
    assert "Cannot run" not in fixed and "The preset is valid: Ctrl+R runs it." in fixed


CANNOT_ACT = [  # pressed one after the other, in an app with no preset and no run
    (["ctrl+r"], "No preset open"),
    (["ctrl+s"], "No preset open"),
    (["ctrl+o"], "No preset open"),
    (["enter"], "No preset to open here"),
    (["d"], "No preset to duplicate here"),
    (["f4", "c"], "No run is going, and no preset is open: F2 lists them"),
    (["f5", "space"], "No runs yet"),
    (["enter"], "No runs yet"),
]


@sync
async def test_every_key_that_cannot_act_says_why(tmp_path, monkeypatch, registry):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "presets").mkdir()  # nothing to open, nothing run
    app = make_app(registry)
    said = []
    async with started(app) as pilot:
        for keys, _ in CANNOT_ACT:
            app.query_one("#status").update("")
            await pilot.press(*keys)
            said.append(status_text(app))
    for (keys, expected), status in zip(CANNOT_ACT, said, strict=True):
        assert status.startswith(expected), (keys, status)


@sync
async def test_c_with_a_preset_open_and_no_run_says_ctrl_r_starts_one(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await pilot.press("f4", "c")
        assert status_text(app).startswith("No run is going: Ctrl+R starts one.")


@sync
async def test_tab_in_the_results_tab_stops_only_where_focus_shows(folders, registry):
    app = runs_app(folders, registry)
    async with started(app) as pilot:
        await pilot.press("f5")
        stops = []
        for _ in range(3):
            await pilot.press("tab")
            stops.append(app.focused.id)
    assert stops == ["runs-table"] * 3


@pytest.mark.parametrize("gap", [0.03, 0.0], ids=["30ms", "burst"])
@sync
async def test_six_keys_typed_into_a_cleared_field_all_arrive(folders, registry, gap):
    """Found in tmux: Ctrl+U and the keys after it in one burst left the field empty.
    Textual ran Ctrl+U's binding only after it bubbled up to the app, by which time
    the printable keys behind it were inserted, and then cleared."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        field = app.query_one("#field--spectrum--params--hurst", Input)
        field.focus()
        await pilot.press("end")
        post_keys(app, ["ctrl+u"])
        for character in "0.7531":
            post_keys(app, [character])
            await asyncio.sleep(gap)
        await wait_until(pilot, lambda: len(field.value) >= 6, timeout=5)
        await pilot.pause()
        value, data = field.value, app.query_one("#form").data
    assert value == "0.7531"
    assert data["spectrum"]["params"]["hurst"] == 0.7531


@sync
async def test_home_then_a_key_types_at_the_start(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        field = app.query_one("#field--name", Input)
        field.focus()
        await pilot.press("end")
        post_keys(app, ["home", "x"])
        await wait_until(pilot, lambda: "x" in field.value, timeout=5)
        value = field.value
    assert value == "xsmall"


@sync
async def test_f1_shows_and_hides_the_key_panel_of_the_focused_part(folders, registry):
    make_runs(folders, registry)  # Results lists Compare with a run to compare
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "f1")
        presets_keys = screen_text(app)
        await press_settled(pilot, "f5")
        results_keys = screen_text(app)
        for _ in range(6):  # F1 again: the next page of a panel taller than 80x24, then hidden
            await press_settled(pilot, "f1")
            if not app.screen.query("HelpPanel"):
                break
        hidden = not app.screen.query("HelpPanel")
    assert "Duplicate" in presets_keys and "Compare" not in presets_keys
    assert "Compare" in results_keys and "Duplicate" not in results_keys
    assert hidden


# ------------------------------------------------------------------ run-time input errors


def profile_preset(folders, content):
    (folders / "presets" / "line.csv").write_text(content)
    data = {**TINY, "spectrum": {"name": "profile-file", "params": {"path": "line.csv", "spacing": 1.0}}}
    write_preset(folders, "tiny", data)


@sync
async def test_a_profile_file_beside_the_preset_is_found_by_the_form(folders, registry):
    profile_preset(folders, "\n".join(str(x) for x in np.random.default_rng(1).normal(size=256)))
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app):
        problems = app.problems
    assert problems == []  # as `frictionlab validate presets/tiny.yaml` says
    assert main(["validate", "presets/tiny.yaml"]) == ExitCode.OK


@sync
async def test_a_missing_profile_file_is_named_and_its_field_focused(folders, registry):
    profile_preset(folders, "1\n2\n")
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        (folders / "presets" / "line.csv").unlink()  # gone after the preset was opened
        await press_settled(pilot, "ctrl+r")
        status, pointed = status_text(app), app.focused.id
        panel = str(app.query_one("#problems").render())
        await pilot.press("enter")
        focused = app.focused.id
    assert not app.running and app.last_out_dir is None
    assert pointed == "form" and focused == "field--spectrum--params--path"
    assert "spectrum.params.path: no such file" in panel  # the form says it too, not "valid"
    assert status.startswith("Cannot run: 1 problem: spectrum.params.path: no such file")
    assert "presets/line.csv'" in status  # the file beside the preset (the core shortens a long path)


@sync
async def test_the_preview_shows_what_an_instrument_file_gave(folders, registry):
    """A valid preset whose spectrum reads an instrument file: the panel says so with the
    line `frictionlab validate` prints (shape, pixel size and its origin, unit, rms height)."""
    from SurfaceTopography import Topography

    z = np.random.default_rng(2).normal(size=(16, 12))
    Topography(z.T.copy(), (12 * 0.5, 16 * 0.5), unit="um").to_netcdf(str(folders / "presets" / "map.nc"))
    spectrum = {"name": "surface-file", "params": {"path": "map.nc", "unit": "nm", "detrend": "mean"}}
    write_preset(folders, "tiny", {**TINY, "spectrum": spectrum, "solver": {"name": "winkler"}})
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app):
        panel = str(app.query_one("#problems").render())
    assert app.problems == [] and panel.startswith("valid: Ctrl+R runs it")
    assert f"read map.nc (Network Common Data Format (NetCDF)): 12 x 16 pixels (x by y) of 500 nm (from the file), rms height " \
           f"{1e3 * np.std(z - z.mean()):.6g} nm, converted from the file's µm" in panel  # fmt: skip


@sync
async def test_the_preview_names_a_file_whose_name_looks_like_markup_as_it_is(folders, registry):
    """The panel took what was read as markup: '[b]map.npy' was drawn as a bold 'map.npy'."""
    np.save(folders / "presets" / "[b]map.npy", np.random.default_rng(2).normal(size=(16, 12)))
    spectrum = {"name": "surface-file", "params": {"path": "[b]map.npy", "unit": "um", "spacing": 0.5}}
    write_preset(folders, "tiny", {**TINY, "spectrum": spectrum, "solver": {"name": "winkler"}})
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app):
        panel = str(app.query_one("#problems").render())
    assert panel.startswith("valid: Ctrl+R runs it") and "read [b]map.npy (.npy)" in panel, panel


@sync
async def test_an_unreadable_profile_file_is_refused_before_a_run_with_its_message(folders, registry):
    """The validator reads a measured profile (as `frictionlab validate` does): Ctrl+R
    refuses the preset with the file's own message instead of running it to fail."""
    profile_preset(folders, "1.0\nabc\n")
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await press_run(pilot)
        await pilot.pause()
        status = status_text(app)
        panel = str(app.query_one("#problems").render())
    assert not app.running and app.last_out_dir is None
    assert status.startswith("Cannot run: 1 problem: spectrum.params: profile-file")
    assert "non-numeric content at line 2" in status and "non-numeric content at line 2" in panel
    assert "ValueError" not in status and ".py:" not in status  # what the user can act on, not the internals


# ------------------------------------------------------------------ New


@sync
async def test_new_starts_from_a_preset_that_runs_and_saves_in_the_presets_folder(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await new_preset(pilot, "fresh")
        problems, path = app.problems, app.draft_path
        assert not (folders / "presets" / "fresh.yaml").exists()  # written on Ctrl+S, where the dialog said
        await press_settled(pilot, "ctrl+s")
    assert problems == []
    assert path == Path("presets/fresh.yaml")  # the folder the list shows
    saved = folders / "presets" / "fresh.yaml"
    quickstart = find_builtin("quickstart").path  # the template offered first: it runs in about a second
    assert yaml.safe_load(saved.read_text()) == {**yaml.safe_load(quickstart.read_text()), "name": "fresh"}
    assert quickstart.read_text().splitlines()[0] in saved.read_text()  # its comments kept
    assert load_scene(saved, registry=registry).preset.name == "fresh"
    assert main(["run", "presets/fresh.yaml", "--out", "runs/fresh", "--quiet", "--workers", "1"]) == ExitCode.OK
    assert json.loads((folders / "runs" / "fresh" / "summary.json").read_text())["status"] == "completed"


@sync
async def test_new_never_replaces_a_file_and_saves_where_the_user_says(folders, registry):
    (folders / "presets" / "fresh.yaml").write_text("keep me\n")
    (folders / "elsewhere").mkdir()
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await new_preset(pilot, "fresh")
        refused = screen_text(app)
        app.screen.query_one("#new-path", Input).focus()
        await press_settled(pilot, "ctrl+u", *"elsewhere/fresh", "enter")
        await press_settled(pilot, "ctrl+s")
    assert "presets/fresh.yaml exists: give another file" in refused  # said in the dialog
    assert (folders / "presets" / "fresh.yaml").read_text() == "keep me\n"
    assert load_scene(folders / "elsewhere" / "fresh.yaml", registry=registry).preset.name == "fresh"


@sync
async def test_ctrl_s_never_replaces_a_file_made_after_the_new_dialog(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await new_preset(pilot, "fresh")
        (folders / "presets" / "fresh.yaml").write_text("keep me\n")  # made meanwhile, by someone else
        await press_settled(pilot, "ctrl+s")
        asked = screen_text(app)
        await press_settled(pilot, "escape")
    assert "presets/fresh.yaml exists now" in asked
    assert (folders / "presets" / "fresh.yaml").read_text() == "keep me\n"


@sync
async def test_the_built_in_presets_are_listed_and_never_written(tmp_path, monkeypatch, registry):
    monkeypatch.chdir(tmp_path)  # no ./presets here: the built-in ones are listed beside the user's
    monkeypatch.setenv("FRICTIONLAB_PRESETS_DIR", str(tmp_path / "mine"))
    quickstart = find_builtin("quickstart").path
    original = quickstart.read_text()
    app = FrictionlabApp(runs_dir="runs", options=RunOptions(workers=1), registry=registry)
    async with started(app, size=BIG) as pilot:
        listed = screen_text(app)
        await app.open_preset(quickstart)
        await type_into(pilot, "field--realizations", "20")
        await press_settled(pilot, "ctrl+s")
        asked = isinstance(app.screen, PathScreen)
        app.screen.query_one(Input).value = "mine.yaml"
        await press_settled(pilot, "enter")
    assert "quickstart" in listed and "built-in" in listed
    assert asked and quickstart.read_text() == original
    assert yaml.safe_load((tmp_path / "mine.yaml").read_text())["realizations"] == 20


def highlighted_path(app) -> str:
    """The path line under the Presets list: the highlighted preset's file."""
    return str(app.query_one("#preset-path").render())


@sync
async def test_a_built_in_presets_copy_goes_by_default_where_the_list_shows_it(tmp_path, monkeypatch, registry):
    """Found by a new user: Ctrl+S on a built-in preset offered ./quickstart.yaml, a
    folder the Presets tab does not list, so the saved preset vanished. Its default is
    now ./presets (made when first saved into), listed, and highlighted after saving."""
    monkeypatch.chdir(tmp_path)  # no ./presets yet
    monkeypatch.setenv("FRICTIONLAB_PRESETS_DIR", str(tmp_path / "mine"))
    quickstart = find_builtin("quickstart").path
    (tmp_path / "presets").mkdir()
    (tmp_path / "presets" / "quickstart.yaml").write_text("keep me\n")  # never replaced unasked
    app = FrictionlabApp(runs_dir="runs", options=RunOptions(workers=1), registry=registry)
    async with started(app, size=BIG) as pilot:
        await app.open_preset(quickstart)
        await press_settled(pilot, "ctrl+s")
        offered = app.screen.query_one(Input).value
        await pilot.press("enter")  # the file exists: the dialog asks a second Enter
        await pilot.pause()
        asked = screen_text(app)
        await press_settled(pilot, "ctrl+u", *"presets/my-qs", "enter")
        await press_settled(pilot, "f2")
        listed, highlighted = screen_text(app), highlighted_path(app)
    assert offered == "presets/quickstart.yaml"
    assert "presets/quickstart.yaml exists: Enter again replaces it" in asked
    assert (tmp_path / "presets" / "quickstart.yaml").read_text() == "keep me\n"
    assert load_scene(tmp_path / "presets" / "my-qs.yaml", registry=registry).preset.name == "quickstart"
    assert "my-qs.yaml" in listed and highlighted == "presets/my-qs.yaml"


@sync
async def test_a_new_preset_goes_by_default_into_the_presets_folder_made_for_it(folders, registry):
    app = FrictionlabApp(presets_dir="mine", runs_dir="runs", options=RunOptions(workers=1), registry=registry)
    async with app.run_test(size=SIZE) as pilot:
        await new_preset(pilot, "fresh")  # --presets mine: a folder that does not exist yet
        await press_settled(pilot, "ctrl+s")
        await press_settled(pilot, "f2")
        listed, highlighted = screen_text(app), highlighted_path(app)
    assert load_scene(folders / "mine" / "fresh.yaml", registry=registry).preset.name == "fresh"
    assert "fresh.yaml" in listed and highlighted == "mine/fresh.yaml"


@sync
async def test_a_runs_folder_that_cannot_be_made_is_named_in_the_status(folders, registry):
    (folders / "runs").write_text("a file where the runs folder should be\n")
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await pilot.press("ctrl+r")
        await wait_until(pilot, lambda: not app.running)
        await pilot.pause()
        status = status_text(app)
        error = str(app.query_one("#run-error").render())
    assert status == "Run failed: runs is a file, not a folder"
    assert "Traceback" not in error and "Error" not in status and not app.last_out_dir
    assert (folders / "runs").read_text().startswith("a file")  # left as it was


# ------------------------------------------------------------------ the help line under the form


@sync
async def test_the_help_line_under_a_field_has_no_doubled_full_stop(folders, registry):
    """Found by a new user: `(M).; allowed: >= 1` and `realizations.npz.; default: True`."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app, size=BIG) as pilot:
        shown = {}
        for field in ("field--realizations", "field--output--realizations"):
            app.query_one(f"#{field}").focus()
            await pilot.pause()
            shown[field] = screen_text(app)
    assert "realizations: Number of independent random lines (M); allowed: >= 1" in shown["field--realizations"]
    assert "Keep per-realization curves in realizations.npz; default: True" in shown["field--output--realizations"]
    # every field's help line is checked for ".;" by test_every_fields_help_is_shown_whole_at_80x24


# ------------------------------------------------------------------ Home and End


def status_mark_line(shown, name):
    return next((line for line in shown.splitlines() if name in line), "")


@sync
async def test_home_and_end_go_to_the_first_and_last_row_of_the_lists(folders, registry):
    """Found by a new user: End did nothing in the Presets list (Ctrl+End did)."""
    for name in ("alpha", "beta", "gamma", "zulu"):
        write_preset(folders, name, merge(TINY, {"name": name, "description": f"the {name} preset"}))
    app = runs_app(folders, registry)
    async with started(app) as pilot:
        await press_settled(pilot, "end")
        at_end = screen_text(app)  # the line about the highlighted preset, under the list
        await press_settled(pilot, "home")
        at_home = screen_text(app)
        await press_settled(pilot, "f5", "end", "enter")
        last_run = screen_text(app)
        await press_settled(pilot, "home", "enter")
        first_run = screen_text(app)
        runs = [entry.path.name for entry in app.query_one("#results-pane").runs]
        await app.open_preset(folders / "presets" / "tiny.yaml")  # Home and End in a text field move its cursor
        field = app.query_one("#field--name", Input)
        field.focus()
        await pilot.press("home")
        post_keys(app, ["end", "x", "home", "y"])
        await wait_until(pilot, lambda: "x" in field.value and "y" in field.value, timeout=5)
        typed = field.value
    assert "the zulu preset" in at_end and "presets/zulu.yaml" in at_end
    assert "the alpha preset" in at_home and "presets/alpha.yaml" in at_home
    assert f"■ {runs[-1]}" in last_run and f"■ {runs[0]}" in first_run  # the overlay names the opened run
    assert typed == "ysmallx"


# ------------------------------------------------------------------ where focus starts


def field_line(shown, label):
    return next(line for line in shown.splitlines() if line.startswith(f"{label} "))


@pytest.mark.parametrize("route", ["list", "command line"])
@sync
async def test_opening_a_preset_either_way_focuses_the_form_and_enter_its_first_field(folders, registry, route):
    """A new user found Tab x3 reached `realizations` after Enter in the list but `name`
    with the preset given on the command line. Either way focus is now on the form (not
    a field: q there quits), Enter goes to `name`, so three Tabs and a number change `realizations`."""
    app = make_app(registry, preset="presets/tiny.yaml" if route == "command line" else None)
    async with app.run_test(size=SIZE) as pilot:
        if route == "list":
            await open_first_preset(pilot)
        await pilot.pause()
        first = app.focused.id
        await press_settled(pilot, "enter")
        entered = app.focused.id
        await press_settled(pilot, "tab", "tab", "tab", "7")
        shown = screen_text(app)
    assert (first, entered) == ("form", "field--name")
    scrollbar = set("▁▂▃▄▅▆▇█")  # the form's scrollbar thumb may share a field's line

    def words(line):
        return [word for word in line.split() if not set(word) <= scrollbar]

    assert words(field_line(shown, "realizations")) == ["realizations", "7"]
    assert words(field_line(shown, "name")) == ["name", "small"]


@sync
async def test_damaged_runs_and_presets_in_its_folders_never_stop_the_tui(folders, registry):
    """Found by a bug hunt: one damaged summary.json in ./runs, or a preset with a 5000-digit
    number, crashed the TUI at start. Each is now listed as far as it can be read, or left out."""
    make_runs(folders, registry)
    good = json.loads((folders / "runs" / "seed1" / "summary.json").read_text())
    damaged = {
        "a-list": [],
        "fit-text": {**good, "fit": "x"},
        "bad-fields": {**good, "fit": {**good["fit"], "a": "x", "a_ci": "zz"}, "normalisation": "x",
                       "contact_count_at_first_load": "many", "realizations": {"done": "lots"}},  # fmt: skip
    }
    for name, summary in damaged.items():
        (folders / "runs" / name).mkdir()
        (folders / "runs" / name / "summary.json").write_text(json.dumps(summary))
    (folders / "runs" / "deep").mkdir()
    (folders / "runs" / "deep" / "summary.json").write_text("[" * 100_000 + "]" * 100_000)
    (folders / "presets" / "huge.yaml").write_text("name: huge\nseed: " + "9" * 5000 + "\n")
    (folders / "presets" / "bomb.yaml").write_text(
        "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
                                                      for p, c in zip("abcdefg", "bcdefgh"))  # fmt: skip
    )
    app = make_app(registry)
    async with started(app, size=BIG) as pilot:
        presets_tab = screen_text(app)
        await press_settled(pilot, "f5")
        for _ in range(6):  # every run into the overlay, one after the other
            await press_settled(pilot, "space", "down")
        results_tab = screen_text(app)
        assert app.is_running
    assert "huge" in presets_tab and "bomb" in presets_tab and "cannot be read" in presets_tab
    assert "seed1" in results_tab and "fit-text" in results_tab and "bad-fields" in results_tab
    for name in ("a-list", "deep"):  # listed as damaged, with its mark: never hidden
        assert any(name in line and "✗" in line and "damaged" in line for line in results_tab.splitlines())


@sync
async def test_every_fields_help_is_shown_whole_at_80x24(folders, registry):
    """Found by a newcomer: at 80x24 the help of height_reference, line_end and loading.unit
    stopped at four lines, before its choices or default. And by a new user: no help line has
    a doubled full stop (`(M).; allowed: >= 1`, `realizations.npz.; default: True`)."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        help_line = app.query_one("#field-help")
        cut, doubled = [], []
        for widget in app.query_one("#form").query("Input, Select, Switch"):
            widget.focus()
            for _ in range(250):  # a loaded machine lays the grown help out a refresh or more later (not a fixed 0.4 s in all)
                await pilot.pause(0.02)
                lines = help_line.content_size.height  # what it shows
                needed = len(help_line.render().wrap(help_line.content_size.width)) if lines else 0
                if needed <= lines:
                    break
            if needed > lines:
                cut.append((widget.id, needed, lines))
            if ".;" in str(help_line.render()):
                doubled.append(widget.id)
    assert not cut, cut
    assert not doubled, doubled
