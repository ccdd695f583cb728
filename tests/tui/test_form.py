"""Editing a preset in the form: the headless validator's messages, saving, switching plugins."""

from pathlib import Path
from typing import ClassVar, Literal

import numpy as np
import pytest
import yaml
from pydantic import Field
from textual.widgets import Input, Select, Static, Switch

from frictionlab import PluginParams, SlopeEstimator
from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab.preset import load_scene
from frictionlab.tui.widgets import PresetForm

from ..conftest import PRESETS, merge
from .conftest import (
    SIZE, TINY, choose, error_text, headless_problems, make_app, new_preset, open_first_preset, post_keys, press_settled,
    sync, type_into, wait_until,
)

# ------------------------------------------------------------------ edit and save


@sync
async def test_a_whole_number_typed_as_1e3_is_saved_as_a_whole_number(folders, registry):
    """Found in tmux: 1e3 typed into realizations was saved as 'realizations: 1000.0', and 1e9
    was refused as 'must be <= 10000000, got 1000000000.0'."""
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        await type_into(pilot, "field--realizations", "1e9")
        too_many = error_text(app, "field--realizations")
        await type_into(pilot, "field--realizations", "1e3")
        await type_into(pilot, "field--loading--steps", "12.0")
        await press_settled(pilot, "ctrl+s")
        assert not app.modified and form.problems == []
    assert too_many == "realizations: must be <= 10000000, got 1000000000"
    text = (folders / "presets" / "tiny.yaml").read_text()
    assert "realizations: 1000\n" in text and "steps: 12\n" in text


@sync
async def test_invalid_value_shows_the_headless_message_then_save_round_trips(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        assert not [line for line in form.query(".field-error") if line.display]  # a valid preset: no message shown
        await type_into(pilot, "field--spectrum--params--hurst", "2.0")
        expected = headless_problems(merge(TINY, {"spectrum": {"params": {"hurst": 2.0}}}), registry)
        assert expected == ["spectrum.params.hurst: must be <= 1.5, got 2.0"]
        assert form.problems == expected
        assert error_text(app, "field--spectrum--params--hurst") == expected[0]
        row = app.query_one("#field--spectrum--params--hurst").parent  # the message right under its field's row
        assert row.parent.children[row.parent.children.index(row) + 1].id == "field--spectrum--params--hurst--error"
        assert app.query_one("#field--spectrum--params--hurst", Input).has_class("-invalid")
        assert expected[0] in str(app.query_one("#problems", Static).render())

        # text where a number belongs: the same words as `frictionlab validate`
        await type_into(pilot, "field--loading--steps", "abc")
        assert form.problems == headless_problems(
            merge(TINY, {"spectrum": {"params": {"hurst": 2.0}}, "loading": {"steps": "abc"}}), registry
        )
        assert error_text(app, "field--loading--steps") == "loading.steps: must be a whole number, got 'abc'"

        await type_into(pilot, "field--loading--steps", "12")
        await type_into(pilot, "field--spectrum--params--hurst", "0.9")
        assert form.problems == []
        assert error_text(app, "field--spectrum--params--hurst") == ""
        await press_settled(pilot, "ctrl+s")
        assert not app.modified

    saved = yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())
    assert saved == merge(TINY, {"spectrum": {"params": {"hurst": 0.9}}, "loading": {"steps": 12}})
    # accepted unchanged by the headless front end
    scene = load_scene(folders / "presets" / "tiny.yaml", registry=registry)
    assert scene.spectrum.params.hurst == 0.9 and scene.preset.loading.steps == 12
    assert main(["run", "presets/tiny.yaml", "--out", "runs/headless", "--quiet", "--workers", "1"]) == ExitCode.OK


@sync
async def test_save_with_problems_asks_first_and_keeps_unknown_sections(folders, registry):
    data = merge(TINY, {"realizations": 0, "notes": {"author": "me", "tags": ["a", "b"]}})
    (folders / "presets" / "tiny.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        assert form.problems == headless_problems(data, registry)
        assert any(p.startswith("notes: ") for p in form.problems)
        await type_into(pilot, "field--seed", "11")
        await press_settled(pilot, "ctrl+s")
        assert app.modified, "saved a preset with problems without asking"
        await pilot.press("n")  # no: nothing is written
        await pilot.pause()
        assert yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())["seed"] == TINY["seed"]
        await press_settled(pilot, "ctrl+s")
        await press_settled(pilot, "y")
        assert not app.modified
        # and a run is refused, with the problems named
        await press_settled(pilot, "ctrl+r")
        assert app.last_snapshot is None and not app.running
    saved = yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())
    assert saved == {**data, "seed": 11}


