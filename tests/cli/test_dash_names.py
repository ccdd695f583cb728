"""A file or folder whose name starts with '-' or holds a space: argparse takes `-x.yaml` for an
option and said only 'unrecognized arguments' or 'expected one argument'; the words after `--`
are names, and an option among them was answered 'did you mean --out?' to `--out`; and the
commands frictionlab suggests (`frictionlab resume -r2`, `frictionlab follow my runs/a`) could
not be pasted back."""

import os
import subprocess

import pytest

from frictionlab.cli import main
from frictionlab.errors import ExitCode, command_word

from ..conftest import SMALL_PRESET, merge
from .conftest import write_preset


@pytest.fixture
def dashed(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return write_preset(tmp_path, merge(SMALL_PRESET, {"realizations": 1, "fit": {"bootstrap": 0}}), "-x.yaml")


def usage_error(capsys, words) -> str:
    with pytest.raises(SystemExit) as ended:
        main(words)
    assert ended.value.code == ExitCode.USAGE
    return capsys.readouterr().err.splitlines()[-1]


def test_a_preset_named_with_a_leading_dash_is_told_how_to_give_it(dashed, capsys):
    said = usage_error(capsys, ["run", "-x.yaml"])
    assert "-x.yaml is a file here: a name that starts with '-' is given as ./-x.yaml" in said, said
    assert main(["validate", "./-x.yaml"]) == 0


def test_options_after_a_double_dash_are_said_to_be_names(dashed, capsys):
    said = usage_error(capsys, ["run", "--", "-x.yaml", "--out", "r"])
    assert "every word after -- is a name, never an option: give the options before --" in said, said
    assert "did you mean" not in said


def test_an_option_value_with_a_leading_dash_is_told_the_equals_form(dashed, capsys):
    said = usage_error(capsys, ["run", "./-x.yaml", "--out", "-r"])
    assert said.endswith("expected one argument; a value that starts with '-' is given as --out=-r"), said


def test_suggested_commands_name_a_folder_as_a_word_to_paste(dashed, tmp_path, capsys):
    assert command_word("-r") == "./-r" and command_word("my runs/a") == "'my runs/a'"
    assert command_word(tmp_path / "a") == str(tmp_path / "a")
    assert main(["run", "./-x.yaml", "--out=-r", "--workers", "1", "--no-plot"]) == 0
    capsys.readouterr()
    assert main(["run", "--", "-r"]) == ExitCode.INPUT_FILE  # a run folder given as a preset
    assert "frictionlab resume ./-r continues the run" in capsys.readouterr().err


def test_the_commands_written_into_a_study_or_exact3d_page_take_their_folders_back():
    """study.md and the exact3d page write the command that made them: `--out -r2` and a
    preset -x.yaml were written as typed, a command argparse refuses; a line break split it."""
    import shlex

    from frictionlab.cli.main import build_parser
    from frictionlab.cli.study import command_line
    from frictionlab.exact3d.report import _command

    args = build_parser().parse_args(["study", "--out=-r2", "--", "-x.yaml"])
    assert shlex.split(command_line(args))[2:] == ["./-x.yaml", "--out", "./-r2"]
    args = build_parser().parse_args(["study", "q.yaml", "--out", "a\nb c"])
    assert command_line(args).endswith("--out $'a\\nb c'")  # bash's quoting: its \\n is the line break
    assert shlex.split(_command(True, "-p", "my runs", False))[3:7] == ["--out", "./-p", "--runs", "my runs"]


@pytest.mark.parametrize("name", [b"r\xff", b"it's \xfe\\xff", b"a\nb\tc", b"esc\x1b[31m", "z\u200bw \u0085".encode(), "caf\u00e9 ok".encode()])
def test_a_suggested_command_names_a_folder_of_any_bytes_as_bash_takes_it_back(name):
    """'resume with: frictionlab resume 'r\\xff'': a name that is not UTF-8 was written with
    Python's escapes inside plain quotes, which bash takes as a backslash, an x and two letters:
    another folder. Bash's $'...' says each byte; printable UTF-8 is quoted as before."""
    word = command_word(os.fsdecode(b"/runs/" + name))
    env = {**os.environ, "LC_ALL": "C.UTF-8"}  # bash writes $'\\u200b' in the locale's encoding
    said = subprocess.run(["bash", "-c", f"printf %s {word}"], capture_output=True, env=env, check=True, timeout=60)
    assert said.stdout == b"/runs/" + name, word
    assert word.isascii() or name == "caf\u00e9 ok".encode()  # the terminal shows every byte of it
    assert (word == "'/runs/caf\u00e9 ok'") == (name == "caf\u00e9 ok".encode())


def test_a_lone_dash_is_stdout_where_a_command_prints_and_refused_elsewhere(tmp_path, monkeypatch, capsys):
    """`schema --out -` wrote a file named '-', and `run --out -` a folder named so: '-' is stdout by
    CLI convention. schema and presets copy print there; an option naming a folder (or a file no
    stdout can stand for, as report's --markdown) refuses it by name (exit 2), making nothing."""
    import json

    monkeypatch.chdir(tmp_path)
    assert main(["schema", "--out", "-"]) == ExitCode.OK
    assert "FitSettings" in json.loads(capsys.readouterr().out)["$defs"]
    assert main(["presets", "copy", "quickstart", "-"]) == ExitCode.OK
    assert "name: quickstart" in capsys.readouterr().out
    for words, option, what in ((["run", "quickstart", "--out", "-"], "--out", "folder"),
                                (["report", "--markdown", "-"], "--markdown", "file"),
                                (["predict", "--from", "-", "--area", "1", "--modulus", "1", "--rms-height", "1",
                                  "--force", "1"], "--from", "folder"),
                                (["runs", "-"], "DIR", "folder")):  # fmt: skip
        assert main(words) == ExitCode.USAGE
        err = capsys.readouterr().err
        assert f"{option} -: '-' stands for standard output or input, which {option} cannot be: it names a {what}" in err
        assert "./- for one named '-'" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
