"""The app's keys and help, the ``tui`` command, and a process pool started from the app's thread."""

import os
import subprocess
import sys

import pytest

from frictionlab.cli import main
from frictionlab.options import RunOptions
from frictionlab.tui.app import FrictionlabApp

from ..conftest import ROOT

# ------------------------------------------------------------------ keys in the docs, CLI


def test_the_docs_list_every_key():
    """F1 shows Textual's key panel, built from the bindings (description, then tooltip);
    the docs' key table has each one."""
    from frictionlab.tui.widgets import PresetForm, PresetsPane, ResultsPane, RunPane
    from frictionlab.tui.widgets.sweeptable import SweepTable
    from frictionlab.tui.widgets.tables import ListTable

    page = (ROOT / "docs" / "how-to" / "tui.md").read_text()
    section = page.split("## Keys", 1)[1]
    for owner in (FrictionlabApp, ListTable, SweepTable, PresetsPane, PresetForm, RunPane, ResultsPane):
        for binding in owner.BINDINGS:
            text = f"{binding.description} {binding.tooltip}".strip()  # as the key panel shows it
            assert text in section, f"docs/how-to/tui.md's key table misses {text!r}"


def test_tui_command_passes_its_folders_and_never_loads_textual_before(tmp_path, monkeypatch):
    import frictionlab.tui

    calls = []
    monkeypatch.setattr(frictionlab.tui, "run_app", lambda *a, **k: calls.append((a, k)) or 0)
    assert main(["tui", "--presets", str(tmp_path), "--runs", str(tmp_path / "r"), "--workers", "1"]) == 0
    assert calls == [((None,), {"presets_dir": str(tmp_path), "runs_dir": str(tmp_path / "r"), "options": RunOptions(workers=1)})]

    # the headless commands, and `tui` refusing a missing file, never import Textual
    code = (
        "import sys; from frictionlab.cli import main; import frictionlab.tui; "
        f"rc = main(['tui', {str(tmp_path / 'missing.yaml')!r}]); "
        f"rc2 = main(['validate', {str(ROOT / 'presets' / 'quickstart.yaml')!r}]); "
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in {'textual', 'rich'}); "
        "print(rc, rc2, bad)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.stdout.strip().splitlines()[-1] == "3 0 []", result.stderr  # 3: ExitCode.INPUT_FILE
    assert "no such preset file" in result.stderr



def test_a_preset_name_given_with_presets_dir_is_looked_for_in_that_folder_first(tmp_path, monkeypatch, capsys):
    """``frictionlab tui --presets DIR NAME`` looked for NAME only here and among the built-ins:
    DIR's own NAME.yaml was "no file 'NAME' and no built-in preset of that name"."""
    import frictionlab.tui

    folder = tmp_path / "mine"
    folder.mkdir()
    for name in ("own.yaml", "quickstart.yaml", "short.yml"):  # quickstart.yaml: DIR's, not the built-in
        (folder / name).write_text((ROOT / "presets" / "quickstart.yaml").read_text())
    monkeypatch.chdir(tmp_path)
    opened = []
    monkeypatch.setattr(frictionlab.tui, "run_app", lambda preset, **kwargs: opened.append(preset) or 0)
    for name in ("own", "own.yaml", "quickstart", "short"):
        assert main(["tui", "--presets", "mine", name]) == 0
    assert opened == [os.path.join("mine", file) for file in ("own.yaml", "own.yaml", "quickstart.yaml", "short.yml")]
    assert main(["tui", "--presets", "elsewhere", "quickstart"]) == 0  # not in DIR: as frictionlab run reads it
    assert opened[-1] == str(ROOT / "presets" / "quickstart.yaml")
    capsys.readouterr()

    assert main(["tui", "--presets", "mine", "onw"]) == 3  # 3: ExitCode.INPUT_FILE, as for a name found nowhere without it
    said = capsys.readouterr().err
    where = os.path.join("mine", "onw")
    assert "'onw'" in said and f"{where}.yaml and {where}.yml" in said and "did you mean 'own'?" in said, said
    assert "Traceback" not in said and len(opened) == 5


def test_a_preset_name_is_looked_for_in_the_folders_the_presets_list_shows(tmp_path, monkeypatch, capsys):
    """In tmux: ``frictionlab tui sw`` beside presets/sw.yaml, listed first on the Presets tab,
    was "no file 'sw' and no built-in preset of that name"; ``quickstart`` opened the built-in
    under the project's own quickstart.yaml the list shows first."""
    import frictionlab.tui

    text = (ROOT / "presets" / "quickstart.yaml").read_text()
    (tmp_path / "presets").mkdir()
    (tmp_path / "user").mkdir()
    for path in ("presets/sw.yaml", "presets/quickstart.yaml", "user/mine.yml", "sw.yaml"):
        (tmp_path / path).write_text(text)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("FRICTIONLAB_PRESETS_DIR", str(tmp_path / "user"))
    opened = []
    monkeypatch.setattr(frictionlab.tui, "run_app", lambda preset, **kwargs: opened.append(preset) or 0)
    for name in ("sw", "quickstart", "mine", "sw.yaml"):  # sw.yaml: the file here, as given
        assert main(["tui", name]) == 0
    assert opened == [os.path.join("presets", "sw.yaml"), os.path.join("presets", "quickstart.yaml"),
                      str(tmp_path / "user" / "mine.yml"), "sw.yaml"]  # fmt: skip
    capsys.readouterr()
    assert main(["tui", "sx"]) == 3
    said = capsys.readouterr().err
    assert "'presets'" in said and "did you mean 'sw'?" in said and "Presets there: mine, quickstart, sw" in said, said


