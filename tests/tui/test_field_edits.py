"""What a form field does with what is typed or pasted into it, as a user in a terminal does it."""

from textual import events
from textual.widgets import Input

from .conftest import SIZE, make_app, open_first_preset, sync, wait_until


async def pasted_into_description(app, pilot, text: str):
    """The first preset opened, ``text`` pasted into its description field: (form, field) once taken."""
    form = await open_first_preset(pilot)
    field = app.query_one("#field--description", Input)
    field.focus()
    await pilot.pause()
    field.post_message(events.Paste(text))
    await wait_until(pilot, lambda: form.data.get("description") is not None, timeout=10.0)
    await pilot.pause()
    return form, field


@sync
async def test_a_paste_of_several_lines_is_kept_whole_on_the_fields_one_line(folders, registry):
    """Textual's Input kept a paste's first line only: a description pasted as a paragraph lost
    the rest of it, and nothing said so."""
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form, field = await pasted_into_description(app, pilot, "Rough line,\n  pressed flat\r\n\nin a second.")
        shown, kept = field.value, form.data["description"]
    assert shown == kept == "Rough line, pressed flat in a second."


@sync
async def test_problems_past_the_panels_six_rows_are_reached_with_the_wheel(folders, registry):
    """A preset with six problems showed five under the form and cut the sixth, with no scroll
    bar nor wheel to reach it."""
    import yaml
    from textual.geometry import Region

    from .conftest import screen_text
    from .test_results import wheel_read

    bad = {"name": 5, "seed": -1, "realizations": "many", "spectrum": 3, "solver": {"name": "nosuch"},
           "loading": {"start": 1, "stop": 0.5, "steps": 1e9}}  # fmt: skip
    (folders / "presets" / "bad.yaml").write_text(yaml.safe_dump(bad))
    app = make_app(registry, preset="presets/bad.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        rows = screen_text(app).splitlines()
        top = next(i for i, row in enumerate(rows) if "problems (as frictionlab validate says)" in row)
        last = "".join(app.problems[-1].split())
        shown_first = last in "".join(screen_text(app).split())
        seen = await wheel_read(pilot, Region(0, top, SIZE[0], SIZE[1] - 2 - top))  # above the status line and footer
    assert len(app.problems) >= 6 and not shown_first
    assert any(last in rows for rows in seen), (last, seen[-1])


@sync
async def test_control_characters_pasted_are_left_out_and_said(folders, registry):
    """A paste's ESC, BEL or colour code went into the field raw and was saved so into the preset:
    a file frictionlab could no longer read (``character #x0007 is not allowed``), or (a BEL in a
    folded description) a character lost. They are left out, a tab becomes a space, and the status
    line names the field and what was left out."""
    from frictionlab.io.safe_yaml import load_yaml

    from .conftest import press_settled, status_text

    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form, field = await pasted_into_description(app, pilot, "Rough\x1b[31m line\x07,\tflat\x7f\x9b")
        said = status_text(app)
        await press_settled(pilot, "escape", "ctrl+s")
    saved = load_yaml((folders / "presets" / "tiny.yaml").read_text(encoding="utf-8"))
    assert saved["description"] == field.value == "Rough[31m line, flat"
    assert "description" in said and "\\x1b" in said and "\\x07" in said, said


@sync
async def test_control_characters_pasted_into_a_dialogs_field_are_said_in_the_dialog(folders, registry):
    """The status line, where the form's field says what a paste left out, is under a dialog
    that fills a 30x8 screen: the dialog says it in its own error line."""
    from .conftest import press_settled

    app = make_app(registry)
    async with app.run_test(size=(30, 8)) as pilot:
        await press_settled(pilot, "n")
        field = app.screen.query_one("#new-name", Input)
        field.post_message(events.Paste("\x1b[1mrough"))
        await pilot.pause()
        await pilot.pause()
        line = app.screen.query_one("#new-error")
        said = " ".join(str(line.render()).split()) if line.display else ""
    assert field.value.endswith("[1mrough"), field.value
    assert "name: the paste's control characters \\x1b" in said, said


@sync
async def test_a_choice_left_unset_says_so_as_a_text_field_does(folders, registry):
    """In tmux: a measured profile's unit and detrend, which the preset leaves to their default,
    showed Textual's prompt "Select" as if that were their value, where a text field left unset
    says "default: not set"."""
    import yaml

    from .conftest import TINY, merge, screen_text

    profile = {"name": "profile-file", "params": {"path": "heights.csv"}}
    (folders / "presets" / "tiny.yaml").write_text(yaml.safe_dump(merge(TINY, {"spectrum": profile}), sort_keys=False))
    app = make_app(registry)
    async with app.run_test(size=(100, 40)) as pilot:
        await open_first_preset(pilot)
        await pilot.pause()
        rows = {line.split()[0]: line.split()[1:] for line in screen_text(app).splitlines() if line.split()}
    assert rows["unit"][:3] == ["default:", "not", "set"] and rows["detrend"][:3] == ["default:", "not", "set"]


@sync
async def test_choosing_the_plugin_a_misspelt_name_meant_keeps_its_parameters(folders, registry):
    """In tmux: a preset whose spectrum said power-lawz (a typo), its hurst and points given,
    opened with the name unset; choosing power-law from the list dropped every parameter the
    file gave (hurst and points then 'is required'), unasked."""
    import yaml

    from .conftest import TINY, choose, merge

    typo = merge(TINY, {"spectrum": {"name": "power-lawz"}})
    (folders / "presets" / "tiny.yaml").write_text(yaml.safe_dump(typo, sort_keys=False))
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        await choose(pilot, "plugin--spectrum", "power-law")
        kept, problems = form.data["spectrum"], form.problems
        shown = app.query_one("#field--spectrum--params--hurst", Input).value
    assert (kept, problems, shown) == (TINY["spectrum"], [], str(TINY["spectrum"]["params"]["hurst"]))


@sync
async def test_enter_in_a_text_field_leaves_it_and_f1_lists_what_its_keys_do(folders, registry):
    """In tmux: a value typed, then Enter, left the cursor in the field and said nothing: F1 listed
    Enter there as Submit, which did nothing, and Up and Down as a scroll of the one-line field,
    where they go to the field above and below."""
    from .conftest import press_settled

    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        field = app.query_one("#field--realizations", Input)
        field.focus()
        await pilot.pause()
        listed = {binding.key: binding.description for _, binding, enabled, _ in app.active_bindings.values() if enabled}
        await press_settled(pilot, "ctrl+u", *"12", "enter")
        left, kept = app.focused is form, form.data["realizations"]
        await press_settled(pilot, "enter", "down")  # back in, and on to the field below
        below = app.focused.id
    assert (left, kept) == (True, 12)
    assert (listed["enter"], listed["up"], listed["down"]) == ("Done", "Field above", "Field below")
    assert below == "plugin--spectrum"


@sync
async def test_switching_between_plugins_keeps_the_parameters_both_have_unless_they_differ_in_kind(folders, registry):
    """Found by a newcomer: power-law to rolloff left hurst and points blank ('is required'),
    though both take them. They are kept; not from a line's spectrum to a surface's (a line's
    points are not a surface's), nor into a file's (its spacing is the file's own)."""
    from .conftest import TINY, choose

    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        await choose(pilot, "plugin--spectrum", "rolloff")
        rolloff = dict(form.data["spectrum"]["params"])
        await choose(pilot, "plugin--spectrum", "power-law-2d")
        surface = dict(form.data["spectrum"]["params"])
        await choose(pilot, "plugin--spectrum", "profile-file")
        measured = dict(form.data["spectrum"]["params"])
        await choose(pilot, "plugin--spectrum", "power-law")
        back = dict(form.data["spectrum"]["params"])
    assert rolloff == TINY["spectrum"]["params"]  # each of power-law's is rolloff's too
    assert surface == {} and measured == {}
    assert back == TINY["spectrum"]["params"]  # its own, kept aside as it was left


@sync
async def test_a_letter_typed_in_a_choice_field_is_not_one_of_the_app_s_keys(folders, registry):
    """Found by a newcomer: with a choice field focused (the footer saying "esc Leave field"), q quit
    the app at once and the rest of what was typed went to the shell; 2 went to the Presets tab."""
    from textual.widgets import Select

    from .conftest import press_settled, status_text

    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await open_first_preset(pilot)
        field = app.query_one("#plugin--spectrum", Select)
        field.focus()
        await pilot.pause()
        before = field.value
        await press_settled(pilot, "q", "2")
        assert app.is_running and app.focused is field and field.value == before
        assert "'2' types nothing in this field: Enter or Space changes it, Esc leaves it" in status_text(app)
        await press_settled(pilot, "space")  # its own key still opens its list
        assert field.expanded
