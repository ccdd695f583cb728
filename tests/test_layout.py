"""The house's shape, as ARCHITECTURE.md draws it: short modules, few at the top, each
folder one job; and the documented imports of modules that moved into those folders."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import pytest

import frictionlab

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 500  # a module longer than this holds more than one job
MAX_TOP_MODULES = 12  # modules beside the packages in frictionlab/


def _modules() -> list[Path]:
    return sorted([*(ROOT / "frictionlab").rglob("*.py"), *(ROOT / "plugins").rglob("*.py")])


def test_no_module_is_over_500_lines():
    long = {str(p.relative_to(ROOT)): n for p in _modules() if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert not long, f"split by job: {long}"


def test_the_top_of_the_package_holds_few_modules_beside_its_packages():
    top = sorted(p.name for p in (ROOT / "frictionlab").glob("*.py"))
    assert len(top) <= MAX_TOP_MODULES, top


@pytest.mark.parametrize("old", sorted(frictionlab._MOVED))
def test_a_moved_module_imports_under_its_old_name_as_the_same_module(old):
    moved = importlib.import_module(f"frictionlab.{frictionlab._MOVED[old]}.{old}")
    assert importlib.import_module(f"frictionlab.{old}") is moved
    assert moved.__spec__.name == moved.__name__  # its own spec kept: its relative imports do not warn
    assert not (ROOT / "frictionlab" / f"{old}.py").exists()  # one copy: the package's


def test_the_documented_imports_of_moved_modules_work_in_a_fresh_process():
    code = (
        "from frictionlab.runner import run_to_folder; from frictionlab.sweep import run_sweep, load_sweep; "
        "from frictionlab.fit import LogFit; from frictionlab.ensemble import RunOutcome; "
        "from frictionlab.listeners import RunListener, SweepListener; from frictionlab.results import column_name; "
        "import frictionlab.registry, frictionlab.engine; "
        "print(run_to_folder.__module__, LogFit.__module__, frictionlab.engine.run.__module__)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["frictionlab.runs.runner", "frictionlab.compute.fit", "frictionlab.compute.engine"]
