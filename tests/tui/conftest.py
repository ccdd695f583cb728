"""Helpers of the TUI tests: the terminal UI driven as a user drives it (Textual's Pilot at 80x24): what it
shows is checked against the headless validator and the headless run, and the
files it writes against what ``frictionlab run`` accepts."""

import asyncio
import contextlib
import functools
import re
import time

import pytest
import yaml
from textual import events
from textual.keys import _character_to_key
from textual.widgets import Input, Select, Static

from frictionlab.errors import PresetError
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.runs.detached import run_state, start_detached, wait_started
from frictionlab.runs.runner import run_to_folder
from frictionlab.tui.app import FrictionlabApp
from frictionlab.tui.widgets import PresetForm

from ..conftest import SMALL_PRESET, merge

SIZE = (80, 24)


def sync(scenario):
    """Run an async Pilot scenario as a plain test (no async pytest plugin needed)."""

    @functools.wraps(scenario)
    def test(*args, **kwargs):
        asyncio.run(scenario(*args, **kwargs))

    return test
@pytest.fixture(autouse=True)
def built_at_start(request, monkeypatch):
    """The app draws its Presets tab first and builds the rest just after (test_start.py drives
    that moment): elsewhere a test drives the app once it is built, as a user does a moment later."""
    if getattr(request.module, "DRIVES_THE_FIRST_SCREEN", False):
        return
    run_test = FrictionlabApp.run_test

    @contextlib.asynccontextmanager
    async def built(app, *args, **kwargs):
        async with run_test(app, *args, **kwargs) as pilot:
            await wait_until(pilot, lambda: app.built or not app.is_running)
            yield pilot

    monkeypatch.setattr(FrictionlabApp, "run_test", built)


TINY = merge(SMALL_PRESET, {"spectrum": {"params": {"points": 512}}, "fit": {"bootstrap": 50}})


def headless_problems(data, registry):
    try:
        build_scene(data, registry=registry)
    except PresetError as exc:
        return exc.problems
    return []


