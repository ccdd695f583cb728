"""Output folders are tried for writing before long work starts: exact3d, study and report
refuse one where no file can be created (exit 4, naming the option and the folder) before
any run, and make no folder."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab.io.files import output_path_problem

# /proc/1 refuses new files to every user, root too (a chmod'ed folder would not stop root)
UNWRITABLE = Path("/proc/1")
pytestmark = pytest.mark.skipif(not UNWRITABLE.is_dir(), reason="needs Linux's /proc")


@pytest.mark.parametrize(
    "argv, option",
    [
        (["exact3d", "--quick", "--quiet", "--out", "OUT"], "--out"),
        (["exact3d", "--quick", "--quiet", "--runs", "OUT"], "--runs"),
        (["study", "quickstart", "--quiet", "--out", "OUT"], "--out"),
        (["report", "--out", "OUT"], "--out"),
        (["report", "--markdown", "OUT/REPRODUCTION.md"], "--markdown"),
        (["run", "quickstart", "--quiet", "--out", "OUT"], ""),
    ],
)
def test_an_output_folder_no_file_can_be_written_in_is_refused_before_any_work(tmp_path, monkeypatch, capsys, argv, option):
    monkeypatch.chdir(tmp_path)
    out = UNWRITABLE / "frictionlab-out"
    code = main([arg.replace("OUT", str(out)) for arg in argv])
    err = capsys.readouterr().err
    assert code == ExitCode.OUTPUT_REFUSED, err
    assert f"{out} cannot be written in (it would be made in {UNWRITABLE})" in err and option in err
    assert list(tmp_path.iterdir()) == []  # no default runs/ folder, no run started


def test_output_path_problem_tries_a_file_and_leaves_nothing(tmp_path):
    assert output_path_problem(tmp_path / "new" / "deeper") is None
    assert list(tmp_path.iterdir()) == []  # the probe file is gone, no folder made
    assert "cannot be written in" in output_path_problem(UNWRITABLE)
    if os.geteuid() != 0:  # permissions stop any user but root
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o555)
        assert "Permission denied" in output_path_problem(locked / "out")


@pytest.mark.parametrize("sweep", [False, True])
def test_a_result_file_that_is_a_folder_is_named_in_the_refusal(tmp_path, capsys, sweep):
    """A run folder whose summary.json is a folder (in a sweep, a point's): the resume is refused
    before any work, naming that file, not its run or sweep folder (exit code 5; a sweep's point
    in error, exit code 1), and the folder and what it holds are left as they were."""
    import yaml

    from ..conftest import SMALL_PRESET, merge

    preset = merge(SMALL_PRESET, {"realizations": 2, "spectrum": {"params": {"points": 256}}, "fit": {"bootstrap": 20}})
    if sweep:
        preset["sweep"] = {"mode": "grid", "parameters": {"spectrum.params.hurst": {"values": [0.5, 0.9]}}}
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset, sort_keys=False))
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "p.yaml"), "--out", str(out), "--quiet", "--no-plot", "--workers", "1"]) == 0
    folder = out / "points" / "01-hurst-0.5" if sweep else out
    (folder / "summary.json").unlink()
    (folder / "summary.json").mkdir()
    (folder / "summary.json" / "mine.txt").write_text("keep me")
    capsys.readouterr()
    code = main(["resume", str(out), "--quiet", "--no-plot"])
    captured = capsys.readouterr()
    said = captured.err + captured.out  # a sweep's table says why its point failed
    assert code == (ExitCode.RUNTIME_FAILURE if sweep else ExitCode.RUN_FOLDER), said
    assert f"{folder / 'summary.json'} is a folder, not a file: the run writes its summary.json there" in said
    assert (folder / "summary.json" / "mine.txt").read_text() == "keep me"
