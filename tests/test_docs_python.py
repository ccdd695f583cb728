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


def test_the_plugin_tutorials_solver_and_estimator_pass_the_kit_and_run(register_plugin):
    """docs/tutorials/write-a-plugin.md showed a spectrum generator only: a solver's author had
    to read frictionlab's source for how a ForceNormalisation is made. Its solver and slope
    estimator, as written, pass the conformance kit and run a realization."""
    from frictionlab.compute.realization import compute_realization
    from frictionlab.preset import build_scene
    from frictionlab.testing import check_plugin

    from .conftest import SMALL_PRESET
    from .testing.fakes import GoodSpectrum

    page = (ROOT / "docs" / "tutorials" / "write-a-plugin.md").read_text(encoding="utf-8")
    (block,) = [b for b in re.findall(r"```python\n(.*?)```", page, re.S) if "class Springs" in b]
    space: dict = {"__name__": "tutorial_plugin"}
    exec(compile(block, "write-a-plugin.md", "exec"), space)
    check_plugin("solver", space["Springs"])
    check_plugin("slope", space["Central"])
    for cls in (GoodSpectrum, space["Springs"], space["Central"]):
        registry = register_plugin(cls)
    data = {**SMALL_PRESET, "spectrum": {"name": GoodSpectrum.name}, "solver": {"name": "my-springs"},
            "slope": {"name": "my-central"}}  # fmt: skip
    result = compute_realization(build_scene(data, registry=registry), 0)
    assert result.error is None and result.xi.shape == (SMALL_PRESET["loading"]["steps"],)
