"""Run directories: every finished chunk kept, resume computes only what is
missing and ends bitwise where an uninterrupted run ends; one run at a time per
directory; a resume with another preset is refused."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from frictionlab import hookimpl
from frictionlab.cli import main
from frictionlab.errors import ExitCode, FrictionlabError, RunFolderError
from frictionlab.preset import build_scene
from frictionlab.runs.rundir import RunDirectory, json_copy, fingerprint
from frictionlab.runs.runner import run_to_folder
from frictionlab.options import RunOptions

from .conftest import SMALL_PRESET, merge

# ~20 ms per realization: 150 of them last long enough to be killed mid-run
NO_PLOT = {"output": {"plot": False}}  # matplotlib costs a second per folder and is not under test
# A run killed once two chunks are on disk must still have most of its work ahead: chunks are
# written every UNSAVED_WORK_SECONDS of computing, so the run is sized at ~20x that per worker
# (80 realizations finished between the second chunk and the signal on a fast machine).
# about 5 s on 2 workers here, the two chunks a test waits for by 1 s: with 480 realizations the run
# took about as long as those chunks, and on a loaded machine ended before its signal or kill
KILL_PRESET = merge(SMALL_PRESET, {"realizations": 2000, "spectrum": {"params": {"points": 65536}}, **NO_PLOT})
# exact half-space contact of a surface with a rolloff, ~0.1 s per realization
KILL_SURFACE = merge(
    yaml.safe_load((Path(__file__).parents[1] / "presets" / "exact3d-h08-rolloff.yaml").read_text()),
    {"realizations": 64, "spectrum": {"params": {"points": 128}}, **NO_PLOT},
)


def same_files(one: Path, two: Path) -> None:
    """The numbers two output folders hold are identical, bit for bit."""
    with np.load(one / "realizations.npz") as a, np.load(two / "realizations.npz") as b:
        assert a.files == b.files
        for name in a.files:
            np.testing.assert_array_equal(a[name], b[name], err_msg=name)
    assert (one / "curve.csv").read_text() == (two / "curve.csv").read_text()
    first, second = (json.loads((d / "summary.json").read_text()) for d in (one, two))
    assert first["fit"] == second["fit"]
    assert first["status"] == second["status"] == "completed"


class CancelAfter:
    def __init__(self, count: int, cancel: threading.Event):
        self.count, self.cancel = count, cancel

    @hookimpl
    def realization_done(self, done):
        if done >= self.count:
            self.cancel.set()


def test_cancelled_run_resumes_to_the_uninterrupted_numbers(make_scene, tmp_path):
    scene = make_scene({"realizations": 40, **NO_PLOT})
    cancel = threading.Event()
    first, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(5, cancel)], cancel=cancel)
    assert first.status == "cancelled" and 5 <= first.done < 40
    stored = sorted(p.name for p in (tmp_path / "run" / "chunks").glob("*.npz"))
    assert stored, "no chunk was kept"

    resumed, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=2, resume=True))
    assert resumed.status == "completed"
    assert resumed.extra["resumed"] == first.done  # only the missing ones were computed
    run_to_folder(scene, tmp_path / "whole", RunOptions(workers=1))
    same_files(tmp_path / "run", tmp_path / "whole")


def test_resuming_a_completed_run_computes_nothing(make_scene, tmp_path):
    scene = make_scene({"realizations": 12, **NO_PLOT})
    first, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1))
    before = (tmp_path / "run" / "curve.csv").read_text()
    again, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, resume=True))
    assert again.extra["resumed"] == 12 and again.done == 12
    # what the realizations cost is read back with them, however little the resume took
    assert first.compute_seconds > 0 and again.compute_seconds == first.compute_seconds
    assert (tmp_path / "run" / "curve.csv").read_text() == before


def recorded_seconds(folder: Path) -> float:
    return json.loads((folder / "summary.json").read_text())["elapsed_seconds"]


def test_a_resume_adds_its_time_to_what_the_run_recorded(make_scene, tmp_path):
    """A resume of a completed run replaced the elapsed_seconds its summary.json recorded with the
    near-zero time of computing nothing (and a resume of a cancelled run with its own share alone)."""
    scene = make_scene({"realizations": 12, **NO_PLOT})
    cancel = threading.Event()
    first, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(4, cancel)], cancel=cancel)
    assert first.status == "cancelled"
    assert recorded_seconds(tmp_path / "run") == pytest.approx(first.elapsed, abs=1e-6)
    second, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, resume=True))
    assert second.status == "completed"
    total = recorded_seconds(tmp_path / "run")
    assert total == pytest.approx(first.elapsed + second.elapsed, abs=2e-6)
    again, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, resume=True))  # computes nothing
    assert recorded_seconds(tmp_path / "run") == pytest.approx(total + again.elapsed, abs=2e-6)
    with pytest.warns(UserWarning, match="runs again"):
        fresh, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1))
    assert recorded_seconds(tmp_path / "run") == pytest.approx(fresh.elapsed, abs=1e-6)  # its own time alone


def test_the_api_gives_a_resumed_run_the_time_its_summary_records(make_scene, tmp_path):
    """frictionlab.run(resume=True).elapsed was the resume's own time while load() of the same
    folder (summary.json) gave the sessions summed: the one run said two times."""
    import frictionlab

    scene = make_scene({"realizations": 12, **NO_PLOT})
    cancel = threading.Event()
    first, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(4, cancel)], cancel=cancel)
    resumed = frictionlab.run(scene.resolved(), out=tmp_path / "run", workers=1, resume=True, progress=False, plot=False)
    assert resumed.realizations == (12, 12)
    assert resumed.elapsed > first.elapsed  # the first session's time is in it
    assert resumed.elapsed == pytest.approx(frictionlab.load(tmp_path / "run").elapsed, abs=1e-6)


def test_a_resume_keeps_the_time_an_older_frictionlab_recorded(make_scene, tmp_path):
    """A completed folder whose manifest records no time (written before it did): the summary's is kept."""
    scene = make_scene({"realizations": 4, **NO_PLOT})
    run_to_folder(scene, tmp_path / "run", RunOptions(workers=1))
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    del manifest["elapsed_seconds"]
    (tmp_path / "run" / "run.json").write_text(json.dumps(manifest))
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    summary["elapsed_seconds"] = 1234.5
    (tmp_path / "run" / "summary.json").write_text(json.dumps(summary))
    again, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, resume=True))
    assert recorded_seconds(tmp_path / "run") == pytest.approx(1234.5 + again.elapsed, abs=2e-6)


