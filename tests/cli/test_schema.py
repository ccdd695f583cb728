"""The headless CLI as a user meets it: real files, real subprocesses, exit codes."""

import json

from frictionlab.cli import main
from frictionlab.errors import ExitCode


def test_schema_lists_installed_plugins_with_their_params(capsys):
    assert main(["schema"]) == ExitCode.OK
    schema = json.loads(capsys.readouterr().out)
    spectra = {v["properties"]["name"]["const"]: v for v in schema["properties"]["spectrum"]["oneOf"]}
    assert {"power-law", "rolloff", "profile-file"} <= set(spectra)
    hurst = spectra["power-law"]["properties"]["params"]["properties"]["hurst"]
    assert hurst["maximum"] == 1.5 and hurst["description"]
    assert spectra["power-law"]["properties"]["params"]["additionalProperties"] is False


def test_schema_out_writes_the_schema_to_a_file(tmp_path, capsys):
    assert main(["schema", "--out", str(tmp_path / "schema.json")]) == ExitCode.OK
    assert capsys.readouterr().out == ""
    schema = json.loads((tmp_path / "schema.json").read_text())
    assert schema["title"] == "frictionlab preset"


def test_schema_out_keeps_an_existing_file_unless_force(tmp_path, capsys):
    mine = tmp_path / "existing.json"
    mine.write_text("mine")
    assert main(["schema", "--out", str(mine)]) == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert "--out" in err and str(mine) in err and "--force" in err
    assert mine.read_text() == "mine"
    assert main(["schema", "--out", str(mine), "--force"]) == ExitCode.OK
    assert json.loads(mine.read_text())["title"] == "frictionlab preset"


def test_schema_out_a_folder_or_under_a_file_is_refused_naming_the_option(tmp_path, capsys):
    (tmp_path / "sdir").mkdir()
    (tmp_path / "afile").write_text("x")
    for out in (tmp_path / "sdir", f"{tmp_path / 'newdir'}/", tmp_path / "afile" / "x.json"):
        assert main(["schema", "--out", str(out), "--force"]) == ExitCode.OUTPUT_REFUSED
        err = capsys.readouterr().err
        assert "--out" in err and ".tmp" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "sdir"] and not any((tmp_path / "sdir").iterdir())
