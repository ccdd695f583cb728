"""What a first-time user trips over (issue 36), each read from the screen: keys that do
what the footer says, every run listed as it starts, damaged folders named, resume
offered wherever a run can be resumed."""

import pytest

from frictionlab.tui.widgets import ResultsPane

from .conftest import SIZE, make_app, make_runs, screen_text, status_text, sync, wait_until


@pytest.mark.long
@sync
async def test_damaged_run_folders_are_listed_with_their_reason(folders, registry):
    make_runs(folders, registry)
    runs = folders / "runs"
    (runs / "seed1" / "summary.json").write_text("{junk")
    (runs / "seed2" / "summary.json").unlink()
    (runs / "seed2" / "summary.json").symlink_to(folders / "presets" / "tiny.yaml")
    (runs / "sw").mkdir()
    (runs / "sw" / "sweep.json").write_text("not a sweep")
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("f5")
        await pilot.pause()
        pane = app.query_one(ResultsPane)
        assert {e.path.name: e.status for e in pane.runs} == {"seed1": "damaged", "seed2": "damaged", "sw": "damaged"}
        screen = screen_text(app)
        for name in ("seed1", "seed2", "sw"):
            line = next(line for line in screen.splitlines() if f" {name} " in line)
            assert "✗" in line and "damaged" in line, line
        row = [e.path.name for e in pane.runs].index("seed2")
        await pilot.press(*["down"] * row, "enter")
        await pilot.pause()
        assert "seed2 is damaged: summary.json" in status_text(app) and "link" in status_text(app)