@sync
async def test_switching_the_solver_swaps_its_parameters(folders, registry):
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        assert app.query("#field--solver--params--youngs_modulus")
        await choose(pilot, "plugin--solver", "winkler")
        assert not app.query("#field--solver--params--youngs_modulus")
        modulus = app.query_one("#field--solver--params--modulus", Input)
        assert "stiffness per unit length" in str(modulus.tooltip)
        await type_into(pilot, "field--solver--params--modulus", "-1")
        assert form.problems == ["solver.params.modulus: must be > 0.0, got -1.0"]
        await type_into(pilot, "field--solver--params--modulus", "4")
        assert form.data["solver"] == {"name": "winkler", "params": {"modulus": 4.0}}
        # back to mdr: its values come back
        await choose(pilot, "plugin--solver", "mdr")
        assert form.data["solver"] == TINY["solver"]
        assert app.query_one("#field--solver--params--youngs_modulus", Input).value == "1.0"
        assert form.problems == []


def comment_lines(text):
    return [line.split("#", 1)[1].strip() for line in text.splitlines() if "#" in line]


@sync
async def test_editing_a_commented_shipped_preset_keeps_its_comments(folders, registry):
    original = (PRESETS / "benad2012-fig2.yaml").read_text()
    path = folders / "presets" / "tiny.yaml"  # the first row of the list
    path.write_text(original)
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        assert form.data["name"] == "benad2012-fig2"
        await type_into(pilot, "field--spectrum--params--hurst", "0.75")
        assert form.problems == []
        await press_settled(pilot, "ctrl+s")
        assert not app.modified
    text = path.read_text()
    assert comment_lines(text) == comment_lines(original) and "h = 1e4" in text
    changed = [(a, b) for a, b in zip(original.splitlines(), text.splitlines(), strict=True) if a != b]
    assert changed == [("    hurst: 1.0", "    hurst: 0.75")]
    assert main(["validate", str(path)]) == ExitCode.OK
    scene = load_scene(path, registry=registry)
    assert scene.spectrum.params.hurst == 0.75 and scene.spectrum.params.rms_height == 1e4


class SmoothedSlope(SlopeEstimator):
    """A third-party plugin registered only in this test: the form has no code for it."""

    name: ClassVar[str] = "smoothed-difference"
    summary: ClassVar[str] = "test plugin: central difference of a smoothed line"

    class Params(PluginParams):
        window: int = Field(3, ge=1, le=99, description="points in the moving average")
        weight: float = Field(0.5, gt=0.0, lt=1.0, description="weight of the centre point (dimensionless)")
        edge: Literal["wrap", "reflect"] = Field("wrap", description="how the line's ends are treated")
        normalise: bool = Field(False, description="divide by the rms slope")

    def slopes(self, heights, spacing, periodic=True):
        return np.gradient(heights, spacing)


@sync
async def test_a_third_party_plugin_gets_a_form_without_code(folders, register_plugin):
    registry = register_plugin(SmoothedSlope)
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        await choose(pilot, "plugin--slope", "smoothed-difference")
        prefix = "#field--slope--params--"
        assert isinstance(app.query_one(prefix + "window"), Input)
        assert isinstance(app.query_one(prefix + "weight"), Input)
        assert isinstance(app.query_one(prefix + "edge"), Select)
        assert isinstance(app.query_one(prefix + "normalise"), Switch)
        assert "allowed: >= 1, <= 99" in str(app.query_one(prefix + "window").tooltip)
        await type_into(pilot, "field--slope--params--window", "200")
        expected = headless_problems(merge(TINY, {"slope": {"name": "smoothed-difference", "params": {"window": 200}}}), registry)
        assert form.problems == expected == ["slope.params.window: must be <= 99, got 200"]
        await type_into(pilot, "field--slope--params--window", "5")
        await choose(pilot, "field--slope--params--edge", "reflect")
        app.query_one(prefix + "normalise", Switch).focus()
        await press_settled(pilot, "space")
        assert form.data["slope"] == {
            "name": "smoothed-difference",
            "params": {"window": 5, "edge": "reflect", "normalise": True},
        }
        assert form.problems == []


