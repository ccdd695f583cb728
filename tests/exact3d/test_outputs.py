"""Where ``frictionlab exact3d`` writes: a --runs folder of the user's is not filled with
runs, --out must be a folder, and Ctrl-C ends the study with 130 keeping what finished."""

import json
import signal
import subprocess
import sys
import time

import pytest

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab.exact3d.report import PAGE

from ..conftest import PRESETS


def _ctrl_c_as_in_a_terminal():
    signal.signal(signal.SIGINT, signal.SIG_DFL)  # a shell's background job would inherit it ignored


def exact3d(*args):
    return main(["exact3d", "--quick", "--presets", str(PRESETS), "--quiet", *map(str, args)])


def test_a_runs_folder_of_the_users_is_refused_before_anything_runs(tmp_path, capsys, users_folders):
    (userruns, _), _ = folders = users_folders("exact3d-time.json")
    for runs, held in folders:
        assert exact3d("--runs", runs, "--out", tmp_path / "page") == ExitCode.OUTPUT_REFUSED
        err = capsys.readouterr().err
        assert f"--runs {runs} is not empty" in err and repr(held) in err and "--force" in err
        assert [p.name for p in runs.iterdir()] == [held]
    assert (userruns / "exact3d-time.json").read_text() == "my own notes"
    assert not (tmp_path / "page").exists()


def test_out_or_runs_that_is_a_file_is_refused_naming_the_option(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("x")
    assert exact3d("--out", afile, "--runs", tmp_path / "r") == ExitCode.OUTPUT_REFUSED
    assert f"--out: {afile} is a file, not a folder" in capsys.readouterr().err
    assert exact3d("--out", tmp_path / "o", "--runs", afile) == ExitCode.OUTPUT_REFUSED
    assert f"--runs: {afile} is a file, not a folder" in capsys.readouterr().err
    assert afile.read_text() == "x" and sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


@pytest.mark.long
def test_ctrl_c_ends_the_study_with_130_keeping_the_finished_ensembles(tmp_path):
    runs, out = tmp_path / "runs", tmp_path / "out"
    first = runs / "h0.8-n64-bem-halfspace"  # the plan runs H = 0.8 first
    command = [sys.executable, "-m", "frictionlab", "exact3d", "--quick", "--presets", str(PRESETS),
               "--out", str(out), "--runs", str(runs), "--workers", "1"]  # fmt: skip
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               preexec_fn=_ctrl_c_as_in_a_terminal)
    deadline = time.monotonic() + 120
    while True:  # the first ensemble finished: the study is in its second
        try:
            if json.loads((first / "run.json").read_text())["status"] == "completed":
                break
        except (OSError, ValueError, KeyError):
            pass
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "the first ensemble did not finish in 120 s"
        time.sleep(0.02)
    process.send_signal(signal.SIGINT)
    out_text, err = process.communicate(timeout=120)
    assert process.returncode == ExitCode.INTERRUPTED, err
    assert f"the ensembles that finished are kept in {runs}" in err and "no page written" in err
    assert "Traceback" not in err and out_text == ""
    assert json.loads((first / "run.json").read_text())["status"] == "completed"
    assert not (out / PAGE).exists()


def test_a_study_that_fails_midway_still_counts_its_time(tmp_path, monkeypatch):
    """The study's wall time is summed over the invocations that computed it, including one
    that ended on an error (a run folder in use by another process, say)."""
    from pathlib import Path

    from frictionlab.errors import FrictionlabError
    from frictionlab.exact3d import plan as study

    runs = tmp_path / "runs"
    runs.mkdir()
    calls = []

    def refused(scene, folder, options, **kwargs):
        calls.append(folder)
        time.sleep(0.05)
        raise FrictionlabError(f"{folder} is in use by another run")

    monkeypatch.setattr(study, "run_to_folder", refused)
    try:
        study.run_plan(Path(PRESETS), runs, study.QUICK)
    except FrictionlabError:
        pass
    else:
        raise AssertionError("the refusal was swallowed")
    assert len(calls) == 1
    recorded = json.loads((runs / study.TIME_FILE).read_text())
    assert recorded["plan"] == "quick" and recorded["seconds"] >= 0.05


