"""The entry-point path end to end: install the example third-party plugin
``examples/frictionlab-gaussian`` (offline, into a temporary directory) and find
it from a fresh process through ``importlib.metadata`` entry points."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "frictionlab-gaussian"

LIST_PLUGINS = """
import json
from frictionlab.plugin.registry import Registry
registry = Registry()
print(json.dumps({
    "plugins": [[i.kind, i.name, i.provider, i.version] for i in registry.infos()],
    "failures": [[f.entry_point, f.distribution, f.error] for f in registry.failures],
}))
"""


def _example_version() -> str:
    with open(EXAMPLE / "pyproject.toml", "rb") as f:
        return tomllib.load(f)["project"]["version"]


@pytest.fixture(scope="session")
def installed_example(tmp_path_factory) -> Path:
    """The example, pip-installed (no deps, no index, no build isolation) into a
    directory of its own; returns that directory, to put on PYTHONPATH."""
    work = tmp_path_factory.mktemp("example-plugin")
    source = work / "src"
    # build from a copy: setuptools writes build/ and *.egg-info next to the sources
    shutil.copytree(EXAMPLE, source, ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__", ".pytest_cache"))
    target = work / "site"
    env = _clean_env()
    env.update(PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1", PIP_NO_INPUT="1")
    result = subprocess.run(
        [
            sys.executable, "-m", "pip", "install", "--quiet",
            "--no-deps", "--no-build-isolation", "--no-index",
            "--target", str(target), str(source),
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=240,
    )
    assert result.returncode == 0, f"pip install of the example failed:\n{result.stdout}\n{result.stderr}"
    assert (target / "frictionlab_gaussian" / "__init__.py").is_file()
    return target


def _clean_env(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("FRICTIONLAB_") and k != "PYTHONPATH"}
    env.update(extra)
    return env


def _run(site: Path, args: list[str], **env: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, *args],
        capture_output=True,
        text=True,
        env=_clean_env(PYTHONPATH=str(site), **env),
        cwd=site,
        timeout=120,
    )


def _plugins(site: Path, **env: str) -> dict:
    result = _run(site, ["-c", LIST_PLUGINS], **env)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def test_installed_example_is_discovered_with_provider_and_version(installed_example):
    listing = _plugins(installed_example)
    assert listing["failures"] == []
    rows = [row for row in listing["plugins"] if row[1] == "gaussian"]
    assert rows == [["spectrum", "gaussian", "frictionlab-gaussian", _example_version()]]
    # the built-ins are there too, provided by frictionlab itself
    assert ["spectrum", "power-law", "frictionlab"] in [row[:3] for row in listing["plugins"]]


@pytest.mark.parametrize(
    "env",
    [
        {"FRICTIONLAB_BLOCK_PLUGINS": "gaussian"},
        {"FRICTIONLAB_DISABLE_DISCOVERY": "1"},
        {"FRICTIONLAB_PLUGINS": "some-other-plugin"},
    ],
    ids=["blocked", "discovery-disabled", "not-listed"],
)
def test_environment_switches_hide_the_example(installed_example, env):
    listing = _plugins(installed_example, **env)
    names = [row[1] for row in listing["plugins"]]
    assert "gaussian" not in names
    assert "power-law" in names


def test_listed_example_is_loaded(installed_example):
    listing = _plugins(installed_example, FRICTIONLAB_PLUGINS="gaussian")
    assert "gaussian" in [row[1] for row in listing["plugins"]]


def test_example_generates_through_the_registry(installed_example):
    code = (
        "import numpy as np; from frictionlab.plugin.registry import Registry; "
        "cls = Registry().get('spectrum', 'Gaussian'); "
        "z = cls(points=64, correlation_length=4.0, rms_height=2.0).generate(np.random.default_rng(1)).heights; "
        "print(cls.__module__, z.size, round(float(np.sqrt(np.mean(z**2))), 9))"
    )
    result = _run(installed_example, ["-c", code])
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["frictionlab_gaussian", "64", "2.0"]


def test_cli_lists_the_example(installed_example):
    result = _run(installed_example, ["-m", "frictionlab", "plugins"])
    assert result.returncode == 0, result.stdout + result.stderr
    assert "gaussian" in result.stdout
    assert "frictionlab-gaussian" in result.stdout
    blocked = _run(installed_example, ["-m", "frictionlab", "plugins"], FRICTIONLAB_BLOCK_PLUGINS="gaussian")
    assert blocked.returncode == 0, blocked.stdout + blocked.stderr
    assert "frictionlab-gaussian" not in blocked.stdout


def test_the_tutorials_step_4_validates_as_shown_and_a_name_switched_alone_is_refused(installed_example, tmp_path):
    """docs/tutorials/write-a-plugin.md: its preset, saved as gaussian.yaml, and its --set
    line from quickstart validate with the plugin installed; the name alone does not."""
    import re
    import shlex

    page = (ROOT / "docs" / "tutorials" / "write-a-plugin.md").read_text(encoding="utf-8")
    step = page.split("## 4. Use it", 1)[1]
    (tmp_path / "gaussian.yaml").write_text(re.search(r"```yaml\n(.*?)```", step, re.S).group(1))
    commands = [shlex.split(line)[1:] for line in re.findall(r"^frictionlab .*$", step, re.M)]
    assert commands[0] == ["validate", "gaussian.yaml"] and "--set" in commands[1]
    for argv in commands:
        done = subprocess.run([sys.executable, "-m", "frictionlab", *argv], capture_output=True, text=True, cwd=tmp_path,
                              env=_clean_env(PYTHONPATH=str(installed_example)), timeout=120)  # fmt: skip
        assert done.returncode == 0 and ": ok (" in done.stdout, (argv, done.stderr)
    alone = subprocess.run([sys.executable, "-m", "frictionlab", "validate", "quickstart", "--set", "spectrum.name=gaussian"],
                           capture_output=True, text=True, cwd=tmp_path, env=_clean_env(PYTHONPATH=str(installed_example)),
                           timeout=120)  # fmt: skip
    assert alone.returncode == 2 and "spectrum.params.hurst: is not a known field" in alone.stderr
