"""A command is parsed by a parser holding only its own subparser (building all fourteen
was a tenth of a short run's start): its help, its usage errors and what it parses are
those of the full parser."""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io

import pytest

from frictionlab.cli import main as cli_main
from frictionlab.cli.main import build_parser, command_names

cli = importlib.import_module("frictionlab.cli.main")  # the module: frictionlab.cli.main is also its function


def subparser(parser: argparse.ArgumentParser, name: str) -> argparse.ArgumentParser:
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices[name]


def outcome(parser: argparse.ArgumentParser, argv: list[str]) -> tuple:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            parsed = vars(parser.parse_args(argv))
            code = None
        except SystemExit as exc:
            parsed, code = None, exc.code
    return parsed, code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("name", command_names())
def test_each_command_s_help_and_errors_are_those_of_the_full_parser(name):
    full, sole = build_parser(), build_parser(name)
    assert subparser(sole, name).format_help() == subparser(full, name).format_help()
    for argv in ([name, "--help"], [name, "--no-such-option"], [name]):
        assert outcome(sole, argv) == outcome(full, argv), argv


def test_run_s_words_parse_alike():
    argv = ["run", "quickstart", "--out", "o", "--set", "seed=3", "--no-plot", "--quiet", "--workers", "2"]
    assert outcome(build_parser("run"), argv) == outcome(build_parser(), argv)


def test_main_builds_only_the_command_asked_but_for_completion(monkeypatch):
    asked = []
    real = cli.build_parser

    def recording(only=None):
        asked.append(only)
        return real(only)

    monkeypatch.setattr(cli, "build_parser", recording)
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        for argv in (["presets"], ["completion", "bash"], ["--version"]):
            with contextlib.suppress(SystemExit):
                cli_main(argv)
    assert asked == ["presets", None, None]