def test_a_study_counts_its_time_after_every_ensemble(tmp_path, monkeypatch):
    """A study killed outright (SIGKILL, its session closed) runs no ``finally``: its wall
    time is on disk up to its last finished ensemble, not lost with it."""
    from pathlib import Path

    from frictionlab.exact3d import plan as study

    runs = tmp_path / "runs"
    runs.mkdir()
    real_run = study.run_to_folder
    seen_before = []

    def killed_at_the_second(scene, folder, options, **kwargs):
        if seen_before:  # the second ensemble: what a SIGKILL here would leave on disk
            raise SystemExit(json.loads((runs / study.TIME_FILE).read_text())["seconds"])
        started = time.perf_counter()
        outcome = real_run(scene, folder, options, **kwargs)
        seen_before.append(time.perf_counter() - started)
        return outcome

    monkeypatch.setattr(study, "run_to_folder", killed_at_the_second)
    with pytest.raises(SystemExit) as killed:
        study.run_plan(Path(PRESETS), runs, study.QUICK)
    assert killed.value.code >= seen_before[0] > 0


@pytest.mark.parametrize(("recorded", "says"), [(5000.0, "**1:23:20** of wall time"), (600.0, "at least **50:00** of wall time")])
def test_the_pages_wall_time_is_never_less_than_the_compute_its_cores_shared(recorded, says):
    """The time file misses invocations stopped before they recorded theirs (a session's
    SIGKILL): the page then gives the compute shared among the machine's cores as a bound."""
    from frictionlab.exact3d.report import wall_time_text

    text = wall_time_text(recorded, compute=3600.0 + 2400.0, cores=2)
    assert says in text
    assert ("10:00" in text) == (recorded == 600.0)  # the record is named beside the bound


def test_the_pages_command_names_the_runs_folder_it_made(tmp_path, monkeypatch):
    """Without --runs the study makes runs/exact3d-quick-<timestamp>; the command the page
    gives to regenerate it names that folder, so it reads those runs back instead of
    computing the study again in yet another new folder."""
    from types import SimpleNamespace

    from frictionlab.exact3d import report

    monkeypatch.chdir(tmp_path)
    said = {}
    monkeypatch.setattr(report, "run_plan", lambda *a, **k: SimpleNamespace(hursts=lambda: [0.8], ensembles=[], seconds=0))
    monkeypatch.setattr(report, "study_numbers", lambda runs: None)
    monkeypatch.setattr(report, "PLOTS", [lambda *a, **k: None] * len(report.FIGURES))
    monkeypatch.setattr(report, "page_text", lambda runs, numbers, command, *a: said.setdefault("command", command))
    report.write_page(tmp_path / "page", quick=True, presets_dir=PRESETS)
    (made,) = (tmp_path / "runs").iterdir()
    assert said["command"] == f"frictionlab exact3d --quick --out {tmp_path / 'page'} --runs runs/{made.name} --force"


def test_an_ensemble_beyond_the_memory_refuses_the_study_before_any_runs(tmp_path, capsys, monkeypatch):
    """The study checked each ensemble's memory as it started it: the full plan ran for hours
    before its 2048² grid was refused. Every ensemble left to run is checked first: here the
    quick plan's 192² grid does not fit, and nothing runs, nothing is made."""
    from frictionlab.compute import memory
    from frictionlab.exact3d import plan

    fits_128 = memory.PROCESS_BASE + 6 * memory.MiB  # 128² px fits; 192² px (the quick plan's finest) does not
    monkeypatch.setattr(memory, "available_memory", lambda: (fits_128, "the memory of a test"))
    monkeypatch.setattr(plan, "run_to_folder", lambda *args, **kwargs: pytest.fail("an ensemble ran"))
    monkeypatch.chdir(tmp_path)
    assert exact3d("--workers", "1") == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert err.startswith("error: the exact 3D study starts nothing: its ensemble H = 0.8, 192² px, exact, 2 surfaces")
    assert "is available (the memory of a test)" in err and "--quick" in err and "Traceback" not in err
    assert not (tmp_path / "runs").exists() or not any((tmp_path / "runs").iterdir())


