"""Every ``--json`` output is one JSON object naming its shape, refusals included, with
nothing else on stdout (the shapes: frictionlab/cli/jsonout.py)."""

from __future__ import annotations

import argparse
import json

import pytest

from frictionlab.cli import main
from frictionlab.cli.main import build_parser
from frictionlab.errors import ExitCode
from frictionlab.preset.builtin import builtin_presets

from ..conftest import SMALL_PRESET, merge
from .conftest import write_preset

PREDICT = ["predict", "--area", "1e-4", "--modulus", "1e9", "--rms-height", "1e-6", "--force", "10"]


def one_object(stdout: str) -> dict:
    """stdout holds exactly one JSON object, naming its shape."""
    data = json.loads(stdout)  # raises on anything before or after the object
    assert isinstance(data, dict) and data["schema"].startswith("frictionlab/") and data["schema"].endswith("/1")
    return data


def commands_with_json() -> set[str]:
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return {name for name, parser in sub.choices.items() if any("--json" in a.option_strings for a in parser._actions)}


def refused(tmp_path):
    """A refused invocation under --json of every command that has it."""
    bad = write_preset(tmp_path, merge(SMALL_PRESET, {"spectrum": {"params": {"hurts": 0.8}}}))
    return {
        "run": ["run", str(bad), "--out", str(tmp_path / "o")],
        "resume": ["resume", str(tmp_path / "no-such-run")],
        "validate": ["validate", str(tmp_path / "missing.yaml")],
        "plugins": ["plugins", "--workers", "2"],  # an option it has not: a usage error
        "presets": ["presets", "--forse"],
        "predict": [*PREDICT, "--a", "1"],  # no --b
        "study": ["study", "no-such-preset", "--out", str(tmp_path / "s")],
        "report": ["report", "--presets", str(tmp_path / "none"), "--out", str(tmp_path / "r"), "--workers", "0"],
        "runs": ["runs", str(tmp_path / "no-such-folder")],
        "follow": ["follow", str(tmp_path / "no-such-run")],
    }


def test_every_command_with_json_has_its_refusal_checked_here(tmp_path):
    assert set(refused(tmp_path)) == commands_with_json()


@pytest.mark.parametrize("command", sorted(commands_with_json()))
def test_a_refusal_under_json_is_one_error_object_on_stdout(tmp_path, command, cli):
    argv = refused(tmp_path)[command]
    done = cli(*argv, "--json", cwd=tmp_path)
    assert done.returncode not in (ExitCode.OK, ExitCode.INTERNAL), done.stderr
    data = one_object(done.stdout)
    if command == "validate":  # its records say each preset's problems: a refusal of one is one record
        assert data["schema"] == "frictionlab/validate/1" and data["ok"] is False
        assert data["presets"][0]["exit_code"] == done.returncode == ExitCode.INPUT_FILE
        return
    assert data["schema"] == "frictionlab/error/1" and data["exit_code"] == done.returncode
    assert data["error"] and data["problems"] and "Traceback" not in done.stderr
    assert data["error"].splitlines()[0] in done.stderr  # a person watching reads it too


def test_a_refused_preset_names_its_field_and_every_problem(tmp_path, cli):
    bad = write_preset(tmp_path, merge(SMALL_PRESET, {"spectrum": {"params": {"hurts": 0.8}}, "realizations": 0}))
    done = cli("run", bad, "--json", "--out", tmp_path / "o")
    data = one_object(done.stdout)
    assert data["exit_code"] == ExitCode.USAGE == done.returncode and data["command"] == "run"
    assert data["field"] == "realizations" and len(data["problems"]) == 2
    assert any(p.startswith("spectrum.params.hurts: is not a known field; did you mean 'hurst'?") for p in data["problems"])
    assert not (tmp_path / "o").exists()


def test_an_option_refused_by_argparse_or_by_its_check_is_named_as_the_field(capsys):
    with pytest.raises(SystemExit):
        main(["run", "quickstart", "--workers", "x", "--json"])
    data = one_object(capsys.readouterr().out)
    assert data["field"] == "--workers" and data["exit_code"] == ExitCode.USAGE and data["command"] == "run"
    assert main(["run", "quickstart", "--workers", "0", "--json"]) == ExitCode.USAGE
    data = one_object(capsys.readouterr().out)
    assert data["field"] == "--workers" and data["error"] == "--workers must be >= 1. Got 0 instead."


def test_successes_are_one_object_each_with_their_shape(tmp_path, capsys):
    assert main(["run", "quickstart", "--set", "realizations=4", "--workers", "1", "--quiet", "--no-plot", "--json",
                 "--out", str(tmp_path / "r")]) == ExitCode.OK  # fmt: skip
    data = one_object(capsys.readouterr().out)
    assert data["schema"] == "frictionlab/run/1" and data["fit"]["a"] == json.loads((tmp_path / "r" / "summary.json").read_text())["fit"]["a"]
    assert main(["validate", "quickstart", "--json"]) == ExitCode.OK
    assert one_object(capsys.readouterr().out)["presets"][0]["name"] == "quickstart"
    assert main(["plugins", "--json"]) == ExitCode.OK
    assert {"kind", "name", "provider"} <= set(one_object(capsys.readouterr().out)["plugins"][0])
    assert main([*PREDICT, "--a", "1.88", "--b", "0.08", "--json"]) == ExitCode.OK
    assert one_object(capsys.readouterr().out)["schema"] == "frictionlab/predict/1"


def test_presets_json_holds_each_whole_description(capsys):
    import yaml

    assert main(["presets", "--json"]) == ExitCode.OK
    listed = one_object(capsys.readouterr().out)["presets"]
    assert [p["name"] for p in listed] == [p.name for p in builtin_presets()]
    for preset in listed:
        own = yaml.safe_load(open(preset["path"], encoding="utf-8")).get("description")
        assert not preset["description"].endswith("...")
        if own:
            assert preset["description"] == " ".join(own.split())


def test_every_shape_is_documented_and_every_command_with_json_prints_one():
    from frictionlab.cli.jsonout import SHAPES

    printed = {command.strip() for commands, _ in SHAPES.values() for command in commands.split(",")}
    assert commands_with_json() <= printed
    page = _hooks().json_reference()
    for name, (commands, holds) in SHAPES.items():
        assert f"`frictionlab/{name}/1`" in page and holds in page, name


def _hooks():
    import importlib.util

    from ..conftest import ROOT

    spec = importlib.util.spec_from_file_location("docs_reference_hooks", ROOT / "docs" / "hooks" / "reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_mistyped_command_under_json_is_an_error_object_too(capsys):
    assert main(["valdate", "quickstart", "--json"]) == ExitCode.USAGE
    data = one_object(capsys.readouterr().out)
    assert data["schema"] == "frictionlab/error/1" and "did you mean 'validate'?" in data["error"]
    assert data["command"] is None and data["exit_code"] == ExitCode.USAGE


def test_presets_json_before_copy_is_refused_not_ignored(tmp_path, cli):
    """`presets --json copy NAME` printed a line of text to a script waiting for JSON."""
    done = cli("presets", "--json", "copy", "quickstart", str(tmp_path / "q.yaml"))
    assert done.returncode == ExitCode.USAGE and not (tmp_path / "q.yaml").exists()
    data = one_object(done.stdout)
    assert data["schema"] == "frictionlab/error/1" and "presets copy prints none: leave --json out" in data["error"]