@pytest.mark.parametrize("forged, kept", [(1e9, 1e9), (1e300, 0.0), ("1", 0.0), (-1.0, 0.0)])
def test_a_forged_recorded_time_is_no_time_or_kept_within_what_a_summary_holds(make_scene, tmp_path, forged, kept):
    """A manifest's elapsed_seconds is read only as a time a summary.json may hold (at most 1e9 s):
    the sum past it was written, and the folder then refused by load() as damaged."""
    import warnings

    import frictionlab

    scene = make_scene({"realizations": 4, **NO_PLOT})
    run_to_folder(scene, tmp_path / "run", RunOptions(workers=1))
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    manifest["elapsed_seconds"] = forged
    (tmp_path / "run" / "run.json").write_text(json.dumps(manifest))
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        again, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, resume=True))
    told = [str(w.message) for w in said if "elapsed_seconds" in str(w.message)]
    assert told == ([] if kept else [f"{tmp_path / 'run'}: the run's recorded elapsed_seconds ({forged!r}) is no time from "
                                     "0 to 1e+09 s: its earlier sessions' time is not counted"])  # was lost without a word
    assert frictionlab.load(tmp_path / "run").elapsed == pytest.approx(min(kept + again.elapsed, 1e9), abs=2e-6)


def test_a_fresh_run_into_its_own_completed_folder_says_it_runs_again(make_scene, tmp_path):
    """A run into the folder of a completed run of the same preset ran it again without a word:
    it says so, and the numbers are the same."""
    import warnings

    scene = make_scene({"realizations": 6, **NO_PLOT})
    run_to_folder(scene, tmp_path / "run", RunOptions(workers=1))
    before = (tmp_path / "run" / "curve.csv").read_text()
    with pytest.warns(UserWarning, match="holds a completed run of this preset: it runs again, to the same numbers"):
        run_to_folder(scene, tmp_path / "run", RunOptions(workers=2))
    assert (tmp_path / "run" / "curve.csv").read_text() == before
    with warnings.catch_warnings():  # a new folder, and an unfinished run resumed, say nothing of it
        warnings.simplefilter("error")  # any warning (an ImportWarning of a moved module once slipped in here)
        run_to_folder(scene, tmp_path / "new", RunOptions(workers=1))


