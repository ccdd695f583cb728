"""The CLI's conventions: version, a bare command, help with examples, --json,
did-you-mean, a closed pipe, tables that fit the terminal, colour on a terminal only
(NO_COLOR honoured), shell completion. What a command prints is checked in this process
(the ``cli`` fixture); a closed pipe or stdout, and a terminal, in a real process."""

from __future__ import annotations

import json
import os
import pty
import re
import shlex
import subprocess
import sys

import pytest

from frictionlab.cli.main import COMMANDS, build_parser
from frictionlab.errors import ExitCode

from ..conftest import ROOT

ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")
COLOUR = re.compile(r"\x1b\[[0-9;]*3[0-7]m|\x1b\[[0-9;]*38;")  # a foreground colour, not bold or cursor moves
NAMES = [command.__name__.rsplit(".", 1)[-1] for command in COMMANDS]


def subparsers():
    parser = build_parser()
    action = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return action.choices


def test_version_short_and_long(cli):
    for flag in ("-V", "--version"):
        done = cli(flag)
        assert done.returncode == 0 and re.fullmatch(r"frictionlab \d+\.\d+\S*\n", done.stdout), done.stdout


def test_the_version_printed_is_the_installed_distributions(cli):
    """Read from frictionlab/_version.py (cheap at start-up); the build's metadata must agree."""
    from importlib.metadata import version

    assert cli("--version").stdout == f"frictionlab {version('frictionlab')}\n"


def test_bare_command_shows_a_short_help_with_every_command_and_examples(cli):
    done = cli()
    assert done.returncode == 0 and done.stderr == ""
    assert "commands:" in done.stdout and "examples:" in done.stdout
    for name in NAMES:
        assert re.search(rf"^  {name} ", done.stdout, re.M), name
    assert len(done.stdout.splitlines()) < 30  # short


@pytest.mark.parametrize("name", NAMES)
def test_every_command_help_has_a_description_and_examples_that_parse(name, cli):
    command = subparsers()[name]
    assert command.description and len(command.description) > 20
    assert command.epilog and command.epilog.startswith("example")
    examples = [line.split("  ")[1] if line.startswith("  ") else line for line in command.epilog.splitlines()[1:]]
    commands = [shlex.split(e.strip())[1:] for e in examples if e.strip().startswith("frictionlab ")]
    assert commands, command.epilog
    parsed = [build_parser().parse_args(argv[: argv.index(">")] if ">" in argv else argv) for argv in commands]
    assert name in {args.command for args in parsed}  # each parses; at least one shows this command
    assert "example" in cli(name, "--help").stdout


@pytest.mark.parametrize("name", ["run", "validate", "plugins", "study", "report", "predict", "presets"])
def test_every_reporting_command_takes_json(name):
    options = {o for a in subparsers()[name]._actions for o in a.option_strings}
    assert "--json" in options


def test_json_output_of_validate_plugins_and_predict_parses(cli):
    done = cli("validate", "quickstart", "--json")
    record = json.loads(done.stdout)["presets"][0]
    assert done.returncode == 0 and record["ok"] and record["name"] == "quickstart"
    done = cli("validate", "quickstart", "--set", "realizations=0", "--json")
    record = json.loads(done.stdout)["presets"][0]
    assert done.returncode == ExitCode.USAGE and not record["ok"] and record["problems"][0].startswith("realizations")
    assert json.loads(cli("plugins", "--json").stdout)["plugins"]
    done = cli("predict", "--a", "1.5", "--b", "0.1", "--area", "1", "--modulus", "1", "--rms-height", "1",
                   "--force", "1", "--json")  # fmt: skip
    out = json.loads(done.stdout)
    assert out["a"] == 1.5 and out["b"] == 0.1


def test_did_you_mean_for_commands_and_plugins(cli):
    done = cli("rn", "quickstart")
    assert done.returncode == ExitCode.USAGE and "did you mean 'run'" in done.stderr and "Traceback" not in done.stderr
    done = cli("valdate", "quickstart")
    assert "did you mean 'validate'?" in done.stderr
    done = cli("validate", "quickstart", "--set", "spectrum.name=power-lw")
    assert done.returncode == ExitCode.USAGE and "did you mean 'power-law'" in done.stderr


