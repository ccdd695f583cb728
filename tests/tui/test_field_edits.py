"""What a form field does with what is typed or pasted into it, as a user in a terminal does it."""

from textual import events
from textual.widgets import Input

from .conftest import SIZE, make_app, open_first_preset, sync, wait_until


@sync
async def test_a_paste_of_several_lines_is_kept_whole_on_the_fields_one_line(folders, registry):
    """Textual's Input kept a paste's first line only: a description pasted as a paragraph lost
    the rest of it, and nothing said so."""
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        field = app.query_one("#field--description", Input)
        field.focus()
        await pilot.pause()
        field.post_message(events.Paste("Rough line,\n  pressed flat\r\n\nin a second."))
        await wait_until(pilot, lambda: form.data.get("description") is not None, timeout=10.0)
        await pilot.pause()
        shown, kept = field.value, form.data["description"]
    assert shown == kept == "Rough line, pressed flat in a second."
