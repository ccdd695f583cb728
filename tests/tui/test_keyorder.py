"""Keys typed fast act in the order typed where one of them moves the focus: the keys after it
go where the focus went (Textual ran Tab's, Enter's and Esc's bindings only once the key had
bubbled up, and handed the keys typed meanwhile to the widget focused before)."""

import pytest
import yaml
from textual import events
from textual.widgets import Input, TabbedContent

from frictionlab.tui.screens import PathScreen
from frictionlab.tui.widgets.presets import PresetsPane

from .conftest import SIZE, TINY, make_app, open_first_preset, post_keys, press_settled, record_said, sync, wait_until


@sync
async def test_enter_then_typing_on_the_form_types_into_the_field(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        assert app.focused is form
        post_keys(app, ["enter", *"xy"])
        await wait_until(pilot, lambda: app.query_one("#field--name", Input).value == TINY["name"] + "xy", timeout=10.0)


@pytest.mark.long  # a TUI session with a preset open, twice: seconds (keys in order: the test above)
@pytest.mark.parametrize("arriving", ["one after the other", "joined by the terminal"])
@sync
async def test_esc_then_q_in_a_field_quits_and_never_types_the_q(folders, registry, arriving):
    """Joined: Esc then q within the terminal's escape delay (0.1 s; keystrokes SSH sends
    together) arrive as one alt+q, whose character q the field typed."""
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await open_first_preset(pilot)
        await pilot.press("enter")  # into the name field
        await pilot.pause()
        assert isinstance(app.focused, Input)
        if arriving == "joined by the terminal":
            app.post_message(events.Key("alt+q", "q"))  # what the terminal parser makes of "\x1bq"
        else:
            post_keys(app, ["escape", "q"])
        await wait_until(pilot, lambda: not app.is_running, timeout=10.0)
        assert not app.modified  # the q was never typed into the name


@sync
async def test_enter_esc_q_typed_fast_on_the_form_quits_and_never_types_the_q(folders, registry):
    """In tmux: Enter, Esc, q typed together typed the q into the name: Esc found the form still
    focused (its Focus message not yet handled), so it waited behind the q."""
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await open_first_preset(pilot)
        post_keys(app, ["enter", "escape", "q"])
        await wait_until(pilot, lambda: not app.is_running, timeout=10.0)
        assert app.query_one("#form").data["name"] == TINY["name"] and not app.modified


@sync
async def test_a_letter_esc_q_typed_fast_asks_before_the_edit_is_lost(folders, registry):
    """In tmux: Enter, z, Esc, q typed together quit at once: the z was still on its way through
    the form when q asked whether there were unsaved changes, and the edit was lost unasked."""
    from frictionlab.tui.screens.dialogs import QuitUnsavedScreen

    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await open_first_preset(pilot)
        post_keys(app, ["enter", "z", "escape", "q"])
        await wait_until(pilot, lambda: isinstance(app.screen, QuitUnsavedScreen) or not app.is_running, timeout=10.0)
        asked = isinstance(app.screen, QuitUnsavedScreen)
        await press_settled(pilot, "n")
        kept = app.query_one("#form").data["name"]
    assert asked and kept == TINY["name"] + "z"


@sync
async def test_esc_in_a_field_then_ctrl_r_shows_the_run_tab(folders, registry):
    """Esc focused the form, Ctrl+R showed the Run tab, and the form's late focus message took
    the screen back to the Edit tab: the run went on unseen, and c (cancel) did nothing there."""
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await open_first_preset(pilot)
        await pilot.press("tab")  # into the name field
        post_keys(app, ["escape", "ctrl+r"])
        await wait_until(pilot, lambda: app.running or app.last_outcome is not None)
        for _ in range(5):  # the late messages, if any, arrive
            await pilot.pause(0.05)
        assert app.query_one("#tabs", TabbedContent).active == "run"
        assert app.focused is app.query_one("#run-pane")


@sync
async def test_down_typed_fast_on_the_form_scrolls_a_line_each(folders, registry):
    """Textual's scroll waits for a refresh and starts from where the form was: 20 Downs typed
    fast (a key held down) scrolled the form one line."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        form = app.query_one("#form")
        await wait_until(pilot, lambda: app.focused is form)
        assert form.max_scroll_y > 12
        post_keys(app, ["down"] * 12)
        await wait_until(pilot, lambda: form.scroll_y == 12, timeout=10.0)
        post_keys(app, ["down"] * (form.max_scroll_y + 5))  # past the end: Up then scrolls from the end
        await wait_until(pilot, lambda: form.scroll_y == form.max_scroll_y, timeout=10.0)
        await pilot.press("up")
        await wait_until(pilot, lambda: form.scroll_y == form.max_scroll_y - 1, timeout=10.0)
        post_keys(app, ["pageup"] * 3)
        await wait_until(pilot, lambda: form.scroll_y == 0, timeout=10.0)


@pytest.mark.parametrize(
    ("typed", "keys"),
    [
        ("\x1b\x13", ["escape", "ctrl+s"]),  # Esc then Ctrl+S in a field: it saved and stayed in the field
        ("\x1b\x12", ["escape", "ctrl+r"]),
        ("\x1b\r", ["escape", "enter"]),
        ("a\x1b\x11", ["a", "escape", "ctrl+q"]),
        ("\x1bq", ["alt+q"]),  # unjoined by the app (above), as before
        ("\x1b\x1b[A", ["escape", "up"]),
        ("\x13", ["ctrl+s"]),
    ],
)
def test_the_terminals_parser_keeps_an_escape_joined_to_a_control_key(typed, keys):
    """Esc then a control key read together (within the escape delay, or a busy machine
    reading keys typed 0.15 s apart at once) reached the app as the control key alone."""
    from textual._xterm_parser import XTermParser

    from frictionlab.tui.keyorder import keep_escape_before_control_keys

    keep_escape_before_control_keys()
    parser = XTermParser()
    read = [*parser.feed(typed), *parser.feed("")]
    assert [event.key for event in read if isinstance(event, events.Key)] == keys


@pytest.mark.parametrize(
    "reads",
    [
        ["\x1b[200~red: \x1b[31mx\x1b[0m, q\x1b[201~", "c"],
        list("\x1b[200~red: \x1b[31mx\x1b[0m, q\x1b[201~c"),  # a read a character (a slow link)
        ["\x1b[200~red: \x1b[31mx\x1b", "[0m, q\x1b[20", "1~c"],  # the end marker split between reads
    ],
    ids=["one-read", "by-character", "split"],
)
def test_an_escape_inside_a_paste_stays_in_the_paste(reads):
    """Text pasted with its colour codes: Textual's parser ended the paste at its first ESC and
    made the rest keys, sent before the paste (``^[31mx^[0m, q`` typed into a field, or, where
    no field has the focus, q quitting). The paste is whole; the keys after it are keys."""
    from textual._xterm_parser import XTermParser

    from frictionlab.tui.keyorder import keep_escape_before_control_keys, paste_keeps_escapes

    keep_escape_before_control_keys()
    paste_keeps_escapes()
    parser = XTermParser()
    read = [event for data in [*reads, ""] for event in parser.feed(data)]
    assert [(type(e).__name__, getattr(e, "text", getattr(e, "key", None))) for e in read] == [
        ("Paste", "red: \x1b[31mx\x1b[0m, q"), ("Key", "c")]


@pytest.mark.parametrize(
    ("keys", "name", "path"),
    [
        (["n", *"rough", "enter"], "rough", "presets/rough.yaml"),  # the name typed into New as it opens
        (["d", "ctrl+u", *"presets/mine", "enter"], "mine", "presets/mine.yaml"),  # Duplicate's file (its name)
    ],
    ids=["new", "duplicate"],
)
@pytest.mark.long  # a TUI session each (keys in order: the first test)
@sync
async def test_keys_typed_as_a_dialog_opens_are_typed_into_it(folders, registry, keys, name, path):
    """n or d then typing at once (keys a terminal or SSH delivers together): the keys came
    before the dialog's field had the focus, went to the list behind it and were lost; New
    then made my-scene, the name it offers."""
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        post_keys(app, keys)
        await wait_until(pilot, lambda: app.draft_path is not None, timeout=10.0)
        await pilot.pause()
        opened = (app.query_one("#field--name", Input).value, str(app.draft_path))
    assert opened == (name, path)


@sync
async def test_arrows_then_d_typed_fast_duplicate_the_row_the_arrows_went_to(folders, registry):
    """Down Down d typed together duplicated the first row: d ran at once while the arrows still
    bubbled up to the list's bindings, so the cursor had not moved yet (and the dialog took them)."""
    for name in ("b-second", "c-third"):
        (folders / "presets" / f"{name}.yaml").write_text(yaml.safe_dump({**TINY, "name": name}, sort_keys=False))
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        names = [entry.path.stem for entry in app.query_one(PresetsPane).presets]
        post_keys(app, ["home", "down", "down", "d"])
        await wait_until(pilot, lambda: isinstance(app.screen, PathScreen), timeout=10.0)
        asked = app.screen.title_text
    assert names[:3] == ["b-second", "c-third", "tiny"]
    assert asked.startswith("Duplicate tiny.yaml")



@sync
async def test_keys_a_field_handles_after_tab_moved_the_focus_are_kept(folders, registry):
    """Keys typed fast then Tab: the app hands the letters to the field's queue and runs Tab at
    once, so the field types them once the focus has moved on. Their edit was taken for the
    Changed that mounting a field posts and dropped: the field showed "big" while the preset
    held it empty (Ctrl+S saved no name, Ctrl+R refused one the screen showed)."""
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        name = app.query_one("#field--name", Input)
        await pilot.press("enter", "tab")  # into the name, then on to the next field
        await pilot.pause()
        assert app.focused is not name
        for key in ["ctrl+u", *"big"]:  # handed to the name before Tab, handled by it after
            name.post_message(events.Key(key, None if key == "ctrl+u" else key))
        name.post_message(events.Paste("-2"))  # a paste, the same
        await wait_until(pilot, lambda: name.value == "big-2", timeout=10.0)
        await pilot.pause()
        kept, problems = form.data["name"], form.problems
    assert (kept, problems) == ("big-2", [])


@pytest.mark.parametrize("after", [["question_mark"], ["f1"], ["n"], ["d"], ["2", "question_mark"]])
@sync
async def test_keys_typed_after_q_are_dropped_not_answered_on_a_closing_screen(folders, registry, after):
    """In tmux: q then ? typed together quit with a traceback and exit code 1 (MountError: the
    keys panel mounted on the screen being removed); the keys after the quit are never read."""
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await open_first_preset(pilot)
        await press_settled(pilot, "f2")
        post_keys(app, ["q", *after])
        await wait_until(pilot, lambda: not app.is_running, timeout=10.0)
    assert app.return_code == 0


async def realizations_typed_then(pilot, value: str, key: str) -> list[str]:
    """The first preset open, ``value`` typed into its realizations, then Esc and ``key`` posted in
    one burst, as a terminal delivers keys typed fast; the list of what the app says from then."""
    app = pilot.app
    await open_first_preset(pilot)
    app.query_one("#field--realizations", Input).focus()
    await pilot.pause()
    said = record_said(app)
    post_keys(app, ["end", "ctrl+u", *value, "escape", key])
    return said


@pytest.mark.parametrize("value", ["0", "12"], ids=["a-problem", "valid"])
@sync
async def test_a_value_typed_then_esc_and_ctrl_s_at_once_is_the_one_saved(folders, registry, value):
    """In tmux: -3 typed into points, then Esc and Ctrl+S, saved points: -3 without the question a
    preset with problems asks first: the field's edit was still on its way to the app when Ctrl+S
    (run at once) read the preset's problems. Typed together, the value saved is the one the field
    shows, asked about when it is a problem."""
    from frictionlab.tui.screens import ConfirmScreen

    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        said = await realizations_typed_then(pilot, value, "ctrl+s")
        await wait_until(pilot, lambda: isinstance(app.screen, ConfirmScreen) or any(s.startswith("Saved") for s in said), timeout=10.0)
        await pilot.pause()
        asked, modified = isinstance(app.screen, ConfirmScreen), app.modified
        saved = yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())["realizations"]
    assert (asked, modified, saved) == ((True, True, TINY["realizations"]) if value == "0" else (False, False, int(value)))


@sync
async def test_a_problem_typed_then_esc_and_ctrl_r_at_once_runs_nothing(folders, registry):
    """The same for Ctrl+R: the run started from the preset as it was before the value typed, which
    the field showed refused (realizations 0) while the run went on with the old one."""
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        said = await realizations_typed_then(pilot, "0", "ctrl+r")
        await wait_until(pilot, lambda: app.running or app.last_outcome is not None or bool(said), timeout=10.0)
        started = app.running or app.last_outcome is not None
        if app.running:
            app.followed.cancel()
            await wait_until(pilot, lambda: app.followed is None)
    assert not started and not (folders / "runs").exists()
    assert said[0].startswith("realizations: must be >= 1")