@sync
async def test_new_preset_from_a_plugins_defaults_when_there_is_no_preset_at_all(folders, registry, monkeypatch):
    import frictionlab.tui.folders

    (folders / "presets" / "tiny.yaml").unlink()  # nothing to start from: none listed, none shipped
    monkeypatch.setattr(frictionlab.tui.folders, "builtin_presets", lambda: [])
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        await new_preset(pilot, "fresh")
        form = app.query_one(PresetForm)
        assert form.data["spectrum"]["name"] == "power-law"
        # power-law's hurst and points have no default: the user is told, as headless would
        assert form.problems == headless_problems(form.data, registry)
        assert {p.split(":")[0] for p in form.problems} == {"spectrum.params.hurst", "spectrum.params.points"}
        await type_into(pilot, "field--spectrum--params--hurst", "0.7")
        await type_into(pilot, "field--spectrum--params--points", "256")
        assert form.problems == []
        await press_settled(pilot, "ctrl+s")
    assert app.draft_path == Path("presets/fresh.yaml")  # the folder the list shows
    assert load_scene(folders / "presets" / "fresh.yaml", registry=registry).spectrum.params.points == 256



@sync
async def test_keys_typed_just_before_esc_reach_the_draft(folders, registry):
    """Esc acts at once (keyorder), before the field has handled the keys typed before it: their
    edit came from a field no longer focused and was dropped as not typed. The field showed 12,
    the draft (what Ctrl+S saves and Ctrl+R runs) kept 8, the title said (saved)."""
    from .conftest import post_keys, wait_until

    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        field = app.query_one("#field--realizations", Input)
        field.focus()
        await pilot.pause()
        post_keys(app, ["end", "ctrl+u", *"12", "escape"])
        await wait_until(pilot, lambda: field.value == "12" and app.focused is not field)
        # the edit's message comes after the focus has left: waited for, not a fixed 0.3 s (a loaded machine is slower)
        # (the field cleared by Ctrl+U leaves realizations unsaid in the draft a moment: .get)
        await wait_until(pilot, lambda: app._draft().get("realizations") == 12 and app.modified)
        draft, modified = app._draft()["realizations"], app.modified
    assert draft == 12 and modified


@sync
async def test_an_edits_message_that_comes_after_the_save_leaves_the_preset_saved(folders, registry):
    """Esc and Ctrl+S read together after typing: the edit's message reached the app after the
    save had written it, and the title said (modified) over a saved file (q asked about unsaved
    changes). Modified now says whether the draft differs from its file."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        form = app.query_one(PresetForm)
        app.query_one("#field--realizations", Input).focus()
        await pilot.press("end", "ctrl+u", "1", "2")
        await pilot.pause()
        edited = app.modified
        await pilot.press("ctrl+s")
        await pilot.pause()
        form.revalidate(changed=True)  # the late one: an edit message that comes after the save
        await pilot.pause()
        after_save = app.modified
        await pilot.press("ctrl+u", "9")
        await pilot.pause()
        changed_again = app.modified
    assert yaml.safe_load((folders / "presets" / "tiny.yaml").read_text())["realizations"] == 12
    assert edited and not after_save and changed_again


@pytest.mark.parametrize("size", [(80, 24), (60, 20)])
@sync
async def test_the_field_tab_goes_to_stays_in_sight_as_the_help_under_the_form_grows(folders, registry, size):
    """Tab onto the form's last row in sight: its help, a line longer than the last field's, made
    the form a row shorter and hid the field focused (height_reference at 80x24)."""
    app = make_app(registry)
    async with app.run_test(size=size) as pilot:
        form = await open_first_preset(pilot)
        await press_settled(pilot, "enter")
        hidden = []
        for _ in range(18):  # the scene's and the spectrum's fields
            await press_settled(pilot, "tab")
            field, shown = app.focused, form.content_region
            if not (shown.y <= field.region.y and field.region.bottom <= shown.bottom):
                hidden.append(field.id)
    assert hidden == []


@sync
async def test_a_switch_or_choice_put_back_to_what_the_file_left_unsaid_is_not_a_change(folders, registry):
    """tiny.yaml has no output section, nor slope params: output.realizations toggled off and on
    again, or line_end chosen away and back, left the title `(modified)` (q asked about unsaved
    changes, Ctrl+S wrote `output: {realizations: true}`) though the preset was as its file."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        switch = app.query_one("#field--output--realizations", Switch)
        switch.focus()
        await press_settled(pilot, "space")
        toggled = app.modified
        await press_settled(pilot, "space")
        switched_back = app.modified
        line_end = app.query_one("#field--slope--params--line_end", Select)
        first = line_end.value
        other = next(v for _, v in line_end._options if v not in (first, Select.NULL))
        await choose(pilot, "field--slope--params--line_end", other)
        chosen = app.modified
        await choose(pilot, "field--slope--params--line_end", first)
        chosen_back, data = app.modified, app._draft()
    assert (toggled, switched_back, chosen, chosen_back) == (True, False, True, False)
    assert "output" not in data and "params" not in data["slope"]


