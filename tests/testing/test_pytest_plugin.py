"""The pytest plugin itself: its fixtures, its loading in every session, its cheap import."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
import textwrap
import types
from pathlib import Path

import pluggy
import pytest

from frictionlab import (
    hookimpl,
)
from frictionlab.errors import PluginError
from frictionlab.plugin import KINDS
from frictionlab.plugin.registry import Registry

from .fakes import GoodSlopes, GoodSolver, GoodSpectrum, provider, spectrum_class

ROOT = Path(__file__).resolve().parents[2]

KIND_HOOKS = {kind: base.register_hook for kind, base in KINDS.items()}


# =========================================================================== fakes


# ==================================================== the pytest plugin itself


def test_frictionlab_registry_fixture(frictionlab_registry):
    assert isinstance(frictionlab_registry, Registry)
    assert "power-law" in frictionlab_registry.names("spectrum")


def test_register_plugin_fixture_accepts_modules_holders_and_classes(register_plugin, frictionlab_registry):
    module = types.ModuleType("acme_module_plugin")
    module.register_solvers = hookimpl(lambda register: register(GoodSolver))
    assert register_plugin(module) is frictionlab_registry
    assert frictionlab_registry.get("solver", "Good_Solver") is GoodSolver
    register_plugin(GoodSlopes)  # a plugin class: registered through its kind's hook
    assert frictionlab_registry.get("slope", "good-slopes") is GoodSlopes
    register_plugin(provider(GoodSpectrum), name="acme-holder")
    assert frictionlab_registry.pm.get_plugin("acme-holder") is not None


def test_register_plugin_fixture_propagates_errors(register_plugin, frictionlab_registry):
    class Typo:
        @hookimpl
        def register_solver(self, register):
            pass

    with pytest.raises(pluggy.PluginValidationError):
        register_plugin(Typo())
    with pytest.raises(PluginError, match="kebab-case"):
        register_plugin(provider(spectrum_class("Not_Kebab")))
    assert frictionlab_registry.names("spectrum") == Registry(discover=False).names("spectrum")


@pytest.mark.long  # a pytest run of its own
def test_pytest_plugin_autoloads_and_unregisters_after_each_test(tmp_path):
    """In a separate pytest run: the fixtures exist without any import (pytest11
    entry point), and a plugin registered in one test is gone in the next even
    when the registry fixture is overridden with a wider scope."""
    (tmp_path / "test_fixture_scope.py").write_text(
        textwrap.dedent(
            '''
            import pytest

            import frictionlab
            from frictionlab.plugin.registry import Registry

            SHARED = Registry(discover=False)

            @pytest.fixture
            def frictionlab_registry():
                return SHARED

            class Holder:
                @staticmethod
                @frictionlab.hookimpl
                def register_slope_estimators(register):
                    pass

            def test_first(register_plugin):
                register_plugin(Holder, name="acme-holder")
                assert SHARED.pm.get_plugin("acme-holder") is Holder

            def test_second():
                assert SHARED.pm.get_plugin("acme-holder") is None
            '''
        )
    )
    env = {k: v for k, v in os.environ.items() if k not in ("PYTEST_DISABLE_PLUGIN_AUTOLOAD", "PYTEST_ADDOPTS")}
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--rootdir", str(tmp_path), str(tmp_path)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
        timeout=120,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "2 passed" in result.stdout


def test_testing_module_import_is_cheap():
    """Loaded in every pytest session: importing it adds nothing to what
    ``import frictionlab`` and ``import pytest`` already import (no registry, no
    plugin discovery, no built-in physics)."""
    code = (
        "import sys, frictionlab, pytest; before = set(sys.modules); "
        "import frictionlab.testing; print(sorted(set(sys.modules) - before))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    added = ast.literal_eval(out.stdout.strip())
    assert "frictionlab.testing" in added, out.stdout
    assert all(name.startswith("frictionlab.testing.") for name in added if name != "frictionlab.testing"), out.stdout


def test_the_checks_run_where_pytest_is_not_installed():
    """The checks are plain functions: without pytest, `from frictionlab.testing import
    check_plugin` failed with "No module named 'pytest'" (pytest is not one of frictionlab's
    dependencies; only the fixtures need it)."""
    code = (
        "import sys; sys.modules['pytest'] = None\n"  # as where it is not installed: importing it fails
        "from frictionlab.testing import *\n"
        "from frictionlab_slopes import ForwardDifference\n"
        "check_plugin('slope', ForwardDifference)\n"
        "print(sorted(name for name in dir() if name.startswith('check_')), 'register_plugin' in dir())"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == ("['check_plugin', 'check_plugin_class', 'check_slope_estimator', 'check_solver', "
                                   "'check_spectrum'] False")
