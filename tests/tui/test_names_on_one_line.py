"""A file name typed into the TUI with a line break, a tab or an escape code is said on one
line of the status line, escaped: 'Saved presets/p' and a second line 'x.yaml' read as two
messages, and a tab pushed the rest of the line aside."""

import sys

import pytest
from textual.widgets import Input

from .conftest import make_app, press_settled, started, status_text, sync

NAME = "p\n\t\x1b[31mx.yaml"


@pytest.mark.skipif(sys.platform == "win32", reason="control characters in file names")
@sync
async def test_the_status_line_after_save_as_names_the_file_on_one_line(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        await press_settled(pilot, "ctrl+o")
        app.screen.query_one(Input).value = f"presets/{NAME}"
        await press_settled(pilot, "enter")
        said = status_text(app)
    assert (folders / "presets" / NAME).is_file()
    assert "Saved presets/p\\n\\t\\x1b[31mx.yaml" in said and "\n" not in said and "\x1b" not in said, said


@pytest.mark.skipif(sys.platform == "win32", reason="control characters in file names")
@sync
async def test_the_presets_and_results_lists_name_a_file_on_one_row(folders, registry):
    """A preset file or run folder named with a line break took two rows of its list (or drove
    the terminal with its escape code)."""
    import shutil

    from frictionlab.tui.widgets.presets import PresetsPane

    shutil.copy(folders / "presets" / "tiny.yaml", folders / "presets" / NAME)
    app = make_app(registry)
    async with started(app) as pilot:
        table = app.query_one(PresetsPane).query_one("#preset-table")
        rows = [" ".join(str(cell) for cell in table.get_row_at(i)) for i in range(table.row_count)]
        await pilot.pause()
    odd = [row for row in rows if row.endswith("p\\n\\t\\x1b[31mx.yaml")]
    assert odd and not any("\n" in row or "\x1b" in row for row in rows), rows


OSC = "\x1b]0;PWNED\x07"  # sets the terminal's title; its BEL dropped, it swallowed the text after it


@pytest.mark.skipif(sys.platform == "win32", reason="control characters in file names")
@sync
async def test_a_preset_s_own_text_with_escape_codes_is_drawn_as_text_everywhere(folders, registry):
    """The preset's description under the list, its path line and the Edit form's fields wrote
    the file's escape codes to the terminal (the pane's title changed, the screen was cleared)."""
    import yaml

    from frictionlab.tui.widgets.pathline import PathLine
    from frictionlab.tui.widgets.presets import PresetsPane

    data = yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())
    data.update(name=f"red\x1b[31m{OSC}", description=f"A {OSC} B\x1b[2J")
    odd = folders / "presets" / f"f{OSC}.yaml"
    odd.write_text(yaml.safe_dump(data))
    app = make_app(registry)
    async with started(app) as pilot:
        pane = app.query_one(PresetsPane)
        pane.highlight(odd)
        await pilot.pause()
        drawn = [str(pane.query_one("#preset-info").render()), str(pane.query_one("#preset-path", PathLine).render())]
        await press_settled(pilot, "enter")  # opens it in the Edit tab's form
        drawn += [field.value for field in app.query(Input)]
    assert any("A \\x1b]0;PWNED\\x07 B\\x1b[2J" in text for text in drawn), drawn  # the description
    assert any("\\x1b]0;PWNED\\x07.yaml" in text for text in drawn), drawn  # the path line
    assert any(text.startswith("red\\x1b[31m") for text in drawn), drawn  # the name's field
    assert not any("\x1b" in text or "\x07" in text for text in drawn), drawn


@sync
async def test_a_question_quoting_an_escape_code_draws_it_as_text(folders, registry):
    from textual.widgets import Static

    from frictionlab.tui.screens.dialogs import ConfirmScreen

    app = make_app(registry)
    async with started(app) as pilot:
        app.push_screen(ConfirmScreen(f"Discard presets/f{OSC}.yaml?"))
        await pilot.pause()
        drawn = [str(static.render()) for static in app.screen.query(Static)]
    assert any("presets/f\\x1b]0;PWNED\\x07.yaml" in text for text in drawn), drawn
    assert not any("\x1b" in text for text in drawn), drawn