@sync
async def test_fields_left_fast_leave_the_help_and_enter_on_the_field_focused(folders, registry):
    """Shift+Tab typed fast (held) from points to seed: the help went on telling of hurst, and
    Esc then Enter went back into hurst, so what was typed next changed another field."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("f3")
        await pilot.pause()
        app.query_one("#field--spectrum--params--points").focus()
        await pilot.pause()
        post_keys(app, ["shift+tab"] * 4)  # hurst, the spectrum's plugin, realizations, seed
        help_of = lambda: str(app.query_one("#field-help", Static).render())  # noqa: E731
        # every key answered and the help line redrawn: waited for, not a fixed 0.2 s (a loaded machine is slower)
        await wait_until(pilot, lambda: app.focused.id == "field--seed" and help_of().startswith("seed:"))
        focused = app.focused.id
        help_line = str(app.query_one("#field-help", Static).render())
        await pilot.press("escape", "enter")
        assert focused == "field--seed"
        assert help_line.startswith("seed:"), help_line
        assert app.focused.id == "field--seed"


@sync
async def test_down_and_up_in_a_field_go_to_the_field_below_and_above(folders, registry):
    """In tmux: Down in a field scrolled the form a line, the cursor left in the field it was in;
    a form's arrows go from field to field, as Tab and Shift+Tab do, however fast typed."""
    app = make_app(registry, preset="presets/tiny.yaml")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        seed, realizations = app.query_one("#field--seed", Input), app.query_one("#field--realizations", Input)
        seed.focus()
        await pilot.pause()
        post_keys(app, ["down", "end", "ctrl+u", *"12"])  # typed at once: the digits go where Down went
        await wait_until(pilot, lambda: "12" in (seed.value, realizations.value))  # all five answered
        below = app.focused
        await press_settled(pilot, "up")
        above = app.focused
        choice = app.query_one("#plugin--spectrum", Select)
        choice.focus()
        await pilot.pause()
        await press_settled(pilot, "down")  # a choice too: Textual's opened its list there
        past_choice, opened = app.focused, choice.expanded
        await press_settled(pilot, "escape", "down")  # on the form itself: a line of scroll, no field
        on_form = app.focused
    assert below is realizations and realizations.value == "12" and above is seed
    assert past_choice is not choice and isinstance(past_choice, Input) and not opened
    assert isinstance(on_form, PresetForm)


@sync
async def test_going_into_a_field_and_out_restyles_the_form_alone_and_leaves_every_style_as_a_whole_restyle(
    folders, registry, monkeypatch
):
    """Enter into a field and Esc back out restyled the form and every one of its hundreds of
    widgets (Textual's default on a focus change: 0.1 s a key here). Only the form is, since
    no rule styles a field by the form's focus; were one added, the styles would differ
    from a whole restyle's, and this test says so."""
    from textual.css.stylesheet import Stylesheet

    restyled = []
    apply = Stylesheet.apply
    monkeypatch.setattr(Stylesheet, "apply", lambda self, node, *a, **k: restyled.append(node) or apply(self, node, *a, **k))

    def styles(app):
        return {id(node): (type(node).__name__, node.styles.base.get_rules()) for node in app.screen.walk_children(with_self=True)}

    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        in_form = len(list(form.walk_children()))
        for key in ("enter", "escape", "enter", "escape", "enter"):
            restyled.clear()
            await press_settled(pilot, key)
            assert (app.focused is form) == (key == "escape")
            assert 0 < len(restyled) < in_form / 2, (key, len(restyled), in_form)
            kept = styles(app)
            app.stylesheet.update(app.screen)  # the whole screen restyled, as Textual would have
            assert styles(app) == kept, key


@sync
async def test_save_with_more_problems_than_it_lists_says_how_many_more(folders, registry):
    """'This preset has 7 problems' was followed by 6 of them and nothing more."""
    from frictionlab.tui.screens import ConfirmScreen

    data = merge(TINY, {"realizations": 0, "seed": -1, **{f"extra{i}": i for i in range(6)}})
    (folders / "presets" / "tiny.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    app = make_app(registry)
    async with app.run_test(size=SIZE) as pilot:
        form = await open_first_preset(pilot)
        count = len(form.problems)
        await type_into(pilot, "field--description", "x")
        await press_settled(pilot, "ctrl+s")
        assert isinstance(app.screen, ConfirmScreen)
        said = " ".join(app.screen.question.split())
    assert count > 6 and f"This preset has {count} problems" in said
    assert f"(and {count - 6} more, listed under the form)" in said
