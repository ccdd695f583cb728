"""What happens around the TUI while it is open: its preset's file written by another program (an
editor, a second TUI), a presets folder it cannot write in, a run folder removed while shown."""

import pytest
import yaml

from ..conftest import merge
from .conftest import TINY, make_app, press_settled, screen_text, started, status_text, sync, type_into, wait_until


def _seed_written_by_another(folders, seed=41):
    """tiny.yaml as another program leaves it: its seed changed, a comment added."""
    path = folders / "presets" / "tiny.yaml"
    path.write_text("# edited elsewhere\n" + yaml.safe_dump(merge(TINY, {"seed": seed}), sort_keys=False))


@pytest.mark.long
@sync
async def test_ctrl_s_asks_before_it_replaces_a_preset_file_another_program_changed(folders, registry):
    app = make_app(registry, preset="presets/tiny.yaml")
    async with started(app) as pilot:
        _seed_written_by_another(folders)
        await wait_until(pilot, lambda: "changed on disk" in status_text(app))  # said as it happens
        assert "Ctrl+S asks before replacing it" in status_text(app)
        await type_into(pilot, "field--realizations", "7")
        await pilot.press("escape")
        await press_settled(pilot, "ctrl+s")
        assert "was changed on disk since it was opened here" in screen_text(app)
        await press_settled(pilot, "n")  # kept as the other program wrote it
        assert yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())["seed"] == 41
        assert app.modified
        await press_settled(pilot, "ctrl+s")
        await press_settled(pilot, "y")  # replaced, as asked
        saved = yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())
        assert (saved["seed"], saved["realizations"]) == (TINY["seed"], 7) and not app.modified
        await type_into(pilot, "field--realizations", "8")
        await pilot.press("escape")
        await press_settled(pilot, "ctrl+s")  # its own write since: saved without a question
        assert yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())["realizations"] == 8
        assert status_text(app) == "Saved presets/tiny.yaml"
