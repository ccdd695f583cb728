"""On a shared server: a process limit (``ulimit -v``) met by a process that already drew a
figure, and the refusal's advice naming only what the command in use accepts."""

import resource
import sys
import types

import pytest

from frictionlab.compute import memory
from frictionlab.errors import RunError
from frictionlab.preset import build_scene

from .conftest import SMALL_PRESET

MiB = memory.MiB
DRAWN = "matplotlib.backends.backend_agg"  # imported once a figure was drawn as PNG


@pytest.fixture
def address_space(monkeypatch):
    """This process as one of ``[vms]`` bytes under a process limit of ``limit[0]`` (RLIMIT_AS), nothing else bounding it."""
    vms, limit = [400 * MiB], [0]
    infinity = resource.RLIM_INFINITY
    monkeypatch.setattr(memory, "_address_space", lambda: (vms[0], vms[0]))
    monkeypatch.setattr(memory, "_machine_rooms", lambda: [])
    monkeypatch.setattr(resource, "getrlimit", lambda which: (limit[0], infinity) if which == resource.RLIMIT_AS else (infinity, infinity))
    for name in ("matplotlib", DRAWN):
        monkeypatch.delitem(sys.modules, name, raising=False)
    return vms, limit


def test_matplotlib_loaded_by_a_figure_drawn_is_counted_once_under_a_process_limit(address_space, monkeypatch):
    """A report's later figures were refused once Fig. 2 had loaded matplotlib: the estimate's
    base allows for it, and the room left, measured after it was loaded, counted it again."""
    vms, limit = address_space
    scene = build_scene(SMALL_PRESET)
    need = memory.estimate(scene, workers=1, executor="serial").total
    limit[0] = vms[0] + need + 20 * MiB
    memory.check_fits(scene, workers=1, executor="serial")  # fits, before any figure
    vms[0] += 71 * MiB  # a figure drawn: what importing matplotlib and drawing took, as measured
    for name in ("matplotlib", DRAWN):
        monkeypatch.setitem(sys.modules, name, types.ModuleType(name))
    memory.check_fits(scene, workers=1, executor="serial")  # still fits: refused before
    vms[0] += 30 * MiB  # more than the plot's share: refused, with a limit that fits it
    with pytest.raises(RunError, match=r"ulimit -v (\d+) or more") as refused:
        memory.check_fits(scene, workers=1, executor="serial")
    advised = int(refused.value.args[0].split("ulimit -v ")[1].split()[0]) * 1024
    assert advised >= vms[0] - 64 * MiB + need  # counted once, never less than it needs


def test_a_report_whose_sweep_point_was_refused_says_so_and_run_again_continues(tmp_path, monkeypatch, capsys):
    """Fig. 5's second point refused by its own memory check (the process grew after the
    check made before the report began): the report ended in an internal error (a point with
    no fit); it says which point and why, and the report run again continues."""
    import yaml

    from frictionlab.cli import main
    from frictionlab.errors import ExitCode
    from frictionlab.paper.figures import FIGURES
    from frictionlab.preset import apply_overrides, load_preset_file
    from frictionlab.runs import sweep

    from .conftest import PRESETS

    presets, out = tmp_path / "presets", tmp_path / "r"
    presets.mkdir()
    small = ["spectrum.params.points=1024", "spectrum.params.length=1024.0", "output.plot=false", "realizations=4",
             "spectrum.params.rms_height=300.0", "loading.steps=12", "fit.bootstrap=20"]  # fmt: skip
    for fig in FIGURES:
        data = apply_overrides(load_preset_file(PRESETS / fig.preset), small)
        (presets / fig.preset).write_text(yaml.safe_dump(data, sort_keys=False))
    real, calls = sweep.run_to_folder, []

    def second_refused(scene, folder, *args, **kwargs):
        calls.append(folder)
        if len(calls) == 2:
            raise RunError("this run would need about 0.18 GiB at its peak, but 0.17 GiB is available")
        return real(scene, folder, *args, **kwargs)

    monkeypatch.setattr(sweep, "run_to_folder", second_refused)
    command = ["report", "--presets", str(presets), "--out", str(out), "--workers", "1", "--quiet"]
    assert main(command) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert "fig5 has no fit (sweep point 2 (spectrum.params.hurst=" in err and "0.17 GiB is available" in err
    assert f"the runs that finished are kept in {out}" in err and "internal error" not in err
    assert not (out / "REPRODUCTION.md").exists()
    monkeypatch.setattr(sweep, "run_to_folder", real)
    assert main(command) == ExitCode.OK and (out / "REPRODUCTION.md").is_file()


def _options_of(command: str) -> set[str]:
    import argparse

    from frictionlab.cli.main import build_parser

    commands = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices
    return set(commands[command]._option_string_actions)


@pytest.mark.parametrize("command, args", [
    ("run", ["quickstart", "--workers", "2"]), ("resume", []), ("validate", ["quickstart"]),
    ("report", ["--workers", "2"]), ("exact3d", ["--quick", "--workers", "2"]),
])  # fmt: skip
def test_a_memory_refusal_names_only_options_of_the_command_in_use(command, args, tmp_path, monkeypatch, capsys):
    """report and exact3d were told that --no-memory-check skips the estimate, an option they
    lack (and every command of frictionlab.run's keywords): each names only its own."""
    import re

    from frictionlab.cli import main
    from frictionlab.errors import ExitCode

    from .conftest import SMALL_PRESET

    if command == "resume":  # a run that stopped, met again with less memory
        import frictionlab

        frictionlab.run(SMALL_PRESET, out=tmp_path / "stopped", workers=1, progress=False)
        args = [str(tmp_path / "stopped"), "--workers", "2"]
    elif command in ("report", "exact3d"):
        args = [*args, "--out", str(tmp_path / "out")]
    monkeypatch.setattr(memory, "available_memory", lambda: (64 * MiB, "a test limit"))
    monkeypatch.setattr(memory, "_machine_rooms", lambda: [(64 * MiB, "a test limit")])
    assert main([command, *args, "--quiet"] if command != "validate" else [command, *args]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert "0.06 GiB is available (a test limit)" in err or "64 MiB is available (a test limit)" in err, err
    named = set(re.findall(r"(?<![\w-])--[a-z][a-z-]*", err))
    assert named <= _options_of(command), err
    assert "memory_check=False" not in err and "in Python" not in err
    skips = "--no-memory-check" in _options_of(command)
    assert ("(--no-memory-check skips this estimate, an upper bound.)" in err) == skips


def test_a_resume_of_a_folder_it_cannot_write_says_to_resume_a_copy_not_to_give_another_folder(tmp_path):
    """``resume DIR`` takes no other folder, yet a folder it could not write (another user's run)
    was met with 'give a folder for the output'."""
    import os
    import subprocess

    import frictionlab

    out = tmp_path / "theirs"
    frictionlab.run(SMALL_PRESET, out=out, workers=1, progress=False)
    drop = ["setpriv", "--bounding-set=-dac_override,-dac_read_search"] if os.geteuid() == 0 else []
    out.chmod(0o555)
    try:
        done = subprocess.run([*drop, sys.executable, "-m", "frictionlab", "resume", str(out), "--quiet"],
                              capture_output=True, text=True, timeout=120)  # fmt: skip
    finally:
        out.chmod(0o755)
    assert done.returncode == 4 and f"{out} cannot be written in: Permission denied" in done.stderr, done.stderr
    assert f"copy it where you can write (cp -r {out} NEW_FOLDER) and resume the copy" in done.stderr
    assert "give a folder for the output" not in done.stderr
