import contextlib
import copy
import gc
import io
import logging
import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

from frictionlab.preset import build_scene
from frictionlab.plugin.registry import Registry

ROOT = Path(__file__).resolve().parents[1]
PRESETS = ROOT / "presets"

# A test process holds every module the commands and the TUI import, and what each test
# leaves for the collector (some 3 x 10^5 objects): Python's default thresholds walked them
# all every ~70,000 new objects, 0.2 s each time, a seventh of a TUI test's CPU. Collected
# less often, as the commands' processes are (frictionlab.cli.main); the numbers live in
# numpy arrays, which the collector never walks.
gc.set_threshold(10_000, 20, 20)
# Textual's animations (a tab's underline sliding, a smooth scroll) end where they would
# jump to; a test that waits for the screen to settle waited out each (0.3 s a tab switch)
os.environ.setdefault("TEXTUAL_ANIMATIONS", "none")

LONG_MODULES = {  # whole modules of long tests (TUI sessions, the exact 3D study, the example plugin pip-installed
    # and found from a fresh process; test_registry.py checks discovery without one): `pytest -m long` runs them
    "tui/test_screen.py", "tui/test_snapshots.py", "tui/test_form.py", "tui/test_run.py", "exact3d/test_study.py",
    "tui/test_detached.py", "tui/test_small_things.py", "test_example_plugin.py",
}  # fmt: skip


@pytest.hookimpl(wrapper=True)
def pytest_xdist_auto_num_workers(config):
    """``-n auto`` (pyproject.toml's addopts): a worker more than pytest-xdist's count of cores,
    whose tests wait part of their time (on a subprocess, the TUI settling, a signal); a count
    set in PYTEST_XDIST_AUTO_NUM_WORKERS stands as given."""
    workers = yield
    return workers if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS") else workers + 1


def pytest_collection_modifyitems(config, items):
    """Mark the tests of ``LONG_MODULES`` ``long``, and leave the long tests out of a bare
    `pytest` (the README's command: a newcomer's run takes minutes). CI runs them with
    `pytest -m long`; a test file or test named on the command line runs whatever it holds."""
    tests = Path(__file__).resolve().parent
    for item in items:
        if item.path.is_relative_to(tests) and item.path.relative_to(tests).as_posix() in LONG_MODULES:
            item.add_marker(pytest.mark.long)
    if config.args_source == pytest.Config.ArgsSource.TESTPATHS and config.option.markexpr == "not slow":
        long = [item for item in items if item.get_closest_marker("long")]
        if long:
            config.hook.pytest_deselected(items=long)
            items[:] = [item for item in items if not item.get_closest_marker("long")]

SMALL_PRESET = {
    "name": "small",
    "seed": 7,
    "realizations": 8,
    "spectrum": {"name": "power-law", "params": {"hurst": 0.8, "points": 1024, "rms_height": 1.0}},
    "solver": {"name": "mdr", "params": {"youngs_modulus": 1.0}},
    "slope": {"name": "forward-difference"},
    "loading": {"control": "force", "start": 0.5, "stop": 20.0, "steps": 16, "spacing": "log"},
    "fit": {"bootstrap": 200},
}


def merge(base: dict, changes: dict) -> dict:
    """Deep-merge ``changes`` (nested dicts) into a copy of ``base``."""
    out = copy.deepcopy(base)
    for key, value in changes.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = merge(out[key], value)
        else:
            out[key] = value
    return out


@pytest.fixture(scope="session")
def registry():
    return Registry(discover=False)


@pytest.fixture(scope="session")
def built_once(tmp_path_factory, worker_id):
    """``built_once(name, build)``: the folder ``name`` that ``build(folder)`` fills, built once a
    session. The pytest-xdist workers share it (built under a file lock) rather than each building
    its own: a reference run of seconds that several tests compare with. Tests only read it."""
    from filelock import FileLock

    shared = tmp_path_factory.getbasetemp()
    if worker_id != "master":
        shared = shared.parent  # the base folder all the workers' own are made in

    def get(name: str, build) -> Path:
        out, done = shared / name, shared / f"{name}.built"
        with FileLock(shared / f"{name}.lock"):
            if not done.is_file():
                assert not out.exists(), f"{out} was left half built by a failed build"
                build(out)
                done.touch()
        return out

    return get


