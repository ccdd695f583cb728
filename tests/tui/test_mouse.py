"""A terminal that sends mouse clicks: a tab clicked acts as its F-key does."""

from .conftest import make_app, screen_text, started, sync, wait_until


@sync
async def test_a_tab_clicked_gives_the_keys_to_its_list_or_form(folders, registry):
    """A click on a tab's title left the focus nowhere (the part focused was in the tab it hid):
    Enter on the Presets list then opened nothing, and the footer listed none of its keys."""
    app = make_app(registry)
    async with started(app) as pilot:
        focused = {}
        for tab in ("edit", "run", "results", "presets"):
            await pilot.click(f"#--content-tab-{tab}")
            await pilot.pause()
            focused[tab] = app.focused.id if app.focused is not None else None
        footer = screen_text(app).splitlines()[-1]
        assert focused == {"edit": "form", "run": "run-pane", "results": "runs-table", "presets": "preset-table"}
        await pilot.press("enter")
        await wait_until(pilot, lambda: app.draft_path is not None)
    assert "Open" in footer and "New" in footer
    assert app.draft_path.name == "tiny.yaml"
