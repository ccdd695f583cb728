"""A folder, preset file or run folder named with a line break, a tab and an escape code is
said on one line of every command's messages, each escaped: report, exact3d, study, run of a
preset file or a run folder, resume, runs, predict and presets copy put the name in as typed."""

import sys

import pytest
import yaml

from frictionlab.cli.main import main
from frictionlab.runs.rundir import RunDirectory
from frictionlab.preset import build_scene

from .conftest import SMALL_PRESET

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="control characters in file names")

ODD = "x\n\tfake\x1b[31m"
SAID = "x\\n\\tfake\\x1b[31m"


def said_on_one_line(capsys, command: list[str], code: int, lines: int = 1) -> str:
    assert main(command) == code
    err = capsys.readouterr().err
    assert SAID in err and "\x1b" not in err and "\t" not in err and err.count("\n") == lines, err
    return err


@pytest.fixture
def odd(tmp_path):
    """A folder named ODD, holding a file that is not frictionlab's."""
    (tmp_path / ODD).mkdir()
    (tmp_path / ODD / "other").write_text("mine\n")
    return tmp_path / ODD


def test_report(odd, capsys):
    said_on_one_line(capsys, ["report", "--markdown", str(odd)], 4)
    said_on_one_line(capsys, ["report", "--presets", str(odd / "none")], 2)


def test_exact3d(odd, capsys):
    said_on_one_line(capsys, ["exact3d", "--runs", str(odd / "none"), "--finished-only"], 2)
    said_on_one_line(capsys, ["exact3d", "--quick", "--presets", str(odd / "none")], 2)


def test_study(odd, capsys):
    said_on_one_line(capsys, ["study", "quickstart", "--out", str(odd)], 4)


def test_run_and_resume(odd, tmp_path, capsys):
    said_on_one_line(capsys, ["run", "quickstart", "--out", str(odd)], 4)
    said_on_one_line(capsys, ["resume", str(odd)], 5)
    said_on_one_line(capsys, ["runs", str(odd / "other")], 2)
    said_on_one_line(capsys, ["presets", "copy", "quickstart", str(odd / "other")], 4)


def test_a_run_folder_given_as_a_preset(tmp_path, capsys):
    with RunDirectory(tmp_path / ODD) as run_dir:
        run_dir.start(build_scene(SMALL_PRESET), resume=False)
    err = said_on_one_line(capsys, ["run", str(tmp_path / ODD)], 3, lines=2)  # the head, its problem
    assert f"frictionlab resume $'{tmp_path}/{SAID}' continues the run" in err, err  # a word bash takes back


def test_a_preset_file_named_oddly(tmp_path, capsys):
    (tmp_path / f"p{ODD}.yaml").write_text(yaml.safe_dump({**SMALL_PRESET, "realizations": 0}))
    assert main(["run", str(tmp_path / f"p{ODD}.yaml")]) == 2
    err = capsys.readouterr().err
    assert f"p{SAID}.yaml: 1 problem in preset" in err and "\x1b" not in err and "\t" not in err, err


def test_predict_from_an_odd_folder(odd, capsys):
    law = ["--area", "1", "--modulus", "1", "--rms-height", "1", "--force", "1"]
    said_on_one_line(capsys, ["predict", "--from", str(odd / "other"), *law], 5)


def test_a_write_the_system_refuses_names_the_file_escaped(tmp_path, capsys, monkeypatch):
    """An OSError a command does not catch ended 'error: Input/output error: <name>', the name
    raw: its escape code drove the terminal."""
    import errno

    def refuse(path, *args, **kwargs):
        raise OSError(errno.EIO, "Input/output error", str(path))

    monkeypatch.setattr("frictionlab.io.files.atomic_write", refuse)
    said_on_one_line(capsys, ["schema", "--out", str(tmp_path / f"s{ODD}.json")], 1)