def test_a_misspelt_option_is_named_before_a_missing_argument(cli):
    """argparse reports a missing positional before it looks at unknown words: a misspelt
    --help left the user told only that the preset is required."""
    done = cli("run", "--hlep")
    assert done.returncode == ExitCode.USAGE and "Traceback" not in done.stderr
    assert "unrecognized arguments: --hlep; did you mean '--help'?" in done.stderr
    assert "required: preset" in done.stderr
    done = cli("run", "--wor", "2")  # a prefix of --workers is an option, not a stray word
    assert "unrecognized" not in done.stderr and "required: preset" in done.stderr
    done = cli("predict", "--a", "-1.5")  # a negative number is a value
    assert "unrecognized" not in done.stderr


@pytest.mark.parametrize("argv", [[], ["presets"], ["completion", "bash"], ["--help"], ["run", "--help"], ["-V"]])
def test_a_closed_pipe_ends_quietly(argv, tmp_path):
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        done = subprocess.run([sys.executable, "-m", "frictionlab", *argv], stdout=write_end, stderr=subprocess.PIPE,
                              cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=60)  # fmt: skip
    finally:
        os.close(write_end)
    assert done.stderr == b""
    assert done.returncode == ExitCode.BROKEN_PIPE


# the run's case is long: a whole run twice, its closed and full stdout met on the path the short commands take
@pytest.mark.parametrize("argv", [["plugins"], ["--help"], ["-V"], pytest.param(["run", "quickstart", "--no-plot", "--quiet"], marks=pytest.mark.long)])
def test_a_closed_stdout_is_written_nowhere_and_a_full_one_is_an_error(argv, tmp_path):
    run = lambda **how: subprocess.run([sys.executable, "-m", "frictionlab", *argv, *(["--out", str(tmp_path / ("closed" if "preexec_fn" in how else "full"))] if argv[0] == "run" else [])],
                                       stderr=subprocess.PIPE, text=True, cwd=tmp_path, timeout=120, **how)  # fmt: skip
    closed = run(preexec_fn=lambda: os.close(1))  # `frictionlab ... >&-`: started without a stdout
    assert (closed.returncode, closed.stderr) == (0, "")
    if os.path.exists("/dev/full"):
        with open("/dev/full", "w") as full:
            done = run(stdout=full)
        assert done.returncode == ExitCode.RUNTIME_FAILURE
        assert done.stderr == "error: cannot write the output: No space left on device\n"
    if argv[0] == "run":  # the run itself is complete either way
        assert (tmp_path / "closed" / "summary.json").is_file()


@pytest.mark.long  # a process of its own, seconds end to end: pytest -m long
def test_progress_that_cannot_be_written_never_stops_a_run(tmp_path):
    command = [sys.executable, "-m", "frictionlab", "run", "quickstart", "--no-plot"]
    closed = subprocess.run([*command, "--out", str(tmp_path / "closed")], stdout=subprocess.DEVNULL, cwd=tmp_path,
                            preexec_fn=lambda: os.close(2), timeout=120)  # fmt: skip
    assert closed.returncode == 0
    if os.path.exists("/dev/full"):
        with open("/dev/full", "w") as full:
            done = subprocess.run([*command, "--out", str(tmp_path / "full")], stdout=subprocess.DEVNULL, stderr=full,
                                  cwd=tmp_path, timeout=120)  # fmt: skip
        assert done.returncode == 0
        assert json.loads((tmp_path / "full" / "run.json").read_text())["status"] == "completed"


def in_terminal(*argv: str, columns: int = 60, **env: str) -> str:
    """The output of ``frictionlab ARGV`` on a pseudo-terminal ``columns`` wide."""
    main, child = pty.openpty()
    environment = {k: v for k, v in os.environ.items() if k != "NO_COLOR"}
    environment.update(COLUMNS=str(columns), LINES="40", TERM="xterm-256color", **env)
    process = subprocess.Popen([sys.executable, "-m", "frictionlab", *argv], stdin=child, stdout=child, stderr=child,
                               env=environment, close_fds=True)  # fmt: skip
    os.close(child)
    chunks = []
    while True:
        try:
            chunk = os.read(main, 65536)
        except OSError:  # the child closed its side
            break
        if not chunk:
            break
        chunks.append(chunk)
    process.wait(timeout=60)
    os.close(main)
    return b"".join(chunks).decode("utf-8", "replace")


