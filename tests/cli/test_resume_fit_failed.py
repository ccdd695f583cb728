"""`frictionlab resume` (and `run --resume`) of a run whose realizations all finished but whose
fit failed (no law), and of a sweep of such points: refused before anything is read or written,
with the recorded reason and what would help; a run or sweep that can go on is resumed."""

import json

import pytest

from frictionlab.errors import ExitCode

from ..conftest import SMALL_PRESET, merge
from .conftest import write_preset

# every load presses the same single point: xi is the same at every load, no law (8 of 8 realizations finished)
NO_LAW = merge(SMALL_PRESET, {"name": "nolaw", "spectrum": {"params": {"points": 512, "rms_height": 1.0e6}},
                              "loading": {"start": 1.0, "stop": 2.0}, "fit": {"bootstrap": 50}})  # fmt: skip
NO_LAW_SWEEP = merge(NO_LAW, {"name": "nolawsweep", "spectrum": {"params": {"rms_height": 1.0}},
                              "sweep": {"parameters": {"spectrum.params.rms_height": {"values": [1.0, 1.0e6]}}}})  # fmt: skip


def files_of(folder):
    """Every file under ``folder``: its bytes and time of change (what a resume would rewrite)."""
    return {path: (path.read_bytes(), path.stat().st_mtime_ns) for path in folder.rglob("*") if path.is_file()}


@pytest.fixture
def no_law_run(tmp_path, cli):
    preset = write_preset(tmp_path, NO_LAW)
    out = tmp_path / "nolaw"
    done = cli("run", preset, "--out", out, "--workers", "1", "--quiet", "--no-plot")
    assert done.returncode == ExitCode.RUNTIME_FAILURE and "error: no law: every load" in done.stderr
    return preset, out


@pytest.mark.parametrize("how", ["resume", "resume --detach", "run --resume"])
def test_resume_of_a_run_with_no_law_says_why_before_anything_and_changes_nothing(no_law_run, cli, how):
    """It restored the 8 realizations, computed nothing, failed the fit again and exited 1
    (rewriting summary.json and run.json, drawing plot.png), saying only the error again."""
    preset, out = no_law_run
    before = files_of(out)
    args = ["run", preset, "--out", out, "--resume"] if how == "run --resume" else [*how.split(), out]
    done = cli(*args, "--no-plot")
    assert done.returncode == ExitCode.RUN_FOLDER, done.stderr
    assert done.stderr.startswith(f"error: cannot resume {out}: all its realizations finished, and its fit failed: "
                                  "no law: every load from 1 to 2 presses the same points")  # fmt: skip
    assert "raise the loads or widen their range" in done.stderr  # the recorded reason, whole
    assert "A resume restores every realization, computes nothing new and fails the same way" in done.stderr
    assert f"run it into a new folder (the preset it ran is {out}/preset.yaml)" in done.stderr
    assert "restored" not in done.stderr and done.stdout == "" and "Traceback" not in done.stderr
    assert files_of(out) == before


def test_only_a_run_none_of_whose_realizations_failed_is_refused(no_law_run, cli):
    """A realization that failed (out of memory, say) is computed again by a resume: not refused."""
    _, out = no_law_run
    assert cli("resume", out, "--no-plot").returncode == ExitCode.RUN_FOLDER
    summary = json.loads((out / "summary.json").read_text())
    summary["realizations"]["failed"] = 1
    (out / "summary.json").write_text(json.dumps(summary))
    done = cli("resume", out, "--no-plot")
    assert "8 restored from the run folder" in done.stderr and "cannot resume" not in done.stderr


def test_resume_of_a_sweep_whose_only_failures_are_no_law_fits_is_refused_naming_the_points(tmp_path, cli):
    """It restored every point's realizations, computed nothing and failed point 2's fit again.
    A point that can go on (here one whose row says it was in error) makes the sweep resumable."""
    preset = write_preset(tmp_path, NO_LAW_SWEEP)
    out = tmp_path / "sw"
    ran = cli("run", preset, "--out", out, "--workers", "1", "--quiet", "--no-plot")
    assert ran.returncode == ExitCode.RUNTIME_FAILURE
    assert "frictionlab resume" not in ran.stderr  # it advised the resume refused below
    assert "a resume would compute nothing new and fail the same way" in ran.stderr
    before = files_of(out)
    for args in (["resume", out], ["run", preset, "--out", out, "--resume"]):
        done = cli(*args, "--no-plot")
        assert done.returncode == ExitCode.RUN_FOLDER, done.stderr
        lines = done.stderr.splitlines()
        assert lines[0] == (f"error: cannot resume {out}: every point of the sweep ended, and at 1 point all the "
                            "realizations finished but the fit failed:")  # fmt: skip
        assert lines[1].startswith("  point 2: no law: every load from 1 to 2 presses the same points")
        assert lines[2].startswith("A resume restores every realization, computes nothing new and fails the same way")
        assert f"(each point's preset is its preset.yaml in {out}/points/)" in lines[2]
        assert "restored" not in done.stderr and "Traceback" not in done.stderr
    assert files_of(out) == before
    followed = cli("follow", out).stdout  # it said `frictionlab resume DIR continues it`
    assert followed.startswith(f"nolawsweep: failed, 2/2 points, in {out}/\n") and "frictionlab resume" not in followed
    record = json.loads((out / "sweep.json").read_text())
    record["points"][0]["status"] = "error"
    (out / "sweep.json").write_text(json.dumps(record))
    done = cli("resume", out, "--no-plot")
    assert "cannot resume" not in done.stderr and "point 1/2" in done.stderr