@pytest.fixture
def small_preset():
    return copy.deepcopy(SMALL_PRESET)


@pytest.fixture
def users_folders(tmp_path):
    """``make(own_name)``: two folders of the user's, one holding a file named as the command's
    own output (``own_name``, text "my own notes"), one another file ("notes.txt", text "keep
    me"); returns [(folder, the file it holds)]. A command must refuse both without --force."""

    def make(own_name: str) -> list[tuple[Path, str]]:
        folders = []
        for folder, held, text in (("mine", own_name, "my own notes"), ("other", "notes.txt", "keep me")):
            (tmp_path / folder).mkdir()
            (tmp_path / folder / held).write_text(text)
            folders.append((tmp_path / folder, held))
        return folders

    return make


@pytest.fixture
def run_folder_writes(monkeypatch) -> list[str]:
    """The names of the files a run folder writes atomically, in order, as they are written."""
    from frictionlab.io import files

    written = []
    atomic_write = files.atomic_write

    def counting(path, *args, **kwargs):
        written.append(Path(path).name)
        return atomic_write(path, *args, **kwargs)

    monkeypatch.setattr("frictionlab.runs.rundir.atomic_write", counting)
    return written


@pytest.fixture
def make_scene(registry):
    def make(changes: dict | None = None, base: dict = SMALL_PRESET):
        return build_scene(merge(base, changes or {}), registry=registry)

    return make


def run_cli(*args, env: dict | None = None, cwd=None, encoding: str | None = None) -> subprocess.CompletedProcess:
    """``frictionlab ARGS`` run in this process by ``cli.main``, as a CompletedProcess
    (returncode, stdout, stderr): for what a command prints, writes and exits with. A
    test of the process itself (signals, a closed descriptor, the interpreter's exit,
    fresh imports, a terminal) runs ``python -m frictionlab`` instead.

    stdout and stderr are strict streams of ``encoding`` (UTF-8 and text back when not
    given; bytes back when given, as PYTHONIOENCODING makes them), never a terminal.
    ``env`` sets variables for the call (None removes one), ``cwd`` its working folder;
    an argument given as bytes is passed as ``sys.argv`` holds it. Warnings are written to
    stderr, as a process writes them."""
    from frictionlab.cli import main

    argv = [os.fsdecode(arg) if isinstance(arg, bytes) else str(arg) for arg in args]
    streams = [io.TextIOWrapper(io.BytesIO(), encoding=encoding or "utf-8", errors="strict", newline="") for _ in "12"]
    with pytest.MonkeyPatch.context() as patch:
        for name, value in (env or {}).items():
            if value is None:
                patch.delenv(name, raising=False)
            else:
                patch.setenv(name, str(value))
        if cwd is not None:
            patch.chdir(cwd)
        patch.setattr(sys, "stdout", streams[0])
        patch.setattr(sys, "stderr", streams[1])
        with warnings.catch_warnings():  # shown on stderr as a process shows them, not kept by pytest
            warnings.simplefilter("default")
            for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning):
                warnings.simplefilter("ignore", category)  # as Python's own filters leave them out
            warnings.showwarning = _show_warning
            try:
                code = main(argv)
            except SystemExit as exc:  # argparse: --help, --version, a usage error
                code = 0 if exc.code is None else exc.code
        for stream in streams:
            stream.flush()
    out, err = (stream.buffer.getvalue() for stream in streams)
    if encoding is None:
        out, err = out.decode(), err.decode()
    return subprocess.CompletedProcess(["frictionlab", *argv], int(code), out, err)


def _show_warning(message, category, filename, lineno, file=None, line=None):
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


@pytest.fixture
def cli():
    """``run_cli``: ``cli("validate", "quickstart").stdout``."""
    return run_cli


@contextlib.contextmanager
def loopback_cluster(n_workers: int, **options):
    """A real Dask LocalCluster of worker processes on 127.0.0.1, dashboards off
    (tests never leave this machine)."""
    import distributed

    with distributed.LocalCluster(
        n_workers=n_workers,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
        silence_logs=logging.ERROR,
        **options,
    ) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        yield cluster
