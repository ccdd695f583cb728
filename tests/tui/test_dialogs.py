"""Dialogs (Save as, New, the questions): what is typed into one is kept, a file is replaced only
when asked twice, and the keys of the screen behind wait until it is closed."""

import pytest
from textual.widgets import Input

from frictionlab.options import RunOptions
from frictionlab.preset.builtin import find_builtin
from frictionlab.tui.app import FrictionlabApp
from frictionlab.tui.screens.dialogs import ConfirmScreen, QuitDuringRunScreen

from .conftest import make_app, press_settled, screen_text, started, status_text, sync


@pytest.mark.long  # a TUI session (dialogs' fast case: the last test)
@sync
async def test_save_as_takes_back_exists_once_another_file_is_typed_and_asks_again_for_it(folders, registry):
    """Save as on a file that exists said 'Enter again replaces it', and said it on under any
    other name typed after; typed back, the first file was then replaced on a single Enter."""
    (folders / "presets" / "other.yaml").write_text("keep me\n")
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "ctrl+o", "ctrl+u", *"presets/other", "enter")
        asked = screen_text(app)
        await press_settled(pilot, "backspace", "backspace")
        retyped = screen_text(app)
        await press_settled(pilot, *"er", "enter")
        asked_again = screen_text(app)
    assert "presets/other.yaml exists: Enter again replaces it" in asked
    assert "exists" not in retyped
    assert "presets/other.yaml exists: Enter again replaces it" in asked_again
    assert (folders / "presets" / "other.yaml").read_text() == "keep me\n"


@pytest.mark.long  # a TUI session (dialogs' fast case: the last test)
@sync
async def test_esc_closes_the_keys_panel_over_a_dialog_and_keeps_what_was_typed(folders, registry):
    """F1 in the New dialog, then Esc: the dialog closed with the panel, and the name typed into
    it was gone (Esc closes the keys panel everywhere else)."""
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "n", *"rough", "f1")
        shown = bool(app.screen.query("HelpPanel"))
        await press_settled(pilot, "escape")
        after_one = (type(app.screen).__name__, bool(app.screen.query("HelpPanel")), app.screen.query_one("#new-name", Input).value)
        await press_settled(pilot, "escape")
        after_two = type(app.screen).__name__
    assert shown
    assert after_one == ("NewPresetScreen", False, "rough")
    assert after_two != "NewPresetScreen"