def test_a_second_run_into_a_locked_directory_is_refused(make_scene, tmp_path):
    with RunDirectory(tmp_path / "run"):
        with pytest.raises(RunFolderError, match=rf"{tmp_path / 'run'} is in use by another run \(pid {os.getpid()}, started"):
            run_to_folder(make_scene(NO_PLOT), tmp_path / "run", RunOptions(workers=1))
    run_to_folder(make_scene(NO_PLOT), tmp_path / "run", RunOptions(workers=1))  # released: now it runs


def test_a_forked_child_does_not_keep_the_lock(tmp_path):
    ready_r, ready_w = os.pipe()
    with RunDirectory(tmp_path / "run"):
        child = os.fork()
        if child == 0:  # pragma: no cover - the child says it runs (at-fork handlers done), then sleeps
            os.write(ready_w, b"x")
            time.sleep(3)
            os._exit(0)
        assert os.read(ready_r, 1) == b"x"
    os.close(ready_r), os.close(ready_w)
    try:
        with RunDirectory(tmp_path / "run"):  # the parent let go; the child's copy was closed at fork
            pass
    finally:
        os.kill(child, signal.SIGKILL)
        os.waitpid(child, 0)


def test_resume_of_a_manifest_whose_fingerprint_is_not_its_presets_says_so(make_scene, tmp_path):
    """A run.json whose fingerprint was edited, resumed with its own preset: it was refused as
    'its preset differs from the one given' with nothing named, though nothing differs."""
    cancel = threading.Event()
    cancel.set()
    scene = make_scene(NO_PLOT)
    run_to_folder(scene, tmp_path / "run", RunOptions(workers=1), cancel=cancel)
    manifest = tmp_path / "run" / "run.json"
    state = json.loads(manifest.read_text())
    state["fingerprint"] = "0" * 64
    manifest.write_text(json.dumps(state))
    with pytest.raises(FrictionlabError, match=r"the fingerprint in its run.json is not that of the preset it holds"):
        run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, resume=True))


def test_resume_with_another_preset_is_refused_naming_what_differs(make_scene, tmp_path):
    cancel = threading.Event()
    cancel.set()  # nothing computed, but the directory is started
    run_to_folder(make_scene(NO_PLOT), tmp_path / "run", RunOptions(workers=1), cancel=cancel)
    other = make_scene({"realizations": 9, "spectrum": {"params": {"hurst": 0.7}}})
    with pytest.raises(FrictionlabError) as caught:
        run_to_folder(other, tmp_path / "run", RunOptions(workers=1, resume=True))
    message = str(caught.value)
    assert message.startswith(f"cannot resume {tmp_path / 'run'}: the preset its run.json started with differs from the one given")
    assert "realizations: 8 in the run directory, 9 given" in message
    assert "spectrum.params.hurst: 0.8 in the run directory, 0.7 given" in message


def test_resume_of_a_folder_whose_preset_yaml_was_edited_names_that_file(make_scene, tmp_path, capsys):
    """`frictionlab resume DIR` gives no preset, yet was told its preset 'differs from the one
    given'; the one given is DIR/preset.yaml, edited, and the message names it and run.json."""
    cancel = threading.Event()
    cancel.set()
    run_to_folder(make_scene(NO_PLOT), tmp_path / "run", RunOptions(workers=1), cancel=cancel)
    stored = tmp_path / "run" / "preset.yaml"
    stored.write_text(stored.read_text().replace("realizations: 8", "realizations: 9"))
    assert main(["resume", str(tmp_path / "run"), "--workers", "1", "--quiet"]) == ExitCode.RUN_FOLDER
    err = capsys.readouterr().err
    assert f"the preset its run.json started with differs from the one given ({stored})" in err
    assert "realizations: 8 in the run directory, 9 given" in err