def test_tables_fit_the_terminal_width_and_wrap_rather_than_cut(cli):
    text = in_terminal("plugins", columns=60)
    lines = [ANSI.sub("", line) for line in text.replace("\r", "").splitlines() if line.strip()]
    assert lines and max(map(len, lines)) <= 60, max(lines, key=len)
    assert "power-law" in "".join(lines) and "forward-difference" in "".join(lines)
    piped = cli("plugins").stdout  # in a pipe: one line per plugin, however long
    assert max(map(len, piped.splitlines())) > 60 and not ANSI.search(piped)


def test_colour_on_a_terminal_only_and_never_with_no_color(cli):
    assert COLOUR.search(in_terminal("presets"))
    assert not COLOUR.search(in_terminal("presets", NO_COLOR="1"))
    assert not COLOUR.search(cli("presets").stdout)
    error = in_terminal("run", "no-such-preset")
    assert COLOUR.search(error) and "error" in ANSI.sub("", error)
    assert not COLOUR.search(in_terminal("run", "no-such-preset", NO_COLOR="1"))


def test_study_json_holds_the_recommendation_and_one_row_per_setting(tmp_path, cli, figure_stubbed):
    done = cli("study", "quickstart", "--axes", "realizations", "--repeats", "1",
                   "--json", "--quiet", "--out", tmp_path / "study")  # fmt: skip
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert out["recommendation"] and not out["interrupted"]
    assert {row["axis"] for row in out["rows"]} == {"realizations"}
    assert (tmp_path / "study" / "study.csv").is_file() and out["files"]["csv"].endswith("study.csv")


@pytest.mark.long  # a process of its own, seconds end to end: pytest -m long
def test_a_run_whose_reader_left_still_finishes_its_folder(tmp_path):
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        done = subprocess.run([sys.executable, "-m", "frictionlab", "run", "quickstart", "--out", str(tmp_path / "q"),
                               "--quiet", "--workers", "1", "--set", "realizations=4"], stdout=write_end, stderr=subprocess.PIPE, timeout=120)  # fmt: skip
    finally:
        os.close(write_end)
    assert done.returncode == ExitCode.BROKEN_PIPE and done.stderr == b""
    state = json.loads((tmp_path / "q" / "run.json").read_text())
    assert state["status"] == "completed" and (tmp_path / "q" / "plot.png").is_file()


def test_tui_takes_a_builtin_name_and_a_mistyped_one_gets_the_closest_before_the_ui_starts(monkeypatch, cli):
    from argparse import Namespace

    import frictionlab.tui
    from frictionlab.cli import tui

    done = cli("tui", "quikstart")
    assert done.returncode == ExitCode.INPUT_FILE and "did you mean 'quickstart'?" in done.stderr
    opened = []
    monkeypatch.setattr(frictionlab.tui, "run_app", lambda preset, **kwargs: opened.append(preset) or 0)
    tui.run(Namespace(preset="quickstart", presets=None, runs=None, workers=1))
    assert len(opened) == 1 and opened[0].endswith("quickstart.yaml")


@pytest.mark.parametrize("option", ["--presets", "--runs"])
def test_tui_refuses_a_file_given_as_its_presets_or_runs_folder_before_the_ui_starts(tmp_path, monkeypatch, cli, option):
    """A file given as --presets or --runs started the TUI, which said 'No presets in FILE' or
    listed no runs, and only a save or a run then failed. A folder not there yet is still taken."""
    import frictionlab.tui

    (tmp_path / "afile").write_text("")
    opened = []
    monkeypatch.setattr(frictionlab.tui, "run_app", lambda preset, **kwargs: opened.append(kwargs) or 0)
    monkeypatch.chdir(tmp_path)
    done = cli("tui", option, "afile")
    assert done.returncode == ExitCode.USAGE and f"{option}: afile is not a folder" in done.stderr
    assert cli("tui", option, "not-yet").returncode == 0 and len(opened) == 1