POOL_UNDER_TEXTUAL = """
import sys, threading
import frictionlab.tui
from frictionlab.compute.engine import run
from frictionlab.preset import build_scene
from frictionlab.options import RunOptions

class Capture:  # what Textual puts in sys.stderr while an app runs: fileno() is -1
    def write(self, text): return len(text)
    def flush(self): pass
    def fileno(self): return -1

if {prestart}:
    frictionlab.tui.start_process_helpers()  # what run_app does before the app starts
scene = build_scene({{"name": "t", "realizations": 4, "fit": {{"bootstrap": 0}},
    "spectrum": {{"name": "power-law", "params": {{"hurst": 0.8, "points": 256}}}},
    "loading": {{"start": 1, "stop": 5, "steps": 4}}}})
status = []
real, sys.stderr = sys.stderr, Capture()
def work():
    try:
        status.append(run(scene, RunOptions(workers=2, executor="processes")).status)  # a pool, however short the run
    except Exception as exc:
        status.append(type(exc).__name__)
worker = threading.Thread(target=work)
worker.start(); worker.join()
sys.stderr = real
print(status)
"""


@pytest.mark.long  # a TUI session that runs a pool
@pytest.mark.skipif(sys.platform != "linux", reason="forkserver start method")
def test_a_process_pool_starts_from_the_app_thread():
    """Found in tmux: a pool run from the app failed with 'bad value(s) in
    fds_to_keep' because Textual's stderr has no file descriptor."""
    for prestart, expected in ((False, "['ValueError']"), (True, "['completed']")):
        result = subprocess.run(
            [sys.executable, "-c", POOL_UNDER_TEXTUAL.format(prestart=prestart)],
            capture_output=True, text=True, timeout=120,
        )
        assert result.stdout.strip().splitlines()[-1] == expected, result.stderr[-2000:]


@pytest.mark.long  # a TUI session drawn to SVG
def test_the_docs_screenshot_is_made_by_its_command(tmp_path, monkeypatch):
    """docs/tui/main.svg comes from `python -m frictionlab.tui.screenshot docs/tui/main.svg`."""
    from frictionlab.tui.screenshot import main as screenshot

    monkeypatch.chdir(ROOT)
    out = tmp_path / "main.svg"
    assert screenshot([str(out)]) == 0
    text = out.read_text()
    assert text.startswith("<svg") and "quickstart" in text
    assert (ROOT / "docs" / "tui" / "main.svg").read_text().startswith("<svg")


@pytest.mark.parametrize("size", ["80", "80x", "wide", "8x24", "80x2", "80x24x3"])
def test_a_screenshot_size_that_is_no_terminal_is_refused_by_name(size, capsys):
    from frictionlab.tui.screenshot import main as screenshot

    with pytest.raises(SystemExit) as exit_:
        screenshot(["out.svg", "--size", size])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and "--size: " in err and repr(size) in err and "Traceback" not in err


@pytest.mark.long  # a TUI session drawn to SVG
def test_a_screenshot_outside_a_clone_opens_the_built_in_quickstart(tmp_path, monkeypatch):
    from frictionlab.tui.screenshot import main as screenshot

    monkeypatch.chdir(tmp_path)  # no presets/ here
    assert screenshot([str(tmp_path / "main.svg"), "--size", "60x20"]) == 0
    assert "quickstart" in (tmp_path / "main.svg").read_text()


def test_the_tui_without_a_terminal_says_so_and_exits_2(tmp_path):
    done = subprocess.run([sys.executable, "-m", "frictionlab", "tui"], stdin=subprocess.DEVNULL, capture_output=True,
                          text=True, cwd=tmp_path, timeout=60)  # fmt: skip
    assert done.returncode == 2 and "needs a terminal" in done.stderr and "Traceback" not in done.stderr


def test_the_tui_on_a_dumb_terminal_says_so_and_exits_2_before_importing_textual(tmp_path):
    """TERM=dumb has no cursor addressing, which Textual needs to draw at all: refused with
    a message (NO_COLOR, which Textual draws in monochrome, is named as the way without colour)."""
    code = (
        "import sys; from frictionlab.cli import main; rc = main(['tui']); "
        "print(rc, sorted(m for m in sys.modules if m.split('.')[0] == 'textual'))"
    )
    env = {**os.environ, "TERM": "dumb"}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=60)
    assert done.stdout.strip().splitlines()[-1] == "2 []", done.stderr
    assert "TERM=dumb says this terminal cannot move its cursor" in done.stderr and "NO_COLOR=1" in done.stderr
    assert "Traceback" not in done.stderr
