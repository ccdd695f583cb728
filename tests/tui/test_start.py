"""The first screen: the Presets tab is drawn before the rest of the app is built (the
other tabs, the plugins, the runs' modules), and a key pressed at once still works."""

import json
import subprocess
import sys

import pytest
from textual.widgets import DataTable

from .conftest import SIZE, TINY, make_app, post_keys, started, sync, wait_until

DRIVES_THE_FIRST_SCREEN = True  # conftest: run_test returns at once, not once the app is built

# what the first screen must not wait for: a run's modules, the comment-keeping YAML
# writer, the live plot's and the other tabs' widgets (each costs tenths of a second)
NOT_ON_THE_FIRST_SCREEN = [
    "frictionlab.runs.detached",
    "frictionlab.runs.progresslog",
    "frictionlab.api",
    "frictionlab.runs.sweep",
    "frictionlab.tui.following",
    "frictionlab.tui.widgets.form",
    "frictionlab.tui.widgets.results",
    "frictionlab.tui.widgets.run",
    "ruamel.yaml",
]


def test_the_app_module_imports_nothing_a_run_needs():
    """``frictionlab tui`` imports these only once its first screen is drawn (in a fresh process:
    this one has imported them all)."""
    code = "import json, sys, frictionlab.tui.app; print(json.dumps(sorted(sys.modules)))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = set(json.loads(done.stdout))
    assert "frictionlab.tui.widgets.presets" in loaded  # the check sees the app's own modules
    assert sorted(loaded & set(NOT_ON_THE_FIRST_SCREEN)) == []


def first_screen(app) -> dict:
    """What the app shows as it paints its first frame."""
    table = app.query_one("#preset-table", DataTable)
    return {
        "tab": app.query_one("#tabs").active,
        "focused": app.focused.id if app.focused else None,
        "presets": [str(table.get_row_at(row)[0]) for row in range(table.row_count)],
        "edit pane": bool(app.query("#edit-pane")),
    }


@sync
async def test_the_first_screen_lists_the_presets_before_the_other_tabs_are_built(folders, registry):
    app = make_app(registry)
    seen, display = [], app._display

    def painted(screen, update):  # each frame goes to the terminal through here (headless: nowhere)
        if not seen and not app._batch_count:
            seen.append(first_screen(app))
        display(screen, update)

    app._display = painted
    async with started(app):
        assert app.query("#edit-pane") and app.query("#runs-table")  # built just after it
    assert seen[0] == {"tab": "presets", "focused": "preset-table", "presets": [TINY["name"]], "edit pane": False}


@sync
async def test_a_key_pressed_as_the_first_screen_appears_is_answered(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        post_keys(app, ["f3"])  # before the other tabs are built: it waits for them
        await wait_until(pilot, lambda: app.built)  # a loaded machine builds the app late
        assert app.query_one("#tabs").active == "edit"
        assert app.focused is app.query_one("#form")
        post_keys(app, ["5"])
        await wait_until(pilot, lambda: app.query_one("#tabs").active == "results", timeout=10.0)


@sync
async def test_q_pressed_as_the_first_screen_appears_quits(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        post_keys(app, ["q"])
        await wait_until(pilot, lambda: not app.is_running)
    assert app.return_code == 0


@pytest.mark.long  # a TUI session that opens a preset: seconds (keys at the first screen: the tests above)
@sync
async def test_enter_typed_before_the_terminal_was_raw_opens_the_highlighted_preset(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        post_keys(app, ["ctrl+j"])  # Enter as the tty hands it on before the app makes it raw
        await wait_until(pilot, lambda: app.built)  # a loaded machine builds the app late
        await wait_until(pilot, lambda: app.query_one("#tabs").active == "edit", timeout=10.0)
        assert app.draft_path is not None and app.draft_path.name == "tiny.yaml"  # the first preset listed


@pytest.mark.long  # a TUI session that opens a preset: seconds
@sync
async def test_keys_typed_before_the_preset_opened_from_the_command_line_is_built_act_in_order(folders, registry):
    """``frictionlab tui PRESET``: Tab then typing, before its Edit form exists, goes into the
    form's first field (the letters were handed to the form, which does not type, and lost)."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        post_keys(app, ["tab", *"abc"])
        await wait_until(pilot, lambda: app.built)
        await wait_until(pilot, lambda: app.query_one("#field--name").value == TINY["name"] + "abc", timeout=10.0)
        await wait_until(pilot, lambda: app.modified, timeout=10.0)  # the form tells the app as it can
