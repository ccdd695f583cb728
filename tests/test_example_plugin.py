"""The entry-point path end to end: install the example third-party plugin
``examples/frictionlab-gaussian`` (offline, into a temporary directory) and find
it from a fresh process through ``importlib.metadata`` entry points; what the
environment switches and the commands make of it is checked in this process, the
folder it is installed in put on ``sys.path``."""

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


def _listing(registry) -> dict:
    return {
        "plugins": [[i.kind, i.name, i.provider, i.version] for i in registry.infos()],
        "failures": [[f.entry_point, f.distribution, f.error] for f in registry.failures],
    }


@pytest.fixture
def example_here(installed_example, monkeypatch):
    """The installed example found by this process: its folder first on ``sys.path``, no
    FRICTIONLAB_ switch set, the caches of what is installed (and the CLI's registry)
    cleared before and after, and its modules forgotten after."""
    from frictionlab.plugin import registry

    before = set(sys.modules)
    monkeypatch.syspath_prepend(str(installed_example))
    for name in [name for name in os.environ if name.startswith("FRICTIONLAB_")]:
        monkeypatch.delenv(name)
    caches = (registry._module_distributions, registry.provider_of, registry.default_registry)
    for cache in caches:
        cache.cache_clear()
    yield installed_example
    for cache in caches:
        cache.cache_clear()
    for name in set(sys.modules) - before:
        if name.partition(".")[0] == "frictionlab_gaussian":
            del sys.modules[name]


def test_installed_example_is_discovered_with_provider_and_version(installed_example):
    result = _run(installed_example, ["-c", LIST_PLUGINS])  # a fresh process, as a user's
    assert result.returncode == 0, result.stderr
    listing = json.loads(result.stdout)
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
def test_environment_switches_hide_the_example(example_here, env):
    from frictionlab.plugin.registry import Registry

    found = [row[1] for row in _listing(Registry(env={})).get("plugins")]
    assert "gaussian" in found  # without the switch it is there
    if "FRICTIONLAB_PLUGINS" in env:  # a name no installed plugin has is said (a typo would leave its plugin out)
        with pytest.warns(RuntimeWarning, match="FRICTIONLAB_PLUGINS names 'some-other-plugin', which is no installed"):
            registry = Registry(env=env)
    else:
        registry = Registry(env=env)
    names = [row[1] for row in _listing(registry)["plugins"]]
    assert "gaussian" not in names
    assert "power-law" in names


def test_listed_example_is_loaded(example_here):
    from frictionlab.plugin.registry import Registry

    listing = _listing(Registry(env={"FRICTIONLAB_PLUGINS": "gaussian"}))
    assert ["spectrum", "gaussian", "frictionlab-gaussian", _example_version()] in listing["plugins"]


def test_example_generates_through_the_registry(example_here):
    import numpy as np

    from frictionlab.plugin.registry import Registry

    cls = Registry(env={}).get("spectrum", "Gaussian")
    z = cls(points=64, correlation_length=4.0, rms_height=2.0).generate(np.random.default_rng(1)).heights
    assert cls.__module__ == "frictionlab_gaussian" and z.size == 64
    assert float(np.sqrt(np.mean(z**2))) == pytest.approx(2.0, abs=1e-9)


def test_cli_lists_the_example(example_here, cli):
    from frictionlab.plugin.registry import default_registry

    result = cli("plugins")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "gaussian" in result.stdout
    assert "frictionlab-gaussian" in result.stdout
    default_registry.cache_clear()  # the CLI's registry is built once per process, switches read then
    blocked = cli("plugins", env={"FRICTIONLAB_BLOCK_PLUGINS": "gaussian"})
    assert blocked.returncode == 0, blocked.stdout + blocked.stderr
    assert "frictionlab-gaussian" not in blocked.stdout


def test_the_tutorials_step_4_validates_as_shown_and_a_name_switched_alone_is_refused(example_here, cli, tmp_path):
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
        done = cli(*argv, cwd=tmp_path)
        assert done.returncode == 0 and ": ok (" in done.stdout, (argv, done.stderr)
    alone = cli("validate", "quickstart", "--set", "spectrum.name=gaussian", cwd=tmp_path)
    assert alone.returncode == 2 and "spectrum.params.hurst: is not a known field" in alone.stderr


def test_the_tutorials_step_3_tests_run_as_shown(example_here, register_plugin):
    """docs/tutorials/write-a-plugin.md, step 3: its conformance tests, run on the example
    (the page's ``Gaussian``), pass as written, each parametrised case and the hook's."""
    import re

    page = (ROOT / "docs" / "tutorials" / "write-a-plugin.md").read_text(encoding="utf-8")
    block = re.search(r"```python\n(.*?)```", page.split("## 3.", 1)[1], re.S).group(1)
    from frictionlab_gaussian import Gaussian

    space = {"Gaussian": Gaussian}
    exec(compile(block, "write-a-plugin.md", "exec"), space)
    (marker,) = space["test_conformance"].pytestmark
    for params in marker.args[1]:
        space["test_conformance"](params)
    space["test_registered_through_the_hook"](register_plugin)
