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