@pytest.fixture
def folders(tmp_path, monkeypatch):
    """A presets folder with one tiny preset and an empty runs folder, as relative
    paths (so snapshots do not show the temporary directory)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "presets").mkdir()
    (tmp_path / "presets" / "tiny.yaml").write_text(yaml.safe_dump(TINY, sort_keys=False))
    return tmp_path


def make_app(registry, preset=None, workers=1):
    return FrictionlabApp(preset, presets_dir="presets", runs_dir="runs", options=RunOptions(workers=workers), registry=registry)


@contextlib.asynccontextmanager
async def started(app, size=SIZE):
    """``app.run_test`` at ``size``; its pilot is handed over once the first screen has settled."""
    async with app.run_test(size=size) as pilot:
        await pilot.pause()
        yield pilot


async def press_settled(pilot, *keys) -> None:
    """Press ``keys``, then let the app answer them (one pause)."""
    await pilot.press(*keys)
    await pilot.pause()


async def new_preset(pilot, name: str) -> None:
    """Press n and accept the New dialog with ``name`` (its default template and file)."""
    await pilot.pause()
    await pilot.press("n")
    await pilot.pause()
    await pilot.press("ctrl+u", *name, "enter")
    await pilot.pause()


async def open_first_preset(pilot):
    await pilot.pause()
    await pilot.press("enter")
    await pilot.pause()
    form = pilot.app.query_one(PresetForm)
    assert form.data is not None, "Enter on the presets list did not open the preset"
    return form


def post_keys(app, keys):
    """Keys as the terminal driver hands them to the app when typed fast: posted
    in one burst, not waited for one by one (``pilot.press`` waits for the app to
    go idle after each key, some 50 ms)."""
    for key in keys:
        if len(key) == 1:
            app.post_message(events.Key(_character_to_key(key), key))
        else:
            app.post_message(events.Key(key, {"ctrl+u": "\x15"}.get(key)))


async def type_into(pilot, widget_id, text):
    """Clear a field and type ``text`` into it, as fast as a terminal delivers keys."""
    field = pilot.app.query_one(f"#{widget_id}", Input)
    field.focus()
    post_keys(pilot.app, ["end", "ctrl+u", *text])
    await pilot.pause()


async def choose(pilot, select_id, value):
    """Pick an option of a Select with the keyboard: Enter opens it, arrows move, Enter picks."""
    select = pilot.app.query_one(f"#{select_id}", Select)
    select.focus()
    await pilot.press("enter")
    options = [v for _, v in select._options if v is not Select.NULL]
    current = options.index(select.value) if select.value in options else -1
    target = options.index(value)
    await pilot.press(*(["down"] * (target - current) if target > current else ["up"] * (current - target)))
    await pilot.press("enter")
    await pilot.pause()
    assert select.value == value


async def wait_until(pilot, condition, timeout=60.0):
    for _ in range(int(timeout / 0.05)):
        if condition():
            return
        await pilot.pause(0.05)
    raise AssertionError("timed out waiting for the app")


async def press_run(pilot):
    """Ctrl+R once the app has settled."""
    await pilot.pause()
    await pilot.press("ctrl+r")


async def run_to_the_end(pilot):
    """Ctrl+R, then wait for the run (or sweep) to finish and the app to show it."""
    await press_run(pilot)
    await wait_until(pilot, lambda: pilot.app.last_outcome is not None)
    await pilot.pause()


def error_text(app, widget_id):
    """The messages under a field ("" when none: the line under it is made once it has one)."""
    app.query_one(f"#{widget_id}")  # the field itself is there
    label = app.query(f"#{widget_id}--error")
    return str(label.first(Static).render()) if label and label.first().display else ""


SWEEP = merge(
    TINY,
    {
        "name": "tinysweep",
        "realizations": 4,
        "spectrum": {"params": {"points": 256}},
        "loading": {"steps": 8},
        "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.7, 0.9]}}},
    },
)


def fits_width(table):
    """Every column of a DataTable is on screen: nothing to scroll sideways to."""
    return table.max_scroll_x == 0 and table.virtual_size.width <= table.scrollable_content_region.width


def numbers_in(cell):
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", str(cell))]


LONG = merge(TINY, {"name": "long", "realizations": 100_000})  # runs for minutes: each test ends it


def start_long_run(folders, registry):
    """``LONG`` started in a process of its own in runs/long, as the TUI starts a run;
    (process, folder) once the process has taken the folder."""
    out = folders / "runs" / "long"
    process = start_detached(build_scene(LONG, registry=registry).resolved(), out, RunOptions(workers=1), plot=False)
    wait_started(process, out)
    return process, out


@contextlib.contextmanager
def long_run_going(folders, registry):
    """``start_long_run`` for the ``with`` block; its process killed (kill -9) when the block ends."""
    process, out = start_long_run(folders, registry)
    try:
        yield process, out
    finally:
        process.kill()
        process.wait()


def interrupted_long_run(folders, registry, done: int = 0):
    """runs/long ended by SIGTERM, as a cancel ends it, once it has stored ``done``
    realizations or more: interrupted, to be resumed. Its folder."""
    process, out = start_long_run(folders, registry)
    deadline = time.monotonic() + 60.0
    while (run_state(out).done or 0) < done:
        assert time.monotonic() < deadline, f"runs/long stored fewer than {done} realizations in 60 s"
        time.sleep(0.05)
    process.terminate()
    process.wait()
    assert run_state(out).status == "interrupted"
    return out


def make_runs(folders, registry):
    for seed in (1, 2):
        data = merge(TINY, {"seed": seed, "name": f"seed{seed}"})
        run_to_folder(build_scene(data, registry=registry), folders / "runs" / f"seed{seed}", RunOptions(workers=1))


def runs_app(folders, registry):
    """The app over a runs folder of two finished runs (``make_runs``)."""
    make_runs(folders, registry)
    return make_app(registry)


def sweep_app(folders, registry, sweep=None):
    """The app with the sweep preset (``SWEEP``, or ``sweep``) written to presets/sweep.yaml and open."""
    (folders / "presets" / "sweep.yaml").write_text(yaml.safe_dump(sweep or SWEEP, sort_keys=False))
    return make_app(registry, preset="presets/sweep.yaml", workers=1)


def screen_text(app) -> str:
    """What the terminal shows now, line by line (the top screen, toasts and dialogs included)."""
    return "\n".join(strip.text for strip in app.screen._compositor.render_strips())


def record_said(app) -> list[str]:
    """Every message the app says from now on, in order: a run's own end may replace a message
    before the key that said it has returned."""
    said, say = [], app.say
    app.say = lambda text, *args, **kwargs: (said.append(text), say(text, *args, **kwargs))[1]
    return said


def status_text(app) -> str:
    """The status line's message ("" if the app has none)."""
    lines = app.query("#status")
    return str(lines.first().render()) if lines else ""
