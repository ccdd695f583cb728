"""The built-in presets: listed from the package, run by name, copied out, and
shipped inside a real (non-editable) install that works from an empty folder."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

import frictionlab

from frictionlab.errors import ExitCode, PresetFileError
from frictionlab.preset.builtin import builtin_presets, find_builtin, resolve_preset_path

from .conftest import PRESETS, ROOT


def test_every_preset_of_the_folder_is_listed_with_its_own_description():
    listed = {p.name: p for p in builtin_presets()}
    assert set(listed) == {p.stem for p in PRESETS.glob("*.yaml")}
    for name, preset in listed.items():
        assert preset.path.is_file() and preset.path.name == f"{name}.yaml"
        own = " ".join(yaml.safe_load(preset.path.read_text())["description"].split())
        words = preset.description.removesuffix(" ...")
        assert own.startswith(words) and 10 < len(preset.description) <= 104, preset.description


def test_a_name_means_the_builtin_and_a_path_stays_a_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert resolve_preset_path("quickstart") == find_builtin("quickstart.yaml").path
    mine = tmp_path / "quickstart.yaml"
    with pytest.raises(PresetFileError, match=r"no file .*quickstart.yaml' here; the built-in preset of that name"):
        resolve_preset_path(mine)  # missing: pointed to the built-in, never swapped for it
    mine.write_text("name: mine\n")
    assert resolve_preset_path(mine) == mine  # a path is never swapped for a built-in
    mine.unlink()
    with pytest.raises(PresetFileError, match=r"did you mean 'quickstart'\?"):
        resolve_preset_path("quikstart")
    with pytest.raises(PresetFileError, match=r"no file 'quickstart.yaml' here; the built-in preset of that name is 'quickstart'"):
        resolve_preset_path("quickstart.yaml")  # from a folder without that file
    (tmp_path / "quickstart").mkdir()  # `frictionlab run quickstart --out quickstart`: a folder is never a preset
    assert resolve_preset_path("quickstart") == find_builtin("quickstart").path
    (tmp_path / "mine").mkdir()
    assert resolve_preset_path("mine") == Path("mine")  # no built-in of that name: read, and refused, as a path


def test_presets_command_lists_as_json_and_copies_without_overwriting(tmp_path, cli):
    listed = json.loads(cli("presets", "--json").stdout)["presets"]
    assert {row["name"] for row in listed} == {p.stem for p in PRESETS.glob("*.yaml")}
    result = cli("presets", "copy", "quickstart", tmp_path)
    assert result.returncode == 0, result.stderr
    copy = tmp_path / "quickstart.yaml"
    assert copy.read_bytes() == (PRESETS / "quickstart.yaml").read_bytes()
    copy.write_text("mine")
    result = cli("presets", "copy", "quickstart", copy)
    assert result.returncode == ExitCode.OUTPUT_REFUSED and "--force" in result.stderr
    assert copy.read_text() == "mine"
    assert cli("presets", "copy", "quickstart", copy, "--force").returncode == 0
    assert copy.read_bytes() == (PRESETS / "quickstart.yaml").read_bytes()
    result = cli("presets", "copy", "fig2")
    assert result.returncode == ExitCode.USAGE and "benad2012-fig2" in result.stderr


def test_presets_copy_to_a_name_ending_in_a_slash_makes_that_folder(tmp_path, cli):
    result = cli("presets", "copy", "quickstart", f"{tmp_path / 'newdir'}/")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "newdir" / "quickstart.yaml").read_bytes() == (PRESETS / "quickstart.yaml").read_bytes()
    (tmp_path / "afile").write_text("mine")
    result = cli("presets", "copy", "quickstart", f"{tmp_path / 'afile' / 'sub'}/")
    assert result.returncode == ExitCode.OUTPUT_REFUSED and "afile is a file" in result.stderr
    assert (tmp_path / "afile").read_text() == "mine"


def test_presets_copy_over_a_folder_of_its_name_is_refused_with_or_without_force(tmp_path, capsys):
    """A folder named as the copy: refused as 'exists, or --force', and --force then failed with exit 1."""
    from frictionlab.cli import main

    (tmp_path / "quickstart.yaml").mkdir()
    (tmp_path / "quickstart.yaml" / "mine.txt").write_text("mine")
    for force in ([], ["--force"]):
        assert main(["presets", "copy", "quickstart", str(tmp_path), *force]) == ExitCode.OUTPUT_REFUSED
        text = capsys.readouterr().err
        assert "quickstart.yaml is a folder, not a file" in text and "give another DEST" in text, text
    assert (tmp_path / "quickstart.yaml" / "mine.txt").read_text() == "mine"


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """frictionlab installed as a user would (a built wheel, not editable), offline,
    into a folder of its own; returns that folder, to put on PYTHONPATH."""
    work = tmp_path_factory.mktemp("install")
    source = work / "src"
    source.mkdir()
    for name in ("frictionlab", "plugins", "presets"):
        shutil.copytree(ROOT / name, source / name, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    for name in ("pyproject.toml", "setup.py", "README.md"):
        shutil.copy(ROOT / name, source / name)
    target = work / "site"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1", PIP_NO_INPUT="1")
    result = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-build-isolation", "--no-index",
         "--target", str(target), str(source)],
        capture_output=True, text=True, env=env, timeout=300,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    return target


@pytest.mark.long
def test_a_real_install_runs_a_builtin_by_name_from_an_empty_folder(installed, tmp_path):
    empty = tmp_path / "anywhere"
    empty.mkdir()
    env = {k: v for k, v in os.environ.items() if not k.startswith("FRICTIONLAB_")}
    env["PYTHONPATH"] = str(installed)

    def cli(*args):
        return subprocess.run([sys.executable, "-m", "frictionlab", *args], capture_output=True, text=True,
                              cwd=empty, env=env, timeout=300)  # fmt: skip

    listed = json.loads(cli("presets", "--json").stdout)["presets"]
    assert {row["name"] for row in listed} == {p.stem for p in PRESETS.glob("*.yaml")}
    for row in listed:  # the installed copies, not the checkout's
        assert Path(row["path"]).is_relative_to(installed / "frictionlab" / "builtin_presets")
    result = cli("run", "quickstart", "--out", "q", "--quiet", "--workers", "1", "--no-plot")
    assert result.returncode == 0, result.stderr
    assert (empty / "q" / "summary.json").is_file() and "a  " in result.stdout
    code = "import frictionlab; r = frictionlab.run('quickstart', progress=False); print(frictionlab.__file__, r.fit.a, r.fit.b)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=empty, env=env, timeout=300)
    where, a, b = done.stdout.split()
    assert Path(where).is_relative_to(installed) and float(a) == frictionlab.load(empty / "q").fit.a


@pytest.mark.parametrize("command", ["run", "validate"])
def test_a_bad_set_on_a_built_in_names_the_built_in_and_the_set_not_the_installed_file(command, tmp_path, cli):
    result = cli(command, "quickstart", "--set", "realizations=-5", cwd=tmp_path)
    assert result.returncode == ExitCode.USAGE
    assert "built-in preset 'quickstart' --set realizations=-5: 1 problem" in result.stderr
    assert "realizations: must be >= 1, got -5" in result.stderr
    assert str(find_builtin("quickstart").path) not in result.stderr
    assert not (tmp_path / "runs").exists()  # nothing started