@pytest.mark.parametrize("text, seconds", [
    ('{"plan": "quick", "seconds": 12.5}', 12.5),
    ('{"plan": "quick", "seconds": -5}', 0.0),  # was printed as the study's wall time, -5.0 s
    ('{"plan": "quick", "seconds": 1e308}', 0.0),  # printed as a number of 300 digits
    ('{"plan": "quick", "seconds": Infinity}', 0.0),
    ('{"plan": "quick", "seconds": NaN}', 0.0),
    ('{"plan": "quick", "seconds": "12"}', 0.0),
    ('{"plan": "full", "seconds": 12.5}', 0.0),  # another plan's: no warning
    ("\x00\xff random", 0.0),
    ("link", 0.0),
])  # fmt: skip
def test_an_edited_time_file_counts_only_a_wall_time_a_study_can_have_taken(tmp_path, text, seconds):
    """A damaged one is said (it was read as no time without a word, and the page's wall time fell)."""
    import warnings

    from frictionlab.exact3d import plan as study

    if text == "link":
        (tmp_path / "elsewhere.json").write_text('{"plan": "quick", "seconds": 12.5}')
        (tmp_path / study.TIME_FILE).symlink_to(tmp_path / "elsewhere.json")
    else:
        (tmp_path / study.TIME_FILE).write_text(text)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        assert study._time(tmp_path, study.QUICK) == seconds
    told = [str(w.message) for w in said]
    assert len(told) == (0 if seconds or '"full"' in text else 1), told
    assert all(study.TIME_FILE in message and message.endswith("the study's earlier invocations' time is not counted "
                                                               "in the wall time its page gives") for message in told)


def test_an_ensembles_folder_its_run_refuses_is_refused_before_any_runs(tmp_path, capsys, monkeypatch):
    """--runs of an earlier study whose last ensemble's folder holds files of the user's: every
    ensemble before it ran (hours, on the full plan), then its run refused the folder. Refused first."""
    from frictionlab.exact3d import plan

    folder = tmp_path / "runs" / "h0.8-n192-bem-halfspace"
    folder.mkdir(parents=True)
    (folder / "notes.txt").write_text("mine")
    monkeypatch.setattr(plan, "run_to_folder", lambda *args, **kwargs: pytest.fail("an ensemble ran"))
    assert exact3d("--workers", "1", "--runs", tmp_path / "runs", "--out", tmp_path / "page") == ExitCode.OUTPUT_REFUSED
    assert f"{folder} is not empty and is not a frictionlab run folder (it holds 'notes.txt')" in capsys.readouterr().err
    assert sorted(p.name for p in (tmp_path / "runs").iterdir()) == [folder.name]


@pytest.mark.parametrize("inside", ["h0.3-n64-mdr", "page"])
@pytest.mark.parametrize("finished_only", [True, False])
def test_an_out_inside_the_runs_folder_is_refused_before_anything_runs(tmp_path, capsys, inside, finished_only):
    """--out RUNS/h0.3-n64-mdr wrote the page and its figures into an ensemble's run folder (exit 0)."""
    runs = tmp_path / "runs"
    (runs / "h0.3-n64-mdr").mkdir(parents=True)
    code = exact3d("--runs", runs, "--out", runs / inside, *(["--finished-only"] if finished_only else []))
    assert code == ExitCode.OUTPUT_REFUSED
    assert capsys.readouterr().err == (f"error: --out {runs / inside} is inside the runs folder {runs}, which holds only "
                                       "the ensembles' runs: give the runs folder itself (the default) or one outside it\n")  # fmt: skip
    assert [p.name for p in runs.rglob("*")] == ["h0.3-n64-mdr"]