def test_resume_of_a_run_whose_preset_yaml_was_given_a_sweep_names_that_file(make_scene, tmp_path, capsys):
    """A sweep section added to a run's preset.yaml made resume run the sweep into the run's folder,
    refused as 'not the folder of a frictionlab sweep ... (--force ...)', an option resume lacks (exit 4)."""
    cancel = threading.Event()
    cancel.set()
    run_to_folder(make_scene(NO_PLOT), tmp_path / "run", RunOptions(workers=1), cancel=cancel)
    stored = tmp_path / "run" / "preset.yaml"
    stored.write_text(stored.read_text() + "sweep:\n  parameters:\n    seed: {values: [1, 2]}\n")
    before = sorted(p.name for p in (tmp_path / "run").rglob("*"))
    assert main(["resume", str(tmp_path / "run"), "--workers", "1", "--quiet"]) == ExitCode.RUN_FOLDER
    err = capsys.readouterr().err
    assert f"cannot resume {tmp_path / 'run'}: its preset.yaml has a sweep section, but the run there is one ensemble" in err
    assert "--force" not in err
    assert sorted(p.name for p in (tmp_path / "run").rglob("*")) == before


def _as_written_before(run: Path, fields: list[tuple[str, ...]]) -> None:
    """Make ``run`` look started by a frictionlab that did not yet have ``fields``: each
    dropped from the stored preset, and the manifest's fingerprint that of what is left."""
    state = json.loads((run / "run.json").read_text())
    for path in fields:
        section = state["preset"]
        for key in path[:-1]:
            section = section[key]
        del section[path[-1]]
    state["fingerprint"] = fingerprint(state["preset"])
    (run / "run.json").write_text(json.dumps(state))
    (run / "preset.yaml").write_text(yaml.safe_dump(state["preset"]))


ADDED_LATER = [("loading", "unit"), ("solver", "params", "poisson_ratio")]


def test_a_run_started_before_a_field_existed_resumes_with_the_field_at_its_default(make_scene, tmp_path):
    scene = make_scene({"realizations": 20, **NO_PLOT})
    cancel = threading.Event()
    first, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(4, cancel)], cancel=cancel)
    assert first.status == "cancelled" and first.done < 20
    _as_written_before(tmp_path / "run", ADDED_LATER)

    resumed, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, resume=True))
    assert resumed.status == "completed" and resumed.extra["resumed"] == first.done
    state = json.loads((tmp_path / "run" / "run.json").read_text())
    assert state["preset"]["loading"]["unit"] == "force"  # the folder now states the field, at its default
    assert state["fingerprint"] == fingerprint(json_copy(scene.resolved()))
    run_to_folder(scene, tmp_path / "whole", RunOptions(workers=1))
    same_files(tmp_path / "run", tmp_path / "whole")


def _as_written_with(run: Path, section: str, key: str, value) -> None:
    """Make ``run`` look started by a frictionlab that took ``section.key: value``, now refused: the
    stored preset holds it, and the manifest's fingerprint is that preset's."""
    state = json.loads((run / "run.json").read_text())
    state["preset"][section][key] = value
    state["fingerprint"] = fingerprint(state["preset"])
    (run / "run.json").write_text(json.dumps(state))
    (run / "preset.yaml").write_text(yaml.safe_dump(state["preset"]))


