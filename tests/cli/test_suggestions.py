"""A mistyped field, option or file is answered with the closest right one."""

import re

import pytest

from frictionlab.cli import main
from frictionlab.errors import ExitCode

from ..conftest import SMALL_PRESET, merge
from .conftest import write_preset


def problems_of(tmp_path, capsys, data) -> str:
    assert main(["validate", str(write_preset(tmp_path, data))]) == ExitCode.USAGE
    return capsys.readouterr().err


@pytest.mark.parametrize(
    ("changes", "suggestion"),
    [
        ({"seeed": 3}, "seeed: is not a known field; did you mean 'seed'?"),  # top level
        ({"loading": {"stpes": 8}}, "loading.stpes: is not a known field; did you mean 'steps'?"),  # a section
        ({"spectrum": {"params": {"hurts": 0.8}}}, "spectrum.params.hurts: is not a known field; did you mean 'hurst'?"),
        ({"solver": {"params": {"youngs_modulud": 2.0}}}, "did you mean 'youngs_modulus'?"),  # a plugin's Params
    ],
)  # fmt: skip
def test_a_misspelt_field_is_answered_with_the_right_name_at_every_level(tmp_path, capsys, changes, suggestion):
    assert suggestion in problems_of(tmp_path, capsys, merge(SMALL_PRESET, changes))


def test_a_misspelt_required_field_is_said_once_by_its_suggestion(tmp_path, capsys):
    data = merge(SMALL_PRESET, {})
    data["loadin"] = data.pop("loading")  # `loading` is required
    err = problems_of(tmp_path, capsys, data)
    assert "loadin: is not a known field; did you mean 'loading'?" in err
    assert "loading: is required" not in err and "1 problem in preset" in err
    del data["loadin"]  # missing with no misspelling to explain it: said as before
    assert "loading: is required" in problems_of(tmp_path, capsys, data)


def test_a_field_far_from_every_name_gets_the_list_without_a_guess(tmp_path, capsys):
    err = problems_of(tmp_path, capsys, merge(SMALL_PRESET, {"zzz": 1}))
    assert "zzz: is not a known field; allowed: description, fit, loading" in err and "did you mean" not in err


def test_an_unknown_option_gets_its_commands_usage_and_the_closest_option(tmp_path, cli):
    done = cli("run", "quickstart", "--ouy", "x", cwd=tmp_path)
    assert done.returncode == ExitCode.USAGE and done.stdout == ""
    assert done.stderr.startswith("usage: frictionlab run ")
    assert "frictionlab run: error: unrecognized arguments: --ouy x; did you mean '--out'?" in done.stderr
    assert "usage: frictionlab [-h]" not in done.stderr
    assert not any(tmp_path.iterdir())  # nothing ran


def usage_error(capsys, argv) -> str:
    """What argparse says on stderr as it exits 2."""
    with pytest.raises(SystemExit) as exited:
        main(argv)
    assert exited.value.code == ExitCode.USAGE
    return capsys.readouterr().err


def test_a_nested_command_and_the_top_level_suggest_their_own_options(capsys):
    err = usage_error(capsys, ["presets", "copy", "quickstart", "--forse"])
    assert err.startswith("usage: frictionlab presets copy") and "did you mean '--force'?" in err
    assert "did you mean '--version'?" in usage_error(capsys, ["--verison"])


def test_a_stray_word_is_refused_by_its_command_without_a_guess(capsys):
    err = usage_error(capsys, ["run", "quickstart", "surplus", "--out", "x"])
    assert err.startswith("usage: frictionlab run ")
    assert err.splitlines()[-1] == "frictionlab run: error: unrecognized arguments: surplus"


def test_a_missing_file_named_as_a_builtin_points_to_the_builtin(tmp_path, cli):
    """Outside the clone, the README's `frictionlab run presets/quickstart.yaml` has no file to read."""
    done = cli("run", "presets/quickstart.yaml", cwd=tmp_path)
    assert done.returncode == ExitCode.INPUT_FILE
    assert "no file 'presets/quickstart.yaml' here; the built-in preset of that name is 'quickstart'" in done.stderr
    assert "frictionlab run quickstart" in done.stderr
    missing = cli("validate", "presets/mine.yaml", cwd=tmp_path)  # no built-in of that name: just missing
    assert missing.returncode == ExitCode.INPUT_FILE and "built-in" not in missing.stderr


def test_a_misspelt_choice_is_answered_with_the_closest_choice(capsys):
    err = usage_error(capsys, ["run", "quickstart", "--executor", "dsk"])
    assert err.startswith("usage: frictionlab run ") and "invalid choice: 'dsk'" in err
    assert re.search(r"dask'?\); did you mean 'dask'\?$", err.rstrip())  # after argparse's list of every choice
    assert usage_error(capsys, ["completion", "fsh"]).rstrip().endswith("; did you mean 'fish'?")
    assert "did you mean" not in usage_error(capsys, ["completion", "zzzz"])


@pytest.mark.parametrize("words", [["run", "quickstart", "--\x1b]0;owned\x07x"], ["run", "quickstart", "\x1b[2J"],
                                   ["runs", "here", "\x1b[2J", "--json"]])
def test_a_word_the_parser_refuses_is_quoted_escaped_never_as_terminal_control(capsys, words):
    """argparse quoted an unrecognized word as typed: an escape sequence in it reached the terminal (a
    title set, the screen cleared) and the JSON error object."""
    with pytest.raises(SystemExit) as refused:
        main(words)
    captured = capsys.readouterr()
    assert refused.value.code == ExitCode.USAGE
    assert "unrecognized arguments: " in captured.err
    assert "\x1b" not in captured.err + captured.out and "\x07" not in captured.err + captured.out
    assert "\\x1b" in captured.err


def test_presets_without_its_action_says_how_to_copy_the_preset_named(capsys):
    """`frictionlab presets quickstart f.yaml` said "invalid choice: 'quickstart' (choose from
    'copy')", no word on what was meant."""
    err = usage_error(capsys, ["presets", "quickstart", "f.yaml"])
    assert err.rstrip().endswith("invalid choice: 'quickstart' (choose from 'copy'); to copy a preset out: "
                                 "frictionlab presets copy quickstart [DEST]")  # fmt: skip
    err = usage_error(capsys, ["presets", "cpy", "quickstart"])
    assert err.rstrip().endswith("did you mean 'copy'?")  # a misspelt action: that alone
