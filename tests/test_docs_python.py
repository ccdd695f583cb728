"""The Python examples of the API reference run as written, from any folder."""

from __future__ import annotations

import re

from .conftest import ROOT

PAGE = ROOT / "docs" / "reference" / "python-api.md"


def test_the_api_references_python_examples_run_from_any_folder(tmp_path, monkeypatch, capsys):
    blocks = re.findall(r"```python\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.S)
    assert blocks
    monkeypatch.chdir(tmp_path)  # a reader's own folder, not the clone: built-ins by name
    for block in blocks:
        exec(compile(block, str(PAGE), "exec"), {})
    assert capsys.readouterr().out.startswith("completed ")
    assert (tmp_path / "runs" / "qs-python" / "summary.json").is_file()


def test_the_readmes_python_example_runs_from_a_clone(tmp_path, monkeypatch):
    """The README's example names presets/quickstart.yaml as a clone holds it; it runs,
    and the run read back has the same fit."""
    import shutil

    (block,) = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(encoding="utf-8"), re.S)
    (tmp_path / "presets").mkdir()
    shutil.copy(ROOT / "presets" / "quickstart.yaml", tmp_path / "presets")
    monkeypatch.chdir(tmp_path)
    space: dict = {}
    exec(compile(block, "README.md", "exec"), space)
    assert space["again"].fit == space["r"].fit and len(space["xi"]) == len(space["r"].table["f"])
