"""The headless CLI as a user meets it: real files, real subprocesses, exit codes."""

import json

from frictionlab.cli import main
from frictionlab.errors import ExitCode


def test_plugins_lists_kind_name_provider_and_version(capsys):
    assert main(["plugins"]) == ExitCode.OK
    out = capsys.readouterr().out
    for kind, name in [("spectrum", "power-law"), ("solver", "mdr"), ("slope", "forward-difference")]:
        line = next(line for line in out.splitlines() if line.split()[:2] == [kind, name])
        assert "frictionlab" in line and "0." in line  # provider and its version
    assert main(["plugins", "--json"]) == ExitCode.OK
    rows = json.loads(capsys.readouterr().out)["plugins"]
    assert {r["name"] for r in rows if r["kind"] == "slope"} >= {"forward-difference", "central-difference", "spectral"}
