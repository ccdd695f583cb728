"""The tutorials' own files and snippets work as a reader copies them: the measured-profile
tutorial's scan and preset validate without a caveat, and the plugin tutorial's
conformance test runs as written."""

from __future__ import annotations

import contextlib
import io
import re
import sys

from frictionlab.cli.main import main

from .conftest import ROOT

TUTORIALS = ROOT / "docs" / "tutorials"


def _blocks(page: str, lang: str) -> list[str]:
    return re.findall(rf"^```{lang}\n(.*?)^```", (TUTORIALS / page).read_text(encoding="utf-8"), flags=re.S | re.M)


def test_the_measured_profile_tutorials_scan_validates_without_a_caveat(tmp_path, monkeypatch):
    """Its test file's heights and its preset's spacing are in one unit: no caveat about
    the rms slope (nor any other) greets a reader's first validation."""
    (command,) = [line for block in _blocks("measured-profile.md", "bash") for line in block.splitlines()
                  if line.startswith("python -c ")]  # fmt: skip
    (preset,) = [block for block in _blocks("measured-profile.md", "yaml") if block.startswith("name: my-scan")]
    monkeypatch.chdir(tmp_path)
    exec(command.removeprefix("python -c ").strip('"'), {})
    (tmp_path / "scan.yaml").write_text(preset, encoding="utf-8")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert main(["validate", "scan.yaml"]) == 0
    assert "read scan.npy" in printed.getvalue()
    assert "caveat" not in printed.getvalue(), printed.getvalue()


def test_the_plugin_tutorials_conformance_test_runs_as_written(monkeypatch, register_plugin):
    """The test module the tutorial shows, with the example plugin importable (as after
    its `pip install -e`): its tests pass when called as pytest would call them."""
    (block,) = [block for block in _blocks("write-a-plugin.md", "python") if "check_plugin" in block]
    monkeypatch.syspath_prepend(str(ROOT / "examples" / "frictionlab-gaussian"))
    before = sys.modules.pop("frictionlab_gaussian", None)
    try:
        space: dict = {}
        exec(compile(block, "write-a-plugin.md", "exec"), space)
        (marks,) = space["test_conformance"].pytestmark
        for params in marks.args[1]:
            space["test_conformance"](params)
        space["test_registered_through_the_hook"](register_plugin)
    finally:  # the example's module leaves with its folder on sys.path
        sys.modules.pop("frictionlab_gaussian", None)
        if before is not None:
            sys.modules["frictionlab_gaussian"] = before
