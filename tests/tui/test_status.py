"""The status line speaks of what is there: a message about a row of a list (a damaged
run, a run that cannot be resumed, a preset that cannot be opened) is taken back once
another row is highlighted (it stayed, under the row it no longer spoke of)."""

import pytest

from .conftest import SIZE, make_app, make_runs, press_settled, started, status_text, sync, wait_until


@pytest.mark.long  # two finished runs made first, then a TUI session: seconds (a message that goes: the test below)
@sync
async def test_a_message_about_a_results_row_goes_when_another_row_is_highlighted(folders, registry):
    make_runs(folders, registry)
    runs = folders / "runs"
    (runs / "seed2" / "summary.json").write_text("{junk")
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await press_settled(pilot, "f5")
        names = [entry.path.name for entry in app.query_one("ResultsPane").runs]
        table = app.query_one("#runs-table")
        table.move_cursor(row=names.index("seed2"))
        await press_settled(pilot, "enter")
        damaged = status_text(app)
        info = str(app.query_one("#results-info").render())
        table.move_cursor(row=names.index("seed1"))
        await pilot.pause()
        after_moving = status_text(app)
        info_after_moving = str(app.query_one("#results-info").render())
        await pilot.press("u")  # a completed run: nothing to resume
        await pilot.pause()
        complete = status_text(app)
        await pilot.press("r")  # the list read again, the same row highlighted: it still speaks of it
        await pilot.pause()
        after_reload = status_text(app)
        table.move_cursor(row=names.index("seed2"))
        await pilot.pause()
        after_moving_back = status_text(app)
    assert "seed2 is damaged" in damaged
    assert after_moving == ""
    assert "summary.json is damaged" in info and "is damaged" not in info_after_moving  # the box beside the plot too
    assert "seed1 is complete" in complete and after_reload == complete
    assert after_moving_back == ""


@sync
async def test_a_preset_that_cannot_be_opened_is_no_longer_named_once_another_is_highlighted(folders, registry):
    (folders / "presets" / "broken.yaml").write_text("name: [unclosed\n")
    app = make_app(registry)
    async with started(app) as pilot:
        pane = app.query_one("PresetsPane")
        rows = {entry.path.name: row for row, entry in enumerate(pane.presets)}
        table = app.query_one("#preset-table")
        table.move_cursor(row=rows["broken.yaml"])
        await pilot.pause()
        await press_settled(pilot, "enter")
        refused = status_text(app)
        table.move_cursor(row=rows["tiny.yaml"])
        await pilot.pause()
        moved = status_text(app)
    assert "Cannot open broken.yaml" in refused
    assert moved == ""


@pytest.mark.long  # a run resumed in a process of its own, seconds end to end
@sync
async def test_a_resume_shows_the_realizations_its_folder_stores_at_once(folders, registry):
    """Not 0 % until the resumed run's process has begun and told its count."""
    import json

    make_runs(folders, registry)
    folder = folders / "runs" / "seed1"
    manifest = json.loads((folder / "run.json").read_text())
    manifest["status"] = "interrupted"  # as a run killed after its last chunk was stored
    (folder / "run.json").write_text(json.dumps(manifest))
    (folder / "summary.json").unlink()
    total = manifest["realizations"]
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("f5")
        app.resume_run(folder)
        bar, stats = app.query_one("#run-bar"), str(app.query_one("#run-stats").render())
        shown = (bar.progress, bar.total)
        await wait_until(pilot, lambda: app.followed is None)
    assert shown == (total, total)
    assert stats == f"{total}/{total} realizations stored (resuming)"


@pytest.mark.long  # a TUI session: seconds
@sync
async def test_new_presets_ctrl_s_message_goes_when_another_preset_opens(folders, registry):
    """`New preset rough.yaml: Ctrl+S saves it as presets/rough.yaml` stayed once the new preset was
    discarded and tiny opened: Ctrl+S then saved tiny.yaml, not what the status line said."""
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "n", "ctrl+u", *"rough", "enter")
        await wait_until(pilot, lambda: app.draft_path is not None)
        said = status_text(app)
        await press_settled(pilot, "f2", "home", "enter")
        await press_settled(pilot, "y")  # discard the new preset's changes
        await wait_until(pilot, lambda: app.draft_path.name == "tiny.yaml")
        await pilot.pause()
        after = status_text(app)
    assert said == "New preset rough.yaml: Ctrl+S saves it as presets/rough.yaml."
    assert after == ""


def test_a_folder_whose_preset_holds_fit_bootstrap_1_is_one_the_tui_can_resume(folders, registry):
    """fit.bootstrap: 1, taken by older versions and now refused, made the TUI refuse the folder's
    stored preset as not valid: it is read as 0 (no intervals), which the resume then says."""
    import json

    import yaml

    from frictionlab.options import RunOptions
    from frictionlab.preset import build_scene
    from frictionlab.runs.rundir import fingerprint
    from frictionlab.runs.runner import run_to_folder

    from .conftest import TINY, merge

    folder = folders / "runs" / "old"
    run_to_folder(build_scene(merge(TINY, {"name": "old"}), registry=registry), folder, RunOptions(workers=1))
    state = json.loads((folder / "run.json").read_text())
    state["preset"]["fit"]["bootstrap"] = 1  # as such a version wrote it
    state["fingerprint"] = fingerprint(state["preset"])
    (folder / "run.json").write_text(json.dumps(state))
    (folder / "preset.yaml").write_text(yaml.safe_dump(state["preset"]))
    scene, sweep = make_app(registry)._stored(folder)
    assert sweep is None and scene.preset.fit.bootstrap == 0