@sync
async def test_save_run_and_save_as_wait_while_a_dialog_is_open_and_say_so(folders, registry):
    """Ctrl+O in the Save as dialog opened a second one over it (Esc then left one up), and
    Ctrl+R started the preset behind it."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "ctrl+o", "ctrl+o", "ctrl+s", "ctrl+r")
        said = status_text(app)
        dialogs = sum(type(screen).__name__ == "PathScreen" for screen in app.screen_stack)
        await press_settled(pilot, "escape")
        left = type(app.screen).__name__, status_text(app)
    assert dialogs == 1 and left == ("Screen", "")  # the message goes with the dialog
    assert said.startswith("A dialog is open: Enter answers it, Esc closes it")
    assert app.followed is None and not (folders / "runs").exists()  # no run started behind the dialog


@pytest.mark.parametrize("opened_by", ["n", "ctrl+o", "question"])
@sync
async def test_f2_to_f5_wait_while_a_dialog_is_open_and_say_so(folders, registry, opened_by):
    """In tmux: n (New), then F5: the Results tab came up behind the dialog, which stayed open over it;
    so in Save a copy and in a question."""
    app = make_app(registry, preset=None if opened_by == "n" else "presets/tiny.yaml")
    async with started(app) as pilot:
        if opened_by == "question":
            app.push_screen(ConfirmScreen("The open preset has unsaved changes. Discard them?"))
        else:
            await pilot.press(opened_by)
        await pilot.pause()
        dialog, tab = app.screen, app.query_one("#tabs").active
        tabs = []
        for key in ("f2", "f3", "f4", "f5"):
            await press_settled(pilot, key)
            tabs.append((app.query_one("#tabs").active, app.screen is dialog))
        said = status_text(app)
        await press_settled(pilot, "escape", "f5")  # closed: F5 switches again
        after = app.query_one("#tabs").active
    assert tab == ("presets" if opened_by == "n" else "edit")
    assert tabs == [(tab, True)] * 4
    # a question takes y or n: "Enter answers it" sent the user to a key that did nothing there
    answers = "y answers yes, n or Esc no" if opened_by == "question" else "Enter answers it, Esc closes it"
    assert said.startswith(f"A dialog is open: {answers}; then") and "F2 to F5 act" in said
    assert after == "results"


@sync
async def test_enter_on_a_question_says_which_keys_answer_it_and_answers_nothing(folders, registry):
    """In tmux: Enter on 'The open preset has unsaved changes. Discard them?' did nothing, and
    nothing said so (the key table listed Enter as a dialog's Confirm)."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        answers = []
        app.push_screen(ConfirmScreen("The open preset has unsaved changes. Discard them?"), answers.append)
        await pilot.pause()
        await press_settled(pilot, "enter")
        said, still_asked = status_text(app), isinstance(app.screen, ConfirmScreen)
        await press_settled(pilot, "n")
        after = status_text(app)
    assert said == "This question is answered by its keys: y answers yes, n or Esc no." and still_asked
    assert answers == [False] and after == ""


@sync
async def test_dialogs_fit_a_60_column_terminal_and_show_their_keys_whole(folders, registry):
    """At 60x20 the dialogs (72 columns wide) ran past the screen's right edge: the end of a file
    name typed into New, and its cursor, were out of sight, and the quit question's hint ended
    before 'Esc: stay'."""
    app = make_app(registry)
    async with started(app, size=(60, 20)) as pilot:
        await press_settled(pilot, "n", "tab", "tab")
        field = app.screen.query_one("#new-path", Input)
        field.value = "presets/a-rather-long-file-name-for-my-scene.yam"
        await press_settled(pilot, "end", "l")
        dialog = app.screen.query_one(".dialog")
        inside = dialog.region.right <= 60 and field.region.right <= 60
        cursor_x = field.cursor_screen_offset.x
        await press_settled(pilot, "escape")
        app.push_screen(QuitDuringRunScreen("A run is going in runs/x (pid 1), a process of its own."))
        await pilot.pause()
        quit_text = screen_text(app)
    assert inside
    assert cursor_x < 60
    assert "Esc: stay" in quit_text


@pytest.mark.long  # a TUI session: seconds
@sync
async def test_save_as_on_a_built_in_preset_offers_a_copy_and_never_writes_the_shipped_file(
    tmp_path, monkeypatch, registry
):
    """Ctrl+O on a built-in preset offered the shipped file itself, and Enter twice replaced it
    (built-in presets are read and copied, never written)."""
    import frictionlab.tui.folders

    shipped = tmp_path / "shipped"  # a copy: the test never risks the installed presets
    shipped.mkdir()
    original = find_builtin("quickstart").path.read_text()
    (shipped / "quickstart.yaml").write_text(original)
    monkeypatch.setattr(frictionlab.tui.folders, "builtin_folder", lambda: shipped)
    monkeypatch.chdir(tmp_path)
    app = FrictionlabApp(str(shipped / "quickstart.yaml"), runs_dir="runs", options=RunOptions(workers=1),
                         registry=registry)  # fmt: skip
    async with started(app) as pilot:
        await press_settled(pilot, "ctrl+o")
        offered = app.screen.query_one(Input).value
        await press_settled(pilot, "ctrl+u", *str(shipped / "quickstart"), "enter", "enter")
        refused = str(app.screen.query_one("#path-error").render())
        await press_settled(pilot, "ctrl+u", *"presets/qs", "enter")
    assert offered == "presets/quickstart-copy.yaml"
    assert f"path: {shipped / 'quickstart.yaml'} is a built-in preset, never written" in refused
    assert (shipped / "quickstart.yaml").read_text() == original
    assert (tmp_path / "presets" / "qs.yaml").is_file()


@sync
async def test_new_takes_back_its_error_once_the_name_is_retyped(folders, registry):
    """New kept saying "got 'my scene!'" under the name "rough" typed since, until Enter."""
    app = make_app(registry)
    async with started(app) as pilot:
        await press_settled(pilot, "n", "ctrl+u", *"my scene!", "enter")
        said = str(app.screen.query_one("#new-error").render())
        await press_settled(pilot, "ctrl+u", *"rough")
        left = app.screen.query_one("#new-error").display
    assert said.startswith("name: must be 1 to 100 of a-z, A-Z, 0-9") and "got 'my scene!'" in said
    assert not left


@pytest.mark.parametrize(("key", "field", "error"), [("ctrl+o", "#path-input", "#path-error"), ("n", "#new-path", "#new-error")])
@sync
async def test_a_file_name_too_long_for_the_system_is_refused_in_the_dialog(folders, registry, key, field, error):
    """Save as (or New) with a name past the file system's limit (255 bytes) crashed the TUI with a
    traceback (File name too long, from the check that the path is not a folder)."""
    app = make_app(registry, preset="presets/tiny.yaml" if key == "ctrl+o" else None)
    async with started(app) as pilot:
        await press_settled(pilot, key)
        app.screen.query_one(field, Input).value = "presets/" + "y" * 300
        await press_settled(pilot, "enter")
        assert app.is_running
        said = str(app.screen.query_one(error).render())
        assert said.startswith("path: 'presets/yyy") and said.endswith("cannot be a file here (File name too long); give another")
        assert sorted(p.name for p in (folders / "presets").iterdir()) == ["tiny.yaml"]
