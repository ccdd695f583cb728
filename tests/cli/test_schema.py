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
