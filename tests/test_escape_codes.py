"""No escape code from a file, a log, a folder's name or an exception reaches the terminal:
each printing path (follow, runs, resume, validate, progress lines, the TUI's status line)
given a payload that would retitle the terminal and clear its screen prints it escaped."""

import io
import json
import subprocess
import sys

import pytest
import yaml

import frictionlab
from frictionlab.cli.main import main
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.progress import ProgressReporter, SweepProgress
from frictionlab.runs.progresslog import PROGRESS_FILE
from frictionlab.compute.realization import RealizationResult
from frictionlab.runs.rundir import RunDirectory
from frictionlab.runs.sweep import plan_sweep, run_sweep

from .conftest import SMALL_PRESET, merge
from .test_forged_logs import hold  # a process that holds a run folder, its run "running"

PAYLOAD = "\x1b]2;pwned\x07\x1b[2J"
ESC = "\x1b"


posix = pytest.mark.skipif(sys.platform == "win32", reason="control characters in file names")


@pytest.mark.long  # follows a held run for 5 s
def test_follow_prints_a_forged_finished_error_escaped(tmp_path):
    holder = hold(tmp_path)  # its run started and "running"
    events = [{"event": "started", "pid": holder.pid, "total": 8},
              {"event": "finished", "status": "failed", "done": 0, "requested": 8, "error": PAYLOAD}]  # fmt: skip
    (tmp_path / PROGRESS_FILE).write_text("".join(json.dumps(e) + "\n" for e in events))
    follow = subprocess.Popen([sys.executable, "-m", "frictionlab", "follow", str(tmp_path)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        out, err = follow.communicate(timeout=5)
    except subprocess.TimeoutExpired:  # still following: the run ends now
        holder.stdin.close()
        out, err = follow.communicate(timeout=60)
    if not holder.stdin.closed:
        holder.stdin.close()
    holder.wait(timeout=30)
    assert "pwned" in err and ESC not in out + err and "\x07" not in err


@posix
def test_runs_prints_a_forged_name_escaped(tmp_path, capsys):
    folder = tmp_path / f"run{PAYLOAD}"
    with RunDirectory(folder) as run_dir:
        run_dir.start(build_scene(SMALL_PRESET), resume=False)
    manifest = json.loads((folder / "run.json").read_text())
    manifest["preset"]["name"], manifest["status"] = PAYLOAD, PAYLOAD
    (folder / "run.json").write_text(json.dumps(manifest))
    assert main(["runs", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert out.count("pwned") == 4 and ESC not in out  # the folder's name twice, as the run's name, the status refused


@posix
def test_runs_lists_a_folder_whose_name_holds_a_line_break_on_one_row(tmp_path, capsys):
    """A line break in a folder's name was kept in its cell (shown keeps a message's lines): the
    name 'x\\nfake  ...  completed' drew a row of a run that is not there."""
    with RunDirectory(tmp_path / "x\nfake  small  completed  8 of 8\tz") as run_dir:
        run_dir.start(build_scene(SMALL_PRESET), resume=False)
    assert main(["runs", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2 and "x\\nfake  small  completed  8 of 8\\tz" in lines[1], lines


@posix
def test_resume_prints_its_warning_about_a_folder_escaped(tmp_path, cli):
    folder = tmp_path / f"run{PAYLOAD}"
    frictionlab.run(SMALL_PRESET, out=folder, workers=1, plot=False, progress=False)
    manifest = json.loads((folder / "run.json").read_text())
    manifest["status"] = "interrupted"
    (folder / "run.json").write_text(json.dumps(manifest))
    [chunk] = (folder / "chunks").iterdir()
    chunk.write_bytes(chunk.read_bytes() + b"!")  # a checksum that does not match: a warning names the folder
    done = cli("resume", folder, "--no-plot")
    assert done.returncode == 0 and "failed verification" in done.stderr
    assert "pwned" in done.stderr + done.stdout and ESC not in done.stderr + done.stdout


@posix
def test_validate_prints_a_file_name_and_a_preset_value_escaped(tmp_path, capsys):
    preset = tmp_path / f"p{PAYLOAD}.yaml"
    preset.write_text(yaml.safe_dump(SMALL_PRESET))
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump({**SMALL_PRESET, "name": PAYLOAD}))
    assert main(["validate", str(preset)]) == 0
    assert main(["validate", str(bad)]) == 2
    said = capsys.readouterr()
    assert said.out.count("pwned") == 1 and "pwned" in said.err and ESC not in said.out + said.err


def test_validate_prints_what_an_input_file_says_escaped(tmp_path, capsys, monkeypatch):
    """An instrument file's unit reaches the line that describes it: escaped there."""
    import frictionlab.api
    import frictionlab.io.inputs

    real = frictionlab.api.scene_record
    monkeypatch.setattr(frictionlab.api, "scene_record", lambda scene: {**real(scene), "input": {"unit": PAYLOAD}})
    monkeypatch.setattr(frictionlab.io.inputs, "describe_input", lambda summary: f"map.nc: unit {summary['unit']}")
    preset = tmp_path / "p.yaml"
    preset.write_text(yaml.safe_dump(SMALL_PRESET))
    assert main(["validate", str(preset)]) == 0
    out = capsys.readouterr().out
    assert "read map.nc: unit" in out and "pwned" in out and ESC not in out


def test_progress_lines_print_a_realization_error_and_a_point_error_escaped():
    class Run:
        scene = build_scene(SMALL_PRESET)
        total, resumed, retried, workers, executor, cores, sized = 2, 0, 0, 1, "serial", 0, False

    stream = io.StringIO()
    reporter = ProgressReporter(stream=stream, interactive=False, after=0.0)
    reporter.run_started(Run())
    reporter.realization_failed(RealizationResult(index=0, seconds=0.1, error=f"ValueError: {PAYLOAD}"), 1, 2)
    sweep = plan_sweep(merge(SMALL_PRESET, {"sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5]}}}}))
    point = sweep.points[0]
    progress = SweepProgress(stream=stream, interactive=False, after=0.0)

    class Failed:
        status, error = "error", PAYLOAD

    progress.point_finished(sweep, point, Failed())
    assert stream.getvalue().count("pwned") == 2 and ESC not in stream.getvalue()


def test_follow_prints_a_forged_point_error_of_sweep_json_escaped(tmp_path, capsys):
    data = merge(SMALL_PRESET, {"realizations": 3, "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5]}}}})
    run_sweep(plan_sweep(data), tmp_path, RunOptions(workers=1), plot=False)
    record = json.loads((tmp_path / "sweep.json").read_text())
    record["points"][0].update(status="error", error=PAYLOAD, a=None)
    (tmp_path / "sweep.json").write_text(json.dumps(record))
    main(["follow", str(tmp_path)])
    said = capsys.readouterr()
    assert "pwned" in said.out and ESC not in said.out + said.err


def test_the_tui_status_line_shows_a_message_escaped(registry, tmp_path, monkeypatch):
    import asyncio

    from frictionlab.tui.app import FrictionlabApp

    monkeypatch.chdir(tmp_path)
    (tmp_path / "presets").mkdir()

    async def scenario():
        app = FrictionlabApp(None, presets_dir="presets", runs_dir="runs", options=RunOptions(workers=1), registry=registry)
        async with app.run_test(size=(80, 24)) as pilot:
            await pilot.pause()
            app.say(f"cannot follow {PAYLOAD}", "error", title=PAYLOAD)
            await pilot.pause()
            return str(app.query_one("#status").render())

    shown = asyncio.run(scenario())
    assert shown.count("pwned") == 2 and ESC not in shown and "\x07" not in shown


@pytest.mark.parametrize(("typed", "said"), [
    ("spectrum.params.hurst\u200b=0.5", "spectrum.params.hurst\\u200b: is not a known field; did you mean 'hurst'?"),
    ("see\u202ed=1", "see\\u202ed: is not a known field"),
    ("seed\u009b2J=1", "seed\\x9b2J: is not a known field"),
])  # fmt: skip
def test_a_key_with_a_character_that_hides_or_reorders_text_is_printed_escaped(tmp_path, capsys, typed, said):
    """A zero-width space typed into a key read 'spectrum.params.hurst: is not a known field;
    did you mean 'hurst'?', the difference invisible; a right-to-left override turned the rest
    of the line around, and a C1 CSI (U+009B) drives a terminal as ESC [ does. Each is escaped."""
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(SMALL_PRESET))
    assert main(["validate", str(path), "--set", typed]) == 2
    err = capsys.readouterr().err
    assert said in err and not {"\u200b", "\u202e", "\u009b"} & set(err), err


@posix
def test_the_api_names_a_preset_file_escaped(tmp_path):
    """frictionlab.validate(path) and run raise a PresetError whose first line names the file:
    printed in a terminal or a notebook, a name holding an escape code drove it (the CLI escapes
    the whole message; the API's message itself held the code)."""
    (tmp_path / f"p{PAYLOAD}.yaml").write_text("name: x\n")
    with pytest.raises(frictionlab.errors.PresetError) as refused:
        frictionlab.validate(tmp_path / f"p{PAYLOAD}.yaml")
    assert "pwned" in str(refused.value) and ESC not in str(refused.value)
    sweep = merge(SMALL_PRESET, {"sweep": {"parameters": {"seed": {"values": [1, 2]}}}})
    (tmp_path / f"s{PAYLOAD}.yaml").write_text(yaml.safe_dump(sweep))
    with pytest.raises(frictionlab.errors.FrictionlabError, match="a sweep writes a run folder per point") as refused:
        frictionlab.run(tmp_path / f"s{PAYLOAD}.yaml", progress=False)  # no out=
    assert "pwned" in str(refused.value) and ESC not in str(refused.value)


@posix
def test_presets_copy_report_and_exact3d_print_paths_escaped(tmp_path, capsys, monkeypatch):
    """presets copy echoed its DEST raw ('copied quickstart to ...' on stdout), and report and
    exact3d printed their progress lines (which name --out, --presets and the files) and the
    written page's path raw: a folder named with an escape code drove the terminal."""
    assert main(["presets", "copy", "quickstart", str(tmp_path / f"q{PAYLOAD}.yaml")]) == 0
    out = capsys.readouterr().out
    assert "copied quickstart to" in out and "pwned" in out and ESC not in out
    page = tmp_path / f"page{PAYLOAD}.md"

    def write(*args, log, **kwargs):  # the study itself is not what is checked: its lines and its page are
        log(f"wrote {page}")
        page.write_text("# page\n")
        return page

    monkeypatch.setattr("frictionlab.paper.reproduce.write_report", write)
    monkeypatch.setattr("frictionlab.exact3d.report.write_page", write)
    for command in (["report", "--out", str(tmp_path / "r")], ["exact3d", "--quick", "--out", str(tmp_path / "e")]):
        assert main(command) == 0
        out, err = capsys.readouterr()
        assert "pwned" in out and "pwned" in err and ESC not in out + err


@posix
def test_an_out_folder_whose_name_holds_a_line_break_is_said_on_one_line(tmp_path, capsys):
    """``--out 'run\\ncompleted'`` printed 'results in .../run' and a line 'completed/': a
    message's lines are kept by ``shown``, and a path in it was put in as text."""
    from pathlib import Path

    from frictionlab.errors import shown, shown_name

    assert shown(Path("a\nb\tc")) == shown_name("a\nb\tc") == "a\\nb\\tc" and shown("a\nb") == "a\nb"
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(merge(SMALL_PRESET, {"realizations": 1, "fit": {"bootstrap": 0}})))
    folder = tmp_path / "run\ncompleted"
    assert main(["run", str(tmp_path / "p.yaml"), "--out", str(folder), "--workers", "1", "--no-plot"]) == 0
    out = capsys.readouterr().out
    assert f"  results in {tmp_path}/run\\ncompleted/" in out and "\ncompleted/" not in out, out
    (tmp_path / "file\nx").write_text("")
    for args in (["--out", str(tmp_path / "file\nx")], ["--resume", "--out", str(tmp_path / "none\nx")]):
        assert main(["run", str(tmp_path / "p.yaml"), *args]) != 0
        err = capsys.readouterr().err
        assert "\\nx" in err and "\nx" not in err, err


@posix
def test_a_preset_or_run_folder_whose_name_holds_a_line_break_is_said_on_one_line(tmp_path, capsys):
    """'p\\nq.yaml: 1 problem in preset', 'in .../r\\nz/' and '.../no\\nx does not exist' each
    printed a name across two lines."""
    preset = merge(SMALL_PRESET, {"realizations": 1, "fit": {"bootstrap": 0}})
    (tmp_path / "p\nq.yaml").write_text(yaml.safe_dump(merge(preset, {"realizations": 0})))
    assert main(["validate", str(tmp_path / "p\nq.yaml")]) != 0
    assert "p\\nq.yaml: 1 problem in preset" in capsys.readouterr().err
    assert main(["resume", str(tmp_path / "no\nx")]) != 0
    assert "no\\nx does not exist" in capsys.readouterr().err
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset))
    assert main(["run", str(tmp_path / "p.yaml"), "--out", str(tmp_path / "r\nz"), "--workers", "1", "--no-plot"]) == 0
    capsys.readouterr()
    assert main(["follow", str(tmp_path / "r\nz")]) == 0
    assert "completed, 1/1 realizations, in " in (out := capsys.readouterr().out) and "r\\nz/" in out, out


@posix
def test_an_output_file_whose_name_holds_a_line_break_is_said_on_one_line(tmp_path, capsys):
    (tmp_path / "j\nk.json").write_text("{}")
    assert main(["schema", "--out", str(tmp_path / "j\nk.json")]) != 0
    err = capsys.readouterr().err
    assert "j\\nk.json exists: give another file" in err, err