def test_a_run_started_with_fit_bootstrap_1_resumes_without_intervals_and_says_so(make_scene, tmp_path, recwarn):
    """fit.bootstrap: 1 was once taken; now refused, a folder holding it was refused by `resume DIR`
    as a preset not valid here: what finished could never be completed. It resumes, fitted with
    no intervals (bootstrap 0), its finished realizations kept, and says so."""
    scene, cancel = make_scene({"realizations": 20, **NO_PLOT}), threading.Event()
    for folder in ("cli", "api"):
        first, _ = run_to_folder(scene, tmp_path / folder, RunOptions(workers=1), listeners=[CancelAfter(4, cancel)], cancel=cancel)
        assert first.status == "cancelled" and first.done < 20
        _as_written_with(tmp_path / folder, "fit", "bootstrap", 1)
        cancel.clear()
    now = make_scene({"realizations": 20, "fit": {"bootstrap": 0}, **NO_PLOT})
    run_to_folder(now, tmp_path / "whole", RunOptions(workers=1))

    assert main(["resume", str(tmp_path / "cli"), "--workers", "1", "--quiet"]) == ExitCode.OK
    said = [str(w.message) for w in recwarn if "fit.bootstrap" in str(w.message)]
    assert len(said) == 1 and f"resume of {tmp_path / 'cli'}: its fit.bootstrap is 1" in said[0], said
    assert "taken as 0, a fit without intervals" in said[0] and "fit.bootstrap 2 or more" in said[0]
    summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert summary["fit"]["bootstrap"] == 0 and summary["fit"]["a_ci"] == [None, None]
    assert summary["resumed_realizations"] == first.done  # what finished was kept, not computed again
    assert yaml.safe_load((tmp_path / "cli" / "preset.yaml").read_text())["fit"]["bootstrap"] == 0
    same_files(tmp_path / "cli", tmp_path / "whole")
    # the preset given as it now reads (bootstrap 0) resumes the folder too
    resumed, _ = run_to_folder(now, tmp_path / "api", RunOptions(workers=1, resume=True))
    assert resumed.status == "completed" and resumed.extra["resumed"] == first.done
    same_files(tmp_path / "api", tmp_path / "whole")


def test_a_field_added_later_but_given_another_value_than_its_default_is_refused(make_scene, tmp_path):
    cancel = threading.Event()
    cancel.set()
    run_to_folder(make_scene(NO_PLOT), tmp_path / "run", RunOptions(workers=1), cancel=cancel)
    _as_written_before(tmp_path / "run", ADDED_LATER)
    other = make_scene({"solver": {"params": {"poisson_ratio": 0.3}}})
    with pytest.raises(FrictionlabError, match=r"solver\.params\.poisson_ratio: '\(absent\)' in the run directory, 0\.3 given"):
        run_to_folder(other, tmp_path / "run", RunOptions(workers=1, resume=True))


def test_a_fresh_run_over_an_unfinished_one_is_refused(make_scene, tmp_path):
    scene = make_scene({"realizations": 30, **NO_PLOT})
    cancel = threading.Event()
    run_to_folder(scene, tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(3, cancel)], cancel=cancel)
    with pytest.raises(FrictionlabError, match="holds an unfinished run .* continue it with --resume"):
        run_to_folder(scene, tmp_path / "run", RunOptions(workers=1))


def test_resume_of_a_folder_without_a_run_says_so(tmp_path, capsys):
    assert main(["resume", str(tmp_path)]) == ExitCode.RUN_FOLDER
    assert f"{tmp_path} holds no run to resume (no preset.yaml)" in capsys.readouterr().err


def test_a_run_resumed_into_a_sweeps_folder_is_told_what_continues_the_sweep(make_scene, tmp_path):
    """run --resume --out SWEEPDIR said only "no run.json": a sweep keeps one per point."""
    (tmp_path / "sweep.json").write_text("{}")
    with pytest.raises(FrictionlabError, match=rf"no run.json\): it is a sweep's folder, which `frictionlab resume {tmp_path}` continues"):
        run_to_folder(make_scene(NO_PLOT), tmp_path, RunOptions(workers=1, resume=True))
    (tmp_path / "sweep.json").unlink()
    with pytest.raises(FrictionlabError, match=r"holds no run to resume \(no run.json\)$"):
        run_to_folder(make_scene(NO_PLOT), tmp_path, RunOptions(workers=1, resume=True))


def _children(pid: int) -> set[int]:
    found = set()
    for task in Path(f"/proc/{pid}/task").glob("*"):
        found.update(int(c) for c in (task / "children").read_text().split())
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        return False
    return state != "Z"


@pytest.fixture
def kill_preset_whole(built_once, registry):
    """``KILL_PRESET`` run uninterrupted, once a session: the numbers its killed runs end with."""
    return built_once("kill-preset-whole", lambda out: run_to_folder(build_scene(KILL_PRESET, registry=registry), out, RunOptions(workers=2)))


@pytest.mark.long
@pytest.mark.parametrize("data", [KILL_PRESET, KILL_SURFACE], ids=["line", "exact-3d-surface"])
def test_kill_9_mid_run_then_resume_gives_the_uninterrupted_numbers(registry, tmp_path, data, request):
    preset = tmp_path / "kill.yaml"
    preset.write_text(yaml.safe_dump(data))
    run_dir = tmp_path / "run"
    command = [sys.executable, "-m", "frictionlab", "run", str(preset), "--out", str(run_dir), "--workers", "2", "--quiet"]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60
    while len(list((run_dir / "chunks").glob("*.npz"))) < 2:
        assert process.poll() is None, process.stderr.read().decode()
        assert time.monotonic() < deadline, "no chunk written in 60 s"
        time.sleep(0.01)
    workers = _children(process.pid)
    process.send_signal(signal.SIGKILL)
    assert process.wait() == -signal.SIGKILL
    assert not (run_dir / "summary.json").exists(), "the run finished before the kill: nothing was tested"
    kept = len(list((run_dir / "chunks").glob("*.npz")))
    deadline = time.monotonic() + 30  # their parent's death signals them at once; a loaded machine runs them later
    while [pid for pid in workers if _alive(pid)] and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not [pid for pid in workers if _alive(pid)], "pool workers outlived the killed run (by 30 s)"

    resumed = subprocess.run(
        [sys.executable, "-m", "frictionlab", "resume", str(run_dir), "--workers", "2", "--json"],
        capture_output=True,
        text=True,
        timeout=600,  # a guard against a hang: a loaded machine took more than 120 s to finish the line's 2000
    )
    assert resumed.returncode == 0, resumed.stderr
    summary = json.loads(resumed.stdout)
    assert 0 < summary["resumed_realizations"] < data["realizations"]
    assert kept >= 2

    if data is KILL_PRESET:
        whole = request.getfixturevalue("kill_preset_whole")
    else:
        whole = tmp_path / "whole"
        run_to_folder(build_scene(data, registry=registry), whole, RunOptions(workers=2))
    same_files(run_dir, whole)


def test_a_chunks_folder_no_file_can_be_written_in_is_refused_before_any_realization(make_scene, tmp_path, monkeypatch, capsys):
    """A resume whose chunks/ cannot be written in (read-only) computed a chunk, failed to write it
    (exit 1) and said `frictionlab resume` computes the rest, which failed the same way: refused at
    once (exit 4), naming the folder, with the chunks kept and nothing computed."""
    import tempfile

    scene = make_scene({"realizations": 20, **NO_PLOT})
    cancel = threading.Event()
    run_to_folder(scene, tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(4, cancel)], cancel=cancel)
    chunks = tmp_path / "run" / "chunks"
    kept = {p.name: p.read_bytes() for p in chunks.iterdir()}
    chunks.chmod(0o555)  # refuses any user but root; for root, as the kernel would say it:
    refuse = tempfile.mkstemp

    def mkstemp(*args, dir=None, **kwargs):
        if dir is not None and Path(dir) == chunks:
            raise PermissionError(13, "Permission denied")
        return refuse(*args, dir=dir, **kwargs)

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    try:
        code = main(["resume", str(tmp_path / "run"), "--workers", "1", "--quiet"])
    finally:
        chunks.chmod(0o755)
    err = capsys.readouterr().err
    assert code == ExitCode.OUTPUT_REFUSED, err
    assert f"{chunks} cannot be written in: Permission denied: the run keeps its realizations there" in err
    assert {p.name: p.read_bytes() for p in chunks.iterdir()} == kept
